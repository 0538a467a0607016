// The workcell at run time (cell::Cell) on cells/cvarl.json in simulated time: both robots
// moving at once through the same motion API as one robot, the Microbo following a frame the
// PUMA moves, two arms driven towards each other stopped before their capsules come within the
// margin, and one robot's fault stopping the others (or, when asked, leaving them working).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "cell_helpers.hpp"
#include "rccx/cell/cell.hpp"
#include "rccx/hw/simulated_arm.hpp"
#include "rccx/math/units.hpp"

using namespace rccx;
using namespace std::chrono_literals;
using namespace rccx::math::literals;

using namespace rccx::cell_test;

/// Every new setpoint's tool point of the PUMA (the leader) and the Microbo (the follower), the
/// control task's, recorded by the cell's cycle observer (set before start()). Shared, so that
/// it outlives the ticks the cell's destructor may still run.
struct ToolPoints {
  struct Sample {
    double t_s;
    math::Vec3 p;
  };
  std::vector<Sample> leader, follower;
  double leader_t = -1.0, follower_t = -1.0;
  /// The leader's tool point at time t, interpolated between its setpoints; false outside them.
  bool leader_at(double t, math::Vec3& p) const {
    const auto it = std::lower_bound(leader.begin(), leader.end(), t,
                                     [](const Sample& s, double x) { return s.t_s < x; });
    if (it == leader.begin() || it == leader.end()) return false;
    const double u = (t - (it - 1)->t_s) / (it->t_s - (it - 1)->t_s);
    p = (it - 1)->p + (it->p - (it - 1)->p) * u;
    return true;
  }
};

std::shared_ptr<ToolPoints> record_tool_points(cell::Cell& c) {
  auto points = std::make_shared<ToolPoints>();
  points->leader.reserve(20000);
  points->follower.reserve(20000);
  c.set_cycle_observer([&c, points](std::uint32_t) {
    ToolPoints& r = *points;
    const rccl::TrajectoryGenerator& gp = c.robot("puma").generator();
    const rccl::TrajectoryGenerator& gm = c.robot("microbo").generator();
    if (gp.last_setpoint().size() == 6 && gp.last_setpoint_time_s() != r.leader_t &&
        r.leader.size() < r.leader.capacity()) {
      r.leader_t = gp.last_setpoint_time_s();
      r.leader.push_back({r.leader_t, tool_point(c, "puma", gp.last_setpoint())});
    }
    if (gm.last_setpoint().size() == 6 && gm.last_setpoint_time_s() != r.follower_t &&
        r.follower.size() < r.follower.capacity()) {
      r.follower_t = gm.last_setpoint_time_s();
      r.follower.push_back({r.follower_t, tool_point(c, "microbo", gm.last_setpoint())});
    }
  });
  return points;
}

TEST(CellRuntime, BuildsEveryRobotOfTheCellFile) {
  const auto c = cell::Cell::load(kCvarl);
  EXPECT_EQ(c->robot_names(), (std::vector<std::string>{"puma", "microbo"}));
  EXPECT_EQ(c->session("puma").period(), 7ms);
  EXPECT_EQ(c->session("microbo").period(), 28ms);
  EXPECT_NE(c->hardware("puma").arm, nullptr);
  EXPECT_NE(c->hardware("microbo").rcu, nullptr);
  const math::Transform w = down_at(kAbove);
  EXPECT_LT(math::max_abs_difference(c->base("microbo") * c->world_to_base("microbo", w), w),
            1e-12);
  try {
    (void)c->robot("scara");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("puma, microbo"), std::string::npos) << e.what();
  }
}

TEST(CellRuntime, AWorldGoalPutsTheRobotsToolAtTheWorldPose) {
  const auto c = cell::Cell::load(kCvarl);
  const math::Transform w = down_at(kAbove + math::Vec3{0.02, -0.01, 0.0});
  for (const std::string robot : {"puma", "microbo"}) {
    const rccl::PositionPtr p = c->world_goal(robot, "GOAL", w);
    const math::Transform tool = c->model().find_robot(robot)->tool.value();
    // world <- base T6 TOOL is the goal: the equation T6 TOOL = BASE_INV GOAL.
    EXPECT_LT(math::max_abs_difference(c->base(robot) * p->t6_now() * tool, w), 1e-12) << robot;
    EXPECT_NE(p->describe().find("T6 " + robot + "_TOOL = " + robot + "_BASE_INV GOAL"),
              std::string::npos)
        << p->describe();
  }
  EXPECT_THROW((void)c->world_goal("scara", "GOAL", w), std::invalid_argument);
}

