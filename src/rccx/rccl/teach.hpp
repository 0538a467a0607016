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
//
// Every line is read strictly (parse_teach_command, pure so it can be fuzzed): whole tokens,
// finite numbers in range with their units, joint numbers 1 .. dof, no extra words. A refused
// line moves nothing and says why. When control ends (a fault, a limit, Ctrl-C) the loop says
// so at once and refuses motion from then on; `e` still exits. A stop signal (SIGINT, SIGTERM)
// ends the loop after the command in progress.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <string_view>

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
  /// When `db` is null: opens (creates) the database at the first `save`, so that a session
  /// that saves nothing leaves no file. Empty: `save` is refused.
  std::function<PositionDb&()> open_db = {};  // = {}: callers may leave it out, unwarned
};

struct Taught {
  math::Transform t6;               ///< m, rad
  kin::JointVector q;               ///< rad / m
  bool ended_by_exit = true;        ///< false: the input ran out before `e` (or a stop signal came)
  std::size_t failed_commands = 0;  ///< lines refused or that failed
  /// How control ended during the loop (code none: it still runs, the arm holds).
  rtc::Termination termination;
  bool stopped_by_signal = false;  ///< SIGINT / SIGTERM ended the loop

  /// True when everything typed was done and control still runs.
  [[nodiscard]] bool ok() const noexcept {
    return failed_commands == 0 && !termination.ended() && !stopped_by_signal;
  }
};

/// The largest pendant step (`s V`), deg or mm: one jog never swings a joint further.
inline constexpr double kMaxTeachStep = 90.0;
/// The largest effort of a simulated push, N m or N.
inline constexpr double kMaxPushEffort = 1000.0;
/// The longest push, s.
inline constexpr double kMaxPushSeconds = 600.0;

/// One line of the teach loop, read.
struct TeachCommand {
  enum class Kind : std::uint8_t {
    none,  ///< a blank line
    exit,
    menu,
    zero_gravity_on,
    zero_gravity_off,
    push,
    move_joint,
    pendant,
    examine_deg,
    examine_rad,
    examine_range,
    motor_parameters,
    hand_open,
    hand_close,
    save,
    // pendant mode
    leave_pendant,
    set_step,
    jog_joint,
    jog_tool,  ///< along a base axis
    turn_tool  ///< about a base axis
  };
  Kind kind = Kind::none;
  std::size_t joint = 0;  ///< 0 .. dof - 1
  /// move_joint: the goal (rad or m, within the joint's limits); push: the effort (N m or N);
  /// set_step: the step (deg or mm).
  double value = 0.0;
  double seconds = 0.0;  ///< push
  int sign = 0;          ///< jogs: +1 or -1
  std::size_t axis = 0;  ///< jog_tool / turn_tool: 0 x, 1 y, 2 z
  std::string name;      ///< save
};

/// Reads one line as the teach loop does (pendant mode takes the pendant's commands). Throws
/// io::ParseError saying what is wrong and what to write instead.
TeachCommand parse_teach_command(std::string_view line, const kin::RobotModel& model,
                                 bool pendant_mode);

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
