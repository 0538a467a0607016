// The Driver for rccx::hw's simulated servo arms (the PUMA with its PID servos, the ideal arm
// for any model, MuJoCo): encoder counts to joint values, speeds from encoder differences,
// commands to servo goals. The arm is advanced to the sample time on each read, so it runs in
// simulated time and real time alike.
//
//   const auto arm = hw::make_simulated_arm(kin::builtin_robot("puma560"));
//   rtc::ServoDriver driver(*arm);                   // the arm must outlive it
//   rtc::Session session(driver, {.period = 10ms, .clock = rtc::ClockKind::simulated});
//   if (hw::ForceSensor* s = driver.force_sensor()) s->set_bias({{0.5, 0, 0}, {0, 0, 0}});
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "rccx/hw/force_sensor.hpp"
#include "rccx/hw/simulated_arm.hpp"
#include "rccx/rtc/driver.hpp"
#include "rccx/rtc/velocity_estimator.hpp"

namespace rccx::rtc {

class ServoDriver final : public Driver {
 public:
  /// `arm` must outlive the driver. An arm with a wrist sensor (SimulatedArm::wrist_wrench)
  /// gets a hw::ForceSensor of the default spec, read into How::force every sample.
  explicit ServoDriver(hw::SimulatedArm& arm);

  [[nodiscard]] const kin::RobotModel& model() const noexcept override { return arm_.model(); }
  void read(double t_s, How& how) noexcept override;
  void send(const JointCommands& commands) noexcept override;
  void hold() noexcept override;
  bool set_power(bool on) noexcept override;
  void set_hand_closed(bool closed) noexcept override;
  void set_zero_gravity(bool on) noexcept override;
  void set_outputs(std::uint16_t bits) noexcept override;

  [[nodiscard]] hw::SimulatedArm& arm() noexcept { return arm_; }
  /// The wrist sensor (to set its bias or inject its frozen fault), or null when the arm has
  /// none.
  [[nodiscard]] hw::ForceSensor* force_sensor() noexcept {
    return force_sensor_ ? &*force_sensor_ : nullptr;
  }
  /// Replaces the wrist sensor's spec (between samples); false when the arm has none.
  bool set_force_sensor_spec(const hw::ForceSensorSpec& spec);

 private:
  hw::SimulatedArm& arm_;
  VelocityEstimator velocity_;
  std::size_t reads_ = 0;
  std::optional<hw::ForceSensor> force_sensor_;
  std::uint32_t force_stale_ = 0;  ///< samples since the sensor's counter last advanced
};

}  // namespace rccx::rtc
