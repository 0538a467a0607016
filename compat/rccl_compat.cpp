// RCCL's 1986 C interface (compat/rccl.h, compat/rtc.h) over rccx::rccl: the thesis's calls
// with its units (mm, deg, ms) on a simulated robot (rtc::SimulatedRobot) and one
// rccl::Manipulator. No exception leaves this file: every entry point catches, sets rtc_error,
// keeps the message and returns an error code (or NULL).
//
// The C side sees plain values that this file keeps up to date: POS.end (no motion to the
// position pending, from Position::pending_ends) and `completed` (every queued motion ended),
// refreshed by every call and after every sample waitfor() lets run.
#include <fmt/format.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rccx/cell/cell.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rccl/position.hpp"
#include "rccx/rccl/transforms.hpp"
#include "rccx/rtc/sample_log.hpp"
#include "rccx/rtc/session.hpp"
#include "rccx/rtc/simulated_robot.hpp"

// The C headers last, so that their macros (EQ, TL, waitfor) never reach rccx's headers. Their
// global names (move, park, t6, completed) are why this file always writes std::move.
#include "rccl.h"
#include "rtc.h"

/// What a TRSF_PTR points to: a shared rccx transform (null for the EQ and TL marks).
struct rccl_trsf {
  rccx::rccl::TransformPtr transform;
};

/// What a MANIP points to: a robot of the open cell and its own settings.
struct rccl_manip {
  std::string name;
  rccx::rccl::Manipulator* arm = nullptr;
  rccx::rccl::MotionSettings settings;  ///< mnp_setvel, mnp_setmod, mnp_settime
  rccx::rccl::StartWhen next;           ///< mnp_after / rccl_together, for the next mnp_move
  POS* park = nullptr;
  TRSF_PTR tool = nullptr, base_inv = nullptr, tool_frame = nullptr;
  std::size_t failures_seen = 0;
  bool told_ended = false;
  std::map<std::uint64_t, std::string> motion_names;
};

