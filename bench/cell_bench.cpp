// The cell's cycle (the workcell issue): N PUMA 560s on one clock at 1 kHz, each tracking a
// small circle in Cartesian mode through a functional transform (inverse kinematics and the
// functional evaluated every sample), collision checks between them on. One iteration is one
// tick of simulated time: both tasks, every robot read, checked, its f1 and f2 (the trajectory
// generator) run, its command applied, the collision check. Wall time, since the two tasks run
// on two threads. Counters: per_robot (wall time a tick, per robot) and compute_p50_us (the
// tick's computing time from the communication task's wake-up to the end of its control cycle,
// SessionGroup::compute). BM_CellCycle runs the robots on the ideal servo (the cycle itself),
// BM_CellCyclePumaPlant on the PUMA's PID and plant (what a simulation costs as well).
// Goal: 250 robots at 1 kHz with the cycle under half the period (2 us a robot).
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>

#include "rccx/cell/cell.hpp"
#include "rccx/cell/load.hpp"

namespace {

using namespace std::chrono_literals;

constexpr double kSpacing_m = 2.5;  // apart enough that the circles never trip the check

void cycle(benchmark::State& state, bool ideal_servo) {
  const auto n = static_cast<std::size_t>(state.range(0));
  rccx::cell::CellOptions options;
  options.ideal_servo = ideal_servo;
  rccx::cell::Cell cell(rccx::cell::grid_cell(n, "puma560", kSpacing_m, 1ms), options);
  rccx::cell::start_circles(cell);
  cell.wait_for(2s);  // every robot on its circle, tracking
  for (auto _ : state) cell.wait_for(1ms);
  const auto compute = cell.group().compute();
  state.counters["per_robot"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * static_cast<double>(n),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["compute_p50_us"] = compute.p50_us;
  state.counters["compute_p99_us"] = compute.p99_us;
  std::size_t stopped = 0;  // robots whose motion failed: they would cost less
  for (const auto& name : cell.robot_names())
    stopped += cell.robot(name).failures().empty() ? 0 : 1;
  state.counters["robots_failed"] = static_cast<double>(stopped);
}

void BM_CellCycle(benchmark::State& state) {
  cycle(state, true);
}
void BM_CellCyclePumaPlant(benchmark::State& state) {
  cycle(state, false);
}

BENCHMARK(BM_CellCycle)
    ->Arg(1)
    ->Arg(2)
    ->Arg(8)
    ->Arg(32)
    ->Arg(128)
    ->Arg(512)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK(BM_CellCyclePumaPlant)
    ->Arg(1)
    ->Arg(8)
    ->Arg(128)
    ->Arg(512)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace
