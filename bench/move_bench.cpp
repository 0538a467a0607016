// A move() to its first setpoint: the C++ peer of python/bench/bench_move.py (make bench-python,
// docs/PYTHON.md "Speed"). A simulated PUMA 560 in simulated time (rtc::SimulatedRobot and its
// rccl::Manipulator, as rccx.Robot("puma560") builds them, its usual 10 ms period), goes back
// and forth between two Cartesian goals (T6 = G, G a constant, joint mode); timed: the move()
// call (the goal checked, the motion queued) and the waitfor of the motion's start, which runs
// samples up to the one whose setpoint is the motion's first. The rest of the motion runs
// untimed (timing paused) before the next move.
#include <benchmark/benchmark.h>

#include <chrono>
#include <string>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rccl/position.hpp"
#include "rccx/rccl/transforms.hpp"
#include "rccx/rtc/simulated_robot.hpp"

namespace {

using namespace rccx;

void BM_MoveToFirstSetpoint(benchmark::State& state) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  const auto k = kin::make_kinematics(robot.model);
  // The two goals: the ready pose, and 0.1 rad off on the waist and the wrist (bench_move.py's).
  kin::JointVector qa = robot.model.ready();
  kin::JointVector qb = qa;
  qb[0] += 0.1;
  qb[4] += 0.1;
  const auto t6 = rccl::t6();
  const rccl::PositionPtr goals[2] = {
      rccl::Position::make("A", {t6}, {rccl::constant("GA", k->forward(qa))}, t6),
      rccl::Position::make("B", {t6}, {rccl::constant("GB", k->forward(qb))}, t6)};
  if (arm.waitfor(arm.move(goals[0]).end()) != rccl::WaitResult::reached) {
    state.SkipWithError("the first motion did not end");
    return;
  }
  int next = 1;
  double move_ns = 0.0;  // the move() calls alone, wall clock (the counter move_ns)
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const rccl::Motion m = arm.move(goals[next]);
    move_ns += static_cast<double>((std::chrono::steady_clock::now() - t0).count());
    const rccl::WaitResult started = arm.waitfor(m.start());
    state.PauseTiming();
    if (started != rccl::WaitResult::reached || arm.waitfor(m.end()) != rccl::WaitResult::reached) {
      state.SkipWithError("a motion did not start or end");
      break;
    }
    next = 1 - next;
    state.ResumeTiming();
  }
  state.counters["move_ns"] = benchmark::Counter(move_ns, benchmark::Counter::kAvgIterations);
  (void)arm.stop_control();
}
// A fixed count: each iteration also runs a whole motion untimed.
BENCHMARK(BM_MoveToFirstSetpoint)->Unit(benchmark::kMicrosecond)->Iterations(1000);

}  // namespace
