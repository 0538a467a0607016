// The trajectory generator slows down where RCCL's would have (issue 14): a transition or a
// segment that would pass a joint's top speed or acceleration bound is given more time instead
// of failing. Judged on every commanded sample against the bounds, computed here from the
// setpoints.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "rccl_harness.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rccl/position.hpp"
#include "rccx/rtc/simulated_robot.hpp"

namespace {

using namespace rccx;
using namespace rccx::math::literals;
using rccl::EventKind;
using rccl::Mode;
using test::GeneratorRun;
using namespace std::chrono_literals;

rccl::PositionPtr pose_position(const std::string& name, const math::Transform& t6) {
  const auto t6_ = rccl::t6();
  return rccl::Position::make(name, {t6_}, {rccl::constant(name, t6)}, t6_);
}

struct Peaks {
  double speed = 0.0, acceleration = 0.0;  ///< as multiples of the joints' bounds
};

Peaks peaks(const GeneratorRun& run) {
  const rccl::GeneratorOptions& o = run.generator.options();
  const double P = run.period;
  Peaks p;
  for (std::size_t k = 2; k < run.qs.size(); ++k) {
    for (std::size_t j = 0; j < run.model.dof(); ++j) {
      const double v = std::abs(run.qs[k][j] - run.qs[k - 1][j]) / P;
      const double a = std::abs(run.qs[k][j] - 2.0 * run.qs[k - 1][j] + run.qs[k - 2][j]) / (P * P);
      p.speed = std::max(p.speed, v / o.max_velocity[j]);
      p.acceleration = std::max(p.acceleration, a / o.max_acceleration[j]);
    }
  }
  return p;
}

/// Motion settings: the tool at 50 mm/s and `rotation_rad_per_s`.
rccl::MotionSettings settings(Mode mode, double rotation_rad_per_s) {
  rccl::MotionSettings s;
  s.mode = mode;
  s.translation_m_per_s = 0.05;
  s.rotation_rad_per_s = rotation_rad_per_s;
  return s;
}

// The pick and place on the Microbo (28 ms): down onto the object and up again in
// Cartesian mode, then a joint move that turns joint 6 by 236 deg queued straight after the
// departure (the two blended), down and up at the place, park. Before: "joint 6 would move at
// 2.045/s, above its top speed 2.000/s" (Lloyd and Hayward's blend of the departure and the joint
// move overshot the joint move's 0.9 of top speed by 16 % of the change of velocity). Now the
// program runs to its end, every sample within the bounds, and joint 6 does turn by 236 deg.
TEST(RcclGeneratorRobust, MicroboWristTurnBlendedIntoACartesianDepartureStaysWithinBounds) {
  GeneratorRun run("microbo", 0.028);
  const rccl::MotionSettings cart = settings(Mode::cartesian, 2.0);
  rccl::MotionSettings joint = settings(Mode::joint, 2.0);
  joint.translation_m_per_s = 0.3;  // the joints' top speeds set the joint move's time
  const auto pose = [&](double q1, double d2, double d3, double q6) {
    return run.kinematics->forward(kin::JointVector{q1, d2, d3, 90_deg, -90_deg, q6});
  };
  // Joint 6 at -127 deg over the pick, 109 deg over the place: 236 deg apart, and 109 deg has
  // no other turn within joint 6's +-250 deg, so the joint move must turn it all the way.
  const math::Transform pick = pose(20_deg, 0.21, 0.35, -127_deg);
  const math::Transform place = pose(-20_deg, 0.21, 0.38, 109_deg);
  const auto above = [](math::Transform t) {
    t.p.z += 0.06;
    return t;
  };
  run.move(pose_position("OVER_PICK", above(pick)), joint);
  run.move(pose_position("PICK", pick), cart);
  const auto depart = run.move(pose_position("OVER_PICK", above(pick)), cart);
  const auto turn = run.move(pose_position("OVER_PLACE", above(place)), joint);
  run.move(pose_position("PLACE", place), cart);
  run.move(pose_position("OVER_PLACE", above(place)), cart);
  const auto park = run.move(rccl::Position::joints("park", run.model.ready()), joint);
  ASSERT_TRUE(run.run_until_rest());
  ASSERT_EQ(run.find_event(EventKind::failed), nullptr)
      << run.find_event(EventKind::failed)->message();
  ASSERT_GE(run.event_time(EventKind::ended, park), 0.0);
  // The departure blended into the turn: the turn started before the departure ended.
  EXPECT_LT(run.event_time(EventKind::started, turn), run.event_time(EventKind::ended, depart));
  // Joint 6 turned from -127 to 109 deg, monotonically (no detour, no overshoot beyond 0.06 deg).
  const double t0 = run.event_time(EventKind::started, turn);
  const double t1 = run.event_time(EventKind::ended, turn);
  double q6_min = 1e9, q6_max = -1e9;
  for (std::size_t k = 0; k < run.qs.size(); ++k) {
    if (run.t[k] < t0 || run.t[k] > t1) continue;
    q6_min = std::min(q6_min, run.qs[k][5]);
    q6_max = std::max(q6_max, run.qs[k][5]);
  }
  EXPECT_NEAR(q6_min, -127_deg, 1e-3);
  EXPECT_NEAR(q6_max, 109_deg, 1e-3);
  const Peaks p = peaks(run);
  std::printf(
      "236 deg wrist turn after a Cartesian departure: peak joint speed %.4f, peak "
      "acceleration %.4f of the bounds\n",
      p.speed, p.acceleration);
  EXPECT_LE(p.speed, 1.0 + 1e-9);
  EXPECT_LE(p.acceleration, 1.0 + rccl::kAccelerationTolerance);
}

// The retry: the wrist turn asked as a Cartesian line. A line takes the shorter way
// round (here 100 deg down from -200 deg), which would take joint 6 past its -250 deg limit; the
// solver then gives the other turn of the same angle and joint 6 would jump. Before, the message
// blamed a singularity (joint 5 at -90 deg is none); now it names joint 6 and its limit, and
// says that joint mode turns it the other way, which then runs.
TEST(RcclGeneratorRobust, ACartesianLinePastAMultiTurnJointsLimitIsRefusedNamingTheLimit) {
  GeneratorRun run("microbo", 0.028);
  const rccl::MotionSettings cart = settings(Mode::cartesian, 1.0);
  const rccl::MotionSettings joint = settings(Mode::joint, 1.0);
  const auto q = [](double q6) { return kin::JointVector{0.3, 0.21, 0.35, 90_deg, -90_deg, q6}; };
  const auto start = run.move(rccl::Position::joints("START", q(-200_deg)), joint);
  ASSERT_TRUE(run.run_until_ended(start));
  const auto line = run.move(pose_position("TURNED", run.kinematics->forward(q(60_deg))), cart);
  ASSERT_TRUE(run.run_until_rest());
  const rccl::MotionEvent* failed = run.find_event(EventKind::failed);
  ASSERT_NE(failed, nullptr) << "the line should not have run";
  EXPECT_EQ(failed->id, line);
  const std::string why(failed->message());
  EXPECT_NE(why.find("joint 6 past its limit (-250.0 deg)"), std::string::npos) << why;
  EXPECT_EQ(why.find("singularity"), std::string::npos) << why;
  // Nothing moved for the refused line: the arm still stands at the start.
  EXPECT_NEAR(run.q[5], -200_deg, 1e-5);
  // Joint mode turns it the long way round, within its limits.
  run.events.clear();
  const auto turn = run.move(pose_position("TURNED", run.kinematics->forward(q(60_deg))), joint);
  ASSERT_TRUE(run.run_until_rest());
  ASSERT_EQ(run.find_event(EventKind::failed), nullptr)
      << run.find_event(EventKind::failed)->message();
  EXPECT_GE(run.event_time(EventKind::ended, turn), 0.0);
  EXPECT_NEAR(run.q[5], 60_deg, 1e-6);
}

}  // namespace