namespace {

namespace math = rccx::math;
namespace kin = rccx::kin;
namespace rtc = rccx::rtc;
namespace rc = rccx::rccl;

/// A position the C program holds: the POS it sees and the equation behind it.
struct PositionBox {
  POS c{1, nullptr};
  std::string name;
  rc::PositionPtr position;
};

/// Everything the C calls share. Members are destroyed in reverse order: the manipulator
/// before the robot whose session it uses, both before the positions and transforms.
struct State {
  std::map<const rccl_trsf*, std::unique_ptr<rccl_trsf>> transforms;
  std::map<const POS*, std::unique_ptr<PositionBox>> positions;
  rc::MotionSettings settings;  ///< setvel, setmod, settime: applied at each move()
  std::unique_ptr<rtc::SimulatedRobot> robot;
  std::unique_ptr<rc::Manipulator> arm;
  bool controlling = false;  ///< rccl_control() was called in this session
  bool told_ended = false;   ///< the end of control was printed
  std::size_t failures_seen = 0;
  std::size_t refused_moves = 0;  ///< move() calls that failed in this session
  int first_refusal_code = RTC_OK;
  std::string first_refusal;
  std::map<std::uint64_t, std::string> motion_names;  ///< motion id -> position name
  std::string message;                                ///< the last error's
  // A cell (rccl_cell_open): declared last, so that it stops before the positions and
  // transforms its generators point to go.
  std::map<std::string, std::unique_ptr<rccl_manip>, std::less<>> manips;
  std::unique_ptr<rccx::cell::Cell> cell;
  bool cell_started = false;
};

State& state() {
  static State s;
  return s;
}

rccl_trsf t6_box{rc::t6()};
rccl_trsf eq_mark{};
rccl_trsf tl_mark{};
POS park_box{1, "park"};

enum class Say : bool { quiet, print };

/// Records an error: rtc_error, the message, and (Say::print) a line on stderr.
int fail(int code, std::string_view text, Say say) noexcept {
  rtc_error = code;
  try {
    state().message.assign(text);
  } catch (...) {  // no memory for the text: the code still tells
  }
  if (say == Say::print)
    std::fprintf(stderr, "rccl: %.*s\n", static_cast<int>(text.size()), text.data());
  return code;
}

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

bool finite(std::initializer_list<double> values) noexcept {
  for (const double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

/// Brings POS.end and `completed` up to date with the trajectory generator.
void refresh() noexcept {
  State& s = state();
  for (auto& [key, box] : s.positions) {
    box->c.end = box->position->pending_ends.load(std::memory_order_acquire) <= 0 ? 1 : 0;
  }
  if (s.arm) {
    park_box.end = s.arm->park()->pending_ends.load(std::memory_order_acquire) <= 0 ? 1 : 0;
    completed = s.arm->happened(rc::Manipulator::completed()) ? 1 : 0;
  } else if (s.cell) {
    park_box.end = 1;
    completed = 1;
    for (const auto& [name, m] : s.manips) {
      if (!m->arm->happened(rc::Manipulator::completed())) completed = 0;
    }
  } else {
    park_box.end = 1;
    completed = 1;
  }
}

std::string motion_name(const State& s, std::uint64_t id) {
  const auto it = s.motion_names.find(id);
  return it == s.motion_names.end() ? fmt::format("motion {}", id)
                                    : fmt::format("motion {} (to {})", id, it->second);
}

std::string describe_end(const rtc::Termination& t) {
  std::string out = fmt::format("control ended at t = {:.3f} s with {} ({}", t.time_s,
                                rtc::to_string(t.code), static_cast<int>(t.code));
  if (t.joint > 0) out += fmt::format(", joint {}", t.joint);
  out += fmt::format("): {}", rtc::describe(t.code));
  if (!t.detail_view().empty()) out += fmt::format("; {}", t.detail_view());
  if (!t.message_view().empty()) out += fmt::format("; rtc_message \"{}\"", t.message_view());
  return out;
}

/// Control has ended by itself: RTC_E_TERMINATED, printed the first time only.
int control_ended(std::string_view call) {
  State& s = state();
  const Say say = s.told_ended ? Say::quiet : Say::print;
  s.told_ended = true;
  return fail(RTC_E_TERMINATED,
              fmt::format("{}: {}; rccl_close() the session", call,
                          describe_end(s.robot->session->termination())),
              say);
}

/// Prints the motions that failed since the last call (and how many were cancelled after).
void report_failures() {
  State& s = state();
  const std::vector<rc::MotionEvent>& f = s.arm->failures();
  std::size_t cancelled = 0;
  for (; s.failures_seen < f.size(); ++s.failures_seen) {
    const rc::MotionEvent& e = f[s.failures_seen];
    if (e.kind == rc::EventKind::failed) {
      fail(RTC_E_MOTION,
           fmt::format("{} failed at t = {:.3f} s: {}; the arm stops where it is",
                       motion_name(s, e.id), e.t_s, e.message()),
           Say::print);
    } else {
      ++cancelled;
    }
  }
  if (cancelled > 0) {
    std::fprintf(stderr, "rccl: %zu queued motion(s) cancelled\n", cancelled);
  }
}

kin::RobotModel choose_robot(const char* robot) {
  std::string name = robot != nullptr ? robot : "";
  if (name.empty()) {
    if (const char* env = std::getenv("RCCX_ROBOT"); env != nullptr) name = env;
  }
  if (name.empty()) name = "microbo";
  const bool file = name.find('/') != std::string::npos || name.ends_with(".json");
  return file ? kin::load_robot_file(name) : kin::builtin_robot(name);
}

/// The separated arguments of makeposition, read before anything can throw.
struct EquationArgs {
  static constexpr std::size_t kMax = 64;
  std::array<TRSF_PTR, kMax> t{};
  std::size_t count = 0;
  std::size_t eq = 0, tl = 0;  ///< indices of EQ and TL in t
  std::string_view problem;    ///< why reading stopped early
};

/// Reads up to the transform after TL. Stops at a NULL, an unknown pointer (it is not
/// dereferenced), EQ twice, TL before EQ or twice: what follows may not be arguments at all.
void read_equation(std::va_list ap, EquationArgs& a) noexcept {
  const State& s = state();
  enum { left, right, tool } part = left;
  for (;;) {
    if (a.count == EquationArgs::kMax) {
      a.problem = "more than 64 arguments: is EQ or TL missing?";
      return;
    }
    TRSF_PTR t = va_arg(ap, TRSF_PTR);
    a.t[a.count++] = t;
    if (t == nullptr) {
      a.problem = "a NULL transform (did gen_tr_rot fail?)";
      return;
    }
    if (t == &eq_mark) {
      if (part != left) {
        a.problem = part == right ? "EQ twice" : "EQ after TL";
        return;
      }
      a.eq = a.count - 1;
      part = right;
      continue;
    }
    if (t == &tl_mark) {
      if (part != right) {
        a.problem = part == left ? "TL before EQ" : "TL twice";
        return;
      }
      a.tl = a.count - 1;
      part = tool;
      continue;
    }
    if (t != &t6_box && s.transforms.find(t) == s.transforms.end()) {
      a.problem = "a pointer that is not a transform (made by gen_tr_rot, or t6)";
      return;
    }
    if (part == tool) return;
  }
}

// --- The cell (rccl_cell_open, MANIP) ------------------------------------------------------------

/// Prints the motions of robot m that failed since the last call; true when its control has
/// ended (printed once).
bool cell_report(rccl_manip& m) {
  const std::vector<rc::MotionEvent>& f = m.arm->failures();
  std::size_t cancelled = 0;
  for (; m.failures_seen < f.size(); ++m.failures_seen) {
    const rc::MotionEvent& e = f[m.failures_seen];
    const auto it = m.motion_names.find(e.id);
    const std::string what = it == m.motion_names.end()
                                 ? fmt::format("{} motion {}", m.name, e.id)
                                 : fmt::format("{} motion {} (to {})", m.name, e.id, it->second);
    if (e.kind == rc::EventKind::failed || !e.message().empty()) {
      fail(
          RTC_E_MOTION,
          fmt::format("{} {} at t = {:.3f} s: {}", what, rc::to_string(e.kind), e.t_s, e.message()),
          Say::print);
    } else {
      ++cancelled;
    }
  }
  if (cancelled > 0)
    std::fprintf(stderr, "rccl: %s: %zu queued motion(s) cancelled\n", m.name.c_str(), cancelled);
  if (m.arm->session().controlling()) return false;
  if (!m.told_ended) {
    m.told_ended = true;
    fail(RTC_E_TERMINATED,
         fmt::format("{}: {}", m.name, describe_end(m.arm->session().termination())), Say::print);
  }
  return true;
}

/// waitfor() with a cell: one tick of the cell's clock.
int cell_wait_tick() {
  State& s = state();
  if (!s.cell_started) {
    return fail(RTC_E_SEQUENCE, "waitfor: call rcclStart() before waiting on the cell", Say::print);
  }
  bool any = false;
  for (auto& [name, m] : s.manips) any = any || m->arm->session().controlling();
  if (any) s.cell->wait_for(s.cell->group().period());
  bool all_ended = true;
  for (auto& [name, m] : s.manips) all_ended = cell_report(*m) && all_ended;
  refresh();
  if (all_ended) {
    return fail(RTC_E_TERMINATED, "waitfor: every robot's control has ended; rcclRelease()",
                Say::quiet);
  }
  return RTC_OK;
}

/// The handle `m` checked: a robot of the open cell.
rccl_manip* known(const MANIP* m) {
  const State& s = state();
  if (m == nullptr || !s.cell) return nullptr;
  for (const auto& [name, box] : s.manips) {
    if (box.get() == m) return box.get();
  }
  return nullptr;
}

int bad_handle(const char* call) {
  return fail(RTC_E_ARGUMENT,
              fmt::format("{}: not a robot of the open cell (a NULL handle, or one from before "
                          "rcclRelease); get one from rcclCreate(name, 0)",
                          call),
              Say::print);
}

/// A robot's position or transform, or NULL (with the error) for a bad handle.
template <class T>
T* member_of(const MANIP* m, const char* call, T* rccl_manip::*member) {
  rccl_manip* r = known(m);
  if (r == nullptr) {
    bad_handle(call);
    return nullptr;
  }
  return r->*member;
}

TRSF_PTR keep_transform(rc::TransformPtr t) {
  auto box = std::make_unique<rccl_trsf>(rccl_trsf{std::move(t)});
  TRSF_PTR p = box.get();
  state().transforms.emplace(p, std::move(box));
  return p;
}

}  // namespace

extern "C" {

int rtc_error = RTC_OK;
int completed = 1;
const VECT xunit = {1.0, 0.0, 0.0};
const VECT yunit = {0.0, 1.0, 0.0};
const VECT zunit = {0.0, 0.0, 1.0};
TRSF_PTR const t6 = &t6_box;
TRSF_PTR const rccl_EQ = &eq_mark;
TRSF_PTR const rccl_TL = &tl_mark;
POS_PTR const park = &park_box;

const char* rtc_error_name(int code) {
  switch (code) {
    case RTC_OK:
      return "RTC_OK";
    case RTC_E_SEQUENCE:
      return "RTC_E_SEQUENCE";
    case RTC_E_ROBOT:
      return "RTC_E_ROBOT";
    case RTC_E_OPEN:
      return "RTC_E_OPEN";
    case RTC_E_ARGUMENT:
      return "RTC_E_ARGUMENT";
    case RTC_E_EQUATION:
      return "RTC_E_EQUATION";
    case RTC_E_UNREACHABLE:
      return "RTC_E_UNREACHABLE";
    case RTC_E_MOTION:
      return "RTC_E_MOTION";
    case RTC_E_TERMINATED:
      return "RTC_E_TERMINATED";
    case RTC_E_INTERNAL:
      return "RTC_E_INTERNAL";
    default:
      return "unknown";
  }
}

const char* rtc_error_message(void) {
  return state().message.c_str();
}

void print_rtc_error(int code, int /*flags*/) {
  static constexpr std::array<const char*, 10> kMeaning = {
      "no error",
      "a call out of order (open, control, move, close)",
      "no such robot, or it cannot be simulated",
      "the control session cannot open",
      "a bad argument",
      "a malformed position equation",
      "a motion that cannot be queued",
      "a motion failed while it ran",
      "control ended",
      "an unexpected failure inside rccx",
  };
  const char* meaning = code >= 0 && code < static_cast<int>(kMeaning.size())
                            ? kMeaning[static_cast<std::size_t>(code)]
                            : "an unknown error code";
  const char* message = rtc_error_message();
  if (code != RTC_OK && code == rtc_error && message[0] != '\0') meaning = message;
  std::printf("rtc error %d (%s): %s\n", code, rtc_error_name(code), meaning);
  std::fflush(stdout);
}

TRSF_PTR gen_tr_rot(const char* name, double x_mm, double y_mm, double z_mm, VECT axis,
                    double angle_deg) {
  TRSF_PTR out = nullptr;
  guarded("gen_tr_rot", Say::print, RTC_E_ARGUMENT, [&] {
    const std::string n = name != nullptr ? name : "?";
    if (!finite({x_mm, y_mm, z_mm, axis.x, axis.y, axis.z, angle_deg})) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("gen_tr_rot({}): every number must be finite (got {}, {}, {} mm, "
                              "axis ({}, {}, {}), {} deg)",
                              n, x_mm, y_mm, z_mm, axis.x, axis.y, axis.z, angle_deg),
                  Say::print);
    }
    const math::Vec3 a{axis.x, axis.y, axis.z};
    if (!(a.norm() > 0.0)) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("gen_tr_rot({}): the rotation axis is zero; use xunit, yunit, "
                              "zunit or any nonzero VECT",
                              n),
                  Say::print);
    }
    const math::Transform value{math::Rot3::about(a, math::deg_to_rad(angle_deg)),
                                {x_mm * 1e-3, y_mm * 1e-3, z_mm * 1e-3}};
    auto box = std::make_unique<rccl_trsf>(rccl_trsf{rc::constant(n, value)});
    TRSF_PTR t = box.get();
    state().transforms.emplace(t, std::move(box));
    out = t;
    return RTC_OK;
  });
  return out;
}

