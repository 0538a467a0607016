// What the files of rccx's C layer (rccl.h, rtc.h) share: the state a C program drives, the
// boxes behind its TRSF and POS pointers, and error reporting. Not installed.
//
// The state is one `State` (state() in rccl_session.cpp, a function-local static: the layer
// owns it, it lives until exit). Its program-wide part (transforms, positions, settings, the last
// error) lasts for the whole program; the rest is one session at a time, each a std::optional that
// its open call emplaces and its close call resets:
//
//   State& s = state();
//   s.arm_session.emplace(model, options);  // rccl_open: a simulated robot and its Manipulator
//   s.arm_session->arm.move(target);        // move(), stop(), waitfor(), teach() ...
//   s.arm_session.reset();                  // rccl_close: all of it goes, in one step
//   s.cell_session.emplace(std::move(cell));  // rccl_cell_open; MANIP handles, mnp_*
//
// A cell is a cell::Workcell and its robots rccl::Arm: cell::Cell and rccl::Manipulator in this
// process, or net::RemoteCell and net::RemoteArm for robots `rccx serve` processes run
// (RCCX_CELL_REMOTE=1, rccl_cell_open_remote). The mnp_ calls go through those interfaces; the
// few that need one kind (a session's clock, a joint start) use `local` / `remote`.
//
// At most one of them is open (and neither while the RTC level's session is, rtc_compat.cpp).
// The sample loop reads the open one (t6 for a C functional transform, nextmove) only while
// control runs: the session is emplaced before control starts and reset after it stopped.
//
// The calls: rccl_session.cpp (open, control, close, errors), rccl_motion.cpp (settings, move,
// stop, distance, waitfor), rccl_teach.cpp (makeposition, update, teach), rccl_transforms.cpp and
// rccl_algebra.cpp (TRSF), rccl_cell.cpp (a cell's robots), rtc_compat.cpp (rtc.h, its own state).
//
// rccx's headers come first and the C headers last, so that the C macros (EQ, TL, Rot, waitfor,
// ...) never reach rccx's headers; the C names (move, stop, park, t6, ...) are why these files
// write std::move.
#pragma once

#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/cell/cell.hpp"
#include "rccx/cell/workcell.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"
#include "rccx/rccl/arm.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rccl/position.hpp"
#include "rccx/rccl/transforms.hpp"
#include "rccx/rtc/sample_log.hpp"
#include "rccx/rtc/session.hpp"
#include "rccx/rtc/simulated_robot.hpp"

// clang-format off
#include "rccl.h"
#include "rtc.h"
// clang-format on

namespace rccx::compat {
struct PositionBox;
}
namespace rccx::net {
class RemoteCell;
class RemoteArm;
}  // namespace rccx::net

/// What a MANIP points to: a robot of the open cell and its own settings.
struct rccl_manip {
  std::string name;
  rccx::rccl::Arm* arm = nullptr;            ///< local or remote, below
  rccx::rccl::Manipulator* local = nullptr;  ///< a robot of this process (cell::Cell)
  rccx::net::RemoteArm* remote = nullptr;    ///< a robot of a serve process (net::RemoteCell)
  rccx::rccl::MotionSettings settings;       ///< mnp_setvel, mnp_setmod, mnp_settime
  rccx::rccl::StartWhen next;                ///< mnp_after / rccl_together, for the next mnp_move
  POS* park = nullptr;
  TRSF_PTR tool = nullptr, base_inv = nullptr, tool_frame = nullptr;
  std::size_t failures_seen = 0;
  bool told_ended = false;
  std::map<std::uint64_t, std::string> motion_names;
  /// motion id -> its position, whose POS.code the motion's end sets (as for one robot)
  std::map<std::uint64_t, rccx::compat::PositionBox*> motion_boxes;
  /// remote: motion id -> its target, until its end, failure or cancellation arrives. A local
  /// generator counts Position::pending_ends itself (POS.end); for a remote one this does.
  std::map<std::uint64_t, rccx::rccl::PositionPtr> in_flight;
};