TEST(CellRuntime, WaitforTakesEventsAndWaitForADurationTheOtherSpellingStillWorks) {
  const auto c = cell::Cell::load(kCvarl);
  c->start();
  rccl::Manipulator& puma = c->robot("puma");
  const double t0 = c->session("puma").how().time_s;
  c->wait_for(70ms);
  (void)puma.wait_for(70ms);
  const double t1 = c->session("puma").how().time_s;
  EXPECT_NEAR(t1 - t0, 0.140, 0.0071);
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
  c->waitfor(70ms);  // the deprecated spellings forward to the right function
  (void)puma.waitfor(70ms);
  EXPECT_NEAR(c->session("puma").how().time_s - t1, 0.140, 0.0071);
  const rccl::Motion m = puma.dwell(0.1);  // an event to wait for (s)
  EXPECT_EQ(c->wait_for({c->event("puma", m.end())}, 20s), rccl::WaitResult::reached)
      << failures_of(puma);
  EXPECT_EQ(puma.wait_for(m.start()), rccl::WaitResult::reached);
#pragma GCC diagnostic pop
  EXPECT_TRUE(puma.happened(m.end())) << failures_of(puma);
}

TEST(CellRuntime, BothRobotsMoveAtOnceInJointAndCartesianMode) {
  const auto c = cell::Cell::load(kCvarl);
  const std::shared_ptr<double> closest = watch_closest(*c);
  const double& closest_m = *closest;
  c->start();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  const math::Vec3 p1 = kAbove + math::Vec3{-0.05, 0.0, 0.0};
  const math::Vec3 m1 = kAbove + math::Vec3{0.10, 0.0, 0.0};
  puma.set_velocity(0.05, 0.5);
  microbo.set_velocity(0.05, 0.5);
  const rccl::Motion a = puma.move(world_position(*c, "puma", "P1", down_at(p1)));
  const rccl::Motion b = microbo.move(world_position(*c, "microbo", "M1", down_at(m1)));
  c->wait_for(100ms);
  EXPECT_TRUE(puma.happened(a.start()) && !puma.happened(a.end()));
  EXPECT_TRUE(microbo.happened(b.start()) && !microbo.happened(b.end()));
  ASSERT_EQ(puma.waitfor(a.end(), 20s), rccl::WaitResult::reached) << failures_of(puma);
  ASSERT_EQ(microbo.waitfor(b.end(), 20s), rccl::WaitResult::reached) << failures_of(microbo);

  // Cartesian: both 30 mm along y, at once.
  puma.set_mode(rccl::Mode::cartesian);
  microbo.set_mode(rccl::Mode::cartesian);
  puma.set_velocity(0.05, 1.0);
  microbo.set_velocity(0.05, 1.0);
  const math::Vec3 dy{0.0, 0.03, 0.0};
  const rccl::Motion a2 = puma.move(world_position(*c, "puma", "P2", down_at(p1 + dy)));
  const rccl::Motion b2 = microbo.move(world_position(*c, "microbo", "M2", down_at(m1 + dy)));
  ASSERT_EQ(puma.waitfor(a2.end(), 20s), rccl::WaitResult::reached) << failures_of(puma);
  ASSERT_EQ(microbo.waitfor(b2.end(), 20s), rccl::WaitResult::reached) << failures_of(microbo);
  c->wait_for(1s);  // the arms settle
  EXPECT_LT((tool_point(*c, "puma", c->session("puma").how().q()) - (p1 + dy)).norm(), 2e-3);
  EXPECT_LT((tool_point(*c, "microbo", c->session("microbo").how().q()) - (m1 + dy)).norm(), 2e-3);
  EXPECT_LT(puma.report(a2).max_commanded_path_error_m, 1e-4);
  EXPECT_LT(microbo.report(b2).max_commanded_path_error_m, 1e-4);
  EXPECT_TRUE(puma.failures().empty());
  EXPECT_TRUE(microbo.failures().empty());
  EXPECT_EQ(c->collision_stops(), 0U);
  EXPECT_GE(closest_m, c->model().collision_margin_m);
}

