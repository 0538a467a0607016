// The loop's force side (rccl::ForceControl through rccl::Manipulator) on an arm whose wrist
// feels a spring table: guards, compliance, the sensor's faults. The plant here is a test
// double (an ideal servo, a linear spring for the table) so that every number is known; the
// same behaviour on MuJoCo's contact is in mujoco_force_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "rccx/hw/arm_base.hpp"
#include "rccx/hw/simulated_arm.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/force_control.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/servo_driver.hpp"
#include "rccx/rtc/session.hpp"

namespace rccx {
namespace {

using math::Transform;
using math::Vec3;

constexpr double kG = 9.81;

/// An ideal servo whose tool tip (kTip along T6's z) meets a table, a spring of stiffness
/// k_N_per_m below the plane z = table_z_m of the base frame; the tool weighs tool_mass_kg at
/// the tip; `push_N` is a force on the tip from outside (world axes).
class SpringTableArm final : public hw::ArmBase {
 public:
  static constexpr double kTip_m = 0.1;

  SpringTableArm(const kin::RobotModel& m, double table_z_m, double k_N_per_m, double tool_mass_kg)
      : ArmBase(m, {}),
        kin_(kin::make_kinematics(m)),
        table_z_m_(table_z_m),
        k_(k_N_per_m),
        mass_(tool_mass_kg) {}

  Vec3 push_N;

  bool wrist_wrench(math::Wrench& w) const noexcept override {
    const Transform t6 = kin_->forward(true_position());
    const Vec3 tip = t6 * Vec3{0, 0, kTip_m};
    const double depth = table_z_m_ - tip.z;
    const Vec3 contact{0, 0, depth > 0 ? k_ * depth : 0.0};
    const Vec3 on_tip = contact + Vec3{0, 0, -mass_ * kG} + push_N;
    const Vec3 torque = math::cross(tip - t6.p, on_tip);
    w = {t6.R.transpose_times(on_tip), t6.R.transpose_times(torque)};
    return true;
  }
  [[nodiscard]] Vec3 tip() const noexcept {
    return kin_->forward(true_position()) * Vec3{0, 0, kTip_m};
  }

 private:
  void servo_tick(double dt) noexcept override {
    for (std::size_t i = 0; i < n_; ++i) {
      JointState& s = joints_[i];
      const double cap = hw::kOverspeedFactor * s.max_velocity;
      const double before = s.q;
      const double left = s.setpoint - s.q;
      s.q = std::abs(left) <= cap * dt ? s.setpoint : s.q + std::copysign(cap * dt, left);
      clamp_to_stops(s);
      s.qd = (s.q - before) / dt;
    }
  }

  std::unique_ptr<kin::Kinematics> kin_;
  double table_z_m_, k_, mass_;
};

struct Rig {
  static constexpr double kTable_m = -0.20;  // base frame: 200 mm below the shoulder
  kin::RobotModel model = kin::builtin_robot("puma560");
  SpringTableArm arm{model, kTable_m, 1e4, 0.5};
  rtc::ServoDriver driver{arm};
  rtc::Session session{driver, [] {
                         rtc::SessionOptions o;
                         o.clock = rtc::ClockKind::simulated;
                         return o;
                       }()};
  rccl::Manipulator manipulator{session};
  rccl::TransformPtr tool =
      rccl::constant("TOOL", Transform::translation(0, 0, SpringTableArm::kTip_m));

