// rccx's position equations for Python: transforms checked and copied between NumPy arrays and
// math::Transform, the C++ errors left to carry rccx's messages (EquationError, MotionError are
// registered as Python exceptions in arm_module.cpp).
#include "rccl.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rccx::python {

namespace {

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

rccl::TransformPtr make_constant(const std::string& name, const InArray& T) {
  return rccl::constant(name, transform_in(T, "const " + name));
}

rccl::TransformPtr make_hold(const std::string& name, const std::optional<InArray>& T) {
  return rccl::hold(name, T ? transform_in(*T, "hold " + name) : math::Transform::identity());
}

void set_hold(rccl::Transform& t, const InArray& T) {
  if (t.kind() != rccl::TransformKind::hold) {
    throw py::type_error(fmt::format("{} is a {} transform: only a hold transform can be set",
                                     t.name(), rccl::to_string(t.kind())));
  }
  t.set(transform_in(T, t.name() + ".set"));
}

OutArray transform_value(const rccl::Transform& t) {
  switch (t.kind()) {
    case rccl::TransformKind::constant:
    case rccl::TransformKind::hold:
      return transform_out(t.value());
    case rccl::TransformKind::functional:
      return transform_out(t.value_now({}));
    case rccl::TransformKind::t6:
      break;
  }
  raise_value_error("T6 has no value of its own: it is the unknown of the equations");
}

std::string transform_repr(const rccl::Transform& t) {
  return fmt::format("rccx.Transform('{}', {})", t.name(), rccl::to_string(t.kind()));
}

StreamTransform::StreamTransform(std::string name, std::shared_ptr<State> state)
    : rccl::Transform(std::move(name), rccl::TransformKind::functional, math::Transform::identity(),
                      // The loop's read: the newest sample, lock-free; never Python.
                      [s = state](const rccl::SampleContext& ctx) {
                        Sample sample;
                        if (!s->latest.load(sample)) return s->initial;
                        // Planning (no sample read) takes the pose as put, as remote frames do.
                        if (ctx.how == nullptr || std::isnan(sample.at_s)) return sample.pose;
                        const double dt = std::clamp(ctx.t_s - sample.at_s, -s->max_extrapolation_s,
                                                     s->max_extrapolation_s);
                        math::Transform p = sample.pose;
                        p.p += sample.velocity_m_per_s * dt;
                        p.R = math::rotated_by(p.R, sample.angular_velocity_rad_per_s, dt);
                        return p;
                      }),
      state_(std::move(state)) {}

void StreamTransform::put(const InArray& T, std::optional<double> at_s,
                          const std::optional<InArray>& velocity) {
  Sample sample;
  sample.pose = transform_in(T, name() + ".put");
  if (at_s) {
    if (!std::isfinite(*at_s)) {
      raise_value_error(
          fmt::format("{}.put: at must be a finite session time, s, got {}", name(), *at_s));
    }
    sample.at_s = *at_s;
  }
  if (velocity) {
    if (!at_s) {
      raise_value_error(fmt::format(
          "{}.put: a velocity needs at= (the session time the pose is for, s, e.g. arm.time)",
          name()));
    }
    if (ndim(*velocity) != 1 || extent(*velocity, 0) != 6 || !all_finite(velocity->data(), 6)) {
      raise_value_error(fmt::format(
          "{}.put: velocity must be 6 finite values (m/s, m/s, m/s, rad/s, rad/s, rad/s), got "
          "shape {}",
          name(), shape_text(*velocity)));
    }
    const double* v = velocity->data();
    sample.velocity_m_per_s = {v[0], v[1], v[2]};
    sample.angular_velocity_rad_per_s = {v[3], v[4], v[5]};
  }
  const ReleaseGil release;  // another writer may hold the lock a moment
  const std::lock_guard lock(state_->writers);
  sample.stamp_ns = steady_ns();
  state_->latest.store(sample);
  ++state_->count;
}

OutArray StreamTransform::newest() const {
  Sample s;
  return transform_out(state_->latest.load(s) ? s.pose : state_->initial);
}

std::optional<double> StreamTransform::age() const {
  Sample s;
  if (!state_->latest.load(s)) return std::nullopt;
  return static_cast<double>(steady_ns() - s.stamp_ns) * 1e-9;
}

std::uint64_t StreamTransform::count() const {
  const std::lock_guard lock(state_->writers);
  return state_->count;
}

std::shared_ptr<StreamTransform> make_stream(const std::string& name,
                                             const std::optional<InArray>& T,
                                             double max_extrapolation_s) {
  if (!(max_extrapolation_s >= 0.0 && max_extrapolation_s <= 10.0)) {
    raise_value_error(fmt::format("stream {}: max_extrapolation must be within 0 .. 10 s, got {}",
                                  name, max_extrapolation_s));
  }
  auto state = std::make_shared<StreamTransform::State>();
  state->initial = T ? transform_in(*T, "stream " + name) : math::Transform::identity();
  state->max_extrapolation_s = max_extrapolation_s;
  return std::make_shared<StreamTransform>(name, std::move(state));
}

rccl::PositionPtr make_position(const std::string& name, const std::vector<rccl::TransformPtr>& lhs,
                                const std::vector<rccl::TransformPtr>& rhs,
                                const rccl::TransformPtr& tool) {
  return tool ? rccl::Position::make(name, lhs, rhs, tool) : rccl::Position::make(name, lhs, rhs);
}

rccl::PositionPtr make_joints(const std::string& name, const InArray& q) {
  if (ndim(q) != 1 || extent(q, 0) == 0 || extent(q, 0) > kin::kMaxJoints) {
    raise_value_error(fmt::format(
        "joints {}: q must have shape (dof,) (rad or m), at most {} values, got shape {}", name,
        kin::kMaxJoints, shape_text(q)));
  }
  if (!all_finite(q.data(), extent(q, 0))) {
    raise_value_error(fmt::format("joints {}: q has a non-finite value", name));
  }
  return rccl::Position::joints(name,
                                kin::JointVector(std::span<const double>(q.data(), extent(q, 0))));
}

OutArray position_t6(const rccl::Position& p) {
  if (p.in_joints()) raise_value_error(p.name() + " is given in joints: it has no equation");
  if (p.moves()) {
    raise_value_error(p.name() + " has a functional transform: its T6 depends on the sample");
  }
  return transform_out(p.t6_now());
}

OutArray position_tool(const rccl::Position& p) {
  return transform_out(p.tool_now());
}

OutArray position_joints(const rccl::Position& p) {
  if (!p.in_joints()) raise_value_error(p.name() + " is an equation, not joint values");
  return to_array(p.joint_values().span());
}

}  // namespace rccx::python
