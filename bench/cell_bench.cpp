// The cell's cycle (the workcell issue): N PUMA 560s on one clock at 1 kHz, each tracking a
// small circle in Cartesian mode through a functional transform (inverse kinematics and the
// functional evaluated every sample), collision checks between them on. One iteration is one
// tick of simulated time: both tasks, every robot read, checked, its f1 and f2 (the trajectory
// generator) run, its command applied, the collision check, and the hand-overs between the
// planning thread and the two tasks. BM_CellCycle runs the robots on the ideal servo (the
// cycle itself), BM_CellCyclePumaPlant on the PUMA's PID and plant (what a simulation costs as
// well). Goal: 250 robots at 1 kHz with the cycle under half the period (2 us a robot).
//
// Counters, over the timed ticks only (the warm-up's joint moves cost less):
//   tick_p50_us, per_robot_us    median wall time of a tick, and it over N
//   cpu_tick_us, cpu_per_robot_us  the process's CPU time a tick (both tasks, the planning
//                                thread, and the spinning of the hand-overs), and it over N:
//                                what the tick would cost one core, waits excluded
//   compute_p50_us               SessionGroup::compute(), every tick since start (warm-up too)
//   robot_pairs, capsule_pairs   what the collision check's last tick passed to its narrow phase
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

constexpr double kSpacing_m = 2.5;  // apart enough that the circles never trip the check

std::int64_t process_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void cycle(benchmark::State& state, bool ideal_servo, bool one_thread) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const double robots = static_cast<double>(n);
  rccx::cell::CellOptions options;
  options.ideal_servo = ideal_servo;
  options.one_thread = one_thread;
  rccx::cell::Cell cell(rccx::cell::grid_cell(n, "puma560", kSpacing_m, 1ms), options);
  rccx::cell::start_circles(cell);
  cell.wait_for(2s);  // every robot on its circle, tracking
  std::vector<double> tick_us;
  tick_us.reserve(static_cast<std::size_t>(state.max_iterations));
  const std::int64_t cpu0 = process_cpu_ns();
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    cell.wait_for(1ms);
    tick_us.push_back(
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
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
  state.counters["robot_pairs"] =
      static_cast<double>(cell.collision_world().last_stats().robot_pairs);
  state.counters["capsule_pairs"] =
      static_cast<double>(cell.collision_world().last_stats().capsule_pairs);
  std::size_t stopped = 0;  // robots whose motion failed: they would cost less
  for (const auto& name : cell.robot_names())
    stopped += cell.robot(name).failures().empty() ? 0 : 1;
  state.counters["robots_failed"] = static_cast<double>(stopped);
}

/// Ticks timed for N robots: about a second of wall time at a few us a robot.
benchmark::IterationCount ticks_for(int n) {
  return std::clamp<benchmark::IterationCount>(51'200 / n, 200, 2000);
}

void add(const char* name, bool ideal_servo, bool one_thread, std::initializer_list<int> ns) {
  for (const int n : ns) {
    benchmark::RegisterBenchmark(
        name, [ideal_servo, one_thread](benchmark::State& s) { cycle(s, ideal_servo, one_thread); })
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
}

const bool registered = (register_cycles(), true);

}  // namespace
