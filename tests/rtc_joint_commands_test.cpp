// Chg into one sample's joint commands (rtc::to_joint_commands, src/rccx/rtc/joint_commands.hpp)
// on constructed inputs: units, the default and POSVEL rates, the limits clamped or refused per
// the checking mode, the exact stop messages, what is kept between samples.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "rccx/rtc/joint_commands.hpp"
#include "rccx/rtc/session.hpp"
#include "rtc_fake_driver.hpp"

using namespace rccx;
using rtc::JointCommand;
using rtc::TerminateCode;
using rtc_test::FakeDriver;

namespace {

constexpr double kPeriodS = 0.01;

/// One call of to_joint_commands, its inputs and outputs kept for the checks.
struct Step {
  FakeDriver driver;
  rtc::How how = driver.calibrated_how({0.0, 0.25});
  rtc::Chg chg;
  rtc::JointTargets last;
  rtc::JointCommands commands{};

  std::optional<rtc::Stop> run() {
    commands = {};
    return rtc::to_joint_commands(chg, driver, kPeriodS, how, last, commands);
  }
};

}  // namespace

TEST(JointCommands, PosTurnsRangeTargetsIntoJointValuesAtTheDefaultSpeed) {
  Step s;
  s.chg.pos(0, 1.5);          // range value: 0.5 rad
  s.chg.pos(1, 0.125, 0.05);  // 0.125 m, at 0.05 m/s
  ASSERT_FALSE(s.run());
  EXPECT_EQ(s.commands[0].kind, JointCommand::Kind::move);
  EXPECT_DOUBLE_EQ(s.commands[0].target, 0.5);
  EXPECT_DOUBLE_EQ(s.commands[0].rate, rtc::kDefaultSpeedFraction * 2.0);
  EXPECT_DOUBLE_EQ(s.commands[1].target, 0.125);
  EXPECT_DOUBLE_EQ(s.commands[1].rate, 0.05);
  EXPECT_DOUBLE_EQ(s.driver.asked_period_s, kPeriodS);
  EXPECT_TRUE(s.last.has[0] && s.last.has[1]);
  EXPECT_DOUBLE_EQ(s.last.target[0], 0.5);
  EXPECT_EQ(s.how.any_flags() & ~rtc::kCalibrated, 0);
}

TEST(JointCommands, PosvelArrivesInOnePeriodFromTheMeasuredJointThenFromTheLastTarget) {
  Step s;
  s.chg.posvel(0, 1.01);  // 0.01 rad from the measured 0
  ASSERT_FALSE(s.run());
  const double first = -1.0 + 1.01;
  EXPECT_DOUBLE_EQ(s.commands[0].rate, std::abs(first - 0.0) / kPeriodS);
  EXPECT_EQ(s.commands[1].kind, JointCommand::Kind::none);  // joint 2 not commanded

  s.how.joint[0].q = 0.5;  // the measured joint no longer matters: the last target does
  s.chg.posvel(0, 1.02);
  ASSERT_FALSE(s.run());
  EXPECT_DOUBLE_EQ(s.commands[0].rate, std::abs((-1.0 + 1.02) - first) / kPeriodS);
}

TEST(JointCommands, PosvelToTheLastTargetGiveOrTakeARoundingGoesAtRateZero) {
  Step s;
  s.how.joint[0].q = 0.19;
  s.chg.posvel(0, 1.2);  // 0.2 rad
  ASSERT_FALSE(s.run());
  EXPECT_GT(s.commands[0].rate, 0.0);
  s.chg.posvel(0, 1.2 + 1e-12);  // rounding noise of a joint a Cartesian motion no longer moves
  ASSERT_FALSE(s.run());
  EXPECT_EQ(s.commands[0].rate, 0.0);
}

TEST(JointCommands, ATargetOutsideTheLimitsIsRefusedWhenChecked) {
  Step s;
  s.chg.pos(0, 0.5);
  s.chg.pos(1, 0.6);  // 0.6 m, above 0.5
  const auto stop = s.run();
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::target_position);
  EXPECT_EQ(stop->joint, 2);
  EXPECT_EQ(stop->detail_view(), "joint 2 commanded to 0.60000 m, limits [0.00000, 0.50000]");
  EXPECT_TRUE(s.how.joint[1].has(rtc::kTargetPositionOut));
  // Joint 1 was done before: in the commands (which are not sent) and remembered.
  EXPECT_EQ(s.commands[0].kind, JointCommand::Kind::move);
  EXPECT_TRUE(s.last.has[0]);
  EXPECT_FALSE(s.last.has[1]);
}

