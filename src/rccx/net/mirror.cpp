#include "rccx/net/mirror.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>

#include "rccx/net/codec.hpp"
#include "rccx/net/dds.hpp"

namespace rccx::net {

std::int64_t steady_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

rccl::TransformPtr remote_frame(std::string name, std::string reference,
                                const cell::SeqLock<FrameState>* source,
                                std::chrono::nanoseconds max_extrapolation) {
  const double max_dt = std::chrono::duration<double>(max_extrapolation).count();
  auto t = rccl::functional(std::move(name), [source, max_dt](const rccl::SampleContext& ctx) {
    FrameState s;
    if (!source->load(s)) return math::Transform::identity();
    if (ctx.how == nullptr) return s.pose;
    // The wall time this setpoint is for: now plus how far the setpoint runs ahead of the
    // sample (the follower's pipeline), against the wall time the source's pose is for.
    const std::int64_t target =
        wall_ns() + static_cast<std::int64_t>((ctx.t_s - ctx.sample_time_s()) * 1e9);
    const double dt = std::clamp(static_cast<double>(target - s.stamp_ns) * 1e-9, -0.25, max_dt);
    math::Transform p = s.pose;
    p.p = p.p + s.velocity_m_per_s * dt + s.acceleration_m_per_s2 * (dt * dt / 2.0);
    p.R = math::rotated_by(p.R, s.angular_velocity_rad_s, dt);
    return p;
  });
  t->set_reference(std::move(reference));
  return t;
}

bool RobotMirror::apply(const rccx_net_RobotState& s, std::int64_t steady) noexcept {
  bool restarted = false;
  // The last state of a serve process that has stopped (control ended) arriving while another
  // instance serves the robot and is alive: stale, not a restart. Taken, it would clear the
  // ledger and end the robot's control for the gates waiting on it.
  if (s.instance != instance_ && instance_ != 0 && !lost() && s.control_ended) return false;
  if (s.instance != instance_) {
    restarted = instance_ != 0;
    instance_ = s.instance;
    participant_.assign(text_of(s.participant));  // rarely: a new serve process
    ledger.clear();
    applied_ = 0;
  }
  FrameState f;
  f.pose = from_pose(s.tool);
  f.velocity_m_per_s = {s.velocity[0], s.velocity[1], s.velocity[2]};
  f.acceleration_m_per_s2 = {s.acceleration[0], s.acceleration[1], s.acceleration[2]};
  f.angular_velocity_rad_s = {s.angular_velocity[0], s.angular_velocity[1], s.angular_velocity[2]};
  f.stamp_ns = s.stamp_ns;
  frame.store(f);
  JointsSample j;
  const std::size_t dof = std::min<std::size_t>(s.dof, kin::kMaxJoints);
  j.q = kin::JointVector(std::span<const double>(s.q_commanded, dof));
  j.qd = kin::JointVector(std::span<const double>(s.qd_commanded, dof));
  j.received_ns = steady;
  joints.store(j);
  // Failures before the counters, so that a reader never sees a failed motion as ended.
  for (int k = 3; k >= 0; --k) {
    const std::uint64_t from = s.failed_from[k], to = s.failed_to[k];
    if (from == 0) continue;
    bool known = false;
    for (std::uint32_t i = 0; i < std::min<std::uint32_t>(applied_, 8); ++i) {
      if (applied_from_[i] == from && applied_to_[i] == to) known = true;
    }
    if (known) continue;
    ledger.mark_failed(from, to);
    applied_from_[applied_ % 8] = from;
    applied_to_[applied_ % 8] = to;
    ++applied_;
  }
  ledger.mark_started(s.started_upto);
  ledger.mark_ended(s.ended_upto);
  control_ended_ = s.control_ended;
  if (!lost()) ledger.set_control_ended(control_ended_);
  received_ns_.store(steady, std::memory_order_release);
  return restarted;
}

void RobotMirror::set_lost(bool lost) noexcept {
  lost_.store(lost, std::memory_order_release);
  ledger.set_control_ended(lost || control_ended_);
}

}  // namespace rccx::net
