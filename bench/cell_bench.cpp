// The cell's cycle (the workcell issue): N PUMA 560s on one clock at 1 kHz, each tracking a
// small circle in Cartesian mode through a functional transform (inverse kinematics and the
// functional evaluated every sample), collision checks between them on. One iteration is one
// tick of simulated time: both tasks, every robot read, checked, its f1 and f2 (the trajectory
// generator) run, its command applied, the collision check, and the hand-overs between the
// planning thread and the two tasks. BM_CellCycle runs the robots on the ideal servo (the
// cycle itself), BM_CellCyclePumaPlant on the PUMA's PID and plant (what a simulation costs as
// well). Goal: 250 robots at 1 kHz with the cycle under half the period (2 us a robot).
//
// Those stand 2.5 m apart: the collision check's narrow phase never runs. BM_CellCycleDense
// (issue 30) puts them 0.70 m apart with the circle 650 mm out and 250 mm below the shoulder,
// so that every robot's forearm reaches into the box of the next one in its row and the check
// computes capsule distances between neighbours every tick, without a stop: the joint move from
// the ready pose keeps 63 mm clear, the circles 73 mm (against 10 mm of margin and a few mm of
// braking allowance). Closer than 0.66 m the joint move trips the check; from 0.74 m the boxes
// part during part of each turn; with the circle where the sparse cases have it no spacing
// gives both (docs/PERFORMANCE.md, the dense cell).
//
// Counters, over the timed ticks only (the warm-up's joint moves cost less):
//   tick_p50_us, per_robot_us    median wall time of a tick, and it over N
//   cpu_tick_us, cpu_per_robot_us  the process's CPU time a tick (both tasks, the planning
//                                thread, and the spinning of the hand-overs), and it over N:
//                                what the tick would cost one core, waits excluded
//   compute_p50_us               SessionGroup::compute(), every tick since start (warm-up too)
//   robot_pairs, capsule_pairs,  what the collision check's last tick passed to its narrow
//   solid_pairs                  phase (robot pairs; capsule-capsule and capsule-solid distances)
//   capsule_pairs_per_tick       capsule distances a tick, averaged over the timed ticks
//   robots_failed, collision_stops  robots whose motion failed, and the cell's collision stops
//                                (both must be 0: a stopped robot costs less)
// A fixed number of ticks per N keeps a full run to a few minutes (the 512 case's warm-up of
// 2000 ticks is most of it).
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <vector>

#include "rccx/cell/cell.hpp"
#include "rccx/cell/load.hpp"

namespace {

using namespace std::chrono_literals;

/// Where the robots stand and where their circles are.
struct Layout {
  double spacing_m = 0.0;
  rccx::math::Vec3 centre_m;  ///< the circle's centre in each robot's base frame
};

/// Apart enough that the circles never trip the check, nor reach the narrow phase.
constexpr Layout kSparse{2.5, rccx::cell::kCircleCentre_m};
/// Neighbours in a row within each other's boxes, never within the check's limit (issue 30;
/// found by measuring the closest capsules, see the header).
constexpr Layout kDense{0.70, {0.650, -0.050, -0.250}};

std::int64_t process_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void cycle(benchmark::State& state, bool ideal_servo, bool one_thread, const Layout& layout) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const double robots = static_cast<double>(n);
  rccx::cell::CellOptions options;
  options.ideal_servo = ideal_servo;
  options.one_thread = one_thread;
  rccx::cell::Cell cell(rccx::cell::grid_cell(n, "puma560", layout.spacing_m, 1ms), options);
  rccx::cell::start_circles(cell, layout.centre_m);
  cell.wait_for(2s);  // every robot on its circle, tracking
  const rccx::cell::CollisionWorld& world = cell.collision_world();
  std::vector<double> tick_us;
  tick_us.reserve(static_cast<std::size_t>(state.max_iterations));
  std::size_t capsule_pairs = 0;  // over the timed ticks
  const std::int64_t cpu0 = process_cpu_ns();
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    cell.wait_for(1ms);
    tick_us.push_back(
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    // wait_for returned after the tick's cycle: the control task is between ticks.
    capsule_pairs += world.last_stats().capsule_pairs;
  }
  const double cpu_tick_us = static_cast<double>(process_cpu_ns() - cpu0) * 1e-3 /
                             static_cast<double>(std::max<std::size_t>(tick_us.size(), 1));
  std::nth_element(tick_us.begin(),
                   tick_us.begin() + static_cast<std::ptrdiff_t>(tick_us.size() / 2),
                   tick_us.end());
  const double tick_p50_us = tick_us.empty() ? 0.0 : tick_us[tick_us.size() / 2];
  state.counters["tick_p50_us"] = tick_p50_us;
  state.counters["per_robot_us"] = tick_p50_us / robots;
  state.counters["cpu_tick_us"] = cpu_tick_us;
  state.counters["cpu_per_robot_us"] = cpu_tick_us / robots;
  state.counters["compute_p50_us"] = cell.group().compute().p50_us;
  // The control task is between ticks (wait_for returned after its cycle): the world is quiet.
  const rccx::cell::CheckStats& last = world.last_stats();
  state.counters["robot_pairs"] = static_cast<double>(last.robot_pairs);
  state.counters["capsule_pairs"] = static_cast<double>(last.capsule_pairs);
  state.counters["solid_pairs"] = static_cast<double>(last.solid_pairs);
  state.counters["capsule_pairs_per_tick"] =
      static_cast<double>(capsule_pairs) /
      static_cast<double>(std::max<std::size_t>(tick_us.size(), 1));
  state.counters["collision_stops"] = static_cast<double>(cell.collision_stops());
  std::size_t stopped = 0;  // robots whose motion failed: they would cost less
  for (const auto& name : cell.robot_names())
    stopped += cell.robot(name).failures().empty() ? 0 : 1;
  state.counters["robots_failed"] = static_cast<double>(stopped);
}

/// Ticks timed for N robots: about a second of wall time at a few us a robot.
benchmark::IterationCount ticks_for(int n) {
  return std::clamp<benchmark::IterationCount>(51'200 / n, 200, 2000);
}

void add(const char* name, bool ideal_servo, bool one_thread, std::initializer_list<int> ns,
         const Layout& layout = kSparse) {
  for (const int n : ns) {
    benchmark::RegisterBenchmark(name,
                                 [ideal_servo, one_thread, layout](benchmark::State& s) {
                                   cycle(s, ideal_servo, one_thread, layout);
                                 })
        ->Arg(n)
        ->Iterations(ticks_for(n))
        ->Unit(benchmark::kMicrosecond)
        ->UseRealTime();
  }
}

void register_cycles() {
  add("BM_CellCycle", true, false, {1, 2, 8, 32, 128, 256, 512});
  add("BM_CellCyclePumaPlant", false, false, {1, 2, 8, 32, 128, 256, 512});
  // Both tasks on one thread (CellOptions::one_thread): the cycle's compute on one core.
  add("BM_CellCycleOneThread", true, true, {1, 2, 8, 32, 128, 256, 512});
  add("BM_CellCyclePumaPlantOneThread", false, true, {1, 2, 8, 32, 128, 256, 512});
  // The dense cell (issue 30): capsule distances between neighbours every tick. Ideal servos.
  add("BM_CellCycleDense", true, true, {8, 32, 128, 256, 512}, kDense);
  add("BM_CellCycleDenseTwoTasks", true, false, {8, 32, 128, 256, 512}, kDense);
}

const bool registered = (register_cycles(), true);

}  // namespace