POS_PTR makeposition(const char* name, ...) {
  EquationArgs a;
  std::va_list ap;
  va_start(ap, name);
  read_equation(ap, a);
  va_end(ap);

  POS_PTR out = nullptr;
  guarded("makeposition", Say::print, RTC_E_EQUATION, [&] {
    const std::string n = name != nullptr ? name : "?";
    if (!a.problem.empty()) {
      return fail(RTC_E_EQUATION,
                  fmt::format("makeposition({}): argument {} after the name: {}; write "
                              "makeposition(name, left side (t6 among it), EQ, right side, "
                              "TL, tool), e.g. makeposition(\"P1\", t6, EQ, b, TL, t6)",
                              n, a.count, a.problem),
                  Say::print);
    }
    std::vector<rc::TransformPtr> lhs, rhs;
    for (std::size_t i = 0; i < a.eq; ++i) lhs.push_back(a.t[i]->transform);
    for (std::size_t i = a.eq + 1; i < a.tl; ++i) rhs.push_back(a.t[i]->transform);
    const rc::TransformPtr& tool = a.t[a.tl + 1]->transform;
    auto box = std::make_unique<PositionBox>();
    box->name = n;
    box->position = rc::Position::make(n, lhs, rhs, tool);
    box->c.name = box->name.c_str();
    POS_PTR p = &box->c;
    state().positions.emplace(p, std::move(box));
    out = p;
    return RTC_OK;
  });
  return out;
}

