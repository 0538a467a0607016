// The sample loop's data (Pinocchio's manner: the data the loop changes, apart from the constant
// model): the phase the arm is in, the segment running and the one planned after it, the
// transition, the halt, the last two setpoints. The generator owns it; the evaluator, the blends
// and the planners read it. The phases follow each other so (docs/TRAJECTORY.md has the figure):
//
//   rest -> transition -> segment -> transition -> segment ... -> transition (to rest) -> rest
//   (or tracking a moving goal); failure, halt, nextmove, stop request -> halting -> rest
//
//   if (loop.phase == Phase::segment) { /* on cur's straight part */ }
//   const Segment& s = loop.present();  // the segment the setpoint belongs to
#pragma once

#include <cstdint>

#include "rccx/rccl/trajectory/blends.hpp"
#include "rccx/rccl/trajectory/halt.hpp"
#include "rccx/rccl/trajectory/segment.hpp"

namespace rccx::rccl::trajectory {

/// What the arm is doing. In rest, tracking and segment, `cur` is the segment it is on: a rest
/// (kind rest), a Cartesian segment resting on its moving goal (resting), a moving segment.
/// During a transition `cur` is the segment it leaves (a rest, a tracking or a moving one).
enum class Phase : std::uint8_t {
  rest,        ///< standing still at cur.q1
  tracking,    ///< at the end of the last Cartesian motion, following its moving goal
  segment,     ///< on the straight part of cur; next may be planned already (has_next)
  transition,  ///< tr: from cur into next (tr.to_next), or to rest at cur's end
  halting,     ///< stopping smoothly (halt), then rest
};

struct LoopState {
  Phase phase = Phase::rest;
  Segment cur, next;
  bool has_next = false;  ///< next is planned (a segment joined to cur, or in transition to)
  double next_tau = 0.0;  ///< half the transition from cur into next, s
  Transition tr;
  Halt halt;
  kin::JointVector last_q, prev_q;  ///< the last two setpoints (rad / m)
  double last_t = 0.0;              ///< the time of last_q, s

  /// The segment the setpoint belongs to: the next one during a transition into it.
  [[nodiscard]] const Segment& present() const noexcept {
    return phase == Phase::transition && tr.to_next ? next : cur;
  }
  /// At rest or tracking: nothing moves but a goal.
  [[nodiscard]] bool resting() const noexcept {
    return phase == Phase::rest || phase == Phase::tracking;
  }
};

}  // namespace rccx::rccl::trajectory
