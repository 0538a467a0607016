#include "rccx/rtc/servo_driver.hpp"

namespace rccx::rtc {

ServoDriver::ServoDriver(hw::SimulatedArm& arm) : arm_(arm) {
  math::Wrench probe;
  if (arm.wrist_wrench(probe)) force_sensor_.emplace(arm);
}

bool ServoDriver::set_force_sensor_spec(const hw::ForceSensorSpec& spec) {
  if (!force_sensor_) return false;
  force_sensor_.emplace(arm_, spec);
  force_stale_ = 0;
  return true;
}

void ServoDriver::read(double t_s, How& how) noexcept {
  arm_.advance_to(t_s);
  const auto& joints = arm_.model().joints;
  const std::size_t n = joints.size();
  how.dof = static_cast<std::uint8_t>(n);
  JointVector q(n);
  bool all_calibrated = true;
  for (std::size_t i = 0; i < n; ++i) {
    const hw::JointReading r = arm_.read(i);
    std::uint16_t flags = 0;
    if (!r.answered) {
      flags |= kNotAnswering;
      q[i] = how.joint[i].q;  // keep the last known value
    } else {
      q[i] = static_cast<double>(r.counts) * joints[i].resolution_per_count;
      if (r.encoder_error) flags |= kEncoderError;
    }
    if (r.calibrated) flags |= kCalibrated;
    if (r.calibrating) flags |= kCalibrating;
    // Calibration makes the counts absolute: the jump is not motion, so the speed starts over.
    if (reads_ > 0 && r.calibrated != how.joint[i].has(kCalibrated)) velocity_.restart(i, q[i]);
    all_calibrated = all_calibrated && r.calibrated;
    how.joint[i].q = q[i];
    how.joint[i].flags = flags;
  }
  const JointVector v = velocity_.update(t_s, q);
  for (std::size_t i = 0; i < n; ++i) how.joint[i].velocity = v[i];
  ++reads_;

  how.all_calibrated = all_calibrated;
  how.power = arm_.power();
  how.hand_closed = arm_.hand_closed();
  how.outputs = arm_.outputs();

  if (force_sensor_) {
    const hw::ForceReading r = force_sensor_->read();
    force_stale_ = r.sequence == how.force.sequence && how.force.present ? force_stale_ + 1 : 0;
    how.force.present = true;
    how.force.wrench = r.wrench;
    how.force.sequence = r.sequence;
    how.force.saturated = r.saturated;
    how.force.frozen = force_stale_ >= kForceFrozenSamples;
  }
}

void ServoDriver::send(const JointCommands& commands) noexcept {
  for (std::size_t i = 0; i < arm_.dof(); ++i) {
    const JointCommand& c = commands[i];
    switch (c.kind) {
      case JointCommand::Kind::none:
        break;
      case JointCommand::Kind::move:
        arm_.command(i, {hw::ServoCommand::Kind::move, c.target, c.rate});
        break;
      case JointCommand::Kind::calibrate:
        arm_.command(i, {hw::ServoCommand::Kind::calibrate, 0.0, 0.0});
        break;
    }
  }
}

void ServoDriver::hold() noexcept {
  arm_.set_zero_gravity(false);  // a yielding arm does not hold: stiffen the servo first
  for (std::size_t i = 0; i < arm_.dof(); ++i) arm_.command(i, {});
}

bool ServoDriver::set_power(bool on) noexcept {
  return arm_.set_power(on);
}
void ServoDriver::set_hand_closed(bool closed) noexcept {
  arm_.set_hand_closed(closed);
}
void ServoDriver::set_zero_gravity(bool on) noexcept {
  arm_.set_zero_gravity(on);
}
void ServoDriver::set_outputs(std::uint16_t bits) noexcept {
  arm_.set_outputs(bits);
}

}  // namespace rccx::rtc