int rccl_open(const char* robot, double period_ms) {
  return guarded("rccl_open", Say::quiet, RTC_E_ROBOT, [&] {
    State& s = state();
    if (s.robot) {
      return fail(RTC_E_SEQUENCE, "rccl_open: a session is open already; rccl_close() it first",
                  Say::quiet);
    }
    if (s.cell) {
      return fail(RTC_E_SEQUENCE, "rccl_open: a cell is open; rcclRelease() it first", Say::quiet);
    }
    if (!(period_ms >= 0.0) || !std::isfinite(period_ms)) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("rccl_open: the period is 0 (the robot's usual one) or 0.25 .. "
                              "56 ms, got {}",
                              period_ms),
                  Say::quiet);
    }
    rtc::SimulatedRobotOptions options;  // simulated time; the log from RCCX_LOG (the session)
    options.period = std::chrono::nanoseconds(std::llround(period_ms * 1e6));
    auto robot_sim = std::make_unique<rtc::SimulatedRobot>(choose_robot(robot), options);
    auto arm = std::make_unique<rc::Manipulator>(*robot_sim->session);
    s.robot = std::move(robot_sim);
    s.arm = std::move(arm);
    s.controlling = false;
    s.told_ended = false;
    s.failures_seen = 0;
    s.refused_moves = 0;
    s.first_refusal.clear();
    s.motion_names.clear();
    refresh();
    return RTC_OK;
  });
}

