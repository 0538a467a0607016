// Safety between arms: N PUMA 560s on a square grid 1.2 m apart (each reaches its neighbours),
// each in a random configuration nudged a little every iteration so that nothing is cached.
// One iteration is one sample of the cell: set_configuration for every robot (link frames,
// capsules, boxes) and check(). BM_CollisionCheckAllPairs is the same sample with the
// brute-force check (every capsule against every capsule of every other robot), for the ratio.
// Counters: per_robot (time per robot per sample), robot_pairs and capsule_pairs (the narrow
// phase's work per sample, averaged). The cell cycle's budget is 2 us per robot (250 robots in
// 0.5 ms at 1 kHz); this check should be a small part of it.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "rccx/cell/collision.hpp"
#include "rccx/kinematics/robot_model.hpp"

namespace {

using rccx::cell::CollisionWorld;
using rccx::cell::RobotCapsules;
using rccx::kin::JointVector;

constexpr double kGridSpacing_m = 1.2;
constexpr double kLinkRadius_m = 0.08;
constexpr double kMargin_m = 0.02;
constexpr double kNudge_rad = 0.01;  // +- per joint, per iteration, around the drawn pose
constexpr std::uint64_t kSeed = 19860601;

// A cheap generator for the per-iteration nudges: the benchmark should time the check, not
// std::mt19937.
struct XorShift {
  std::uint64_t s = 0x9E3779B97F4A7C15ULL;
  double next_unit() noexcept {  // in [-1, 1)
    s ^= s << 13;
    s ^= s >> 7;
    s ^= s << 17;
    return static_cast<double>(s >> 11) * 0x1.0p-52 - 1.0;
  }
};

struct Cell {
  std::vector<JointVector> home;  // each robot's drawn configuration
  CollisionWorld world;
};

Cell grid_cell(std::size_t n) {
  const rccx::kin::RobotModel model = rccx::kin::builtin_robot("puma560");
  const auto columns = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  std::mt19937_64 rng(kSeed);
  std::vector<RobotCapsules> robots;
  std::vector<JointVector> home;
  const double radius = kLinkRadius_m;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = kGridSpacing_m * static_cast<double>(i % columns);
    const double y = kGridSpacing_m * static_cast<double>(i / columns);
    robots.emplace_back(model, std::span(&radius, 1),
                        rccx::math::Transform::translation(x, y, 0.0));
    JointVector q(model.dof());
    for (std::size_t j = 0; j < model.dof(); ++j) {
      std::uniform_real_distribution<double> u(model.joints[j].lower, model.joints[j].upper);
      q[j] = u(rng);
    }
    home.push_back(q);
  }
  return {std::move(home), CollisionWorld(std::move(robots), kMargin_m)};
}

template <bool kAllPairs>
void run(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Cell cell = grid_cell(n);
  XorShift rng;
  double robot_pairs = 0.0, capsule_pairs = 0.0;
  std::size_t contacts = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) {
      JointVector q = cell.home[i];
      for (double& v : q) v += kNudge_rad * rng.next_unit();
      cell.world.set_configuration(i, q);
    }
    const auto hit = kAllPairs ? cell.world.check_all_pairs() : cell.world.check();
    contacts += hit ? 1 : 0;
    benchmark::DoNotOptimize(hit);
    robot_pairs += static_cast<double>(cell.world.last_stats().robot_pairs);
    capsule_pairs += static_cast<double>(cell.world.last_stats().capsule_pairs);
  }
  state.counters["per_robot"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate |
                                                     benchmark::Counter::kInvert);
  if (!kAllPairs) {
    state.counters["robot_pairs"] =
        benchmark::Counter(robot_pairs, benchmark::Counter::kAvgIterations);
    state.counters["capsule_pairs"] =
        benchmark::Counter(capsule_pairs, benchmark::Counter::kAvgIterations);
  }
  state.counters["contact"] =
      benchmark::Counter(static_cast<double>(contacts), benchmark::Counter::kAvgIterations);
}

void BM_CollisionCheck(benchmark::State& state) {
  run<false>(state);
}
void BM_CollisionCheckAllPairs(benchmark::State& state) {
  run<true>(state);
}

}  // namespace

BENCHMARK(BM_CollisionCheck)->Arg(2)->Arg(8)->Arg(32)->Arg(128)->Arg(512);
BENCHMARK(BM_CollisionCheckAllPairs)->Arg(32)->Arg(128);
