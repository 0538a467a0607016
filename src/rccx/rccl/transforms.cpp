#include "rccx/rccl/transforms.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "rccx/rtc/types.hpp"

namespace rccx::rccl {
namespace {

void check_rigid(const std::string& name, const math::Transform& value) {
  if (!is_rigid(value)) {
    throw std::invalid_argument(
        fmt::format("transform {}: the value is not a rigid transform (its rotation must be "
                    "orthonormal and right-handed, every element finite)",
                    name));
  }
}

}  // namespace

double SampleContext::sample_time_s() const noexcept {
  return how != nullptr ? how->time_s : t_s;
}

std::string_view to_string(TransformKind kind) noexcept {
  switch (kind) {
    case TransformKind::constant:
      return "constant";
    case TransformKind::functional:
      return "functional";
    case TransformKind::hold:
      return "hold";
    case TransformKind::t6:
      return "T6";
  }
  return "?";
}

Transform::Transform(std::string name, TransformKind kind, const math::Transform& value,
                     TransformFunction function)
    : name_(std::move(name)),
      kind_(kind),
      planning_value_(value),
      function_(std::move(function)),
      loop_value_(value) {}

void Transform::set(const math::Transform& value) {
  if (kind_ != TransformKind::hold) {
    throw std::logic_error(
        fmt::format("transform {} is {}: only hold transforms can be set after they are made "
                    "(make it with rccl::hold)",
                    name_, to_string(kind_)));
  }
  check_rigid(name_, value);
  planning_value_ = value;
  published_.publish(value);
}

math::Transform Transform::value_now(const SampleContext& ctx) const {
  switch (kind_) {
    case TransformKind::functional:
      return function_(ctx);
    case TransformKind::t6:
      throw std::logic_error("T6 has no value of its own: it is the unknown");
    default:
      return planning_value_;
  }
}

const math::Transform& Transform::evaluate(const SampleContext& ctx) const {
  if (ctx.sample != loop_sample_ || ctx.sample == 0) {
    loop_value_ = function_(ctx);
    loop_sample_ = ctx.sample;
  }
  return loop_value_;
}

const math::Transform& Transform::latch() const noexcept {
  published_.take(loop_value_);
  return loop_value_;
}

bool is_rigid(const math::Transform& t, double tolerance) noexcept {
  for (double v : t.rows()) {
    if (!std::isfinite(v)) return false;
  }
  const math::Rot3& R = t.R;
  const auto near = [tolerance](double a, double b) { return std::abs(a - b) <= tolerance; };
  return near(dot(R.n, R.n), 1) && near(dot(R.o, R.o), 1) && near(dot(R.a, R.a), 1) &&
         near(dot(R.n, R.o), 0) && near(dot(R.n, R.a), 0) && near(dot(R.o, R.a), 0) &&
         near(dot(cross(R.n, R.o), R.a), 1);
}

TransformPtr constant(std::string name, const math::Transform& value) {
  check_rigid(name, value);
  return std::make_shared<Transform>(std::move(name), TransformKind::constant, value,
                                     TransformFunction{});
}

TransformPtr functional(std::string name, TransformFunction function) {
  if (!function) {
    throw std::invalid_argument(fmt::format("functional transform {} needs a function", name));
  }
  return std::make_shared<Transform>(std::move(name), TransformKind::functional,
                                     math::Transform::identity(), std::move(function));
}

TransformPtr hold(std::string name, const math::Transform& value) {
  auto t = std::make_shared<Transform>(std::move(name), TransformKind::hold,
                                       math::Transform::identity(), TransformFunction{});
  t->set(value);
  return t;
}

TransformPtr t6() {
  static const TransformPtr the_t6 = std::make_shared<Transform>(
      "T6", TransformKind::t6, math::Transform::identity(), TransformFunction{});
  return the_t6;
}

}  // namespace rccx::rccl
