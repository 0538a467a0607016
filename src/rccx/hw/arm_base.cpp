#include "rccx/hw/arm_base.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rccx::hw {

ArmBase::ArmBase(kin::RobotModel model, const SimulatedArmOptions& options)
    : n_(model.dof()), model_(std::move(model)) {
  if (n_ == 0 || n_ > kin::kMaxJoints) {
    throw std::invalid_argument(
        fmt::format("{}: a simulated arm needs 1 to {} joints", model_.name, kin::kMaxJoints));
  }
  const kin::JointVector initial = options.initial.empty() ? model_.ready() : options.initial;
  if (initial.size() != n_) {
    throw std::invalid_argument(
        fmt::format("{}: {} initial joint values for {} joints", model_.name, initial.size(), n_));
  }
  for (std::size_t i = 0; i < n_; ++i) {
    const kin::Joint& j = model_.joints[i];
    JointState& s = joints_[i];
    if (!(j.resolution_per_count > 0) || !(j.max_velocity > 0) || !(j.lower < j.upper)) {
      throw std::invalid_argument(
          fmt::format("{}: joint {} needs limits, an encoder resolution and a max velocity",
                      model_.name, i + 1));
    }
    const double margin =
        j.type == kin::JointType::revolute ? kHardStopMargin_rad : kHardStopMargin_m;
    s.stop_lo = j.lower - margin;
    s.stop_hi = j.upper + margin;
    if (!(initial[i] >= s.stop_lo && initial[i] <= s.stop_hi)) {
      throw std::invalid_argument(fmt::format("{}: joint {}'s initial value {} is beyond its stops",
                                              model_.name, i + 1, initial[i]));
    }
    s.q = s.goal = s.setpoint = initial[i];
    s.max_velocity = j.max_velocity;
    s.resolution = j.resolution_per_count;
    s.calibrated = options.calibrated;
    s.origin = options.calibrated ? 0.0 : initial[i];
  }
  power_ = options.powered;
}

void ArmBase::advance_to(double t_s) noexcept {
  if (!(t_s >= time_s())) return;  // also refuses NaN
  // A tick is due at every whole servo period up to t_s (the epsilon absorbs the rounding of
  // t_s computed as a sum of periods).
  const auto due = static_cast<std::int64_t>(std::floor(t_s / kServoPeriod_s + 1e-6));
  while (ticks_ < due) tick();
}

double ArmBase::time_s() const noexcept {
  return static_cast<double>(ticks_) * kServoPeriod_s;
}

void ArmBase::advance_setpoint(JointState& s, double dt) const noexcept {
  const double previous = s.setpoint;
  if (s.rate <= 0.0) {
    s.setpoint = s.goal;
    s.setpoint_velocity = 0.0;
    return;
  }
  const double step = s.rate * dt;
  const double left = s.goal - s.setpoint;
  s.setpoint = std::abs(left) <= step ? s.goal : s.setpoint + std::copysign(step, left);
  s.setpoint_velocity = (s.setpoint - previous) / dt;
}

void ArmBase::tick() noexcept {
  const double dt = kServoPeriod_s;
  const bool servoing = power_ && !zero_gravity_;
  for (std::size_t i = 0; i < n_; ++i) {
    JointState& s = joints_[i];
    if (servoing) {
      advance_setpoint(s, dt);
    } else {
      s.goal = s.setpoint = s.q;
      s.setpoint_velocity = 0.0;
    }
  }
  if (power_) {
    servo_tick(dt);
  } else {
    // Brakes: a constant deceleration to rest, then held.
    for (std::size_t i = 0; i < n_; ++i) {
      JointState& s = joints_[i];
      const double dv = s.max_velocity / kBrakeStopTime_s * dt;
      s.qd = std::abs(s.qd) <= dv ? 0.0 : s.qd - std::copysign(dv, s.qd);
      s.q += s.qd * dt;
    }
  }
  for (std::size_t i = 0; i < n_; ++i) {
    JointState& s = joints_[i];
    clamp_to_stops(s);
    if (s.calibrating && servoing && s.setpoint == s.goal) {
      const double ready = model_.joints[i].ready;
      if (std::abs(s.q - ready) <= kCalibrationTolerance_counts * s.resolution &&
          std::abs(s.qd) <= kCalibrationStillFactor * s.max_velocity) {
        // The calibration mark is found: the counts become absolute.
        s.origin = 0.0;
        s.count_jump = 0;
        s.calibrated = true;
        s.calibrating = false;
      }
    }
  }
  ++ticks_;
}

void ArmBase::clamp_to_stops(JointState& s) const noexcept {
  if (s.q <= s.stop_lo) {
    s.q = s.stop_lo;
    s.qd = std::max(s.qd, 0.0);
  } else if (s.q >= s.stop_hi) {
    s.q = s.stop_hi;
    s.qd = std::min(s.qd, 0.0);
  }
}