TEST(CellRuntime, TheMicroboFollowsAFrameThePumaMoves) {
  const auto c = cell::Cell::load(kCvarl);
  const std::shared_ptr<ToolPoints> points = record_tool_points(*c);
  const std::vector<ToolPoints::Sample>& follower = points->follower;
  c->start();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");

  // GRASP: the Microbo's tool 150 mm along the PUMA's tool x (the world's x: both point down).
  const math::Transform grasp_offset = math::Transform::translation(0.15, 0.0, 0.0);
  const math::Vec3 p0 = kAbove + math::Vec3{-0.05, 0.0, 0.0};
  puma.set_velocity(0.05, 0.5);  // joint moves slow enough near the other arm
  microbo.set_velocity(0.05, 0.5);
  puma.move(world_position(*c, "puma", "P0", down_at(p0)));
  microbo.move(world_position(*c, "microbo", "M0", down_at(p0) * grasp_offset));
  ASSERT_EQ(puma.waitfor(rccl::Manipulator::completed(), 20s), rccl::WaitResult::reached)
      << failures_of(puma);
  ASSERT_EQ(microbo.waitfor(rccl::Manipulator::completed(), 20s), rccl::WaitResult::reached)
      << failures_of(microbo);

  // T6 TOOL = BASE_INV(microbo) PUMA_TOOL GRASP_OFFSET
  const auto t6 = rccl::t6();
  const auto tool = rccl::constant("TOOL", c->model().find_robot("microbo")->tool.value());
  const auto puma_tool = c->in_base_of("microbo", c->tool_frame("puma"));
  const auto grasp = rccl::constant("GRASP_OFFSET", grasp_offset);
  const auto follow = rccl::Position::make("FOLLOW", {t6, tool}, {puma_tool, grasp}, tool);
  microbo.set_mode(rccl::Mode::cartesian);
  const rccl::Motion f = microbo.move(follow);
  ASSERT_EQ(microbo.waitfor(f.end(), 20s), rccl::WaitResult::reached) << failures_of(microbo);

  // The PUMA carries the board 30 mm one way along y, then the other, then back.
  const std::size_t from = follower.size();
  const double following_from_s = follower.back().t_s;
  puma.set_mode(rccl::Mode::cartesian);
  puma.set_velocity(0.02, 0.5);
  puma.move(world_position(*c, "puma", "PY1", down_at(p0 + math::Vec3{0.0, 0.03, 0.0})));
  puma.move(world_position(*c, "puma", "PY2", down_at(p0 + math::Vec3{0.0, -0.03, 0.0})));
  puma.move(world_position(*c, "puma", "PY3", down_at(p0)));
  ASSERT_EQ(puma.waitfor(rccl::Manipulator::completed(), 60s), rccl::WaitResult::reached)
      << failures_of(puma);
  c->wait_for(500ms);
  EXPECT_TRUE(puma.failures().empty());
  EXPECT_TRUE(microbo.failures().empty()) << microbo.failures().front().message();
  EXPECT_TRUE(c->session("microbo").controlling());

  // Each follower setpoint against the leader's tool at the same instant (interpolated
  // between its setpoints), through the grasp offset.
  double worst_m = 0.0, travel_m = 0.0;
  std::size_t compared = 0;
  for (std::size_t i = from; i < follower.size(); ++i) {
    const double t = follower[i].t_s;
    math::Vec3 lp;
    if (t <= following_from_s || !points->leader_at(t, lp)) continue;
    worst_m = std::max(worst_m, (follower[i].p - (lp + math::Vec3{0.15, 0.0, 0.0})).norm());
    travel_m = std::max(travel_m, std::abs(follower[i].p.y));
    ++compared;
  }
  RecordProperty("worst_mm", std::to_string(worst_m * 1e3));
  EXPECT_GT(compared, 100U);
  EXPECT_GT(travel_m, 0.029) << "the follower did not move with the leader";
  EXPECT_LT(worst_m, 1e-3) << "commanded tool points apart by up to " << worst_m * 1e3 << " mm";
}

// A motion to a goal on another robot's frame that waits for that robot's motion is judged where
// the frame will be when it starts, not where it is when queued: out of the Microbo's reach while
// the PUMA stands away, reached once the PUMA has brought it back (the circuit board's probes,
// queued while the board was still on its way across hosts, were refused). Still out of reach
// when it starts, the motion fails then, saying why, and the Microbo does not move; queued to
// start at once, it is refused at once as before.
TEST(CellRuntime, AGatedMotionToAMovingGoalIsJudgedWhenItStarts) {
  const auto c = cell::Cell::load(kCvarl);
  c->start();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  const math::Vec3 p0 = kAbove + math::Vec3{-0.05, 0.0, 0.0};
  const math::Vec3 away = p0 + math::Vec3{-0.10, -0.30, 0.0};  // the goal 150 mm on: out of reach
  puma.set_velocity(0.05, 0.5);  // joint moves slow enough near the other arm
  microbo.set_velocity(0.05, 0.5);
  puma.move(world_position(*c, "puma", "P0", down_at(p0)));
  microbo.move(world_position(*c, "microbo", "M0", down_at(p0 + math::Vec3{0.15, 0.0, 0.0})));
  ASSERT_EQ(microbo.waitfor(rccl::Manipulator::completed(), 30s), rccl::WaitResult::reached)
      << failures_of(microbo);
  puma.move(world_position(*c, "puma", "AWAY", down_at(away)));
  ASSERT_EQ(puma.waitfor(rccl::Manipulator::completed(), 30s), rccl::WaitResult::reached)
      << failures_of(puma);

  // T6 TOOL = BASE_INV(microbo) PUMA_TOOL GRASP: 150 mm along the PUMA's tool x.
  const auto t6 = rccl::t6();
  const auto tool = rccl::constant("TOOL", c->model().find_robot("microbo")->tool.value());
  const auto puma_tool = c->in_base_of("microbo", c->tool_frame("puma"));
  const auto grasp = rccl::constant("GRASP", math::Transform::translation(0.15, 0.0, 0.0));
  const auto on_puma = rccl::Position::make("ON_PUMA", {t6, tool}, {puma_tool, grasp}, tool);
  const rtc::How h = c->session("microbo").how();
  const math::Transform goal_now = on_puma->t6_at({h.time_s, h.sample, nullptr});
  ASSERT_FALSE(microbo.kinematics().inverse(goal_now))
      << "the test's premise: the goal is out of the Microbo's reach while the PUMA is away";
  EXPECT_THROW(microbo.move(on_puma), rccl::MotionError) << "starting at once: refused at once";

  // Gated on the PUMA's next motion: queued, and judged when it starts.
  const kin::JointVector q_before = c->session("microbo").how().q();
  const rccl::Motion stay = puma.dwell(0.5);
  rccl::Motion m;
  ASSERT_NO_THROW(m = microbo.move(on_puma, c->after("puma", stay.end())));
  EXPECT_EQ(microbo.waitfor(m.end(), 30s), rccl::WaitResult::failed);
  ASSERT_FALSE(microbo.failures().empty());
  EXPECT_NE(microbo.failures().back().message().find("ON_PUMA cannot be reached"),
            std::string::npos)
      << microbo.failures().back().message();
  // Measured: the servo's jitter is a few 1e-5 rad; the goal lies over 150 mm away.
  const math::Vec3 moved = tool_point(*c, "microbo", c->session("microbo").how().q()) -
                           tool_point(*c, "microbo", q_before);
  EXPECT_LT(moved.norm(), 0.5e-3) << "the Microbo's tool moved " << moved.norm() * 1e3 << " mm";

  const rccl::Motion back = puma.move(world_position(*c, "puma", "BACK", down_at(p0)));
  ASSERT_NO_THROW(m = microbo.move(on_puma, c->after("puma", back.end())));
  ASSERT_EQ(microbo.waitfor(m.end(), 30s), rccl::WaitResult::reached) << failures_of(microbo);
  c->wait_for(100ms);
  const math::Vec3 tip = tool_point(*c, "microbo", c->session("microbo").how().q());
  const math::Vec3 want =
      (c->tool_sample("puma").pose * math::Transform::translation(0.15, 0, 0)).p;
  EXPECT_LT((tip - want).norm(), 1e-3) << "the Microbo's tool " << (tip - want).norm() * 1e3
                                       << " mm from the point on the PUMA's tool";
  EXPECT_TRUE(puma.failures().empty()) << failures_of(puma);
}

