// The sample loop's data (Pinocchio's manner: the data the loop changes, apart from the constant
// model): the segment running and the one planned after it, the transition, the halt, the last
// two setpoints. The generator owns it; the evaluator, the blends and the planners read it.
//
//   loop.present();   // the segment the setpoint belongs to (the next one in a transition into it)
#pragma once

#include "rccx/rccl/trajectory/blends.hpp"
#include "rccx/rccl/trajectory/halt.hpp"
#include "rccx/rccl/trajectory/segment.hpp"

namespace rccx::rccl::trajectory {

struct LoopState {
  Segment cur, next;
  bool has_next = false;  ///< next is planned (a segment joined to cur, or in transition to)
  double next_tau = 0.0;  ///< half the transition from cur into next, s
  Transition tr;
  bool in_transition = false;  ///< tr runs
  Halt halt;
  bool halting = false;             ///< halt runs
  kin::JointVector last_q, prev_q;  ///< the last two setpoints (rad / m)
  double last_t = 0.0;              ///< the time of last_q, s

  /// The segment the setpoint belongs to: the next one during a transition into it.
  [[nodiscard]] const Segment& present() const noexcept {
    return in_transition && tr.to_next ? next : cur;
  }
};

}  // namespace rccx::rccl::trajectory