// --- Configurations (issue 14, item 3) ----------------------------------------------------------

namespace {

double rotation_angle_between(const math::Rot3& a, const math::Rot3& b) {
  const math::Rot3 r = a.transposed() * b;
  math::Vec3 axis;
  double angle = 0.0;
  r.to_axis_angle(axis, angle);
  return angle;
}

rccl::PositionPtr at(const std::string& name, const math::Transform& t6) {
  return pose_position(name, t6);
}

// On the PUMA 560 in a session: set_configuration(name) and a joint move put the arm into each
// of RCCL's eight configurations in turn, at the same pose (measured: forward kinematics of the
// joints the arm reports, and its configuration from them).
TEST(RcclConfiguration, JointMoveGoesIntoTheConfigurationAskedFor) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  const kin::Kinematics& kin = arm.kinematics();
  arm.start();
  // A pose as many configurations as possible reach within the limits (searched).
  std::mt19937 rng(560);
  math::Transform goal;
  kin::IkSolutions best;
  for (int i = 0; i < 5000 && best.count < 8; ++i) {
    kin::JointVector q(6);
    for (std::size_t j = 0; j < 6; ++j) {
      const kin::Joint& J = robot.model.joints[j];
      q[j] = std::uniform_real_distribution<double>(J.lower + 0.2, J.upper - 0.2)(rng);
    }
    const kin::IkSolutions all = kin.inverse_all(kin.forward(q));
    if (all.count > best.count) {
      best = all;
      goal = kin.forward(q);
    }
  }
  ASSERT_EQ(kin.configuration_names().size(), 8u);
  ASSERT_GE(best.count, 6u);
  std::size_t changes = 0;
  for (const kin::IkResult& target : best.solutions()) {
    const std::string_view name = kin.configuration_name(target.configuration);
    const kin::Configuration before = kin.configuration_of(robot.session->how().q());
    arm.set_configuration(name);
    ASSERT_EQ(arm.waitfor(arm.move(at("G", goal)).end()), rccl::WaitResult::reached)
        << name << ": " << (arm.failures().empty() ? "" : arm.failures().back().message());
    robot.session->wait_for(300ms);  // the servo settles
    const kin::JointVector q = robot.session->how().q();
    EXPECT_EQ(kin.configuration_name(kin.configuration_of(q)), name);
    EXPECT_LT((kin.forward(q).p - goal.p).norm(), 1e-3) << name;
    EXPECT_LT(rotation_angle_between(kin.forward(q).R, goal.R), 1e-2) << name;
    changes += before == target.configuration ? 0 : 1;
  }
  std::printf("configurations visited at one pose: %zu of 8, %zu changes\n", best.count, changes);
  EXPECT_GE(changes, best.count - 1);
  EXPECT_TRUE(arm.failures().empty());
  EXPECT_FALSE(arm.stop_control().ended());
}