// A Cartesian line onto a frame another robot moves is straight relative to that frame: the
// Microbo, held 20 mm above what the PUMA carries, is lowered onto it while the PUMA carries it
// along y at 20 mm/s (issue 28: the line started where the frame had been when it was
// planned, and swept along its way).
TEST(CellRuntime, ALineOntoAFrameThePumaMovesIsStraightRelativeToIt) {
  const auto c = cell::Cell::load(kCvarl);
  const std::shared_ptr<ToolPoints> points = record_tool_points(*c);
  const std::vector<ToolPoints::Sample>& follower = points->follower;
  c->start();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");

  constexpr double kHeight_m = 0.02, kDescent_m_per_s = 0.01;
  const math::Transform grasp_offset = math::Transform::translation(0.15, 0.0, 0.0);
  // Tools point down: their z is the world's -z.
  const math::Transform up = math::Transform::translation(0.0, 0.0, -kHeight_m);
  const math::Vec3 p0 = kAbove + math::Vec3{-0.05, -0.05, 0.0};
  puma.set_velocity(0.05, 0.5);
  microbo.set_velocity(0.05, 0.5);
  puma.move(world_position(*c, "puma", "P0", down_at(p0)));
  microbo.move(world_position(*c, "microbo", "M0", down_at(p0) * grasp_offset * up));
  ASSERT_EQ(puma.waitfor(rccl::Manipulator::completed(), 20s), rccl::WaitResult::reached)
      << failures_of(puma);
  ASSERT_EQ(microbo.waitfor(rccl::Manipulator::completed(), 20s), rccl::WaitResult::reached)
      << failures_of(microbo);

  // T6 TOOL = BASE_INV(microbo) PUMA_TOOL GRASP_OFFSET UP, then the same without UP.
  const auto t6 = rccl::t6();
  const auto tool = rccl::constant("TOOL", c->model().find_robot("microbo")->tool.value());
  const auto puma_tool = c->in_base_of("microbo", c->tool_frame("puma"));
  const auto grasp = rccl::constant("GRASP_OFFSET", grasp_offset);
  const auto above =
      rccl::Position::make("ABOVE", {t6, tool}, {puma_tool, grasp, rccl::constant("UP", up)}, tool);
  const auto on = rccl::Position::make("ON", {t6, tool}, {puma_tool, grasp}, tool);
  microbo.set_mode(rccl::Mode::cartesian);
  ASSERT_EQ(microbo.waitfor(microbo.move(above).end(), 20s), rccl::WaitResult::reached)
      << failures_of(microbo);

  // The PUMA carries it 100 mm along y at 20 mm/s; once under way, the Microbo goes down.
  puma.set_mode(rccl::Mode::cartesian);
  puma.set_velocity(0.02, 0.5);
  const rccl::Motion carry =
      puma.move(world_position(*c, "puma", "PY", down_at(p0 + math::Vec3{0.0, 0.1, 0.0})));
  ASSERT_EQ(puma.waitfor(carry.start(), 20s), rccl::WaitResult::reached) << failures_of(puma);
  c->wait_for(1s);
  microbo.set_velocity(kDescent_m_per_s, 0.5);
  const rccl::Motion down = microbo.move(on);
  ASSERT_EQ(microbo.waitfor(down.end(), 20s), rccl::WaitResult::reached) << failures_of(microbo);
  const double down_from_s = microbo.report(down).start_s;
  const double down_to_s = microbo.report(down).end_s;
  ASSERT_EQ(puma.waitfor(carry.end(), 20s), rccl::WaitResult::reached) << failures_of(puma);
  EXPECT_GT(puma.report(carry).end_s, down_to_s) << "the PUMA stopped before the descent ended";
  EXPECT_TRUE(microbo.failures().empty()) << failures_of(microbo);

  // Each follower setpoint from the leader's tool at the same instant (interpolated between
  // its setpoints), through the grasp offset: on the vertical line, at most the set speed.
  double off_line_m = 0.0, fastest_m_per_s = 0.0, lowest_m = kHeight_m;
  std::size_t compared = 0;
  math::Vec3 previous;
  double previous_t = -1.0;
  for (const ToolPoints::Sample& f : follower) {
    math::Vec3 leader_p;
    if (f.t_s < down_from_s || f.t_s > down_to_s || !points->leader_at(f.t_s, leader_p)) continue;
    const math::Vec3 rel = f.p - (leader_p + math::Vec3{0.15, 0.0, 0.0});
    off_line_m = std::max(off_line_m, std::hypot(rel.x, rel.y));
    lowest_m = std::min(lowest_m, rel.z);
    if (previous_t >= 0.0) {
      fastest_m_per_s = std::max(fastest_m_per_s, (rel - previous).norm() / (f.t_s - previous_t));
    }
    previous = rel;
    previous_t = f.t_s;
    ++compared;
  }
  RecordProperty("off_line_mm", std::to_string(off_line_m * 1e3));
  RecordProperty("fastest_mm_per_s", std::to_string(fastest_m_per_s * 1e3));
  std::printf(
      "descent onto the PUMA's frame: %zu samples, %.3f mm off the line, lowest %.3f mm, "
      "fastest %.2f mm/s relative to it\n",
      compared, off_line_m * 1e3, lowest_m * 1e3, fastest_m_per_s * 1e3);
  EXPECT_GT(compared, 40U);
  EXPECT_LT(lowest_m, 0.5e-3) << "it did not reach the frame";
  EXPECT_LT(off_line_m, 0.5e-3);
  EXPECT_LE(fastest_m_per_s, kDescent_m_per_s * 1.05);
}

