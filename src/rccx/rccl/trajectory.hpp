// The trajectory generator (thesis 2.4.2, RCCL's setpoint): the RTC control function that turns
// the queue of motion requests into one joint setpoint per sample - joint and Cartesian
// segments, transitions that keep velocity continuous, plans checked as they will run, slowing
// down instead of failing. docs/TRAJECTORY.md describes the algorithm in the order a sample runs
// it, its phases, and the files of src/rccx/rccl/trajectory/ that hold it.
//
//   rccl::TrajectoryGenerator gen(kinematics, {.period_s = 0.01});
//   gen.reset(q_measured, 0.0);                       // at rest where the arm is
//   rccl::MotionRequest r;
//   r.id = 1;
//   r.position = &goal;                               // kept alive by the planning level
//   gen.submit(r);                                    // lock-free: planning level -> loop
//   const std::uint64_t id = gen.step(ctx, &q_measured, q_setpoint);  // every sample
//   while (auto e = gen.next_event()) { /* started, ended, failed, cancelled */ }
#pragma once

#include "rccx/rccl/trajectory/generator.hpp"
#include "rccx/rccl/trajectory/requests.hpp"
