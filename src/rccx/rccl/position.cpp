#include "rccx/rccl/position.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace rccx::rccl {
namespace {

std::string names(const std::vector<TransformPtr>& side) {
  std::string s;
  for (const TransformPtr& t : side) {
    if (!s.empty()) s += ' ';
    s += t ? t->name() : "(null)";
  }
  return s;
}

}  // namespace

void Position::append(Factors& to, const TransformPtr& t, bool inverted, std::uint8_t& holds) {
  Factor f;
  f.kind = t->kind();
  f.inverted = inverted;
  if (f.kind == TransformKind::constant) {
    const math::Transform v = inverted ? t->value().inverse() : t->value();
    if (!to.empty() && to.back().kind == TransformKind::constant) {
      to.back().value = to.back().value * v;  // a run of constants: one product, once
      return;
    }
    f.value = v;
  } else {
    f.source = t.get();
    if (f.kind == TransformKind::hold) f.hold_slot = holds++;
  }
  to.push_back(f);
}

PositionPtr Position::make(std::string name, const std::vector<TransformPtr>& lhs,
                           const std::vector<TransformPtr>& rhs) {
  // An empty left side is refused by make() below for its missing T6.
  return make(std::move(name), lhs, rhs, lhs.empty() ? nullptr : lhs.back());
}

PositionPtr Position::make(std::string name, const std::vector<TransformPtr>& lhs,
                           const std::vector<TransformPtr>& rhs, const TransformPtr& tool) {
  const auto fail = [&](std::string_view why) {
    return EquationError(
        fmt::format("position {} ({} = {}): {}", name, names(lhs), names(rhs), why));
  };
  const auto is_t6 = [](const TransformPtr& t) { return t && t->kind() == TransformKind::t6; };
  for (const auto* side : {&lhs, &rhs}) {
    if (std::any_of(side->begin(), side->end(), [](const TransformPtr& t) { return !t; })) {
      throw fail("a transform is null (was it made?)");
    }
  }
  if (std::any_of(rhs.begin(), rhs.end(), is_t6)) {
    throw fail("T6 is on the right side; write it on the left: T6 [TOOL] = ...");
  }
  const auto t6_count = std::count_if(lhs.begin(), lhs.end(), is_t6);
  if (t6_count == 0) throw fail("there is no T6 on the left side: every equation solves for T6");
  if (t6_count > 1) throw fail("T6 appears more than once on the left side");
  if (rhs.empty()) throw fail("the right side is empty: give the goal, e.g. T6 = B");
  std::vector<const Transform*> seen;
  for (const auto* side : {&lhs, &rhs}) {
    for (const TransformPtr& t : *side) {
      if (is_t6(t)) continue;
      if (std::find(seen.begin(), seen.end(), t.get()) != seen.end()) {
        throw fail(fmt::format("transform {} appears twice; an equation uses each transform once",
                               t->name()));
      }
      seen.push_back(t.get());
    }
  }
  const auto t6_at =
      static_cast<std::size_t>(std::find_if(lhs.begin(), lhs.end(), is_t6) - lhs.begin());
  if (!tool) throw fail("no tool transform given (name T6 itself when there is no tool)");
  const auto tool_it = std::find(lhs.begin() + static_cast<std::ptrdiff_t>(t6_at), lhs.end(), tool);
  if (tool_it == lhs.end()) {
    throw fail(
        fmt::format("the tool {} is not on the left side after T6; the tool is one of "
                    "the transforms between T6 and the equals sign (or T6 itself)",
                    tool->name()));
  }
  const auto tool_at = static_cast<std::size_t>(tool_it - lhs.begin());
  std::size_t holds = 0;
  for (const auto* side : {&lhs, &rhs}) {
    holds += static_cast<std::size_t>(std::count_if(side->begin(), side->end(), [](const auto& t) {
      return t->kind() == TransformKind::hold;
    }));
  }
  if (holds > kMaxHolds) {
    throw fail(fmt::format("{} hold transforms; at most {} in one equation", holds, kMaxHolds));
  }

  PositionPtr p(new Position());
  p->name_ = std::move(name);
  p->lhs_ = lhs;
  p->rhs_ = rhs;
  p->tool_transform_ = tool;
  std::uint8_t slots = 0;
  // goal = Ak⁻¹ .. A1⁻¹  C1 .. Cn  Bm⁻¹ .. Bj+1⁻¹
  for (std::size_t i = t6_at; i-- > 0;) append(p->goal_, lhs[i], true, slots);
  for (const TransformPtr& t : rhs) append(p->goal_, t, false, slots);
  for (std::size_t i = lhs.size(); i-- > tool_at + 1;) append(p->goal_, lhs[i], true, slots);
  // tool = B1 .. Bj
  for (std::size_t i = t6_at + 1; i <= tool_at; ++i) append(p->tool_, lhs[i], false, slots);
  for (const Factors* fs : {&p->goal_, &p->tool_}) {
    for (const Factor& f : *fs) {
      if (f.kind == TransformKind::functional) p->moves_ = true;
      if (f.kind == TransformKind::hold) p->holds_[f.hold_slot] = f.source;
    }
  }
  p->hold_count_ = slots;
  return p;
}