// A goal the arm's present configuration cannot reach (another can): move() refuses it at the
// call in Cartesian mode, and in joint mode without set_configuration, naming a configuration
// that can and how to switch; nothing is queued. set_configuration(that) then a joint move gets
// there. A goal with a functional transform is checked at its present value the same way.
TEST(RcclConfiguration, GoalOutsideThePresentConfigurationIsRefusedAtTheCallOrJoinedInJointMode) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  const kin::Kinematics& kin = arm.kinematics();
  arm.start();
  const kin::Configuration present = kin.configuration_of(robot.session->how().q());
  // Search joint vectors for a pose whose solutions within limits leave out the present
  // configuration (the PUMA's limits cut some configurations off at many poses).
  std::mt19937 rng(14);
  math::Transform goal;
  bool found = false;
  for (int i = 0; i < 20000 && !found; ++i) {
    kin::JointVector q(6);
    for (std::size_t j = 0; j < 6; ++j) {
      const kin::Joint& J = robot.model.joints[j];
      q[j] = std::uniform_real_distribution<double>(J.lower + 0.1, J.upper - 0.1)(rng);
    }
    const math::Transform t = kin.forward(q);
    const kin::IkSolutions all = kin.inverse_all(t);
    bool has_present = false;
    for (const auto& s : all.solutions()) has_present |= s.configuration == present;
    if (!has_present && all.count > 0) {
      goal = t;
      found = true;
    }
  }
  ASSERT_TRUE(found);
  kin::IkOptions o;
  o.configuration = present;
  ASSERT_FALSE(kin.inverse(goal, o));  // independently: not in the present configuration
  const std::uint64_t before = arm.last_queued();
  std::string message;
  // A Cartesian line, and a joint move asked to stay in the present configuration: refused.
  for (const rccl::Mode m : {rccl::Mode::cartesian, rccl::Mode::joint}) {
    arm.set_mode(m);
    arm.set_configuration(m == rccl::Mode::joint ? kin.configuration_name(present) : "");
    try {
      arm.move(at("ELSEWHERE", goal));
      FAIL() << "move() accepted a goal outside the present configuration";
    } catch (const rccl::MotionError& e) {
      message = e.what();
    }
    EXPECT_NE(message.find("ELSEWHERE"), std::string::npos) << message;
    EXPECT_NE(message.find(kin.configuration_name(present)), std::string::npos) << message;
    EXPECT_NE(message.find("then move in joint mode"), std::string::npos) << message;
  }
  arm.set_configuration("");
  EXPECT_EQ(arm.last_queued(), before);
  // The configuration it names reaches the goal: switch to it, in joint mode.
  const std::size_t q1 = message.find("set_configuration(\"") + 19;
  const std::string name = message.substr(q1, message.find('"', q1) - q1);
  o.configuration = kin.find_configuration(name);
  ASSERT_TRUE(o.configuration.has_value()) << message;
  EXPECT_TRUE(kin.inverse(goal, o)) << name;
  // A functional goal, checked at its present value.
  const auto t6 = rccl::t6();
  const auto moving = rccl::Position::make("MOVING", {t6},
                                           {rccl::functional("BELT",
                                                             [](const rccl::SampleContext& c) {
                                                               return math::Transform::translation(
                                                                   0, 1e-4 * c.t_s, 0);
                                                             }),
                                            rccl::constant("G", goal)},
                                           t6);
  arm.set_mode(rccl::Mode::cartesian);
  EXPECT_THROW(arm.move(moving), rccl::MotionError);
  EXPECT_EQ(arm.last_queued(), before);
  arm.set_mode(rccl::Mode::joint);
  arm.set_configuration(name);
  ASSERT_EQ(arm.waitfor(arm.move(at("ELSEWHERE", goal)).end()), rccl::WaitResult::reached)
      << (arm.failures().empty() ? "" : arm.failures().back().message());
  robot.session->wait_for(300ms);
  const kin::JointVector q = robot.session->how().q();
  EXPECT_EQ(kin.configuration_name(kin.configuration_of(q)), name);
  EXPECT_LT((kin.forward(q).p - goal.p).norm(), 1e-3);
  // Now in that configuration, a Cartesian move there is accepted.
  arm.set_configuration("");
  arm.set_mode(rccl::Mode::cartesian);
  EXPECT_NO_THROW(arm.move(at("AGAIN", goal)));
  EXPECT_EQ(arm.waitfor(arm.completed()), rccl::WaitResult::reached);
  // Back to park, then a joint move with no configuration asked: the present one cannot reach
  // the goal, so the move takes one that can (the nearest), as a manual program expects.
  arm.set_mode(rccl::Mode::joint);
  ASSERT_EQ(arm.waitfor(arm.move(arm.park()).end()), rccl::WaitResult::reached);
  ASSERT_EQ(kin.configuration_of(robot.session->how().q()), present);
  ASSERT_EQ(arm.waitfor(arm.move(at("AUTO", goal)).end()), rccl::WaitResult::reached)
      << (arm.failures().empty() ? "" : arm.failures().back().message());
  robot.session->wait_for(300ms);
  const kin::JointVector q_auto = robot.session->how().q();
  EXPECT_NE(kin.configuration_of(q_auto), present);
  EXPECT_LT((kin.forward(q_auto).p - goal.p).norm(), 1e-3);
  EXPECT_TRUE(arm.failures().empty());
  EXPECT_FALSE(arm.stop_control().ended());
}

}  // namespace

