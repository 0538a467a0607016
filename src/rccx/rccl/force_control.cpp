#include "rccx/rccl/force_control.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rccx::rccl {

namespace {

/// Frame F moved by a small offset expressed in its own axes: translation, then rotation by the
/// rotation vector (rad).
math::Transform offset_frame(const std::array<double, 6>& x) noexcept {
  const math::Vec3 w{x[3], x[4], x[5]};
  const double angle = w.norm();
  math::Transform t = math::Transform::translation(x[0], x[1], x[2]);
  if (angle > 0.0) t.R = math::Rot3::about(w, angle);
  return t;
}

}  // namespace

// The planning side writes only the pending copies (the loop's own are never read here).
void ForceControl::set_tool_load(const force::ToolLoad& load) noexcept {
  pending_load_ = load;
  load_changed_.store(true, std::memory_order_release);
}

void ForceControl::set_world_from_base(const math::Rot3& r) noexcept {
  pending_world_ = r;
  load_changed_.store(true, std::memory_order_release);
}

void ForceControl::reset() noexcept {
  offset_ = {};
  applied_ = {};
  past_count_ = past_next_ = 0;
  past_motion_ = 0;
}

double ForceControl::guarded_value(const ForceGuard& g) const noexcept {
  if (g.kind == ForceGuard::Kind::magnitude) return applied_.force_N.norm();
  return applied_.to_array()[std::min<std::size_t>(g.axis, 5)];
}

Contact ForceControl::contact(std::uint64_t id) const noexcept {
  return contacts_[id % kContacts];
}

void ForceControl::record_contact(std::uint64_t id, const ForceGuard& g,
                                  const math::Transform& tool) noexcept {
  // Going back from the trip: the contact began after the last sample whose force was below
  // the onset (the guard trips only once the contact has pushed back hard enough).
  const double onset = kOnsetFraction * std::abs(g.threshold);
  std::size_t k = (past_next_ + kHistory - 1) % kHistory;  // the newest: this sample
  std::size_t first = k;
  for (std::size_t n = 0; n < past_count_; ++n) {
    const Past& p = past_[k];
    const double along = g.kind == ForceGuard::Kind::magnitude
                             ? p.guarded
                             : std::copysign(1.0, g.threshold) * p.guarded;
    if (along < onset) break;
    first = k;
    k = (k + kHistory - 1) % kHistory;
  }
  Contact c;
  c.motion = id;
  c.t_s = past_[first].t_s;
  c.t6 = past_[first].t6;
  c.tool_frame = c.t6 * tool;
  c.wrench = applied_;
  contacts_[id % kContacts] = c;
}

void ForceControl::comply(const Compliance& c, double dt) noexcept {
  const std::array<double, 6> f = applied_.to_array();
  for (std::size_t i = 0; i < 6; ++i) {
    const bool force_axis = i < 3;
    const double top = force_axis ? c.max_speed_m_per_s : c.max_rotation_rad_per_s;
    const double far = force_axis ? c.max_offset_m : c.max_offset_rad;
    double rate = 0.0;
    if (c.compliant(i)) {
      const double damping = c.damping[i] > 0.0 ? c.damping[i]
                                                : (force_axis ? kDefaultDamping_N_s_per_m
                                                              : kDefaultDamping_N_m_s_per_rad);
      rate = ((c.force[i] - f[i]) - c.stiffness[i] * offset_[i]) / damping;
    } else {
      // Back to the path in a few tenths of a second, never faster than the limit.
      rate = -offset_[i] / 0.25;
    }
    rate = std::clamp(rate, -top, top);
    offset_[i] = std::clamp(offset_[i] + rate * dt, -far, far);
    // The last bit of a returning offset: done (an exponential never reaches zero).
    if (!c.compliant(i) && std::abs(offset_[i]) < (force_axis ? 1e-7 : 1e-6)) offset_[i] = 0.0;
  }
}

