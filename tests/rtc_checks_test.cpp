// The checks of a controlled sample (src/rccx/rtc/sample_checks.hpp) on constructed inputs: each
// returns its stop, with the exact detail, or none; the checking mode and the order of
// precedence; the flags the observed limits leave in How.
#include <gtest/gtest.h>

#include "rccx/rtc/sample_checks.hpp"
#include "rtc_fake_driver.hpp"

using namespace rccx;
using rtc::TerminateCode;
using rtc_test::FakeDriver;

TEST(CheckRequests, ATerminateRequestStopsWithItsCodeAndJoint) {
  std::uint32_t seen = 4;
  const auto stop = rtc::check_requests({TerminateCode::user_request, 3, 5, false}, seen);
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::user_request);
  EXPECT_EQ(stop->joint, 3);
  EXPECT_EQ(stop->detail_view(), "");
  EXPECT_EQ(seen, 4U);  // the Ctrl-C is still to be seen
}

TEST(CheckRequests, ANewCtrlCStopsUnlessTheUsersHandlerTakesIt) {
  std::uint32_t seen = 4;
  EXPECT_FALSE(rtc::check_requests({TerminateCode::none, 0, 4, false}, seen));
  const auto stop = rtc::check_requests({TerminateCode::none, 0, 5, false}, seen);
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::user_interrupt);
  EXPECT_EQ(seen, 5U);
  EXPECT_FALSE(rtc::check_requests({TerminateCode::none, 0, 6, true}, seen));
  EXPECT_EQ(seen, 6U);
}

TEST(CheckFaults, PowerLostWhileExpectedComesFirst) {
  FakeDriver driver;
  rtc::How how = driver.calibrated_how({0.0, 0.25});
  how.power = false;
  how.joint[0].flags |= rtc::kNotAnswering;  // what losing power looks like
  const auto stop = rtc::check_faults(how, true, driver);
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::power_failure);
  EXPECT_EQ(stop->joint, 0);
  EXPECT_EQ(stop->detail_view(), "arm power went off");
  how.joint[0].flags = rtc::kCalibrated;
  EXPECT_FALSE(rtc::check_faults(how, false, driver));  // off, as expected
}

TEST(CheckFaults, TheFirstFaultyJointStopsWithTheDriversDetail) {
  FakeDriver driver;
  driver.faults = {"", "TIMEOUT_GET"};
  rtc::How how = driver.calibrated_how({0.0, 0.25});
  EXPECT_FALSE(rtc::check_faults(how, true, driver));
  // Not answering before an encoder error, whatever else the joint reports.
  how.joint[1].flags |= rtc::kEncoderError | rtc::kNotAnswering | rtc::kJointFault;
  auto stop = rtc::check_faults(how, true, driver);
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::joint_not_answering);
  EXPECT_EQ(stop->joint, 2);
  EXPECT_EQ(stop->detail_view(), "TIMEOUT_GET");
  const std::pair<rtc::JointFlag, TerminateCode> each[] = {
      {rtc::kEncoderError, TerminateCode::encoder_error},
      {rtc::kPhaseError, TerminateCode::phase_error},
      {rtc::kJointFault, TerminateCode::joint_fault}};
  for (const auto& [flag, code] : each) {
    how.joint[1].flags = rtc::kCalibrated | flag;
    stop = rtc::check_faults(how, true, driver);
    ASSERT_TRUE(stop);
    EXPECT_EQ(stop->code, code);
  }
}

TEST(CheckForce, AFrozenOrSaturatedSensorStopsOnlyWhenPresentAndChecked) {
  rtc::ForceHow force;
  force.frozen = true;
  force.saturated = true;
  force.sequence = 7;
  EXPECT_FALSE(rtc::check_force(force, rtc::kCheckAll));  // no sensor
  force.present = true;
  EXPECT_FALSE(rtc::check_force(force, rtc::kCheckAll & ~rtc::kCheckForce));
  auto stop = rtc::check_force(force, rtc::kCheckAll);  // frozen first
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::force_frozen);
  EXPECT_EQ(stop->detail_view(), "the wrist sensor's reading 7 repeated for 3 samples");
  force.frozen = false;
  force.wrench = {{10.04, -20.0, 30.5}, {1.234, 0.0, -0.5}};
  stop = rtc::check_force(force, rtc::kCheckForce);
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::force_saturated);
  EXPECT_EQ(stop->detail_view(),
            "wrist force (10.0, -20.0, 30.5) N, torque (1.23, 0.00, -0.50) N m");
  force.saturated = false;
  EXPECT_FALSE(rtc::check_force(force, rtc::kCheckAll));
}

