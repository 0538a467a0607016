// Teaching positions by hand (thesis 4.5.4.4): the program stops at a teach call, the queue
// having run out, and hands the terminal to the teach loop; the operator moves the arm (zero
// gravity and a push, a joint to a value, jogging in pendant mode), examines it, saves it by
// name, and leaves with `e`; the call returns what was taught and the program goes on.
//
// Commands, one per line (`?` lists them):
//   Z / z          zero gravity on / off (the joints follow a push and stay)
//   push J E S     a simulated hand pushes joint J with effort E (N m or N) for S seconds
//   m J V          move joint J to V (deg, or mm for a prismatic joint)
//   p              pendant mode: `J+` / `J-` jog joint J by the step; `x+` `y-` `z+` ... move
//                  the tool along the base axes; `rx+` `ry-` ... turn it about them; `s V`
//                  sets the step (deg or mm); `q` leaves pendant mode
//   xd / xr / xR   examine the joints in deg and mm / rad and m / range values, and T6
//   X J            the motor parameters of joint J (the Microbo's RCU, Appendix B)
//   h / H          open / close the hand
//   save NAME      store T6 in the position database as NAME
//   e              exit: the call returns
#pragma once

#include <functional>
#include <iosfwd>
#include <string>

#include "rccx/rccl/manipulator.hpp"
#include "rccx/rccl/position_db.hpp"

namespace rccx::rccl {

struct TeachIo {
  std::istream& in;
  std::ostream& out;
  PositionDb* db = nullptr;  ///< for `save` and for teach()'s look-up; may be null
  /// A simulated hand pushing joint (0-based) with an effort (N m or N); empty when the robot
  /// cannot be pushed.
  std::function<void(std::size_t joint, double effort)> push;
};

struct Taught {
  math::Transform t6;         ///< m, rad
  kin::JointVector q;         ///< rad / m
  bool ended_by_exit = true;  ///< false: the input ran out before `e`
};

/// Runs the teach loop on `arm` (after waiting for its queue to complete) until `e`.
Taught teach_loop(Manipulator& arm, TeachIo io);
/// T6 as taught.
math::Transform teach_t6(Manipulator& arm, TeachIo io);
/// The joint values as taught (rad / m).
kin::JointVector teach_angles(Manipulator& arm, TeachIo io);
/// The tool frame of `position` (T6 times its tool transforms) as taught.
math::Transform teach_pos(Manipulator& arm, const Position& position, TeachIo io);
/// RCCL's teach(trans, pos): `x` looked up by name in the database first; when absent, taught
/// and solved so that `position` holds at the taught T6, then stored under its name. A hold
/// `x` is set to the value; the value is returned either way.
math::Transform teach(Manipulator& arm, Transform& x, const Position& position, TeachIo io);

}  // namespace rccx::rccl