PositionPtr Position::joints(std::string name, const kin::JointVector& q) {
  for (double v : q) {
    if (!std::isfinite(v)) {
      throw EquationError(fmt::format("position {}: a joint value is not finite", name));
    }
  }
  PositionPtr p(new Position());
  p->name_ = std::move(name);
  p->in_joints_ = true;
  p->joints_ = q;
  return p;
}

std::string Position::describe() const {
  if (in_joints_) return fmt::format("{} (joint values)", name_);
  return fmt::format("{}: {} = {} (tool {})", name_, names(lhs_), names(rhs_),
                     tool_transform_->name());
}

math::Transform Position::product(const Factors& fs, const SampleContext& ctx,
                                  const LatchedHolds& holds) {
  math::Transform r = math::Transform::identity();
  bool first = true;
  for (const Factor& f : fs) {
    math::Transform v;
    switch (f.kind) {
      case TransformKind::constant:
        v = f.value;
        break;
      case TransformKind::functional:
        v = ctx.predicted ? f.source->value_now(ctx) : f.source->evaluate(ctx);
        break;
      case TransformKind::hold:
        v = holds.values[f.hold_slot];
        break;
      case TransformKind::t6:
        continue;
    }
    if (f.inverted && f.kind != TransformKind::constant) v = v.inverse();
    r = first ? v : r * v;
    first = false;
  }
  return r;
}

void Position::latch(LatchedHolds& holds) const noexcept {
  for (std::uint8_t i = 0; i < hold_count_; ++i) holds.values[i] = holds_[i]->latch();
}

void Position::evaluate(const SampleContext& ctx, const LatchedHolds& holds, math::Transform& goal,
                        math::Transform& tool) const {
  goal = product(goal_, ctx, holds);
  tool = product(tool_, ctx, holds);
}

math::Transform Position::solve_for(const Transform& x, const math::Transform& t6,
                                    const SampleContext& ctx) const {
  if (in_joints_) throw EquationError(fmt::format("position {} is given in joints", name_));
  if (x.kind() == TransformKind::t6) {
    throw EquationError(
        fmt::format("position {}: T6 is what the equation solves for; name "
                    "another of its transforms",
                    describe()));
  }
  // L1 X L2 = R (x on the left) or L = R1 X R2 (on the right): X = L1⁻¹ R L2⁻¹ or R1⁻¹ L R2⁻¹.
  const auto value = [&](const TransformPtr& t) {
    return t->kind() == TransformKind::t6 ? t6 : t->value_now(ctx);
  };
  const auto split = [&](const std::vector<TransformPtr>& side, math::Transform& before,
                         math::Transform& after) {
    bool found = false;
    before = after = math::Transform::identity();
    for (const TransformPtr& t : side) {
      if (t.get() == &x) {
        found = true;
      } else if (found) {
        after = after * value(t);
      } else {
        before = before * value(t);
      }
    }
    return found;
  };
  const auto product = [&](const std::vector<TransformPtr>& side) {
    math::Transform p = math::Transform::identity();
    for (const TransformPtr& t : side) p = p * value(t);
    return p;
  };
  math::Transform before, after;
  if (split(lhs_, before, after)) return before.inverse() * product(rhs_) * after.inverse();
  if (split(rhs_, before, after)) return before.inverse() * product(lhs_) * after.inverse();
  throw EquationError(
      fmt::format("position {}: transform {} is not in the equation", describe(), x.name()));
}

math::Transform Position::tool_now() const {
  for (const Factor& f : tool_) {
    if (f.kind == TransformKind::functional) {
      throw std::logic_error(fmt::format(
          "position {}: its tool has functional transforms, known only in the sample loop", name_));
    }
  }
  LatchedHolds holds;
  for (std::uint8_t i = 0; i < hold_count_; ++i) holds.values[i] = holds_[i]->value();
  return product(tool_, {}, holds);
}

math::Transform Position::t6_at(const SampleContext& ctx) const {
  LatchedHolds holds;
  for (std::uint8_t i = 0; i < hold_count_; ++i) holds.values[i] = holds_[i]->value();
  SampleContext c = ctx;
  c.predicted = true;  // functional transforms called afresh, the loop's cache left alone
  math::Transform goal, tool;
  evaluate(c, holds, goal, tool);
  return goal * tool.inverse();
}

math::Transform Position::t6_now() const {
  if (moves_) {
    throw std::logic_error(fmt::format(
        "position {} has functional transforms: its T6 is known only in the sample loop", name_));
  }
  LatchedHolds holds;
  for (std::uint8_t i = 0; i < hold_count_; ++i) holds.values[i] = holds_[i]->value();
  math::Transform goal, tool;
  evaluate({}, holds, goal, tool);
  return goal * tool.inverse();
}

}  // namespace rccx::rccl