TEST(CellRuntime, TwoArmsDrivenTowardsEachOtherStopOutsideTheMargin) {
  const auto c = cell::Cell::load(kCvarl);
  const double margin_m = c->model().collision_margin_m;
  const std::shared_ptr<double> closest = watch_closest(*c);
  const double& closest_m = *closest;
  c->start();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  // Each to the other's side of the board: their tools would cross.
  const rccl::Motion a =
      puma.move(world_position(*c, "puma", "PX", down_at(kAbove + math::Vec3{0.04, 0, 0})));
  const rccl::Motion b =
      microbo.move(world_position(*c, "microbo", "MX", down_at(kAbove + math::Vec3{-0.04, 0, 0})));
  EXPECT_EQ(puma.waitfor(a.end(), 20s), rccl::WaitResult::failed) << failures_of(puma);
  EXPECT_EQ(microbo.waitfor(b.end(), 20s), rccl::WaitResult::failed) << failures_of(microbo);
  c->wait_for(1s);  // both stand
  EXPECT_GE(c->collision_stops(), 1U);
  EXPECT_GE(closest_m, margin_m) << "capsules came within the margin";
  RecordProperty("closest_mm", std::to_string(closest_m * 1e3));
  for (rccl::Manipulator* m : {&puma, &microbo}) {
    ASSERT_FALSE(m->failures().empty());
    const std::string msg(m->failures().front().message());
    EXPECT_NE(msg.find("collision stop: puma "), std::string::npos) << msg;
    EXPECT_NE(msg.find(" and microbo "), std::string::npos) << msg;
    EXPECT_TRUE(m->session().controlling()) << "a collision stop is a failed motion, not an end";
  }
  // Stopped inside each other's braking zone, both may move apart again at once, each back the
  // way it came (the braking zone grows with speed: they go slowly), with no further stop.
  const std::uint64_t stops = c->collision_stops();
  puma.set_velocity(0.03, 0.3);
  microbo.set_velocity(0.03, 0.3);
  const rccl::Motion pa = puma.move(puma.park());
  const rccl::Motion ma = microbo.move(microbo.park());
  EXPECT_EQ(puma.waitfor(pa.end(), 20s), rccl::WaitResult::reached) << failures_of(puma);
  EXPECT_EQ(microbo.waitfor(ma.end(), 20s), rccl::WaitResult::reached) << failures_of(microbo);
  EXPECT_EQ(c->collision_stops(), stops);
  EXPECT_GE(closest_m, margin_m);
}