namespace rccx::compat {

namespace math = rccx::math;
namespace kin = rccx::kin;
namespace rtc = rccx::rtc;
namespace rc = rccx::rccl;

/// What a named TRSF (newtrans, gentr_*, t6, a cell's) is behind its C struct.
struct TrsfBox {
  TRSF c{};  ///< what the program sees; c.rccx points back here
  std::string name;
  /// The transform the sample loop evaluates for varb, functional and system transforms (t6:
  /// rc::t6()); null for const and hold, whose value is read at each move().
  rc::TransformPtr live;
  /// RCCL_SYSTEM: rccx's transform the live one copies into c at each sample.
  rc::TransformPtr source;
  math::Transform last_good;  ///< functional: the last value that was finite (loop side)
  /// functional: when last_good was computed, and the position and time of the value before
  /// (a moving goal's velocity for the generator's predictions).
  double last_t_s = -1.0, previous_t_s = -1.0;
  math::Vec3 previous_p;
};

/// A position the C program holds: the POS it sees and the equation behind it.
struct PositionBox {
  POS c{1, nullptr, 0};
  POS* shown = &c;  ///< the POS the program holds (park: the global one)
  std::string name;
  std::vector<TRSF*> lhs, rhs;  ///< as written; t6 among lhs
  TRSF* tool = nullptr;
  rc::PositionPtr joints;  ///< a position given in joints (park): no equation
  /// Each move() builds a position from the transforms' values then; those not ended yet.
  std::vector<rc::PositionPtr> queued;
};

/// The motions refused during a session: a 1986 program does not look at move()'s result, so
/// rccl_close() and rcclRelease() tell.
struct Refusals {
  std::size_t count = 0;  ///< refused calls in this session
  int first_code = RTC_OK;
  std::string first;  ///< the first refusal's message
  /// Counts `code` when it is an error; the first one's message (rtc_error_message) is kept.
  void note(int code) noexcept;
};

/// What an open arm (rccl_open .. rccl_close) needs. Members are destroyed in reverse order:
/// the manipulator before the robot whose session it uses.
struct ArmSession {
  ArmSession(kin::RobotModel model, const rtc::SimulatedRobotOptions& options);
  rtc::SimulatedRobot robot;
  rc::Manipulator arm;
  std::string configuration;  ///< setconf, as letters ("" keeps the present one)
  math::Transform displacement = math::Transform::identity();  ///< distance(), for the next move
  bool controlling = false;  ///< rccl_control() was called in this session
  bool told_ended = false;   ///< the end of control was printed
  /// The sample at which every queued motion had ended (0: not yet): `completed` waits from
  /// there for the measured arm to come to rest, at most kSettleTimeout_s.
  std::uint64_t ended_at_sample = 0;
  std::size_t failures_seen = 0;
  Refusals refusals;                                   ///< move() calls that failed
  std::map<std::uint64_t, std::string> motion_names;   ///< motion id -> position name
  std::map<std::uint64_t, PositionBox*> motion_boxes;  ///< motion id -> its position
};

/// What an open cell (rccl_cell_open .. rcclRelease) needs: the cell, its robots' MANIP handles.
struct CellSession {
  explicit CellSession(std::unique_ptr<rccx::cell::Cell> loaded);
  explicit CellSession(std::unique_ptr<rccx::net::RemoteCell> joined);
  std::map<std::string, std::unique_ptr<rccl_manip>, std::less<>> manips;
  /// After the handles, which point into it: it stops its robots before they go (a remote
  /// cell leaves the domain: the serve processes then stop the robots it had attached).
  std::unique_ptr<rccx::cell::Workcell> cell;
  rccx::cell::Cell* local = nullptr;        ///< *cell, when it runs in this process
  rccx::net::RemoteCell* remote = nullptr;  ///< *cell, when serve processes run it
  bool started = false;                     ///< rcclStart() was called
  Refusals refusals;                        ///< mnp_move() calls that failed
};

/// Everything the C calls share: the program-wide part, then the one open session. Members are
/// destroyed in reverse order: a session before the positions and transforms its generators
/// point to.
struct State {
  std::map<const TRSF*, std::unique_ptr<TrsfBox>> transforms;
  std::map<const POS*, std::unique_ptr<PositionBox>> positions;
  rc::MotionSettings settings;  ///< setvel, setmod, settime: applied at each move()
  std::string message;          ///< the last error's
  /// main() opened the session for a manual-style pumatask(): the task's own rccl_open and
  /// rccl_control are then accepted (rccl_open reopens it as asked while nothing has moved).
  /// Program-wide: it stays set when the task closes that session itself.
  bool opened_for_task = false;
  std::optional<ArmSession> arm_session;    ///< rccl_open .. rccl_close
  std::optional<CellSession> cell_session;  ///< rccl_cell_open .. rcclRelease
};

State& state();
/// For rccl_main.cpp (which declares them itself: it sees only the C headers).
void mark_session_for_task() noexcept;
bool session_open() noexcept;
TrsfBox& t6_box();
POS& park_box();

enum class Say : bool { quiet, print };

/// Records an error: rtc_error, the message, and (Say::print) a line on stderr.
int fail(int code, std::string_view text, Say say) noexcept;

/// Runs `body` (which returns an error code); an exception becomes an error code. `invalid` is
/// the code for std::invalid_argument, whose meaning depends on the call.
template <class F>
int guarded(const char* call, Say say, int invalid, F&& body) noexcept {
  const auto failed = [&](int code, const char* what) noexcept {
    try {
      return fail(code, fmt::format("{}: {}", call, what), say);
    } catch (...) {
      return fail(code, what, say);
    }
  };
  try {
    return body();
  } catch (const rc::EquationError& e) {
    return failed(RTC_E_EQUATION, e.what());
  } catch (const rc::MotionError& e) {
    return failed(RTC_E_UNREACHABLE, e.what());
  } catch (const kin::RobotFileError& e) {
    return failed(RTC_E_ROBOT, e.what());
  } catch (const rtc::LogError& e) {
    return failed(RTC_E_OPEN, e.what());
  } catch (const rtc::SessionError& e) {
    return failed(RTC_E_OPEN, e.what());
  } catch (const std::invalid_argument& e) {
    return failed(invalid, e.what());
  } catch (const std::exception& e) {
    return failed(RTC_E_INTERNAL, e.what());
  } catch (...) {
    return failed(RTC_E_INTERNAL, "an unknown exception");
  }
}

bool finite(std::initializer_list<double> values) noexcept;

/// A TRSF's value in rccx's units (mm to m), and back.
math::Transform to_math(const TRSF& t) noexcept;
void to_c(const math::Transform& value, TRSF& t) noexcept;
VECT to_c(const math::Vec3& v) noexcept;
math::Vec3 to_math(const VECT& v) noexcept;

/// The box of a TRSF made here (newtrans, gentr_*, t6, a cell's), or null.
TrsfBox* box_of(const TRSF* t) noexcept;
/// Registers rccx's transform `source` as a named TRSF: constants as RCCL_CONST (their value
/// copied), others as RCCL_SYSTEM (copied into the struct at every sample).
TRSF_PTR keep_transform(const rc::TransformPtr& source);

/// The rccx transform standing for `b` in a position built now: constants and holds at their
/// present values (`as_hold`: as a hold transform, so that it stays a factor of its own for
/// update()), the live transform for the others.
rc::TransformPtr transform_now(TrsfBox& b, bool as_hold);

/// The position `p` with the values its const and hold transforms have now, and `extra` (a
/// displacement from distance()) after its right side. `x` (may be null) is built as a hold
/// and returned in `x_out`.
rc::PositionPtr build_position(const PositionBox& p, const math::Transform& extra,
                               const TRSF* x = nullptr, rc::TransformPtr* x_out = nullptr);

/// Brings POS.end, POS.code, `completed` and t6's value up to date with the generators.
void refresh() noexcept;
/// Prints the motions of the arm that failed since the last call (and sets POS.code).
void report_failures(ArmSession& a);
/// The arm's measured T6 (m, rad).
math::Transform measured_t6(const ArmSession& a);
/// The checks every motion call of one arm makes (an arm open and controlling, no cell): RTC_OK
/// or the error, printed. `what` names the call in the message.
int check_can_move(State& s, const std::string& what);
/// Control has ended by itself: RTC_E_TERMINATED, printed the first time only.
int control_ended(ArmSession& a, std::string_view call);
/// The box behind `park` for the open session (built on first use; the arm's park joints).
PositionBox& park_position(State& s, const ArmSession& a);
/// The position box of `p` (park included), or null with the error printed.
PositionBox* position_of(POS_PTR p, const char* call);
/// Calls take(word) for each word of `text` (separated by spaces, commas or tabs; empty words
/// too, which take() skips): the argument strings of distance(), comply(), limit() and
/// mnp_touch().
template <class F>
void for_each_word(const std::string& text, F&& take) {
  std::string word;
  for (const char c : text) {
    if (c == ' ' || c == ',' || c == '\t') {
      take(word);
      word.clear();
    } else {
      word += c;
    }
  }
  take(word);
}
/// POS.code of each motion's position from the arm's events since the last call: 0 ended,
/// RCCL_NEXTMOVE / RCCL_ONF ended early by nextmove, RTC_E_MOTION failed or cancelled.
/// Returns the events it took.
std::vector<rc::MotionEvent> show_motion_codes(
    rc::Arm& arm, const std::map<std::uint64_t, PositionBox*>& motion_boxes);
/// The robot for rccl_open / RCCX_ROBOT.
kin::RobotModel choose_robot(const char* robot);
/// waitfor() with a cell: one tick of the cell's clock.
int cell_wait_tick();
/// True once `e` of robot `m` has happened, or (a motion's end) it failed or was cancelled:
/// mnp_ended, mnp_completed and `completed` alike in one process and across processes.
bool cell_event_done(rccl_manip& m, const rc::Event& e);
/// How a control session ended, for messages.
std::string describe_end(const rtc::Termination& t);
/// Applies the planning side of `nextmove` (a program that set it between samples).
void take_nextmove() noexcept;
/// Called in the sample loop after a transform's function ran: acts on `nextmove`.
void loop_nextmove() noexcept;

}  // namespace rccx::compat
