// rccl::calibrate_tool_load on an arm with a wrist sensor: a fake arm (the ideal servo of the
// PUMA 560's robot file) whose wrist carries a known tool, read through rtc::ServoDriver's
// hw::ForceSensor (its bias and noise) in a simulated session. The calibration recovers the
// tool and the bias, leaves the arm where it found it, and compensates its readings to zero
// at orientations it never visited; a robot without a sensor is refused with what to do.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <stdexcept>
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
  ToolArm(const kin::RobotModel& model, double mass_kg, const math::Vec3& com_m,
          const hw::SimulatedArmOptions& options = {})
      : inner_(model, options),
        kinematics_(kin::make_kinematics(model)),
        mass_(mass_kg),
        com_(com_m) {}
  /// A contact on the tool: its wrench about T6's origin in T6's axes (between samples).
  void set_contact(const math::Wrench& w) { contact_ = w; }

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
    w = weight_at(kinematics_->forward(true_position()).R) + contact_;
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
  math::Wrench contact_;
};

/// The arm, its driver (with the sensor's bias), a simulated session and a started manipulator.
struct Rig {
  Rig(double mass_kg, const math::Vec3& com_m, const math::Wrench& bias,
      const hw::SimulatedArmOptions& options = {})
      : arm(kin::builtin_robot("puma560"), mass_kg, com_m, options), driver(arm) {
    hw::ForceSensorSpec spec;  // the default noise: 0.06 N, 0.002 N m
    spec.bias = bias;
    spec.seed = 7;
    if (!driver.set_force_sensor_spec(spec)) throw std::logic_error("no sensor");
    session = std::make_unique<rtc::Session>(driver);
    manipulator = std::make_unique<rccl::Manipulator>(*session);
    manipulator->start();
    (void)session->wait_for(50ms);
  }
  ToolArm arm;
  rtc::ServoDriver driver;
  std::unique_ptr<rtc::Session> session;
  std::unique_ptr<rccl::Manipulator> manipulator;
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

TEST(ToolCalibration, CompensatedReadingsGiveTheContactAtTheTool) {
  // Calibrate, then push the tool's tip (0.1 m out along T6's a axis) with a known force: the
  // reading, compensated and carried to the tool, is that force, to the averaged noise.
  const math::Wrench bias{{-0.4, 0.9, 1.7}, {-0.02, 0.01, 0.03}};
  Rig rig(0.6, {0.0, 0.01, 0.05}, bias);
  const force::ToolLoad load = rccl::calibrate_tool_load(*rig.manipulator);
  const math::Transform tool = math::Transform::translation(0.0, 0.0, 0.1);
  const Eigen::Vector3d F(3.0, -2.0, 5.0);                             // tool axes = T6 axes
  const Eigen::Vector3d moment = Eigen::Vector3d(0, 0, 0.1).cross(F);  // about T6's origin
  rig.arm.set_contact({{F.x(), F.y(), F.z()}, {moment.x(), moment.y(), moment.z()}});
  (void)rig.session->wait_for(30ms);  // the How at hand was read before the push
  math::Wrench sum;
  int n = 0;
  (void)rig.session->wait_until(
      [&](const rtc::How& h) {
        const math::Rot3 R = rig.manipulator->kinematics().forward(h.q()).R;
        sum = sum + force::at_tool(tool, force::external_wrench(load, R, h.force.wrench));
        return ++n >= 25;
      },
      5s);
  ASSERT_EQ(n, 25);
  const math::Wrench mean = sum * (1.0 / n);
  EXPECT_LT((E(mean.force_N) - F).norm(), 0.06);
  EXPECT_LT(E(mean.torque_N_m).norm(), 0.003);
  // Without the compensation, the tool's weight and the bias would be off by newtons.
  EXPECT_GT((E(force::at_tool(tool, rig.session->how().force.wrench).force_N) - F).norm(), 1.0);
}

TEST(ToolCalibration, TurnsTheOtherWayNearALimit) {
  // Joint 5 starts 5 deg from its upper limit (100 deg): the turns that would pass it go the
  // other way; every pose is within the limits and the tool is still recovered.
  const kin::RobotModel model = kin::builtin_robot("puma560");
  hw::SimulatedArmOptions options;
  options.initial = model.ready();
  options.initial[4] = model.joints[4].upper - 0.087;
  options.initial[3] = model.joints[3].lower + 0.2;  // joint 4, 11 deg from its lower limit
  Rig rig(0.9, {0.02, 0.0, 0.07}, {}, options);
  rccl::ToolCalibrationReadings readings;
  const force::ToolLoad load = rccl::calibrate_tool_load(*rig.manipulator, {}, nullptr, &readings);
  EXPECT_NEAR(load.mass_kg, 0.9, 0.005);
  EXPECT_LT((E(load.com_m) - Eigen::Vector3d(0.02, 0.0, 0.07)).norm(), 0.003);
  ASSERT_EQ(readings.joints.size(), 6U);
  bool went_down = false;
  for (const auto& q : readings.joints) {
    for (std::size_t j = 3; j < 6; ++j) {
      EXPECT_GE(q[j], model.joints[j].lower - 1e-3) << j;
      EXPECT_LE(q[j], model.joints[j].upper + 1e-3) << j;
    }
    went_down = went_down || q[4] < options.initial[4] - 0.6;
  }
  EXPECT_TRUE(went_down);
}

TEST(ToolCalibration, AFrozenSensorEndsItWithTheReason) {
  Rig rig(0.5, {}, {});
  rig.driver.force_sensor()->set_frozen(true);
  try {
    (void)rccl::calibrate_tool_load(*rig.manipulator);
    ADD_FAILURE() << "calibrated with a frozen sensor";
  } catch (const rccl::ToolCalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("froze"), std::string::npos) << e.what();
  }
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
