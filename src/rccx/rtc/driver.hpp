// The communication task's side of one robot: read every joint into How, send this sample's
// joint commands, hold, power. One Driver per robot kind: ServoDriver for the simulated servo
// arms of rccx::hw, MicroboDriver for the Microbo's RCU. The communication task calls these
// every sample: noexcept, no allocation.
//
//   rtc::ServoDriver driver(*arm);                   // a Driver
//   rtc::Session session(driver, {.period = 10ms});  // calls it every sample:
//   driver.read(t_s, how);                           //   the arm into How: q rad / m, flags
//   driver.send(commands);                           //   checked targets, rad / m and rad/s
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "rccx/kinematics/robot_model.hpp"
#include "rccx/rtc/types.hpp"

namespace rccx::rtc {

/// One joint's command after the communication task has checked it: joint values, never
/// outside the limits.
struct JointCommand {
  enum class Kind : std::uint8_t { none, move, calibrate };
  Kind kind = Kind::none;
  double target = 0.0;  ///< joint value, rad or m
  double rate = 0.0;    ///< rad/s or m/s at which to travel to target; 0 = at once
};
using JointCommands = std::array<JointCommand, kMaxJoints>;

class Driver {
 public:
  virtual ~Driver() = default;
  Driver() = default;
  Driver(const Driver&) = delete;
  Driver& operator=(const Driver&) = delete;

  [[nodiscard]] virtual const kin::RobotModel& model() const noexcept = 0;

  /// Reads the arm at time t_s (s since the session opened) into `how`: for each joint q,
  /// velocity and the flags kCalibrated, kCalibrating, kNotAnswering, kEncoderError,
  /// kPhaseError, kJointFault; and power, hand_closed, outputs. Range values and limit flags
  /// are the caller's.
  virtual void read(double t_s, How& how) noexcept = 0;
  /// Sends this sample's commands (entries of kind none are skipped).
  virtual void send(const JointCommands& commands) noexcept = 0;
  /// Every joint stops where it is and stays (leaving zero gravity if it was on).
  virtual void hold() noexcept = 0;
  /// The fastest joint `joint` may be commanded at a sample period of `period_s`, rad/s or m/s:
  /// the model's top speed, or less where the driver needs it (the Microbo's work areas).
  [[nodiscard]] virtual double velocity_limit(std::size_t joint, double period_s) const noexcept {
    (void)period_s;
    return model().joints[joint].max_velocity;
  }
  /// The shortest sample period this robot's link can serve (its bus traffic per sample), s.
  [[nodiscard]] virtual double minimum_period_s() const noexcept { return 0.0; }
  /// What went wrong with a joint the last read flagged (e.g. "TIMEOUT_GET"); may be empty.
  [[nodiscard]] virtual std::string_view fault_detail(std::size_t joint) const noexcept {
    (void)joint;
    return {};
  }
  /// Applies a joint controller setting (Setting::examine: reads the joint's motor parameters
  /// into how.motor_parameters at the next read). False when this robot's controllers have no
  /// such setting.
  virtual bool apply(const SettingChg& setting) noexcept {
    (void)setting;
    return false;
  }
  /// Arm power; false when it could not be switched (power failure).
  virtual bool set_power(bool on) noexcept = 0;
  virtual void set_hand_closed(bool closed) noexcept = 0;
  /// Zero gravity: the joints yield to external effort (gravity compensated) and stay.
  virtual void set_zero_gravity(bool on) noexcept = 0;
  virtual void set_outputs(std::uint16_t bits) noexcept = 0;
};

}  // namespace rccx::rtc
