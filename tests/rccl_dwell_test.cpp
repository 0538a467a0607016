// RCCL's stop(ms) between two motions: the arm comes to rest, stays still for ms, then goes on
// (docs/RCCL.md, "stop(ms)"). Measured on the setpoints: the longest run of samples in which no
// joint moves, against ms from 0 to 2,000 in steps around the transition time.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

#include "rccl_harness.hpp"
#include "rccx/rccl/position.hpp"

namespace {

using namespace rccx;
using test::GeneratorRun;

/// The longest time no joint's setpoint changes between samples, s (a still arm: its
/// setpoints repeat exactly).
double longest_still_s(const GeneratorRun& run) {
  double longest = 0.0;
  std::size_t from = 0;
  for (std::size_t k = 1; k < run.qs.size(); ++k) {
    bool still = true;
    for (std::size_t j = 0; j < run.model.dof(); ++j) {
      if (std::abs(run.qs[k][j] - run.qs[k - 1][j]) > 1e-12) still = false;
    }
    if (!still) {
      from = k;
      continue;
    }
    longest = std::max(longest, run.t[k] - run.t[from]);
  }
  return longest;
}

struct DwellCase {
  const char* robot;
  double period_s;
  rccl::Mode mode;
};

void PrintTo(const DwellCase& c, std::ostream* os) {
  *os << c.robot << " at " << c.period_s * 1e3 << " ms";
}

std::string dwell_case_name(const ::testing::TestParamInfo<DwellCase>& param) {
  return std::string(param.param.robot) +
         (param.param.mode == rccl::Mode::joint ? "_joint" : "_cartesian");
}

class Dwell : public ::testing::TestWithParam<DwellCase> {};

TEST_P(Dwell, TheArmIsStillForTheTimeAStopAsks) {
  const DwellCase c = GetParam();
  const std::vector<double> asked_ms = {0,   20,  50,  80,  100, 150,  190, 200,
                                        210, 250, 300, 400, 600, 1000, 2000};
  double previous = -1.0;
  for (double ms : asked_ms) {
    GeneratorRun run(c.robot, c.period_s);
    const math::Transform home = run.kinematics->forward(run.model.ready());
    const auto t6 = rccl::t6();
    const auto a = rccl::Position::make(
        "A", {t6}, {rccl::constant("A", {home.R, home.p + math::Vec3{0.0, 0.04, -0.02}})}, t6);
    const auto b = rccl::Position::make(
        "B", {t6}, {rccl::constant("B", {home.R, home.p + math::Vec3{0.0, -0.04, -0.02}})}, t6);
    rccl::MotionSettings s;
    s.mode = c.mode;
    s.translation_m_per_s = 0.1;
    s.transition_time_s = 0.2;  // the times asked step around it
    run.move(a, s);
    run.dwell(ms / 1000.0);
    const std::uint64_t last = run.move(b, s);
    ASSERT_TRUE(run.run_until_ended(last, 30.0));
    ASSERT_EQ(run.find_event(rccl::EventKind::failed), nullptr);
    // Only the stop is still: the arm at rest before the first motion and after the last is
    // not in the record (it starts at once and the record ends as it stops).
    const double still = longest_still_s(run);
    // The rule (docs/RCCL.md): ms rounded up to whole samples, at least 3.
    const double rule = std::max(std::ceil(ms * 1e-3 / c.period_s - 1e-9), 3.0) * c.period_s;
    std::printf("%s stop(%4.0f): still %.3f s (the rule: %.3f s)\n", c.robot, ms, still, rule);
    EXPECT_NEAR(still, rule, 1e-9) << "stop(" << ms << ")";
    EXPECT_GE(still, previous) << "stop(" << ms << ") is still for less than a shorter stop";
    previous = still;
  }
}

INSTANTIATE_TEST_SUITE_P(Robots, Dwell,
                         ::testing::Values(DwellCase{"puma560", 0.01, rccl::Mode::cartesian},
                                           DwellCase{"puma560", 0.01, rccl::Mode::joint},
                                           DwellCase{"microbo", 0.028, rccl::Mode::cartesian}),
                         dwell_case_name);

}  // namespace