int rccl_control(void) {
  return guarded("rccl_control", Say::quiet, RTC_E_INTERNAL, [] {
    State& s = state();
    if (!s.arm) return fail(RTC_E_SEQUENCE, "rccl_control: call rccl_open() first", Say::quiet);
    if (s.controlling) {
      return fail(RTC_E_SEQUENCE, "rccl_control: the trajectory generator runs already",
                  Say::quiet);
    }
    s.arm->start();
    s.controlling = true;
    refresh();
    return RTC_OK;
  });
}

int rccl_close(int power_off) {
  return guarded("rccl_close", Say::quiet, RTC_E_INTERNAL, [&] {
    State& s = state();
    if (!s.robot) return fail(RTC_E_SEQUENCE, "rccl_close: no session is open", Say::quiet);
    // Whatever happens below, the session is gone afterwards.
    struct Closer {
      State& s;
      ~Closer() {
        s.arm.reset();
        s.robot.reset();
        // Motions still queued will never end now.
        for (auto& [key, box] : s.positions) box->position->pending_ends.store(0);
        s.controlling = false;
        s.motion_names.clear();
        refresh();
      }
    } closer{s};

    int code = RTC_OK;
    std::string why;
    if (s.controlling) report_failures();
    const rtc::Termination t =
        s.controlling ? s.arm->stop_control() : s.robot->session->termination();
    const std::vector<rc::MotionEvent>& failures = s.arm->failures();
    if (t.ended()) {
      code = RTC_E_TERMINATED;
      why = describe_end(t);
    } else if (!failures.empty()) {
      const rc::MotionEvent& first = failures.front();
      code = RTC_E_MOTION;
      why = fmt::format("{} motion(s) failed or were cancelled during the session; first {} {}{}{}",
                        failures.size(), motion_name(s, first.id), rc::to_string(first.kind),
                        first.message().empty() ? "" : ": ", first.message());
    } else if (s.refused_moves > 0) {
      code = s.first_refusal_code;
      why = fmt::format("{} move() call(s) were refused during the session; the first: {}",
                        s.refused_moves, s.first_refusal);
    }
    s.robot->session->close(power_off != 0);
    return code == RTC_OK ? RTC_OK : fail(code, "rccl_close: " + why, Say::quiet);
  });
}

int setvel(double mm_per_s, double deg_per_s) {
  return guarded("setvel", Say::print, RTC_E_ARGUMENT, [&] {
    if (!(mm_per_s > 0.0) || !(deg_per_s > 0.0) || !finite({mm_per_s, deg_per_s})) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("setvel({}, {}): both speeds must be finite and > 0 (mm/s, deg/s)",
                              mm_per_s, deg_per_s),
                  Say::print);
    }
    State& s = state();
    s.settings.translation_m_per_s = mm_per_s * 1e-3;
    s.settings.rotation_rad_per_s = math::deg_to_rad(deg_per_s);
    return RTC_OK;
  });
}

int setmod(int mode) {
  return guarded("setmod", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    if (mode == 'j' || mode == 'J') {
      s.settings.mode = rc::Mode::joint;
    } else if (mode == 'c' || mode == 'C') {
      s.settings.mode = rc::Mode::cartesian;
    } else {
      const std::string got = mode > ' ' && mode < 127
                                  ? fmt::format("'{}'", static_cast<char>(mode))
                                  : fmt::format("{}", mode);
      return fail(RTC_E_ARGUMENT,
                  fmt::format("setmod({}): the mode is 'j' (joint) or 'c' (Cartesian)", got),
                  Say::print);
    }
    return RTC_OK;
  });
}

int settime(double transition_ms, double segment_ms) {
  return guarded("settime", Say::print, RTC_E_ARGUMENT, [&] {
    if (!(transition_ms > 0.0) || !(segment_ms >= 0.0) || !finite({transition_ms, segment_ms})) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("settime({}, {}): the transition time (ms) must be > 0 and the "
                              "segment time (ms) >= 0 (0: from the speeds of setvel)",
                              transition_ms, segment_ms),
                  Say::print);
    }
    State& s = state();
    s.settings.transition_time_s = transition_ms * 1e-3;
    s.settings.segment_time_s = segment_ms * 1e-3;
    return RTC_OK;
  });
}