ForceControl::Outcome ForceControl::apply_offset(const math::Transform& tool,
                                                 kin::JointVector& q) noexcept {
  const bool moved = std::any_of(offset_.begin(), offset_.end(), [](double x) { return x != 0; });
  if (!moved) return Outcome::none;
  const math::Transform frame = kin_.forward(q) * tool;
  const math::Transform t6 = frame * offset_frame(offset_) * tool.inverse();
  kin::IkOptions o;
  o.configuration = kin_.configuration_of(q);
  o.near = q;
  kin::IkResult r = kin_.inverse(t6, o);
  if (!r) {
    const std::string_view reason = kin::describe(r.status);
    // Back to the last offset that could be followed, and no further.
    r = kin_.inverse(frame * offset_frame(last_good_offset_) * tool.inverse(), o);
    if (r) q = r.q;
    std::snprintf(why_.data(), why_.size(),
                  "compliance moved the tool where the arm cannot follow (%.*s)",
                  static_cast<int>(reason.size()), reason.data());
    offset_ = last_good_offset_;
    return Outcome::unreachable;
  }
  last_good_offset_ = offset_;
  q = r.q;
  return Outcome::none;
}

ForceControl::Outcome ForceControl::step(const rtc::How& how, std::uint64_t id,
                                         const MotionSettings* settings, double period_s,
                                         kin::JointVector& q) noexcept {
  if (load_changed_.exchange(false, std::memory_order_acquire)) {
    load_ = pending_load_;
    world_from_base_ = pending_world_;
  }
  const bool wants = settings != nullptr && (settings->guard.on() || settings->compliance.any());
  const bool offset = std::any_of(offset_.begin(), offset_.end(), [](double x) { return x != 0; });
  if (!how.force.present || (!wants && !offset)) {
    applied_ = {};
    past_count_ = 0;
    return Outcome::none;
  }
  if (settings != nullptr) last_tool_ = settings->tool;
  const math::Transform& tool = last_tool_;
  const math::Transform t6 = kin_.forward(how.q());
  const math::Wrench external =
      force::external_wrench(load_, world_from_base_ * t6.R, how.force.wrench);
  applied_ = force::at_tool(tool, external) * -1.0;

  if (settings != nullptr && settings->guard.on()) {
    const ForceGuard& g = settings->guard;
    if (id != past_motion_) {
      past_motion_ = id;
      past_count_ = 0;
    }
    past_[past_next_] = {how.time_s, guarded_value(g), t6};
    past_next_ = (past_next_ + 1) % kHistory;
    past_count_ = std::min(past_count_ + 1, kHistory);
    const double v = guarded_value(g);
    const bool tripped = g.kind == ForceGuard::Kind::magnitude || g.threshold >= 0.0
                             ? v >= std::abs(g.threshold)
                             : v <= g.threshold;
    if (tripped) {
      record_contact(id, g, tool);
      return Outcome::contact;
    }
  }

  // After an overload the offset stays as it was until the next motion starts.
  if (held_for_ != 0 && id != held_for_) held_for_ = 0;
  if (held_for_ != 0 || (id == 0 && held_after_stop_)) return apply_offset(tool, q);
  held_after_stop_ = false;
  const Compliance none{};
  const Compliance& c = settings != nullptr ? settings->compliance : none;
  if (c.any()) {
    const double f = applied_.force_N.norm(), t = applied_.torque_N_m.norm();
    const bool over = f > c.max_force_N || t > c.max_torque_N_m;
    if (id != yield_motion_) {  // its first compliant sample
      yield_motion_ = id;
      yielding_ = over;
      yield_since_s_ = how.time_s;
    } else if (!over) {
      yielding_ = false;  // from now on the limits hold
    }
    const double yielded_s = how.time_s - yield_since_s_;
    if (over && !(yielding_ && yielded_s < kYieldWithin_s)) {
      if (yielding_) {
        std::snprintf(why_.data(), why_.size(),
                      "the tool still exerted %.1f N, %.2f N m after yielding %.1f s from the "
                      "start of the compliant motion (limits %.1f N, %.2f N m)",
                      f, t, yielded_s, c.max_force_N, c.max_torque_N_m);
      } else {
        std::snprintf(why_.data(), why_.size(),
                      "the tool exerted %.1f N, %.2f N m while compliant (limits %.1f N, %.2f N m)",
                      f, t, c.max_force_N, c.max_torque_N_m);
      }
      held_for_ = id;
      held_after_stop_ = true;
      return Outcome::overload;
    }
  }
  comply(c, period_s);
  const Outcome o = apply_offset(tool, q);
  if (o == Outcome::unreachable) {
    held_for_ = id;
    held_after_stop_ = true;
  }
  return o;
}

}  // namespace rccx::rccl