TEST(CellRuntime, WhatAMotionMayTouchIsNamedAndAnUnknownNameIsRefused) {
  cell::CellModel model = cell::load_cell_file(kCvarl);
  const auto c = std::make_unique<cell::Cell>(model);
  EXPECT_EQ(c->objects({"xy_stage", "board"}), 0b110U);  // objects 2 and 3 of the file
  EXPECT_EQ(c->touching({"board"}).touch, 0b100U);
  EXPECT_EQ(c->objects({}), 0U);
  try {
    (void)c->touching({"bord"});
    ADD_FAILURE() << "an unknown object was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no object \"bord\"; its objects: table, xy_stage, board"),
              std::string::npos)
        << e.what();
  }
  // Only the first 64 objects fit a motion's touch set.
  for (int k = 0; k < 64; ++k) {
    cell::CellObject o = model.objects[0];
    o.name = "far" + std::to_string(k);
    o.pose = math::Transform::translation(5.0 + k, 5.0, 0.0);
    model.objects.push_back(o);
  }
  const auto many = std::make_unique<cell::Cell>(model);
  EXPECT_NO_THROW((void)many->objects({"far60"}));
  EXPECT_THROW((void)many->objects({"far61"}), std::invalid_argument);
}

TEST(CellRuntime, TwoArmsStanding40mmApartAreSeparatedWithNoStop) {
  // The Microbo's arm swings from its ready pose towards the PUMA's wrist (a straight line in
  // its joints) until its closest part is 40 mm from the PUMA's: inside the zone where any
  // approach is stopped.
  cell::CellModel model = cell::load_cell_file(kCvarl);
  kin::RobotModel& mb = model.robots[1].model;
  const kin::JointVector from = mb.ready();
  kin::JointVector to = from;
  to[0] = -0.337;  // theta1 towards the PUMA's wrist, 127 mm to the side at 330 mm
  to[1] = mb.joints[1].upper;
  to[2] = 0.385;
  const auto gap = [&](double s) {
    for (std::size_t j = 0; j < 3; ++j) mb.joints[j].ready = from[j] + s * (to[j] - from[j]);
    std::vector<cell::RobotCapsules> arms;
    for (const cell::CellRobot& r : model.robots) {
      arms.emplace_back(r.model, r.link_radius_m, r.base, cell::Cell::shapes_of(r));
    }
    return cell::CollisionWorld(std::move(arms), 0.0).min_distance(0, 1).distance_m;
  };
  double lo = 0.0, hi = 1.0;
  ASSERT_GT(gap(lo), 0.04);
  ASSERT_LT(gap(hi), 0.04) << "the Microbo cannot reach within 40 mm of the PUMA";
  for (int k = 0; k < 40; ++k) ((gap((lo + hi) / 2) > 0.04) ? lo : hi) = (lo + hi) / 2;
  ASSERT_NEAR(gap(lo), 0.04, 1e-4);
  const auto c = std::make_unique<cell::Cell>(model);
  const std::shared_ptr<double> closest = watch_closest(*c);
  const double& closest_m = *closest;
  c->start();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  // Both at once, slowly (the braking zone grows with speed): the Microbo swings back the way
  // it came (joint mode) and the PUMA draws its hand back along its axis (Cartesian).
  puma.set_velocity(0.03, 0.3);
  microbo.set_velocity(0.03, 0.3);
  puma.set_mode(rccl::Mode::cartesian);
  math::Transform back = c->tool_sample("puma").pose;
  back.p = back.p - back.R.a * 0.06 + math::Vec3{0, 0, 0.02};
  const rccl::Motion pa = puma.move(world_position(*c, "puma", "PA", back));
  const rccl::Motion ma = microbo.move(microbo.park());
  EXPECT_EQ(puma.waitfor(pa.end(), 20s), rccl::WaitResult::reached) << failures_of(puma);
  EXPECT_EQ(microbo.waitfor(ma.end(), 20s), rccl::WaitResult::reached) << failures_of(microbo);
  // Then each to its own side, tool down (joint mode: the PUMA's wrist turns the long way).
  puma.set_mode(rccl::Mode::joint);
  const rccl::Motion pb =
      puma.move(world_position(*c, "puma", "PB", down_at(kAbove + math::Vec3{-0.12, 0.05, 0.05})));
  const rccl::Motion mb2 = microbo.move(
      world_position(*c, "microbo", "MB", down_at(kAbove + math::Vec3{0.14, -0.02, 0.03})));
  EXPECT_EQ(puma.waitfor(pb.end(), 20s), rccl::WaitResult::reached) << failures_of(puma);
  EXPECT_EQ(microbo.waitfor(mb2.end(), 20s), rccl::WaitResult::reached) << failures_of(microbo);
  EXPECT_EQ(c->collision_stops(), 0U);
  EXPECT_GE(closest_m, 0.04 - 1e-4) << "they came closer on the way apart";
  const double apart = c->collision_world().min_distance(0, 1).distance_m;
  EXPECT_GT(apart, 0.1);
  RecordProperty("apart_mm", std::to_string(apart * 1e3));
}

namespace {

/// Both arms moving; the PUMA's joint 1 stops answering 200 ms in. Returns the Microbo's motion.
rccl::Motion fault_the_puma_while_both_move(cell::Cell& c, const math::Vec3& m1) {
  rccl::Manipulator& puma = c.robot("puma");
  rccl::Manipulator& microbo = c.robot("microbo");
  const math::Vec3 p1 = kAbove + math::Vec3{-0.05, 0.0, 0.0};
  puma.set_velocity(0.05, 0.5);
  microbo.set_velocity(0.05, 0.5);
  const rccl::Motion a = puma.move(world_position(c, "puma", "P1", down_at(p1)));
  const rccl::Motion b = microbo.move(world_position(c, "microbo", "M1", down_at(m1)));
  c.wait_for(200ms);
  c.hardware("puma").arm->inject(hw::Fault::joint_not_answering, 1);
  EXPECT_EQ(puma.waitfor(a.end(), 5s), rccl::WaitResult::session_ended) << failures_of(puma);
  EXPECT_EQ(c.session("puma").termination().code, rtc::TerminateCode::joint_not_answering);
  return b;
}

}  // namespace