int move(POS_PTR p) {
  const int code = guarded("move", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    if (p == nullptr) {
      return fail(RTC_E_ARGUMENT, "move(NULL): no position (did makeposition fail?)", Say::print);
    }
    const auto it = s.positions.find(p);
    if (p != park && it == s.positions.end()) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("move: {} is not a position made by makeposition() (or park)",
                              static_cast<const void*>(p)),
                  Say::print);
    }
    const std::string name = p == park ? "park" : it->second->name;
    if (s.cell) {
      return fail(RTC_E_SEQUENCE,
                  fmt::format("move({}): a cell is open: name the robot, mnp_move(robot, p)", name),
                  Say::print);
    }
    if (!s.arm || !s.controlling) {
      return fail(RTC_E_SEQUENCE,
                  fmt::format("move({}): call rccl_open() and rccl_control() before move()", name),
                  Say::print);
    }
    if (!s.robot->session->controlling()) return control_ended("move(" + name + ")");
    const rc::PositionPtr& target = p == park ? s.arm->park() : it->second->position;
    s.arm->set_mode(s.settings.mode);
    s.arm->set_velocity(s.settings.translation_m_per_s, s.settings.rotation_rad_per_s);
    s.arm->set_segment_time(s.settings.segment_time_s);
    s.arm->set_transition_time(s.settings.transition_time_s);
    const rc::Motion m = s.arm->move(target);
    s.motion_names[m.id] = name;
    refresh();
    return RTC_OK;
  });
  // A 1986 program does not look at move()'s result: rccl_close() will tell.
  State& s = state();
  if (code != RTC_OK && s.robot && ++s.refused_moves == 1) {
    s.first_refusal_code = code;
    try {
      s.first_refusal = rtc_error_message();
    } catch (...) {
    }
  }
  return code;
}

int rccl_wait_sample(void) {
  return guarded("waitfor", Say::print, RTC_E_INTERNAL, [] {
    State& s = state();
    if (s.cell) return cell_wait_tick();
    if (!s.arm || !s.controlling) {
      return fail(RTC_E_SEQUENCE,
                  "waitfor: nothing runs to wait on; call rccl_open() and rccl_control() first",
                  Say::print);
    }
    rtc::Session& session = *s.robot->session;
    if (session.controlling()) session.wait_for(session.period());
    report_failures();
    refresh();
    if (!session.controlling()) return control_ended("waitfor");
    return RTC_OK;
  });
}

// --- The cell
// --------------------------------------------------------------------------------------

int rccl_cell_open(const char* cell_file) {
  return guarded("rccl_cell_open", Say::quiet, RTC_E_ROBOT, [&] {
    State& s = state();
    if (s.robot || s.cell) {
      return fail(RTC_E_SEQUENCE,
                  "rccl_cell_open: a session or cell is open; rccl_close() or rcclRelease() it "
                  "first",
                  Say::quiet);
    }
    std::string path = cell_file != nullptr ? cell_file : "";
    if (path.empty()) {
      if (const char* env = std::getenv("RCCX_CELL"); env != nullptr) path = env;
    }
    if (path.empty()) {
      // The source tree's (a build), else the installed copy.
      std::error_code ec;
      path =
          std::filesystem::exists(RCCX_DEFAULT_CELL, ec) ? RCCX_DEFAULT_CELL : RCCX_INSTALLED_CELL;
    }
    try {
      s.cell = rccx::cell::Cell::load(path);
    } catch (const rccx::cell::CellFileError& e) {
      return fail(RTC_E_ROBOT, fmt::format("rccl_cell_open: {}", e.what()), Say::quiet);
    }
    s.cell_started = false;
    s.refused_moves = 0;
    s.first_refusal.clear();
    refresh();
    return RTC_OK;
  });
}

MANIP* rcclCreate(const char* name, int /*flags*/) {
  MANIP* out = nullptr;
  guarded("rcclCreate", Say::print, RTC_E_ROBOT, [&] {
    State& s = state();
    if (!s.cell) {
      return fail(RTC_E_SEQUENCE, "rcclCreate: call rccl_cell_open() first", Say::print);
    }
    const std::string n = name != nullptr ? name : "";
    if (const auto it = s.manips.find(n); it != s.manips.end()) {
      out = it->second.get();
      return RTC_OK;
    }
    auto m = std::make_unique<rccl_manip>();
    m->name = n;
    m->arm = &s.cell->robot(n);  // std::invalid_argument names the cell's robots
    const rccx::cell::CellRobot& cr = *s.cell->model().find_robot(n);
    m->tool =
        keep_transform(rc::constant(n + "_TOOL", cr.tool.value_or(math::Transform::identity())));
    m->base_inv = keep_transform(rc::constant(n + "_BASE_INV", cr.base.inverse()));
    m->tool_frame = keep_transform(s.cell->tool_frame(n));
    auto park_pos = std::make_unique<PositionBox>();
    park_pos->name = n + " park";
    park_pos->position = m->arm->park();
    park_pos->c.name = park_pos->name.c_str();
    m->park = &park_pos->c;
    s.positions.emplace(m->park, std::move(park_pos));
    out = m.get();
    s.manips.emplace(n, std::move(m));
    return RTC_OK;
  });
  return out;
}