  Rig() {
    manipulator.start();
    force::ToolLoad load;
    load.mass_kg = 0.5;
    load.com_m = {0, 0, SpringTableArm::kTip_m};
    manipulator.set_tool_load(load);
  }
  /// The tool pointing down (its z along the base's -z) with its tip at (x, y, z), m.
  rccl::PositionPtr at(const std::string& name, double x, double y, double z) {
    Transform goal = Transform::translation(x, y, z);
    goal.R = math::Rot3::rot_x(M_PI);
    return rccl::Position::make(name, {rccl::t6(), tool}, {rccl::constant(name + "_G", goal)},
                                tool);
  }
  rccl::Motion go(const rccl::PositionPtr& p) {
    const rccl::Motion m = manipulator.move(p);
    EXPECT_EQ(manipulator.waitfor(m.end(), std::chrono::seconds(30)), rccl::WaitResult::reached)
        << p->name();
    return m;
  }
};

TEST(ForceControl, AGuardedMoveStopsAtTheTableAndReportsWhereItTouched) {
  Rig r;
  r.go(r.at("ABOVE", 0.45, 0.15, Rig::kTable_m + 0.02));  // joint mode, from park
  r.manipulator.set_mode(rccl::Mode::cartesian);
  r.manipulator.set_velocity(0.02, 0.5);
  rccl::ForceGuard g;
  g.kind = rccl::ForceGuard::Kind::along;
  g.axis = 2;
  g.threshold = 5.0;
  r.manipulator.set_guard(g);
  const rccl::Motion down = r.go(r.at("BELOW", 0.45, 0.15, Rig::kTable_m - 0.03));
  const auto c = r.manipulator.contact(down);
  ASSERT_TRUE(c.has_value()) << "the guard did not trip";
  EXPECT_NEAR(c->tool_frame.p.z, Rig::kTable_m, 0.5e-3);
  // Rest, then the arm's travel since the contact.
  r.manipulator.set_guard({});
  r.manipulator.waitfor(rccl::Manipulator::completed());
  r.session.wait_for(std::chrono::milliseconds(200));
  const double travel = c->tool_frame.p.z - r.arm.tip().z;
  EXPECT_LT(travel, 1e-3) << "travelled " << travel * 1e3 << " mm after the contact";
  EXPECT_GE(travel, 0.0);
}

TEST(ForceControl, HoldingAForceOnTheTableWhileMovingAlongItKeepsItWithinTenPercent) {
  Rig r;
  r.go(r.at("START", 0.40, 0.15, Rig::kTable_m));  // touching
  r.manipulator.set_mode(rccl::Mode::cartesian);
  r.manipulator.set_velocity(0.02, 0.5);
  rccl::Compliance c;
  c.axes = 1U << 2;
  c.force[2] = 5.0;
  r.manipulator.set_compliance(c);
  const rccl::Motion wipe = r.manipulator.move(r.at("END", 0.50, 0.15, Rig::kTable_m));
  double worst = 0.0;
  int samples = 0;
  const double t0 = r.session.how().time_s;
  while (!r.manipulator.happened(wipe.end())) {
    r.session.wait_for(std::chrono::milliseconds(10));
    const double t = r.session.how().time_s - t0;
    if (std::getenv("RCCX_FORCE_DEBUG") != nullptr) {
      std::printf("%.2f z %.5f f %.3f\n", t, r.arm.tip().z,
                  1e4 * std::max(Rig::kTable_m - r.arm.tip().z, 0.0));
    }
    if (t > 3.0) {  // steady state: the last 2 s of the 5 s wipe (time constant D / k = 1 s)
      const double depth = Rig::kTable_m - r.arm.tip().z;
      const double f = 1e4 * std::max(depth, 0.0);
      worst = std::max(worst, std::abs(f - 5.0) / 5.0);
      ++samples;
    }
    ASSERT_LT(t, 30.0);
  }
  for (const auto& f : r.manipulator.failures()) ADD_FAILURE() << f.message();
  EXPECT_GT(samples, 100);
  EXPECT_LT(worst, 0.10);
}

// A compliant motion that starts with the tool pressing past its limit (a stop left the command
// 15 mm into the table: 150 N on the 10^4 N/m spring) yields toward the set force first and
// holds it; one that cannot yield that way (only x compliant) fails after the bounded time,
// saying so, instead of at its first sample.
TEST(ForceControl, ACompliantMotionStartingPastItsLimitYieldsFirstOrFailsAfterTheBoundedTime) {
  for (const bool along_z : {true, false}) {
    SCOPED_TRACE(along_z ? "fz compliant" : "only fx compliant");
    Rig r;
    r.go(r.at("INTO", 0.40, 0.15, Rig::kTable_m - 0.015));  // pressing 150 N
    const double pressing_N = 1e4 * (Rig::kTable_m - r.arm.tip().z);
    ASSERT_GT(pressing_N, 120.0);
    r.manipulator.set_mode(rccl::Mode::cartesian);
    r.manipulator.set_velocity(0.02, 0.5);
    rccl::Compliance c;
    c.axes = along_z ? 1U << 2 : 1U << 0;
    c.force[2] = 5.0;
    r.manipulator.set_compliance(c);
    const double t0 = r.session.how().time_s;
    const rccl::Motion wipe = r.manipulator.move(r.at("END", 0.45, 0.15, Rig::kTable_m - 0.015));
    EXPECT_EQ(r.manipulator.waitfor(wipe.end(), std::chrono::seconds(30)),
              along_z ? rccl::WaitResult::reached : rccl::WaitResult::failed);
    const double took_s = r.session.how().time_s - t0;
    const double end_N = 1e4 * std::max(Rig::kTable_m - r.arm.tip().z, 0.0);
    if (along_z) {
      for (const auto& f : r.manipulator.failures()) ADD_FAILURE() << f.message();
      EXPECT_NEAR(end_N, 5.0, 0.5);
    } else {
      ASSERT_FALSE(r.manipulator.failures().empty());
      const std::string why(r.manipulator.failures().front().message());
      EXPECT_NE(why.find("still exerted"), std::string::npos) << why;
      EXPECT_NE(why.find("after yielding 1.0 s"), std::string::npos) << why;
      EXPECT_GT(took_s, rccl::ForceControl::kYieldWithin_s);
    }
  }
}

TEST(ForceControl, CompliantAxesYieldToAPushAndLockedOnesDoNotMove) {
  Rig r;
  r.go(r.at("HERE", 0.45, 0.10, Rig::kTable_m + 0.05));
  rccl::Compliance c;
  c.axes = 1U << 0;  // fx: the tool's x is the base's x here
  c.stiffness[0] = 1000.0;
  c.damping[0] = 500.0;  // time constant D / K = 0.5 s
  r.manipulator.set_compliance(c);
  const Vec3 start = r.arm.tip();
  const rccl::Motion hold = r.manipulator.dwell(3.0);
  r.session.wait_for(std::chrono::milliseconds(100));
  r.arm.push_N = {-10.0, 0.0, 0.0};  // a hand pushes the tool towards -x
  double worst_locked = 0.0;
  while (!r.manipulator.happened(hold.end())) {
    r.session.wait_for(std::chrono::milliseconds(10));
    const Vec3 d = r.arm.tip() - start;
    worst_locked = std::max({worst_locked, std::abs(d.y), std::abs(d.z)});
  }
  const Vec3 d = r.arm.tip() - start;
  // K x = f: 10 N on 1000 N/m is 10 mm, reached well within the dwell.
  EXPECT_NEAR(d.x, -0.010, 0.0015);
  EXPECT_LT(worst_locked, 0.1e-3);
  for (const auto& f : r.manipulator.failures()) ADD_FAILURE() << f.message();
}

TEST(ForceControl, ACompliantMotionOnARobotWithoutASensorIsRefused) {
  const kin::RobotModel model = kin::builtin_robot("puma560");
  auto arm = hw::make_simulated_arm(model);
  rtc::ServoDriver driver(*arm);
  rtc::Session session(driver);
  rccl::Manipulator m(session);
  m.start();
  rccl::Compliance c;
  c.axes = 1U << 2;
  m.set_compliance(c);
  try {
    m.move(m.park());
    FAIL() << "no refusal";
  } catch (const rccl::MotionError& e) {
    EXPECT_NE(std::string(e.what()).find("wrist force sensor"), std::string::npos) << e.what();
  }
  rccl::ForceGuard g;
  g.kind = rccl::ForceGuard::Kind::magnitude;
  g.threshold = -1.0;
  EXPECT_THROW(m.set_guard(g), rccl::MotionError);
  c.force[2] = 500.0;
  EXPECT_THROW(m.set_compliance(c), rccl::MotionError);
}

TEST(ForceControl, ASaturatedSensorEndsControlWithItsCodeAndTheArmHolds) {
  Rig r;
  r.session.wait_for(std::chrono::milliseconds(50));
  const kin::JointVector before = r.arm.true_position();
  r.arm.push_N = {0, 0, -400};  // beyond the sensor's 290 N
  const rtc::Termination t = r.session.wait_terminated(std::chrono::seconds(1));
  EXPECT_EQ(t.code, rtc::TerminateCode::force_saturated);
  r.session.wait_for(std::chrono::milliseconds(100));
  const kin::JointVector after = r.arm.true_position();
  for (std::size_t i = 0; i < before.size(); ++i) EXPECT_NEAR(after[i], before[i], 1e-6);
}

TEST(ForceControl, AFrozenSensorEndsControlWithItsCode) {
  Rig r;
  r.session.wait_for(std::chrono::milliseconds(50));
  ASSERT_NE(r.driver.force_sensor(), nullptr);
  r.driver.force_sensor()->set_frozen(true);
  const rtc::Termination t = r.session.wait_terminated(std::chrono::seconds(1));
  EXPECT_EQ(t.code, rtc::TerminateCode::force_frozen);
  EXPECT_LE(t.sample, 10U);
}

}  // namespace
}  // namespace rccx
