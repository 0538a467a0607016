// A driver for the RTC sample steps' tests without threads or an arm (rtc_checks_test.cpp,
// rtc_joint_commands_test.cpp, rtc_channel_test.cpp): a two-joint robot, one revolute and one
// prismatic, whose readings, top speeds and fault details the test sets, and which remembers
// what it was asked (the period of a top speed, commands sent, holds, power).
//
//   FakeDriver driver;
//   driver.top = {1.0, 0.05};                  // rad/s, m/s
//   driver.arm = driver.calibrated_how({0.0, 0.25});   // what read() returns
//   ... driver.sends, driver.sent[0].target, driver.holds
#pragma once

#include <array>
#include <string_view>

#include "rccx/rtc/driver.hpp"

namespace rtc_test {

using namespace rccx;

/// Joint 1 revolute in [-1, 1] rad, 1 mrad a count, 2 rad/s; joint 2 prismatic in [0, 0.5] m,
/// 10 um a count, 0.1 m/s.
inline kin::RobotModel two_joint_model() {
  kin::RobotModel m;
  m.name = "fake";
  kin::Joint revolute;
  revolute.name = "theta1";
  revolute.type = kin::JointType::revolute;
  revolute.lower = -1.0;
  revolute.upper = 1.0;
  revolute.resolution_per_count = 1e-3;
  revolute.max_velocity = 2.0;
  kin::Joint prismatic;
  prismatic.name = "d2";
  prismatic.type = kin::JointType::prismatic;
  prismatic.lower = 0.0;
  prismatic.upper = 0.5;
  prismatic.resolution_per_count = 1e-5;
  prismatic.max_velocity = 0.1;
  m.joints = {revolute, prismatic};
  return m;
}

class FakeDriver final : public rtc::Driver {
  kin::RobotModel model_ = two_joint_model();  // first: the members below read it

 public:
  const kin::RobotModel& model() const noexcept override { return model_; }
  void read(double, rtc::How& how) noexcept override { how = arm; }
  void send(const rtc::JointCommands& commands) noexcept override {
    sent = commands;
    ++sends;
  }
  void hold() noexcept override { ++holds; }
  double velocity_limit(std::size_t joint, double period_s) const noexcept override {
    asked_period_s = period_s;
    return top[joint];
  }
  std::string_view fault_detail(std::size_t joint) const noexcept override { return faults[joint]; }
  bool set_power(bool on) noexcept override {
    arm.power = on;
    return true;
  }
  void set_hand_closed(bool) noexcept override {}
  void set_zero_gravity(bool) noexcept override {}
  void set_outputs(std::uint16_t) noexcept override {}

  /// A How of both joints at `q` (rad, m), calibrated, standing still, power on.
  [[nodiscard]] rtc::How calibrated_how(std::array<double, 2> q) const {
    rtc::How h;
    h.dof = 2;
    for (std::size_t i = 0; i < 2; ++i) {
      h.joint[i].q = q[i];
      h.joint[i].range = q[i] - model_.joints[i].lower;
      h.joint[i].flags = rtc::kCalibrated;
    }
    h.power = true;
    h.all_calibrated = true;
    return h;
  }

  std::array<double, 2> top{2.0, 0.1};  ///< velocity_limit's answers, rad/s and m/s
  std::array<std::string_view, 2> faults{};
  mutable double asked_period_s = -1.0;        ///< the period velocity_limit was last asked for, s
  rtc::How arm = calibrated_how({0.0, 0.25});  ///< what read() returns
  rtc::JointCommands sent{};                   ///< the last commands sent
  int sends = 0, holds = 0;
};

}  // namespace rtc_test