int rcclStart(void) {
  return guarded("rcclStart", Say::quiet, RTC_E_INTERNAL, [] {
    State& s = state();
    if (!s.cell) return fail(RTC_E_SEQUENCE, "rcclStart: call rccl_cell_open() first", Say::quiet);
    if (s.cell_started) {
      return fail(RTC_E_SEQUENCE, "rcclStart: the cell runs already", Say::quiet);
    }
    s.cell->start();
    s.cell_started = true;
    refresh();
    return RTC_OK;
  });
}

int rcclRelease(int power_off) {
  return guarded("rcclRelease", Say::quiet, RTC_E_INTERNAL, [&] {
    State& s = state();
    if (!s.cell) return fail(RTC_E_SEQUENCE, "rcclRelease: no cell is open", Say::quiet);
    struct Closer {
      State& s;
      ~Closer() {
        s.cell.reset();
        s.cell_started = false;
        s.manips.clear();
        for (auto& [key, box] : s.positions) box->position->pending_ends.store(0);
        refresh();
      }
    } closer{s};
    int code = RTC_OK;
    std::string why;
    for (auto& [name, m] : s.manips) {
      if (s.cell_started) cell_report(*m);
      const rtc::Termination t =
          s.cell_started ? m->arm->stop_control() : m->arm->session().termination();
      if (code != RTC_OK) continue;
      const std::vector<rc::MotionEvent>& failures = m->arm->failures();
      if (t.ended()) {
        code = RTC_E_TERMINATED;
        why = fmt::format("{}: {}", name, describe_end(t));
      } else if (!failures.empty()) {
        code = RTC_E_MOTION;
        why = fmt::format("{}: {} motion(s) failed or were cancelled; first motion {} {}: {}", name,
                          failures.size(), failures.front().id,
                          rc::to_string(failures.front().kind), failures.front().message());
      }
    }
    if (code == RTC_OK && s.refused_moves > 0) {
      code = s.first_refusal_code;
      why = fmt::format("{} mnp_move() call(s) were refused; the first: {}", s.refused_moves,
                        s.first_refusal);
    }
    (void)power_off;  // the cell's robots hold; simulated arms have no power to cut
    return code == RTC_OK ? RTC_OK : fail(code, "rcclRelease: " + why, Say::quiet);
  });
}

int mnp_setvel(MANIP* m, double mm_per_s, double deg_per_s) {
  rccl_manip* r = known(m);
  if (r == nullptr) return bad_handle("mnp_setvel");
  State& s = state();
  const rc::MotionSettings saved = s.settings;
  const int code = setvel(mm_per_s, deg_per_s);  // the same checks and words
  if (code == RTC_OK) {
    r->settings.translation_m_per_s = s.settings.translation_m_per_s;
    r->settings.rotation_rad_per_s = s.settings.rotation_rad_per_s;
  }
  s.settings = saved;
  return code;
}

int mnp_setmod(MANIP* m, int mode) {
  rccl_manip* r = known(m);
  if (r == nullptr) return bad_handle("mnp_setmod");
  State& s = state();
  const rc::MotionSettings saved = s.settings;
  const int code = setmod(mode);
  if (code == RTC_OK) r->settings.mode = s.settings.mode;
  s.settings = saved;
  return code;
}

int mnp_settime(MANIP* m, double transition_ms, double segment_ms) {
  rccl_manip* r = known(m);
  if (r == nullptr) return bad_handle("mnp_settime");
  State& s = state();
  const rc::MotionSettings saved = s.settings;
  const int code = settime(transition_ms, segment_ms);
  if (code == RTC_OK) {
    r->settings.transition_time_s = s.settings.transition_time_s;
    r->settings.segment_time_s = s.settings.segment_time_s;
  }
  s.settings = saved;
  return code;
}

int mnp_move(MANIP* m, POS_PTR p) {
  rccl_manip* r = known(m);
  if (r == nullptr) return bad_handle("mnp_move");
  const int code = guarded("mnp_move", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    const auto it = p != nullptr ? s.positions.find(p) : s.positions.end();
    if (it == s.positions.end()) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("mnp_move({}, {}): not a position made by makeposition() (or "
                              "mnp_park)",
                              r->name, static_cast<const void*>(p)),
                  Say::print);
    }
    if (!s.cell_started) {
      return fail(
          RTC_E_SEQUENCE,
          fmt::format("mnp_move({}, {}): call rcclStart() first", r->name, it->second->name),
          Say::print);
    }
    if (!r->arm->session().controlling()) {
      return fail(
          RTC_E_TERMINATED,
          fmt::format("mnp_move({}, {}): {}'s control has ended: {}", r->name, it->second->name,
                      r->name, describe_end(r->arm->session().termination())),
          Say::print);
    }
    r->arm->set_mode(r->settings.mode);
    r->arm->set_velocity(r->settings.translation_m_per_s, r->settings.rotation_rad_per_s);
    r->arm->set_segment_time(r->settings.segment_time_s);
    r->arm->set_transition_time(r->settings.transition_time_s);
    const rc::Motion mo = r->arm->move(it->second->position, r->next);
    r->next = rc::StartWhen{};
    r->motion_names[mo.id] = it->second->name;
    refresh();
    return RTC_OK;
  });
  State& s = state();
  if (code != RTC_OK && ++s.refused_moves == 1) {
    s.first_refusal_code = code;
    try {
      s.first_refusal = rtc_error_message();
    } catch (...) {
    }
  }
  return code;
}

