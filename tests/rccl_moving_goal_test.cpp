// Motions onto and off a moving goal, measured in the goal's own frame: a part on a belt, the
// hand brought above it, lowered onto it, lifted off it, each a straight line relative to the
// part at no more than the set speed relative to it (issue 28: the lines started where the part
// had been when they were planned, a look-ahead earlier, and swept along the belt).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>

#include "rccl_harness.hpp"
#include "rccx/rccl/position.hpp"

namespace {

using namespace rccx;
using test::GeneratorRun;

struct BeltCase {
  const char* robot;
  double period_s;
  double belt_m_per_s;
};

std::string case_name(const ::testing::TestParamInfo<BeltCase>& info) {
  return std::string(info.param.robot) + "_" +
         std::to_string(static_cast<int>(std::lround(info.param.belt_m_per_s * 1000.0))) +
         "mm_per_s";
}

rccl::MotionSettings cartesian(double v_m_per_s) {
  rccl::MotionSettings s;
  s.mode = rccl::Mode::cartesian;
  s.translation_m_per_s = v_m_per_s;
  return s;
}

void PrintTo(const BeltCase& c, std::ostream* os) {
  *os << c.robot << " at " << c.period_s * 1e3 << " ms, belt " << c.belt_m_per_s * 1e3 << " mm/s";
}

/// A part on a belt along y, 40 mm below the ready pose's T6, `upstream_s` of belt travel
/// upstream of it at t = 0; ABOVE is `height_m` over it (world z), ON on it.
struct Belt {
  Belt(const GeneratorRun& run, double speed_m_per_s, double upstream_s, double height_m)
      : speed(speed_m_per_s) {
    const math::Transform home = run.kinematics->forward(run.model.ready());
    part_at_0 = {home.R, home.p + math::Vec3{0.0, -speed * upstream_s, -0.04}};
    const auto conv = rccl::functional("CONV", [v = speed](const rccl::SampleContext& ctx) {
      return math::Transform::translation(0.0, v * ctx.t_s, 0.0);
    });
    const auto part = rccl::constant("PART", part_at_0);
    const auto up = rccl::constant("UP", math::Transform::translation(0.0, 0.0, height_m));
    const auto t6 = rccl::t6();
    above = rccl::Position::make("ABOVE", {t6}, {conv, up, part}, t6);
    on = rccl::Position::make("ON", {t6}, {conv, part}, t6);
  }
  /// T6 (no tool transform) of setpoint k from the part (which only translates), m.
  [[nodiscard]] math::Vec3 relative(const GeneratorRun& run, std::size_t k) const {
    const math::Vec3 part_now = part_at_0.p + math::Vec3{0.0, speed * run.t[k], 0.0};
    return run.kinematics->forward(run.qs[k]).p - part_now;
  }
  double speed;
  math::Transform part_at_0;
  rccl::PositionPtr above, on;
};

class MovingGoal : public ::testing::TestWithParam<BeltCase> {};

// Above the part, down onto it, up off it, each joined to a stop on the part (the arm tracks it
// meanwhile): every join is along the same vertical line in the part's frame, so the whole of
// it, transitions included, lies on that line.
TEST_P(MovingGoal, DescentAndLiftAreStraightRelativeToThePartAtTheSetSpeed) {
  const BeltCase c = GetParam();
  GeneratorRun run(c.robot, c.period_s);
  constexpr double kHeight_m = 0.05;       // above the part
  constexpr double kSpeed_m_per_s = 0.05;  // down and up, relative to the part
  const Belt belt(run, c.belt_m_per_s, 2.5, kHeight_m);

  run.move(belt.above, cartesian(0.2));
  run.dwell(0.3);
  const std::uint64_t down = run.move(belt.on, cartesian(kSpeed_m_per_s));
  run.dwell(0.3);
  const std::uint64_t lift = run.move(belt.above, cartesian(kSpeed_m_per_s));
  const std::uint64_t last = run.dwell(0.3);
  ASSERT_TRUE(run.run_until_ended(last, 30.0));
  ASSERT_EQ(run.find_event(rccl::EventKind::failed), nullptr)
      << run.find_event(rccl::EventKind::failed)->message();

  // From the first stop above the part (the approach's own transition is over) to the end.
  const double from_s = run.event_time(rccl::EventKind::ended, 1) + 0.3;
  double off_line_m = 0.0, fastest_m_per_s = 0.0, lowest_m = kHeight_m;
  math::Vec3 previous;
  bool have_previous = false;
  for (std::size_t k = 0; k < run.qs.size(); ++k) {
    if (run.t[k] < from_s) continue;
    const math::Vec3 rel = belt.relative(run, k);
    off_line_m = std::max(off_line_m, std::hypot(rel.x, rel.y));
    lowest_m = std::min(lowest_m, rel.z);
    if (have_previous) {
      fastest_m_per_s = std::max(fastest_m_per_s, (rel - previous).norm() / run.period);
    }
    previous = rel;
    have_previous = true;
  }
  std::printf(
      "%s at %.0f mm/s: %.4f mm off the line, lowest %.4f mm, fastest %.2f mm/s "
      "relative to the part (descent %llu, lift %llu)\n",
      c.robot, c.belt_m_per_s * 1e3, off_line_m * 1e3, lowest_m * 1e3, fastest_m_per_s * 1e3,
      static_cast<unsigned long long>(down), static_cast<unsigned long long>(lift));
  EXPECT_LT(off_line_m, 0.5e-3);
  EXPECT_LT(std::abs(lowest_m), 0.05e-3);  // it did reach the part
  EXPECT_LE(fastest_m_per_s, kSpeed_m_per_s * 1.01);
}

// The same motions joined without stops: the corner from the approach into the descent is cut
// by its transition (as any corner), the turn from the descent into the lift runs back along
// the same line. Below the transition's reach (the lower 60 % of the way) both are on the line.
TEST_P(MovingGoal, JoinedWithoutStopsTheDescentAndTheLiftStayOnTheLine) {
  const BeltCase c = GetParam();
  GeneratorRun run(c.robot, c.period_s);
  constexpr double kHeight_m = 0.05, kSpeed_m_per_s = 0.05;
  const Belt belt(run, c.belt_m_per_s, 1.5, kHeight_m);
  run.move(belt.above, cartesian(0.2));
  const std::uint64_t down = run.move(belt.on, cartesian(kSpeed_m_per_s));
  const std::uint64_t lift = run.move(belt.above, cartesian(kSpeed_m_per_s));
  ASSERT_TRUE(run.run_until_ended(lift, 30.0));
  ASSERT_EQ(run.find_event(rccl::EventKind::failed), nullptr)
      << run.find_event(rccl::EventKind::failed)->message();
  double off_line_m = 0.0, fastest_m_per_s = 0.0;
  std::size_t compared = 0;
  math::Vec3 previous;
  bool have_previous = false;
  for (std::size_t k = 0; k < run.qs.size(); ++k) {
    const math::Vec3 rel = belt.relative(run, k);
    const bool on_line =
        (run.segment[k] == down || run.segment[k] == lift) && rel.z < 0.6 * kHeight_m;
    if (on_line) {
      off_line_m = std::max(off_line_m, std::hypot(rel.x, rel.y));
      ++compared;
      if (have_previous)
        fastest_m_per_s = std::max(fastest_m_per_s, (rel - previous).norm() / run.period);
    }
    previous = rel;
    have_previous = on_line;
  }
  std::printf("%s at %.0f mm/s, joined: %.4f mm off the line (%zu samples), fastest %.2f mm/s\n",
              c.robot, c.belt_m_per_s * 1e3, off_line_m * 1e3, compared, fastest_m_per_s * 1e3);
  EXPECT_GT(compared, 20U);
  EXPECT_LT(off_line_m, 0.5e-3);
  EXPECT_LE(fastest_m_per_s, kSpeed_m_per_s * 1.01);
}

// A joint motion onto a moving goal ends on fixed joints: those of the goal where it will be
// when the motion's line ends, so that a Cartesian line from there (the descent) starts above
// the part and runs straight down onto it.
TEST_P(MovingGoal, AJointMotionEndsWhereTheGoalWillBeAndTheDescentFromThereIsStraight) {
  const BeltCase c = GetParam();
  GeneratorRun run(c.robot, c.period_s);
  constexpr double kHeight_m = 0.05, kSpeed_m_per_s = 0.05;
  const Belt belt(run, c.belt_m_per_s, 1.5, kHeight_m);

  rccl::MotionSettings joint;
  joint.mode = rccl::Mode::joint;
  // Slow, so that it ends at a moderate speed: the corner the transition into the descent
  // cuts (it blends the joint line, continued past its end, with the descent) stays small.
  joint.segment_time_s = 1.5;
  run.move(belt.above, joint);
  const std::uint64_t down = run.move(belt.on, cartesian(kSpeed_m_per_s));
  ASSERT_TRUE(run.run_until_ended(down, 30.0));
  ASSERT_EQ(run.find_event(rccl::EventKind::failed), nullptr)
      << run.find_event(rccl::EventKind::failed)->message();

  // The lower half of the descent, past the corner the transition from the joint motion cuts.
  double off_line_m = 0.0;
  std::size_t compared = 0;
  for (std::size_t k = 0; k < run.qs.size(); ++k) {
    const math::Vec3 rel = belt.relative(run, k);
    if (run.segment[k] != down || rel.z > 0.5 * kHeight_m) continue;
    off_line_m = std::max(off_line_m, std::hypot(rel.x, rel.y));
    ++compared;
  }
  std::printf("%s at %.0f mm/s, joint motion then descent: %.4f mm off the line (%zu samples)\n",
              c.robot, c.belt_m_per_s * 1e3, off_line_m * 1e3, compared);
  EXPECT_GT(compared, 10U);
  EXPECT_LT(off_line_m, 0.5e-3);
}

INSTANTIATE_TEST_SUITE_P(Belts, MovingGoal,
                         ::testing::Values(BeltCase{"puma560", 0.01, 0.02},
                                           BeltCase{"puma560", 0.01, 0.1},
                                           BeltCase{"microbo", 0.028, 0.02},
                                           BeltCase{"microbo", 0.028, 0.1}),
                         case_name);

}  // namespace
