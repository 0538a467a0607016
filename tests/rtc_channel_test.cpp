// One robot's channel (src/rccx/rtc/robot_channel.hpp) driven step by step on one thread, the
// test playing both tasks with a clock that is never started and a fake driver: the steps of a
// sample in order, a fault, a late f1, a throwing f1, release's requests on a tick the robot is
// not due.
#include <gtest/gtest.h>

#include <stdexcept>

#include "rccx/rtc/robot_channel.hpp"
#include "rccx/rtc/sample_clock.hpp"
#include "rtc_fake_driver.hpp"

using namespace rccx;
using namespace std::chrono_literals;
using rtc::TerminateCode;
using rtc_test::FakeDriver;

namespace {

constexpr std::int64_t kPeriodNs = 10'000'000;

rtc::SessionOptions ten_ms() {
  rtc::SessionOptions o;
  o.period = std::chrono::nanoseconds(kPeriodNs);
  return o;
}

/// A robot sampled every `multiple`-th tick of a 10 ms clock that does not run.
struct Rig {
  explicit Rig(int multiple = 1) : robot(driver, clock, multiple, 0, nullptr) {}
  FakeDriver driver;
  rtc::SampleClock clock{ten_ms()};
  rtc::RobotChannel robot;
};

}  // namespace

TEST(RobotChannel, OneSampleStepByStep) {
  Rig r;
  int f1_runs = 0, f2_runs = 0;
  r.robot.prepare_control(
      [&](rtc::Control& c) {
        ++f1_runs;
        EXPECT_EQ(c.how().sample, 1U);
        c.chg().pos(0, 1.5);  // 0.5 rad
      },
      [&](rtc::Control& c) {
        ++f2_runs;
        EXPECT_EQ(c.chg().motion[0].set, rtc::SetMode::none);  // one-shot: cleared after f1
      },
      false);
  r.robot.begin_control();
  ASSERT_TRUE(r.robot.communication_cycle(1, kPeriodNs));  // read and checked: hand How over
  ASSERT_TRUE(r.robot.in_cycle(1));
  EXPECT_EQ(r.robot.how().sample, 0U);  // a handed How is published once its Chg is applied
  r.robot.run_f1();
  EXPECT_EQ(f1_runs, 1);
  EXPECT_EQ(r.driver.sends, 0);
  r.robot.take_chg(1, true);
  ASSERT_EQ(r.driver.sends, 1);
  EXPECT_EQ(r.driver.sent[0].kind, rtc::JointCommand::Kind::move);
  EXPECT_DOUBLE_EQ(r.driver.sent[0].target, 0.5);
  EXPECT_DOUBLE_EQ(r.driver.sent[0].rate, rtc::kDefaultSpeedFraction * 2.0);
  const rtc::How h = r.robot.how();
  EXPECT_EQ(h.sample, 1U);
  EXPECT_DOUBLE_EQ(h.time_s, 0.01);
  EXPECT_DOUBLE_EQ(h.joint[1].range, 0.25);
  EXPECT_EQ(r.robot.run_f2(), 0);
  EXPECT_EQ(f2_runs, 1);
  EXPECT_TRUE(r.robot.controlling());
  EXPECT_FALSE(r.robot.release().ended());
  EXPECT_FALSE(r.robot.controlling());
}

TEST(RobotChannel, AFaultEndsControlAtTheTickItIsReadAndTheArmHolds) {
  Rig r;
  r.driver.arm.joint[1].flags |= rtc::kEncoderError;
  r.driver.faults[1] = "ENCODER";
  r.robot.prepare_control({}, {}, false);
  r.robot.begin_control();
  EXPECT_FALSE(r.robot.communication_cycle(3, 3 * kPeriodNs));
  EXPECT_FALSE(r.robot.in_cycle(3));
  ASSERT_TRUE(r.robot.ended());
  EXPECT_EQ(r.driver.holds, 1);
  const rtc::Termination t = r.robot.termination();
  EXPECT_EQ(t.code, TerminateCode::encoder_error);
  EXPECT_EQ(t.joint, 2);
  EXPECT_EQ(t.sample, 3U);
  EXPECT_DOUBLE_EQ(t.time_s, 0.03);
  EXPECT_EQ(t.detail_view(), "ENCODER");
  EXPECT_EQ(r.robot.release().code, TerminateCode::encoder_error);
  EXPECT_FALSE(r.robot.ended());
}

TEST(RobotChannel, AnF1ThatDoesNotHandChgOverInTimeEndsControlWithOverrun) {
  Rig r;
  r.robot.prepare_control({}, {}, false);
  r.robot.begin_control();
  ASSERT_TRUE(r.robot.communication_cycle(1, kPeriodNs));
  r.robot.take_chg(1, false);
  EXPECT_EQ(r.driver.sends, 0);
  const rtc::Termination t = r.robot.termination();
  EXPECT_EQ(t.code, TerminateCode::overrun);
  EXPECT_EQ(t.detail_view(), "f1 of sample 1 did not hand Chg over within its period");
}

TEST(RobotChannel, AThrowingF1EndsControlAtTheNextTickWithItsMessage) {
  Rig r;
  r.robot.prepare_control([](rtc::Control&) { throw std::runtime_error("boom"); }, {}, false);
  r.robot.begin_control();
  ASSERT_TRUE(r.robot.communication_cycle(1, kPeriodNs));
  r.robot.run_f1();
  r.robot.take_chg(1, true);
  r.robot.run_f2();
  EXPECT_TRUE(r.robot.controlling());
  EXPECT_FALSE(r.robot.communication_cycle(2, 2 * kPeriodNs));
  const rtc::Termination t = r.robot.termination();
  EXPECT_EQ(t.code, TerminateCode::control_exception);
  EXPECT_EQ(t.message_view(), "boom");
  EXPECT_EQ(t.sample, 2U);
}

TEST(RobotChannel, ARobotOfMultipleTwoIsReadEveryOtherTickButHoldsAtTheNextOne) {
  Rig r(2);
  EXPECT_FALSE(r.robot.communication_cycle(1, kPeriodNs));  // not in control: read, published
  EXPECT_EQ(r.robot.how().sample, 1U);
  EXPECT_FALSE(r.robot.communication_cycle(2, 2 * kPeriodNs));  // not due: not read
  EXPECT_EQ(r.robot.how().sample, 1U);
  EXPECT_EQ(r.robot.period(), 20ms);
  r.robot.request_hold(false);
  r.robot.communication_cycle(4, 4 * kPeriodNs);  // not due either: the hold goes out all the same
  EXPECT_EQ(r.driver.holds, 1);
  EXPECT_EQ(r.robot.how().sample, 1U);
  r.robot.communication_cycle(5, 5 * kPeriodNs);
  EXPECT_EQ(r.robot.how().sample, 5U);
  EXPECT_EQ(r.driver.holds, 1);
}
