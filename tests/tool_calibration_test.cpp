// rccl::calibrate_tool_load on an arm with a wrist sensor: a fake arm (the ideal servo of the
// PUMA 560's robot file) whose wrist carries a known tool, read through rtc::ServoDriver's
// hw::ForceSensor (its bias and noise) in a simulated session. The calibration recovers the
// tool and the bias, leaves the arm where it found it, and compensates its readings to zero
// at orientations it never visited; a robot without a sensor is refused with what to do.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <string>

#include "rccx/force/tool_load.hpp"
#include "rccx/hw/ideal_arm.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rccl/tool_calibration.hpp"
#include "rccx/rtc/servo_driver.hpp"
#include "rccx/rtc/session.hpp"
#include "rccx/rtc/simulated_robot.hpp"

namespace {

using namespace rccx;
using namespace std::chrono_literals;

Eigen::Vector3d E(const math::Vec3& v) {
  return {v.x, v.y, v.z};
}

/// hw::IdealArm (final) with a tool of known mass and centre of mass on its wrist: its
/// wrist_wrench is the tool's weight at the arm's true pose, as a sensor at T6 would feel it.
class ToolArm final : public hw::SimulatedArm {
 public:
  ToolArm(const kin::RobotModel& model, double mass_kg, const math::Vec3& com_m)
      : inner_(model), kinematics_(kin::make_kinematics(model)), mass_(mass_kg), com_(com_m) {}

  [[nodiscard]] const kin::RobotModel& model() const noexcept override { return inner_.model(); }
  void advance_to(double t_s) noexcept override { inner_.advance_to(t_s); }
  [[nodiscard]] double time_s() const noexcept override { return inner_.time_s(); }
  [[nodiscard]] hw::JointReading read(std::size_t j) const noexcept override {
    return inner_.read(j);
  }
  bool command(std::size_t j, const hw::ServoCommand& c) noexcept override {
    return inner_.command(j, c);
  }
  bool set_power(bool on) noexcept override { return inner_.set_power(on); }
  [[nodiscard]] bool power() const noexcept override { return inner_.power(); }
  void set_hand_closed(bool closed) noexcept override { inner_.set_hand_closed(closed); }
  [[nodiscard]] bool hand_closed() const noexcept override { return inner_.hand_closed(); }
  void set_outputs(std::uint16_t bits) noexcept override { inner_.set_outputs(bits); }
  [[nodiscard]] std::uint16_t outputs() const noexcept override { return inner_.outputs(); }
  void set_zero_gravity(bool on) noexcept override { inner_.set_zero_gravity(on); }
  void set_external_effort(std::size_t j, double effort) noexcept override {
    inner_.set_external_effort(j, effort);
  }
  void inject(hw::Fault fault, std::size_t j) noexcept override { inner_.inject(fault, j); }
  void clear_faults() noexcept override { inner_.clear_faults(); }
  [[nodiscard]] kin::JointVector true_position() const noexcept override {
    return inner_.true_position();
  }
  [[nodiscard]] kin::JointVector true_velocity() const noexcept override {
    return inner_.true_velocity();
  }

  [[nodiscard]] bool wrist_wrench(math::Wrench& w) const noexcept override {
    w = weight_at(kinematics_->forward(true_position()).R);
    return true;
  }
  /// The tool's weight at T6 for T6's orientation `R` (world = base, gravity along -z), worked
  /// out here without rccx::math's weight_wrench.
  [[nodiscard]] math::Wrench weight_at(const math::Rot3& R) const noexcept {
    Eigen::Matrix3d m;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m(r, c) = R(r, c);
    }
    const Eigen::Vector3d f = m.transpose() * Eigen::Vector3d(0, 0, -mass_ * 9.81);
    const Eigen::Vector3d t = E(com_).cross(f);
    return {{f.x(), f.y(), f.z()}, {t.x(), t.y(), t.z()}};
  }
  [[nodiscard]] const kin::Kinematics& kinematics() const { return *kinematics_; }

 private:
  hw::IdealArm inner_;
  std::unique_ptr<kin::Kinematics> kinematics_;
  double mass_;
  math::Vec3 com_;
};

TEST(ToolCalibration, RecoversTheToolAndTheSensorsBias) {
  const double mass = 1.2;
  const math::Vec3 com{0.01, -0.015, 0.085};
  const math::Wrench bias{{0.8, -1.3, 2.1}, {0.04, 0.03, -0.05}};
  ToolArm arm(kin::builtin_robot("puma560"), mass, com);
  rtc::ServoDriver driver(arm);
  ASSERT_NE(driver.force_sensor(), nullptr);
  hw::ForceSensorSpec spec;  // the default noise: 0.06 N, 0.002 N m
  spec.bias = bias;
  spec.seed = 7;
  ASSERT_TRUE(driver.set_force_sensor_spec(spec));
  rtc::Session session(driver);
  rccl::Manipulator manipulator(session);
  manipulator.start();
  (void)session.wait_for(50ms);
  const kin::JointVector start = session.how().q();

  force::LoadFit fit;
  rccl::ToolCalibrationReadings readings;
  const force::ToolLoad load = rccl::calibrate_tool_load(manipulator, {}, &fit, &readings);

  // 40 readings a pose average the noise down to 0.01 N and 0.0003 N m.
  EXPECT_NEAR(load.mass_kg, mass, 0.005);
  EXPECT_LT((E(load.com_m) - E(com)).norm(), 0.002);
  EXPECT_LT((E(load.bias.force_N) - E(bias.force_N)).norm(), 0.03);
  EXPECT_LT((E(load.bias.torque_N_m) - E(bias.torque_N_m)).norm(), 0.002);
  EXPECT_LT(fit.rms_force_N, 0.03);
  EXPECT_LT(fit.rms_torque_N_m, 0.001);
  ASSERT_EQ(readings.samples.size(), 6U);
  // It turned the wrist about more than one axis: gravity took well-spread directions.
  EXPECT_GT(fit.conditioning, 0.05);
  // Back where it started.
  const kin::JointVector end = session.how().q();
  for (std::size_t j = 0; j < start.size(); ++j) EXPECT_NEAR(end[j], start[j], 1e-3) << j;

  // At orientations it never visited, compensation leaves the noise.
  const auto& k = arm.kinematics();
  for (const kin::JointVector& q : {kin::JointVector{0.3, 0.9, -2.9, 1.2, -0.6, 2.0},
                                    kin::JointVector{-0.5, 0.5, -3.3, -0.8, 1.3, -1.0}}) {
    const math::Rot3 R = k.forward(q).R;
    const math::Wrench reading = arm.weight_at(R) + bias;
    const math::Wrench left = force::external_wrench(load, R, reading);
    EXPECT_LT(E(left.force_N).norm(), 0.05);
    EXPECT_LT(E(left.torque_N_m).norm(), 0.003);
  }
  EXPECT_FALSE(manipulator.stop_control().ended());
}

TEST(ToolCalibration, RefusesARobotWithoutAWristSensor) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));  // the PUMA's plant has no contact
  rccl::Manipulator manipulator(*robot.session);
  manipulator.start();
  (void)robot.session->wait_for(20ms);
  try {
    (void)rccl::calibrate_tool_load(manipulator);
    ADD_FAILURE() << "calibrated without a sensor";
  } catch (const rccl::ToolCalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("no wrist force sensor"), std::string::npos) << e.what();
  }
}

}  // namespace