TEST(CellRuntime, OneRobotsFaultStopsTheOthersWhichHoldAndMayMoveAgain) {
  const auto c = cell::Cell::load(kCvarl);
  c->start();
  rccl::Manipulator& microbo = c->robot("microbo");
  // The Microbo draws its arm in (d3 alone, its wrist at the ready height) while the PUMA's
  // flange, stopped by the fault, stands near it.
  const math::Vec3 m1 = kAbove + math::Vec3{0.12, 0.0, -0.0016};
  const rccl::Motion b = fault_the_puma_while_both_move(*c, m1);
  EXPECT_EQ(microbo.waitfor(b.end(), 20s), rccl::WaitResult::failed);
  ASSERT_FALSE(microbo.failures().empty());
  const std::string why(microbo.failures().front().message());
  EXPECT_NE(why.find("puma's control ended (joint_not_answering"), std::string::npos) << why;
  // It holds, still under control: the joints stay where the stop left them.
  c->wait_for(300ms);
  EXPECT_TRUE(c->session("microbo").controlling());
  const kin::JointVector held = c->session("microbo").how().q();
  c->wait_for(1s);
  const kin::JointVector later = c->session("microbo").how().q();
  for (std::size_t j = 0; j < held.size(); ++j) EXPECT_NEAR(later[j], held[j], 1e-3) << j;
  // And the program may move it again.
  const rccl::Motion b2 = microbo.move(world_position(*c, "microbo", "M1b", down_at(m1)));
  EXPECT_EQ(microbo.waitfor(b2.end(), 20s), rccl::WaitResult::reached) << failures_of(microbo);
}

TEST(CellRuntime, WithoutStopOnFaultTheOthersGoOn) {
  cell::CellOptions o;
  o.stop_others_on_fault = false;
  const auto c = cell::Cell::load(kCvarl, o);
  c->start();
  rccl::Manipulator& microbo = c->robot("microbo");
  const math::Vec3 m1 = kAbove + math::Vec3{0.10, 0.0, 0.0};
  const rccl::Motion b = fault_the_puma_while_both_move(*c, m1);
  ASSERT_EQ(microbo.waitfor(b.end(), 20s), rccl::WaitResult::reached) << failures_of(microbo);
  EXPECT_TRUE(c->session("microbo").controlling());
  c->wait_for(500ms);
  EXPECT_LT((tool_point(*c, "microbo", c->session("microbo").how().q()) - m1).norm(), 2e-3);
  // And it goes on moving.
  microbo.set_mode(rccl::Mode::cartesian);
  const rccl::Motion b2 =
      microbo.move(world_position(*c, "microbo", "M2", down_at(m1 + math::Vec3{0.0, -0.03, 0.0})));
  EXPECT_EQ(microbo.waitfor(b2.end(), 20s), rccl::WaitResult::reached) << failures_of(microbo);
  EXPECT_TRUE(microbo.failures().empty());
}

TEST(CellRuntime, TheToolFrameIsTheKinematicsT6OfTheLastSetpoint) {
  // The cell takes each robot's tool frame from its capsules' link frames (one forward
  // kinematics a robot a tick): the same as the solver's T6, base and tool applied.
  const auto c = cell::Cell::load(kCvarl);
  c->start();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  puma.set_velocity(0.05, 0.5);
  microbo.set_velocity(0.05, 0.5);
  puma.move(world_position(*c, "puma", "P1", down_at(kAbove + math::Vec3{-0.05, 0.0, 0.0})));
  microbo.move(world_position(*c, "microbo", "M1", down_at(kAbove + math::Vec3{0.10, 0.0, 0.0})));
  c->wait_for(300ms);
  for (const std::string name : {"puma", "microbo"}) {
    rccl::Manipulator& m = c->robot(name);
    const kin::JointVector& q = m.generator().last_setpoint();
    const math::Transform tool =
        c->model().robots[c->index(name)].tool.value_or(math::Transform::identity());
    const math::Transform expected = c->base(name) * m.kinematics().forward(q) * tool;
    EXPECT_LT(math::max_abs_difference(c->tool_sample(name).pose, expected), 1e-9) << name;
    EXPECT_DOUBLE_EQ(c->tool_sample(name).t_s, m.generator().last_setpoint_time_s()) << name;
  }
}