TEST(JointCommands, ATargetOutsideTheLimitsIsClampedWhenNotChecked) {
  Step s;
  s.chg.checking = rtc::kCheckAll & ~rtc::kCheckTargetPosition;
  s.chg.pos(0, 2.5);  // 1.5 rad, above 1
  ASSERT_FALSE(s.run());
  EXPECT_EQ(s.commands[0].target, 1.0);
  EXPECT_TRUE(s.how.joint[0].has(rtc::kTargetPositionOut));
  EXPECT_EQ(s.last.target[0], 1.0);
}

TEST(JointCommands, ATargetWithinTheToleranceOfALimitGoesAsItIs) {
  Step s;
  s.chg.pos(0, 2.0 + 5e-10);  // half kLimitTolerance above the upper limit
  ASSERT_FALSE(s.run());
  EXPECT_EQ(s.commands[0].target, -1.0 + (2.0 + 5e-10));
  EXPECT_FALSE(s.how.joint[0].has(rtc::kTargetPositionOut));
}

TEST(JointCommands, ATargetThatIsNotANumberIsRefusedEvenUnchecked) {
  Step s;
  s.chg.checking = 0;
  s.chg.pos(0, std::numeric_limits<double>::quiet_NaN());
  const auto stop = s.run();
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::target_position);
  EXPECT_EQ(stop->detail_view(), "joint 1 commanded to nan rad, limits [-1.00000, 1.00000]");
}

TEST(JointCommands, ARateAboveTheTopSpeedIsRefusedWhenChecked) {
  Step s;
  s.chg.posvel(0, 1.5);  // 0.5 rad in 10 ms: 50 rad/s
  const auto stop = s.run();
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::target_velocity);
  EXPECT_EQ(stop->joint, 1);
  EXPECT_EQ(stop->detail_view(), "joint 1 commanded at 50.0000 rad/s, maximum 2.0000");
  EXPECT_TRUE(s.how.joint[0].has(rtc::kTargetVelocityOut));
  EXPECT_FALSE(s.last.has[0]);
}

TEST(JointCommands, ARateAboveTheTopSpeedIsLoweredToItWhenNotChecked) {
  Step s;
  s.driver.top[1] = 0.04;  // the driver's limit, below the model's 0.1 m/s
  s.chg.checking = rtc::kCheckAll & ~rtc::kCheckTargetVelocity;
  s.chg.pos(1, 0.3, 0.2);
  ASSERT_FALSE(s.run());
  EXPECT_EQ(s.commands[1].rate, 0.04);
  EXPECT_TRUE(s.how.joint[1].has(rtc::kTargetVelocityOut));
  // Within a relative 1e-9 of the top speed is not above it.
  Step t;
  t.chg.pos(1, 0.3, 0.1 * (1.0 + 5e-10));
  ASSERT_FALSE(t.run());
  EXPECT_EQ(t.commands[1].rate, 0.1 * (1.0 + 5e-10));
}

TEST(JointCommands, ARateThatIsNotFiniteIsRefusedEvenUnchecked) {
  Step s;
  s.chg.checking = 0;
  s.chg.pos(1, 0.3, std::numeric_limits<double>::infinity());
  const auto stop = s.run();
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::target_velocity);
  EXPECT_EQ(stop->detail_view(), "joint 2 commanded at inf m/s, maximum 0.1000");
}

TEST(JointCommands, AJointNotCalibratedRefusesTargetsButTakesStopcal) {
  Step s;
  s.how.joint[1].flags = 0;
  s.chg.stopcal(0);
  s.chg.pos(1, 0.3);
  const auto stop = s.run();
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::not_calibrated);
  EXPECT_EQ(stop->joint, 2);
  EXPECT_EQ(stop->detail_view(), "");
  EXPECT_TRUE(s.how.joint[1].has(rtc::kNotCalibratedTarget));

  s.how.joint[0].flags = 0;
  s.chg = {};
  s.last.has[0] = true;
  s.chg.stopcal(0);
  ASSERT_FALSE(s.run());
  EXPECT_EQ(s.commands[0].kind, JointCommand::Kind::calibrate);
  EXPECT_FALSE(s.last.has[0]);  // POSVEL after calibrating starts from the measured joint
}

TEST(JointCommands, OnlyTheRobotsJointsAreRead) {
  Step s;
  s.how.dof = 1;
  s.chg.pos(0, 1.0);
  s.chg.pos(1, 99.0);  // beyond the robot's one joint: not looked at
  ASSERT_FALSE(s.run());
  EXPECT_EQ(s.commands[1].kind, JointCommand::Kind::none);
}

TEST(JointCommands, TheCommandedJointsAreTheLastTargetsElseTheMeasuredOnes) {
  rtc::JointTargets last;
  last.target[1] = 0.3;
  last.has[1] = true;
  const kin::JointVector commanded = last.commanded(kin::JointVector{0.1, 0.2});
  EXPECT_EQ(commanded, (kin::JointVector{0.1, 0.3}));
}
