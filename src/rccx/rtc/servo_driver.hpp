// The Driver for rccx::hw's simulated servo arms (the PUMA with its PID servos, the ideal arm
// for any model): encoder counts to joint values, speeds from encoder differences, commands to
// servo goals. The arm is advanced to the sample time on each read, so it
// runs in simulated time and real time alike.
#pragma once

#include <array>
#include <cstdint>

#include "rccx/hw/simulated_arm.hpp"
#include "rccx/rtc/driver.hpp"
#include "rccx/rtc/velocity_estimator.hpp"

namespace rccx::rtc {

class ServoDriver final : public Driver {
 public:
  /// `arm` must outlive the driver.
  explicit ServoDriver(hw::SimulatedArm& arm) noexcept;

  [[nodiscard]] const kin::RobotModel& model() const noexcept override { return arm_.model(); }
  void read(double t_s, How& how) noexcept override;
  void send(const JointCommands& commands) noexcept override;
  void hold() noexcept override;
  bool set_power(bool on) noexcept override;
  void set_hand_closed(bool closed) noexcept override;
  void set_zero_gravity(bool on) noexcept override;
  void set_outputs(std::uint16_t bits) noexcept override;

  [[nodiscard]] hw::SimulatedArm& arm() noexcept { return arm_; }

 private:
  hw::SimulatedArm& arm_;
  VelocityEstimator velocity_;
  std::size_t reads_ = 0;
};

}  // namespace rccx::rtc