TEST(CheckObservedLimits, APositionOutsideTheLimitsStopsWhenChecked) {
  FakeDriver driver;
  rtc::How how = driver.calibrated_how({1.1, 0.25});
  const auto stop = rtc::check_observed_limits(how, driver, 10'000'000, rtc::kCheckAll);
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::observed_position);
  EXPECT_EQ(stop->joint, 1);
  EXPECT_EQ(stop->detail_view(), "joint 1 measured at 1.10000 rad, limits [-1.00000, 1.00000]");
  EXPECT_TRUE(how.joint[0].has(rtc::kObservedPositionOut));
}

TEST(CheckObservedLimits, UncheckedTheJointIsFlaggedAndTheNextOnesLookedAt) {
  FakeDriver driver;
  rtc::How how = driver.calibrated_how({1.1, 0.6});
  const auto stop = rtc::check_observed_limits(how, driver, 10'000'000,
                                               rtc::kCheckAll & ~rtc::kCheckObservedPosition);
  EXPECT_FALSE(stop);
  EXPECT_TRUE(how.joint[0].has(rtc::kObservedPositionOut));
  EXPECT_TRUE(how.joint[1].has(rtc::kObservedPositionOut));
}

TEST(CheckObservedLimits, TwoCountsBeyondALimitAreQuantisationAtAHardStop) {
  FakeDriver driver;
  rtc::How how = driver.calibrated_how({-1.0 - 1.5e-3, 0.5 + 1.5e-5});
  EXPECT_FALSE(rtc::check_observed_limits(how, driver, 10'000'000, rtc::kCheckAll));
  how = driver.calibrated_how({0.0, 0.5 + 4e-5});
  const auto stop = rtc::check_observed_limits(how, driver, 10'000'000, rtc::kCheckAll);
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->detail_view(), "joint 2 measured at 0.50004 m, limits [0.00000, 0.50000]");
}

TEST(CheckObservedLimits, UncalibratedOrCalibratingJointsAreNotJudged) {
  FakeDriver driver;
  rtc::How how = driver.calibrated_how({5.0, 0.25});
  how.joint[0].flags = 0;
  how.joint[0].velocity = 100.0;
  EXPECT_FALSE(rtc::check_observed_limits(how, driver, 10'000'000, rtc::kCheckAll));
  how.joint[0].flags = rtc::kCalibrated | rtc::kCalibrating;
  EXPECT_FALSE(rtc::check_observed_limits(how, driver, 10'000'000, rtc::kCheckAll));
  EXPECT_EQ(how.joint[0].flags & (rtc::kObservedPositionOut | rtc::kObservedVelocityOut), 0);
}

TEST(CheckObservedLimits, ASpeedAboveTheTopWithItsSlackStops) {
  FakeDriver driver;
  rtc::How how = driver.calibrated_how({0.0, 0.25});
  // Joint 1: top 2 rad/s, slack 5 % and two counts in 10 ms, 0.3 rad/s.
  how.joint[0].velocity = -2.29;
  EXPECT_FALSE(rtc::check_observed_limits(how, driver, 10'000'000, rtc::kCheckAll));
  EXPECT_DOUBLE_EQ(driver.asked_period_s, 0.01);
  how.joint[0].velocity = -2.31;
  auto stop = rtc::check_observed_limits(how, driver, 10'000'000, rtc::kCheckAll);
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code, TerminateCode::observed_velocity);
  EXPECT_EQ(stop->detail_view(), "joint 1 measured at -2.3100 rad/s, maximum 2.0000");
  how = driver.calibrated_how({0.0, 0.25});
  how.joint[1].velocity = 0.108;  // top 0.1 m/s, slack 0.007 m/s
  stop = rtc::check_observed_limits(how, driver, 10'000'000,
                                    rtc::kCheckAll & ~rtc::kCheckObservedVelocity);
  EXPECT_FALSE(stop);
  EXPECT_TRUE(how.joint[1].has(rtc::kObservedVelocityOut));
  stop = rtc::check_observed_limits(how, driver, 10'000'000, rtc::kCheckAll);
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->detail_view(), "joint 2 measured at 0.1080 m/s, maximum 0.1000");
}