int mnp_last_motion(const MANIP* m) {
  const rccl_manip* r = known(m);
  return r == nullptr ? 0 : static_cast<int>(r->arm->last_queued());
}

int mnp_after(MANIP* m, MANIP* other, int motion, int event) {
  rccl_manip* r = known(m);
  rccl_manip* o = known(other);
  if (r == nullptr || o == nullptr) return bad_handle("mnp_after");
  return guarded("mnp_after", Say::print, RTC_E_ARGUMENT, [&] {
    if (event != RCCL_START && event != RCCL_END) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("mnp_after({}, {}, {}, {}): the event is RCCL_START or RCCL_END",
                              r->name, o->name, motion, event),
                  Say::print);
    }
    if (motion < 1 || static_cast<std::uint64_t>(motion) > o->arm->last_queued()) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("mnp_after({}, {}, {}): {} has queued {}; take the number "
                              "from mnp_last_motion() after its mnp_move",
                              r->name, o->name, motion, o->name,
                              o->arm->last_queued() == 0
                                  ? std::string("no motion yet")
                                  : fmt::format("motions 1 .. {}", o->arm->last_queued())),
                  Say::print);
    }
    if (r->next.after.size() >= rc::StartWhen::kMaxGates) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("mnp_after({}): a motion waits for at most {} events", r->name,
                              rc::StartWhen::kMaxGates),
                  Say::print);
    }
    const rc::Motion mo{static_cast<std::uint64_t>(motion)};
    r->next.after.push_back(
        state().cell->event(o->name, event == RCCL_START ? mo.start() : mo.end()));
    return RTC_OK;
  });
}

int rccl_together(int end_together, ...) {
  std::array<MANIP*, rc::Rendezvous::kMaxParticipants + 1> list{};
  std::size_t n = 0;
  std::va_list ap;
  va_start(ap, end_together);
  for (; n < list.size(); ++n) {
    list[n] = va_arg(ap, MANIP*);
    if (list[n] == nullptr) break;
  }
  va_end(ap);
  return guarded("rccl_together", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    if (n == list.size()) {
      return fail(RTC_E_ARGUMENT,
                  "rccl_together: more than 64 robots: is the NULL that ends the list missing?",
                  Say::print);
    }
    std::vector<std::string> names;
    for (std::size_t i = 0; i < n; ++i) {
      const rccl_manip* r = known(list[i]);
      if (r == nullptr) return bad_handle("rccl_together");
      names.push_back(r->name);
    }
    if (!s.cell) return fail(RTC_E_SEQUENCE, "rccl_together: no cell is open", Say::print);
    const rccx::cell::Together t = s.cell->together(names, end_together != 0);
    for (std::size_t i = 0; i < n; ++i) {
      rccl_manip* r = known(list[i]);
      r->next.together = t.rendezvous;
      r->next.slot = i;
    }
    return RTC_OK;
  });
}

int mnp_started(const MANIP* m, int motion) {
  const rccl_manip* r = known(m);
  if (r == nullptr || motion < 0) return 0;
  return r->arm->happened(rc::Motion{static_cast<std::uint64_t>(motion)}.start()) ? 1 : 0;
}

int mnp_ended(const MANIP* m, int motion) {
  const rccl_manip* r = known(m);
  if (r == nullptr || motion < 0) return 0;
  return r->arm->happened(rc::Motion{static_cast<std::uint64_t>(motion)}.end()) ? 1 : 0;
}

int mnp_completed(const MANIP* m) {
  const rccl_manip* r = known(m);
  return r != nullptr && r->arm->happened(rc::Manipulator::completed()) ? 1 : 0;
}

POS_PTR mnp_park(MANIP* m) {
  return member_of(m, "mnp_park", &rccl_manip::park);
}

TRSF_PTR mnp_tool(MANIP* m) {
  return member_of(m, "mnp_tool", &rccl_manip::tool);
}

TRSF_PTR mnp_base_inv(MANIP* m) {
  return member_of(m, "mnp_base_inv", &rccl_manip::base_inv);
}

TRSF_PTR mnp_tool_frame(MANIP* leader) {
  return member_of(leader, "mnp_tool_frame", &rccl_manip::tool_frame);
}

}  // extern "C"