JointReading ArmBase::read(std::size_t joint) const noexcept {
  JointReading r;
  if (joint >= n_ || joints_[joint].not_answering) {
    r.answered = false;
    return r;
  }
  const JointState& s = joints_[joint];
  r.counts = std::llround((s.q - s.origin) / s.resolution) + s.count_jump;
  r.encoder_error = s.encoder_error;
  r.calibrated = s.calibrated;
  r.calibrating = s.calibrating;
  return r;
}

bool ArmBase::command(std::size_t joint, const ServoCommand& c) noexcept {
  if (joint >= n_ || joints_[joint].not_answering) return false;
  if (!std::isfinite(c.target) || !std::isfinite(c.rate)) return false;
  if (!power_ || zero_gravity_) return true;  // the controller answers; its servo is off
  JointState& s = joints_[joint];
  switch (c.kind) {
    case ServoCommand::Kind::move:
      s.goal = c.target + s.origin;
      s.rate = std::abs(c.rate);
      s.calibrating = false;
      break;
    case ServoCommand::Kind::hold:
      s.goal = s.setpoint = s.q;
      s.rate = 0.0;
      s.setpoint_velocity = 0.0;
      s.calibrating = false;
      break;
    case ServoCommand::Kind::calibrate:
      // The seek starts where the joint is, slowly, towards the true ready position.
      s.setpoint = s.q;
      s.setpoint_velocity = 0.0;
      s.goal = model_.joints[joint].ready;
      s.rate = kCalibrationSpeedFactor * s.max_velocity;
      s.calibrating = true;
      break;
  }
  return true;
}

void ArmBase::hold_here(std::size_t j) noexcept {
  JointState& s = joints_[j];
  s.goal = s.setpoint = s.q;
  s.rate = 0.0;
  s.setpoint_velocity = 0.0;
  s.calibrating = false;
  on_servo_restart(j);
}

bool ArmBase::set_power(bool on) noexcept {
  if (on) {
    if (power_lost_) return false;
    if (!power_) {
      power_ = true;
      for (std::size_t i = 0; i < n_; ++i) hold_here(i);
    }
    return true;
  }
  power_ = false;
  for (std::size_t i = 0; i < n_; ++i) joints_[i].calibrating = false;
  return true;
}

void ArmBase::set_zero_gravity(bool on) noexcept {
  if (on == zero_gravity_) return;
  zero_gravity_ = on;
  for (std::size_t i = 0; i < n_; ++i) hold_here(i);
}

void ArmBase::set_external_effort(std::size_t joint, double effort) noexcept {
  if (joint < n_ && std::isfinite(effort)) joints_[joint].external = effort;
}

void ArmBase::inject(Fault fault, std::size_t joint) noexcept {
  switch (fault) {
    case Fault::joint_not_answering:
      if (joint < n_) joints_[joint].not_answering = true;
      break;
    case Fault::encoder_error:
      if (joint < n_) {
        joints_[joint].encoder_error = true;
        joints_[joint].count_jump += kEncoderErrorJump_counts;
      }
      break;
    case Fault::power_loss:
      power_lost_ = true;
      (void)set_power(false);
      break;
  }
}

void ArmBase::clear_faults() noexcept {
  power_lost_ = false;
  for (std::size_t i = 0; i < n_; ++i) {
    joints_[i].not_answering = false;
    joints_[i].encoder_error = false;
    joints_[i].count_jump = 0;
  }
}

kin::JointVector ArmBase::true_position() const noexcept {
  kin::JointVector q(n_);
  for (std::size_t i = 0; i < n_; ++i) q[i] = joints_[i].q;
  return q;
}

kin::JointVector ArmBase::true_velocity() const noexcept {
  kin::JointVector v(n_);
  for (std::size_t i = 0; i < n_; ++i) v[i] = joints_[i].qd;
  return v;
}

double ArmBase::servo_effort(const JointState& s, const ServoGains& g, double inertia,
                             double viscous, double max_effort, double hold, double dt,
                             double& integral) const noexcept {
  double tau = 0.0;
  if (zero_gravity()) {
    integral = 0.0;
    tau = hold - kZeroGravityDamping_per_s * inertia * s.qd;
  } else {
    const double e = s.setpoint - s.q;
    const double pd =
        g.kp * e + g.kd * (s.setpoint_velocity - s.qd) + viscous * s.setpoint_velocity + hold;
    double next = integral;
    if (std::abs(g.kp * e) < max_effort) {
      next = std::clamp(integral + e * dt, -max_effort / g.ki, max_effort / g.ki);
    }
    tau = pd + g.ki * next;
    if (std::abs(tau) < max_effort) integral = next;  // no wind-up while saturated
  }
  // The motor: max_effort at rest, falling to zero at the no-load speed when driving along the
  // motion; braking against the motion keeps the full effort.
  double drive_limit = max_effort;
  if (tau * s.qd > 0.0) {
    drive_limit *= std::max(0.0, 1.0 - std::abs(s.qd) / (kOverspeedFactor * s.max_velocity));
  }
  return std::clamp(tau, -drive_limit, drive_limit);
}

}  // namespace rccx::hw