// The conveyor: a part on a belt at 0.5 m/s, joined in Cartesian mode with a 0.1 s
// transition (lengthened by the generator as the bounds need) and tracked: the measured tool
// point (forward kinematics of the joints as read) against the part where the belt has it at
// the time of that reading, once the arm has joined it.
/// A conveyor along y in front of the PUMA 560, tool down (configuration ruf reaches all of
/// it): PART = CONV START, CONV moving at speed_m_per_s from t0_s on (still until t0_s is set).
struct Belt {
  explicit Belt(double speed) : speed_m_per_s(speed) {}
  double speed_m_per_s;
  double t0_s = -1.0;
  math::Transform start{math::Rot3::rot_x(180_deg), {0.45, -0.2, 0.0}};
  [[nodiscard]] math::Transform at(double t) const {
    const double dt = t0_s < 0.0 ? 0.0 : std::max(0.0, t - t0_s);
    return math::Transform::translation(0.0, speed_m_per_s * dt, 0.0);
  }
  /// The part's position equation; it refers to this belt, which must outlive it.
  [[nodiscard]] rccl::PositionPtr part() const {
    const auto conv =
        rccl::functional("CONV", [this](const rccl::SampleContext& ctx) { return at(ctx.t_s); });
    const auto t6 = rccl::t6();
    return rccl::Position::make("PART", {t6}, {conv, rccl::constant("START", start)}, t6);
  }
};