namespace {

/// Another process's robot as the network layer would give it: fixed joints of a given age.
class FixedRemote : public cell::RemoteRobotSource {
 public:
  kin::JointVector q;
  double age_s = 0.0;
  bool latest(std::size_t remote, kin::JointVector& out, kin::JointVector& qd,
              double& age) const noexcept override {
    if (remote != 0) return false;
    out = q;
    qd = kin::JointVector(q.size());  // standing
    age = age_s;
    return true;
  }
};

/// Runs the PUMA alone (the Microbo served elsewhere, standing with its tool 40 mm to the
/// PUMA's side of the board's centre) towards the Microbo's side; returns the closest the two
/// came (m), how far the PUMA's tool went before it stood (m) and the PUMA's failure text.
std::tuple<double, double, std::string> puma_towards_a_remote_microbo(double remote_age_s) {
  cell::CellOptions options;
  options.local_robots = {"puma"};
  cell::Cell c(cell::load_cell_file(kCvarl), options);
  const cell::CellRobot& m = *c.model().find_robot("microbo");
  const auto k = kin::make_kinematics(m.model);
  const math::Transform goal =
      m.base.inverse() * down_at(kAbove + math::Vec3{-0.04, 0, 0}) * m.tool->inverse();
  const kin::IkResult ik = k->inverse(goal);
  EXPECT_TRUE(ik) << "the Microbo's pose is out of its reach";
  FixedRemote remote;
  remote.q = ik.q;
  remote.age_s = remote_age_s;
  c.set_remote_source(&remote);
  const std::shared_ptr<double> closest = watch_closest(c);
  c.start();
  rccl::Manipulator& puma = c.robot("puma");
  const math::Vec3 from = c.tool_sample("puma").pose.p;
  const rccl::Motion a =
      puma.move(world_position(c, "puma", "PX", down_at(kAbove + math::Vec3{0.04, 0, 0})));
  EXPECT_EQ(puma.waitfor(a.end(), 20s), rccl::WaitResult::failed) << failures_of(puma);
  c.wait_for(500ms);
  return {*closest, (c.tool_sample("puma").pose.p - from).norm(),
          puma.failures().empty() ? "" : std::string(puma.failures()[0].message())};
}

}  // namespace

TEST(CellRuntime, AnotherProcesssRobotIsInTheCollisionCheckWithItsStatesAgeInTheMargin) {
  const double margin_m = cell::load_cell_file(kCvarl).collision_margin_m;
  const auto [fresh_m, fresh_travel_m, fresh_why] = puma_towards_a_remote_microbo(0.0);
  EXPECT_GE(fresh_m, margin_m) << "the PUMA came within the margin of the remote Microbo";
  EXPECT_NE(fresh_why.find("microbo"), std::string::npos) << fresh_why;
  EXPECT_NE(fresh_why.find("another process's"), std::string::npos) << fresh_why;
  // A state 300 ms old: the Microbo may have moved since, so the PUMA stops sooner.
  const auto [old_m, old_travel_m, old_why] = puma_towards_a_remote_microbo(0.3);
  EXPECT_GE(old_m, margin_m);
  EXPECT_LT(old_travel_m, fresh_travel_m - 0.005)
      << "the age did not widen the margin: " << old_why << " (went " << old_travel_m * 1e3
      << " mm against " << fresh_travel_m * 1e3 << " mm)";
  EXPECT_NE(old_why.find("300 ms old"), std::string::npos) << old_why;
}

TEST(CellRuntime, ACellRunsOnlyItsLocalRobotsAndNamesTheOthersAsServedElsewhere) {
  cell::CellOptions options;
  options.local_robots = {"microbo"};
  cell::Cell c(cell::load_cell_file(kCvarl), options);
  EXPECT_EQ(c.robot_names(), std::vector<std::string>{"microbo"});
  EXPECT_EQ(c.remote_names(), std::vector<std::string>{"puma"});
  try {
    (void)c.robot("puma");
    FAIL() << "a remote robot was given as local";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("served by another process"), std::string::npos)
        << e.what();
  }
  options.local_robots = {"pumaa"};
  EXPECT_THROW(cell::Cell(cell::load_cell_file(kCvarl), options), std::invalid_argument);
  // The remote robot's margin grows with its state's age: from rest, as its acceleration bound
  // lets it (a t^2 / 2, four times as far in twice the time); moving, by its speed too; never
  // past its top speed (an unknown speed: the top speed).
  const std::size_t dof = c.model().find_robot("puma")->model.dof();
  const kin::JointVector rest(dof);
  kin::JointVector moving(dof);
  moving[0] = 0.5;
  kin::JointVector unknown(dof);
  for (std::size_t j = 0; j < dof; ++j) unknown[j] = std::nan("");
  EXPECT_EQ(c.remote_allowance_m(0, rest, 0.0), 0.0);
  EXPECT_GT(c.remote_allowance_m(0, rest, 0.02), 0.0);
  EXPECT_NEAR(c.remote_allowance_m(0, rest, 0.02), c.remote_allowance_m(0, rest, 0.01) * 4, 1e-12);
  EXPECT_GT(c.remote_allowance_m(0, moving, 0.02), c.remote_allowance_m(0, rest, 0.02) + 1e-3);
  EXPECT_GT(c.remote_allowance_m(0, unknown, 0.02), c.remote_allowance_m(0, moving, 0.02));
  EXPECT_NEAR(c.remote_allowance_m(0, unknown, 0.2), 2 * c.remote_allowance_m(0, unknown, 0.1),
              1e-12);
}