// RCCL's stop(ms) after a motion onto a moving goal: the arm stays on that position for the
// time, riding along with the conveyor (before, the dwell froze the joints and the belt left the
// tool behind); the dwell ends on time and the next motion starts from the belt.
TEST(RcclGeneratorRobust, ADwellOnAMovingGoalKeepsTrackingIt) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  const kin::Kinematics& kin = arm.kinematics();
  arm.start();
  Belt belt(0.1);
  const math::Transform& start = belt.start;
  const auto part = belt.part();
  arm.set_configuration("ruf");
  ASSERT_EQ(arm.waitfor(arm.move(pose_position("OVER", start)).end()), rccl::WaitResult::reached);
  arm.set_configuration("");
  arm.set_mode(Mode::cartesian);
  belt.t0_s = robot.session->how().time_s;
  ASSERT_EQ(arm.waitfor(arm.move(part).end(), 5s), rccl::WaitResult::reached);
  const rccl::Motion dwell = arm.dwell(1.5);
  const double dwell_from = robot.session->how().time_s;
  double worst = 0.0;
  while (!arm.happened(dwell.end())) {
    robot.session->wait_for(10ms);
    const rtc::How h = robot.session->how();
    worst = std::max(worst, (kin.forward(h.q()).p - (belt.at(h.time_s) * start).p).norm());
    ASSERT_LT(h.time_s - dwell_from, 3.0) << "the dwell did not end";
  }
  const double dwell_s = robot.session->how().time_s - dwell_from;
  std::printf("a 1.5 s dwell on the belt took %.3f s; the tool stayed within %.2f mm of the part\n",
              dwell_s, worst * 1e3);
  EXPECT_LT(worst, 2e-3);
  EXPECT_GE(dwell_s, 1.5 - 0.03);  // its time, plus the transitions in and out at most
  EXPECT_LT(dwell_s, 1.8);
  // Off the belt to a fixed pose: from the moving goal, with no failure.
  arm.set_mode(Mode::joint);
  ASSERT_EQ(arm.waitfor(arm.move(pose_position("OVER", start)).end(), 10s),
            rccl::WaitResult::reached);
  EXPECT_TRUE(arm.failures().empty())
      << (arm.failures().empty() ? "" : arm.failures().front().message());
  arm.halt();
}

TEST(RcclGeneratorRobust, AConveyorAtHalfAMetreASecondIsJoinedAndTrackedWithin2mm) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  const kin::Kinematics& kin = arm.kinematics();
  arm.start();
  Belt belt(0.5);  // starts when the arm leaves rest
  const math::Transform& start = belt.start;
  const auto part = belt.part();
  arm.set_configuration("ruf");
  ASSERT_EQ(arm.waitfor(arm.move(pose_position("OVER", start)).end()), rccl::WaitResult::reached);
  arm.set_configuration("");
  robot.session->wait_for(300ms);
  arm.set_mode(Mode::cartesian);
  arm.set_transition_time(0.1);
  arm.set_velocity(1.0, 2.0);
  belt.t0_s = robot.session->how().time_s;
  const rccl::Motion m = arm.move(part);
  ASSERT_EQ(arm.waitfor(m.end(), 5s), rccl::WaitResult::reached)
      << (arm.failures().empty() ? "" : arm.failures().back().message());
  const double joined_s = robot.session->how().time_s - belt.t0_s;
  double worst = 0.0;
  int samples = 0;
  for (; samples < 40; ++samples) {  // 0.4 s of tracking, 0.2 m of belt
    robot.session->wait_for(10ms);
    const rtc::How h = robot.session->how();
    const math::Vec3 goal = (belt.at(h.time_s) * start).p;
    worst = std::max(worst, (kin.forward(h.q()).p - goal).norm());
  }
  std::printf("joined the belt %.3f s after it started; tracked within %.2f mm over %d samples\n",
              joined_s, worst * 1e3, samples);
  EXPECT_LT(worst, 2e-3);
  EXPECT_TRUE(arm.failures().empty())
      << (arm.failures().empty() ? "" : arm.failures().front().message());
  arm.halt();
}
