// RCCL's C interface (compat/rccl.h, compat/rtc.h) over rccx::rccl: the manual's and the
// thesis's calls with their units (mm, deg, ms) on a simulated robot (rtc::SimulatedRobot) and
// one rccl::Manipulator. No exception leaves this file: every entry point catches, sets
// rtc_error, keeps the message and returns an error code (or NULL).
//
// The C side sees plain values that this file keeps up to date: POS.end and POS.code (from
// the positions each move() built and the generator's events), `completed` (every queued
// motion ended) and t6's value, refreshed by every call and after every sample waitfor() lets
// run. Transforms are in rccl_transforms.cpp and rccl_algebra.cpp, the cell in rccl_cell.cpp.
#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

#include "compat_internal.hpp"
#include "compat_shared.hpp"
#include "rccx/rccl/position_db.hpp"
#include "rccx/rccl/teach.hpp"

namespace rccx::compat {

State& state() {
  static State s;
  return s;
}

TrsfBox& t6_box() {
  static TrsfBox b = [] {
    TrsfBox box;
    box.name = "T6";
    box.live = rc::t6();
    to_c(math::Transform::identity(), box.c);
    box.c.type = RCCL_T6;
    box.c.age = -1;
    return box;
  }();
  b.c.name = b.name.c_str();
  b.c.rccx = &b;
  return b;
}

POS& park_box() {
  static POS p{1, "park", 0};
  return p;
}

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

ArmSession::ArmSession(kin::RobotModel model, const rtc::SimulatedRobotOptions& options)
    : robot(std::move(model), options), arm(*robot.session) {}

void Refusals::note(int code) noexcept {
  if (code != RTC_OK && ++count == 1) {
    first_code = code;
    try {
      first = rtc_error_message();
    } catch (...) {
    }
  }
}

namespace {

/// `completed` also waits for the measured arm to stop (every joint under this fraction of its
/// top speed): a follower such as the Microbo's RCU trails the setpoints by a few samples, and
/// a program that reads t6 once its motions are complete expects the arm there.
constexpr double kSettledSpeedFraction = 0.002;
/// ... but at most this long after the last motion ended (an arm that keeps trembling).
constexpr double kSettleTimeout_s = 1.0;

bool arm_settled(ArmSession& a, bool ended) noexcept {
  if (!ended) {
    a.ended_at_sample = 0;
    return false;
  }
  if (!a.controlling || !a.robot.session->controlling()) return true;
  const rtc::Session& session = *a.robot.session;
  const rtc::How how = session.how();
  if (a.ended_at_sample == 0) a.ended_at_sample = std::max<std::uint64_t>(how.sample, 1);
  const double waited_s = static_cast<double>(how.sample - a.ended_at_sample) *
                          std::chrono::duration<double>(session.period()).count();
  if (waited_s >= kSettleTimeout_s) return true;
  const auto& joints = a.arm.kinematics().model().joints;
  for (std::size_t j = 0; j < how.dof && j < joints.size(); ++j) {
    if (std::abs(how.joint[j].velocity) > kSettledSpeedFraction * joints[j].max_velocity) {
      return false;
    }
  }
  return true;
}

}  // namespace

void mark_session_for_task() noexcept {
  state().opened_for_task = true;
}
bool session_open() noexcept {
  return state().arm_session.has_value();
}

void refresh() noexcept {
  State& s = state();
  for (auto& [key, box] : s.positions) {
    std::erase_if(box->queued, [](const rc::PositionPtr& p) {
      return p->pending_ends.load(std::memory_order_acquire) <= 0;
    });
    box->shown->end = box->queued.empty() ? 1 : 0;
  }
  if (s.arm_session) {
    ArmSession& a = *s.arm_session;
    completed = arm_settled(a, a.arm.happened(rc::Manipulator::completed())) ? 1 : 0;
  } else if (s.cell_session) {
    completed = 1;
    for (const auto& [name, m] : s.cell_session->manips) {
      if (!m->arm->happened(rc::Manipulator::completed())) completed = 0;
    }
  } else {
    completed = 1;
  }
}

namespace {

std::string motion_name(const ArmSession& a, std::uint64_t id) {
  const auto it = a.motion_names.find(id);
  return it == a.motion_names.end() ? fmt::format("motion {}", id)
                                    : fmt::format("motion {} (to {})", id, it->second);
}

/// The arm's measured T6 (m, rad).
math::Transform measured_t6(const ArmSession& a) {
  return a.arm.kinematics().forward(a.robot.session->how().q());
}

/// Control has ended by itself: RTC_E_TERMINATED, printed the first time only.
int control_ended(ArmSession& a, std::string_view call);

/// The configuration `asked` (letters or words) in the robot's names, letters not given taken
/// from `present`. Throws std::invalid_argument naming the robot's letters.
std::string configuration_letters(const kin::Kinematics& k, std::string_view asked,
                                  std::string_view present) {
  // Each word or letter is one choice: l r (shoulder), u d (elbow), n f (wrist).
  static constexpr std::array<std::pair<std::string_view, char>, 14> kWords{{
      {"lefty", 'l'},
      {"left", 'l'},
      {"righty", 'r'},
      {"right", 'r'},
      {"up", 'u'},
      {"above", 'u'},
      {"down", 'd'},
      {"below", 'd'},
      {"noflip", 'n'},
      {"flip", 'f'},
      {"l", 'l'},
      {"r", 'r'},
      {"n", 'n'},
      {"f", 'f'},
  }};
  std::string letters;
  std::string word;
  const auto take = [&](std::string_view w) {
    if (w.empty()) return;
    for (const auto& [name, letter] : kWords) {
      if (w == name) {
        letters += letter;
        return;
      }
    }
    for (const char c : w) letters += c;  // "lun", "ud": letters run together
  };
  for (const char c : asked) {
    if (c == ' ' || c == ',' || c == '-' || c == '_') {
      take(word);
      word.clear();
    } else {
      word += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
  }
  take(word);
  std::string out(present);
  const auto names = k.configuration_names();
  for (const char c : letters) {
    bool placed = false;
    for (std::size_t i = 0; i < out.size() && !placed; ++i) {
      // Position i takes the letters that the robot's names use there.
      for (const std::string_view n : names) {
        if (i < n.size() && n[i] == c) {
          out[i] = c;
          placed = true;
          break;
        }
      }
    }
    if (!placed) {
      std::string known;
      for (const std::string_view n : names)
        known += fmt::format("{}{}", known.empty() ? "" : ", ", n);
      throw std::invalid_argument(fmt::format(
          "setconf(\"{}\"): robot {} has no configuration letter '{}'; its configurations are "
          "{} (l/r shoulder lefty/righty, u/d elbow up/down, n/f wrist noflip/flip)",
          asked, k.model().name, c, known.empty() ? "none" : known));
    }
  }
  return out;
}

/// Settings, configuration and the queue's bookkeeping for one move() or stop().
void apply_settings(ArmSession& a, const rc::MotionSettings& settings) {
  a.arm.set_mode(settings.mode);
  a.arm.set_velocity(settings.translation_m_per_s, settings.rotation_rad_per_s);
  a.arm.set_segment_time(settings.segment_time_s);
  a.arm.set_transition_time(settings.transition_time_s);
  a.arm.set_guard(settings.guard);
  a.arm.set_compliance(settings.compliance);
  // setconf() is for joint moves, which may change configuration; a Cartesian line keeps the
  // arm's (the manual's setconf letters stay asked for the joint moves that follow).
  if (a.configuration.empty() || settings.mode == rc::Mode::cartesian) {
    a.arm.set_configuration("");
  } else {
    const kin::Kinematics& k = a.arm.kinematics();
    const std::string present(
        k.configuration_names()[k.configuration_of(a.robot.session->how().q()).index]);
    a.arm.set_configuration(configuration_letters(k, a.configuration, present));
  }
}

/// The checks every motion call makes; RTC_OK or the error (printed).
int check_can_move(State& s, const std::string& what) {
  if (s.cell_session) {
    return fail(RTC_E_SEQUENCE,
                fmt::format("{}: a cell is open: name the robot, mnp_move(robot, p)", what),
                Say::print);
  }
  if (!s.arm_session || !s.arm_session->controlling) {
    return fail(RTC_E_SEQUENCE,
                fmt::format("{}: call rccl_open() and rccl_control() before it", what), Say::print);
  }
  if (!s.arm_session->robot.session->controlling()) return control_ended(*s.arm_session, what);
  return RTC_OK;
}

/// A 1986 program does not look at move()'s result: rccl_close() will tell.
void note_refusal(int code) noexcept {
  State& s = state();
  if (s.arm_session) s.arm_session->refusals.note(code);
}

int control_ended(ArmSession& a, std::string_view call) {
  const Say say = a.told_ended ? Say::quiet : Say::print;
  a.told_ended = true;
  return fail(RTC_E_TERMINATED,
              fmt::format("{}: {}; rccl_close() the session", call,
                          describe_end(a.robot.session->termination())),
              say);
}

/// The position box of `p` (park included), or null with the error printed.
PositionBox* position_of(POS_PTR p, const char* call) {
  State& s = state();
  if (p == nullptr) {
    fail(RTC_E_ARGUMENT, fmt::format("{}(NULL): no position (did makeposition fail?)", call),
         Say::print);
    return nullptr;
  }
  const auto it = s.positions.find(p);
  if (it == s.positions.end()) {
    fail(RTC_E_ARGUMENT,
         fmt::format("{}: {} is not a position made by makeposition() (or park)", call,
                     static_cast<const void*>(p)),
         Say::print);
    return nullptr;
  }
  return it->second.get();
}

/// The box behind `park` for the open session (built on first use).
PositionBox& park_position(State& s, const ArmSession& a) {
  auto it = s.positions.find(&park_box());
  if (it == s.positions.end()) {
    auto box = std::make_unique<PositionBox>();
    box->name = "park";
    box->shown = &park_box();
    it = s.positions.emplace(&park_box(), std::move(box)).first;
  }
  it->second->joints = a.arm.park();
  return *it->second;
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
  enum { left, right, tool } part = left;
  for (;;) {
    if (a.count == EquationArgs::kMax) {
      a.problem = "more than 64 arguments: is EQ or TL missing?";
      return;
    }
    TRSF_PTR t = va_arg(ap, TRSF_PTR);
    a.t[a.count++] = t;
    if (t == nullptr) {
      a.problem = "a NULL transform (did newtrans or gentr_ fail?)";
      return;
    }
    if (t == rccl_EQ) {
      if (part != left) {
        a.problem = part == right ? "EQ twice" : "EQ after TL";
        return;
      }
      a.eq = a.count - 1;
      part = right;
      continue;
    }
    if (t == rccl_TL) {
      if (part != right) {
        a.problem = part == left ? "TL before EQ" : "TL twice";
        return;
      }
      a.tl = a.count - 1;
      part = tool;
      continue;
    }
    if (box_of(t) == nullptr) {
      a.problem = "a pointer that is not a transform made by newtrans or gentr_ (or t6)";
      return;
    }
    if (part == tool) return;
  }
}

/// The result of a C transform's function, the planning side: `nextmove` set by the program.
void act_on_nextmove(State& s) noexcept {
  if (s.arm_session) s.arm_session->arm.generator().request_next();
  if (s.cell_session) {
    for (const auto& [name, m] : s.cell_session->manips) m->arm->generator().request_next();
  }
}

TRSF eq_mark{};
TRSF tl_mark{};

}  // namespace

std::string describe_end(const rtc::Termination& t) {
  std::string out = fmt::format("control ended at t = {:.3f} s with {} ({}", t.time_s,
                                rtc::to_string(t.code), static_cast<int>(t.code));
  if (t.joint > 0) out += fmt::format(", joint {}", t.joint);
  out += fmt::format("): {}", rtc::describe(t.code));
  if (!t.detail_view().empty()) out += fmt::format("; {}", t.detail_view());
  if (!t.message_view().empty()) out += fmt::format("; rtc_message \"{}\"", t.message_view());
  return out;
}

bool rccl_session_open() noexcept {
  const State& s = state();
  return s.arm_session || s.cell_session;
}

void take_nextmove() noexcept {
  State& s = state();
  if (nextmove != 0) {
    nextmove = 0;
    act_on_nextmove(s);
  }
}

void loop_nextmove() noexcept {
  if (nextmove == 0) return;
  nextmove = 0;
  // The loop is the generator's own thread: request_next() takes effect at the next step.
  act_on_nextmove(state());
}

void show_motion_codes(rc::Manipulator& arm,
                       const std::map<std::uint64_t, PositionBox*>& motion_boxes) {
  for (const rc::MotionEvent& e : arm.take_events()) {
    const auto it = motion_boxes.find(e.id);
    if (it == motion_boxes.end()) continue;
    if (e.kind == rc::EventKind::ended) {
      int code = 0;
      if (e.message() == rc::kNextmoveText) {
        code = arm.contact(rc::Motion{e.id}) ? RCCL_ONF : RCCL_NEXTMOVE;
      }
      it->second->shown->code = code;
    } else if (e.kind == rc::EventKind::failed || e.kind == rc::EventKind::cancelled) {
      it->second->shown->code = RTC_E_MOTION;
    }
  }
}

void report_failures(ArmSession& a) {
  // Ended events of nextmove, and failures, set POS.code of the motion's position.
  show_motion_codes(a.arm, a.motion_boxes);
  const std::vector<rc::MotionEvent>& f = a.arm.failures();
  std::size_t cancelled = 0;
  for (; a.failures_seen < f.size(); ++a.failures_seen) {
    const rc::MotionEvent& e = f[a.failures_seen];
    if (e.kind == rc::EventKind::failed) {
      fail(RTC_E_MOTION,
           fmt::format("{} failed at t = {:.3f} s: {}; the arm stops where it is",
                       motion_name(a, e.id), e.t_s, e.message()),
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

}  // namespace rccx::compat

using namespace rccx::compat;

extern "C" {

int rtc_error = RTC_OK;
int completed = 1;
volatile int nextmove = 0;
TRSF_PTR const t6 = &t6_box().c;
TRSF_PTR const rccl_EQ = &eq_mark;
TRSF_PTR const rccl_TL = &tl_mark;
POS_PTR const park = &park_box();

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
    case RTC_E_NOT_YET:
      return "RTC_E_NOT_YET";
    default:
      return "unknown";
  }
}

const char* rtc_error_message(void) {
  return state().message.c_str();
}

void print_rtc_error(int code, int /*flags*/) {
  static constexpr std::array<const char*, 11> kMeaning = {
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
      "not done by this version of rccx yet",
  };
  const char* meaning = code >= 0 && code < static_cast<int>(kMeaning.size())
                            ? kMeaning[static_cast<std::size_t>(code)]
                            : "an unknown error code";
  const char* message = rtc_error_message();
  if (code != RTC_OK && code == rtc_error && message[0] != '\0') meaning = message;
  std::printf("rtc error %d (%s): %s\n", code, rtc_error_name(code), meaning);
  std::fflush(stdout);
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
    auto box = std::make_unique<PositionBox>();
    box->name = n;
    for (std::size_t i = 0; i < a.eq; ++i) box->lhs.push_back(a.t[i]);
    for (std::size_t i = a.eq + 1; i < a.tl; ++i) box->rhs.push_back(a.t[i]);
    box->tool = a.t[a.tl + 1];
    // Built once now so that a malformed equation is refused here (the values are checked at
    // each move(): they may change until then).
    std::vector<rc::TransformPtr> lhs, rhs;
    rc::TransformPtr tool;
    const auto stand_in = [](TRSF* t) {
      TrsfBox* b = box_of(t);
      return b == &t6_box() ? rc::t6() : rc::constant(b->name, math::Transform::identity());
    };
    for (TRSF* t : box->lhs) {
      lhs.push_back(stand_in(t));
      if (t == box->tool) tool = lhs.back();
    }
    for (TRSF* t : box->rhs) rhs.push_back(stand_in(t));
    if (!tool && box->tool != nullptr) {
      return fail(RTC_E_EQUATION,
                  fmt::format("makeposition({}): the tool transform after TL ({}) must be one of "
                              "the left side's, at or after t6 (t6 itself for no tool)",
                              n, box_of(box->tool)->name),
                  Say::print);
    }
    (void)rc::Position::make(n, lhs, rhs, tool);  // throws EquationError saying what is wrong
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
    if (s.arm_session && s.opened_for_task) {
      // pumatask() opening the session main() opened for it: as it asks, if nothing has moved.
      if (!s.arm_session->motion_names.empty()) return RTC_OK;
      s.opened_for_task = false;
      if (const int code = rccl_close(0); code != RTC_OK) return code;
    }
    if (s.arm_session) {
      return fail(RTC_E_SEQUENCE, "rccl_open: a session is open already; rccl_close() it first",
                  Say::quiet);
    }
    if (s.cell_session) {
      return fail(RTC_E_SEQUENCE, "rccl_open: a cell is open; rcclRelease() it first", Say::quiet);
    }
    if (rtc_session_open()) {
      return fail(RTC_E_SEQUENCE,
                  "rccl_open: an RTC session (control, rtc_open) is open; release() or "
                  "rtc_close() it first",
                  Say::quiet);
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
    const ArmSession& a = s.arm_session.emplace(choose_robot(robot), options);
    t6_box().c.age = -1;
    nextmove = 0;
    park_position(s, a);
    to_c(measured_t6(a), t6_box().c);
    refresh();
    return RTC_OK;
  });
}

int rccl_control(void) {
  return guarded("rccl_control", Say::quiet, RTC_E_INTERNAL, [] {
    State& s = state();
    if (!s.arm_session) {
      return fail(RTC_E_SEQUENCE, "rccl_control: call rccl_open() first", Say::quiet);
    }
    ArmSession& a = *s.arm_session;
    if (a.controlling && s.opened_for_task) return RTC_OK;
    if (a.controlling) {
      return fail(RTC_E_SEQUENCE, "rccl_control: the trajectory generator runs already",
                  Say::quiet);
    }
    a.arm.start();
    a.controlling = true;
    refresh();
    return RTC_OK;
  });
}

int rccl_close(int power_off) {
  return guarded("rccl_close", Say::quiet, RTC_E_INTERNAL, [&] {
    State& s = state();
    if (!s.arm_session) return fail(RTC_E_SEQUENCE, "rccl_close: no session is open", Say::quiet);
    // Whatever happens below, the session is gone afterwards.
    struct Closer {
      State& s;
      ~Closer() {
        s.arm_session.reset();
        // Motions still queued will never end now.
        for (auto& [key, box] : s.positions) box->queued.clear();
        if (auto it = s.positions.find(&park_box()); it != s.positions.end()) {
          it->second->joints.reset();  // the next session's robot has its own park
        }
        refresh();
      }
    } closer{s};

    ArmSession& a = *s.arm_session;
    int code = RTC_OK;
    std::string why;
    if (a.controlling) report_failures(a);
    // The motions have ended: let the arm come to rest before control stops (bounded).
    if (a.controlling && a.robot.session->controlling() &&
        a.arm.happened(rc::Manipulator::completed())) {
      rtc::Session& session = *a.robot.session;
      refresh();
      while (completed == 0 && session.controlling()) {
        session.wait_for(session.period());
        refresh();
      }
    }
    const rtc::Termination t =
        a.controlling ? a.arm.stop_control() : a.robot.session->termination();
    const std::vector<rc::MotionEvent>& failures = a.arm.failures();
    if (t.ended()) {
      code = RTC_E_TERMINATED;
      why = describe_end(t);
    } else if (!failures.empty()) {
      const rc::MotionEvent& first = failures.front();
      code = RTC_E_MOTION;
      why = fmt::format("{} motion(s) failed or were cancelled during the session; first {} {}{}{}",
                        failures.size(), motion_name(a, first.id), rc::to_string(first.kind),
                        first.message().empty() ? "" : ": ", first.message());
    } else if (a.refusals.count > 0) {
      code = a.refusals.first_code;
      why = fmt::format(
          "{} call(s) to queue a motion were refused during the session; the "
          "first: {}",
          a.refusals.count, a.refusals.first);
    }
    a.robot.session->close(power_off != 0);
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
    s.settings.rotation_rad_per_s = deg_per_s * (std::numbers::pi / 180.0);
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

int setconf(const char* configuration) {
  return guarded("setconf", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    const std::string asked = configuration != nullptr ? configuration : "";
    if (s.arm_session && !asked.empty()) {
      // Checked now against the robot's letters (the arm's present ones fill the rest).
      const kin::Kinematics& k = s.arm_session->arm.kinematics();
      if (k.configuration_names().empty()) {
        return fail(RTC_E_ARGUMENT,
                    fmt::format("setconf(\"{}\"): robot {} has no named configurations", asked,
                                k.model().name),
                    Say::print);
      }
      const std::string present(
          k.configuration_names()[k.configuration_of(s.arm_session->robot.session->how().q())
                                      .index]);
      (void)configuration_letters(k, asked, present);
    }
    // Kept by the open session's arm only: rccl_open starts with none.
    if (s.arm_session) s.arm_session->configuration = asked;
    return RTC_OK;
  });
}

int move(POS_PTR p) {
  const int code = guarded("move", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    PositionBox* box = p == park ? nullptr : position_of(p, "move");
    if (p != park && box == nullptr) return rtc_error;
    const std::string name = p == park ? "park" : box->name;
    if (const int c = check_can_move(s, "move(" + name + ")"); c != RTC_OK) return c;
    ArmSession& a = *s.arm_session;
    if (p == park) box = &park_position(s, a);
    take_nextmove();
    const rc::PositionPtr target = build_position(*box, a.displacement);
    apply_settings(a, s.settings);
    const rc::Motion m = a.arm.move(target);
    a.displacement = math::Transform::identity();
    box->queued.push_back(target);
    a.motion_names[m.id] = name;
    a.motion_boxes[m.id] = box;
    refresh();
    return RTC_OK;
  });
  note_refusal(code);
  return code;
}

int stop(double ms) {
  const int code = guarded("stop", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    if (!(ms > 0.0) || !std::isfinite(ms)) {
      return fail(RTC_E_ARGUMENT, fmt::format("stop({}): the time is > 0 ms", ms), Say::print);
    }
    if (const int c = check_can_move(s, fmt::format("stop({})", ms)); c != RTC_OK) return c;
    ArmSession& a = *s.arm_session;
    apply_settings(a, s.settings);
    const rc::Motion m = a.arm.dwell(ms * 1e-3);
    a.motion_names[m.id] = fmt::format("stop {} ms", ms);
    refresh();
    return RTC_OK;
  });
  note_refusal(code);
  return code;
}

int distance(const char* what, ...) {
  std::va_list ap;
  va_start(ap, what);
  // Read every value before anything can throw (at most one per word of `what`).
  std::array<double, 16> values{};
  std::size_t words = 0;
  const std::string text = what != nullptr ? what : "";
  {
    bool in_word = false;
    for (const char c : text) {
      const bool sep = c == ' ' || c == ',' || c == '\t';
      if (!sep && !in_word && words < values.size()) values[words++] = va_arg(ap, double);
      in_word = !sep;
    }
  }
  va_end(ap);
  return guarded("distance", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    math::Transform trans = math::Transform::identity();
    math::Rot3 rotation = math::Rot3::identity();
    std::size_t k = 0;
    const auto take = [&](const std::string& w) {
      if (w.empty()) return;
      const double v = values[k++];
      if (!std::isfinite(v)) {
        throw std::invalid_argument(
            fmt::format("distance(\"{}\"): the value of {} is not finite", text, w));
      }
      if (w == "dx")
        trans.p.x += v * 1e-3;
      else if (w == "dy")
        trans.p.y += v * 1e-3;
      else if (w == "dz")
        trans.p.z += v * 1e-3;
      else if (w == "rx")
        rotation = rotation * math::Rot3::rot_x(v * std::numbers::pi / 180.0);
      else if (w == "ry")
        rotation = rotation * math::Rot3::rot_y(v * std::numbers::pi / 180.0);
      else if (w == "rz")
        rotation = rotation * math::Rot3::rot_z(v * std::numbers::pi / 180.0);
      else {
        throw std::invalid_argument(fmt::format(
            "distance(\"{}\"): unknown displacement \"{}\"; the words are dx dy dz (mm) and rx "
            "ry rz (deg), each followed by its value (a double) among the arguments",
            text, w));
      }
    };
    if (words > 15) {
      return fail(RTC_E_ARGUMENT, fmt::format("distance(\"{}\"): at most 15 displacements", text),
                  Say::print);
    }
    for_each_word(text, take);
    if (k == 0) {
      return fail(RTC_E_ARGUMENT, "distance: no displacement given; e.g. distance(\"dz\", -30.)",
                  Say::print);
    }
    trans.R = rotation;
    // Kept by the open session's arm only: rccl_open starts with none.
    if (s.arm_session) s.arm_session->displacement = s.arm_session->displacement * trans;
    return RTC_OK;
  });
}

int rccl_wait_sample(void) {
  return guarded("waitfor", Say::print, RTC_E_INTERNAL, [] {
    State& s = state();
    take_nextmove();
    if (s.cell_session) return cell_wait_tick();
    if (!s.arm_session || !s.arm_session->controlling) {
      return fail(RTC_E_SEQUENCE,
                  "waitfor: nothing runs to wait on; call rccl_open() and rccl_control() first",
                  Say::print);
    }
    ArmSession& a = *s.arm_session;
    rtc::Session& session = *a.robot.session;
    if (session.controlling()) session.wait_for(session.period());
    report_failures(a);
    const rtc::How how = session.how();
    rtime = std::lround(how.time_s * 1e3);
    rccl_sample = static_cast<long>(how.sample);
    to_c(a.arm.kinematics().forward(how.q()), t6_box().c);
    refresh();
    if (!session.controlling()) return control_ended(a, "waitfor");
    return RTC_OK;
  });
}

namespace {
/// update() and updatecontact(): trans solved for pos's equation with T6 = `t6`, or the
/// measured T6 when there is none.
TRSF_PTR solve_update(const char* call, TRSF_PTR trans, POS_PTR pos,
                      const std::optional<math::Transform>& t6) {
  TRSF_PTR out = nullptr;
  guarded(call, Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    PositionBox* box = position_of(pos, call);
    if (box == nullptr) return rtc_error;
    TrsfBox* x = box_of(trans);
    if (x == nullptr || x == &t6_box()) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("{}(..., {}): the transform to solve for must be one of the "
                              "equation's, made by newtrans or gentr_, not t6",
                              call, box->name),
                  Say::print);
    }
    if (!s.arm_session) {
      return fail(RTC_E_SEQUENCE,
                  fmt::format("{}: call rccl_open() first (T6 is read from the arm)", call),
                  Say::print);
    }
    rc::TransformPtr xt;
    const rc::PositionPtr p = build_position(*box, math::Transform::identity(), trans, &xt);
    if (!xt) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("{}({}, {}): {} is not in the equation {}", call, x->name, box->name,
                              x->name, p->describe()),
                  Say::print);
    }
    to_c(p->solve_for(*xt, t6 ? *t6 : measured_t6(*s.arm_session)), *trans);
    out = trans;
    return RTC_OK;
  });
  return out;
}

/// The contact of the last motion to `box` that ended, if its guard tripped.
std::optional<rc::Contact> last_contact(const State& s, const PositionBox* box) {
  if (!s.arm_session) return std::nullopt;
  const ArmSession& a = *s.arm_session;
  for (auto it = a.motion_boxes.rbegin(); it != a.motion_boxes.rend(); ++it) {
    if (it->second != box) continue;
    const rc::Motion m{it->first};
    if (!a.arm.happened(m.end())) continue;
    return a.arm.contact(m);
  }
  return std::nullopt;
}
}  // namespace

TRSF_PTR update(TRSF_PTR trans, POS_PTR pos) {
  return solve_update("update", trans, pos, std::nullopt);
}

int teach(TRSF_PTR trans, POS_PTR pos) {
  int answer = NO;
  guarded("teach", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    PositionBox* box = position_of(pos, "teach");
    if (box == nullptr) return rtc_error;
    TrsfBox* x = box_of(trans);
    if (x == nullptr || x == &t6_box()) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("teach(..., {}): the transform to teach must be one of the "
                              "equation's, made by newtrans or gentr_, not t6",
                              box->name),
                  Say::print);
    }
    if (const int c = check_can_move(s, "teach(" + x->name + ")"); c != RTC_OK) return c;
    rc::TransformPtr xt;
    const rc::PositionPtr p = build_position(*box, math::Transform::identity(), trans, &xt);
    if (!xt) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("teach({}, {}): {} is not in the equation {}", x->name, box->name,
                              x->name, p->describe()),
                  Say::print);
    }
    const char* env = std::getenv("RCCX_DB");
    const std::string file = env != nullptr && env[0] != '\0' ? env : "rccx.db";
    std::unique_ptr<rc::PositionDb> opened;
    try {
      opened = std::make_unique<rc::PositionDb>(file);
    } catch (const rc::DatabaseError& e) {
      return fail(RTC_E_OPEN,
                  fmt::format("teach({}): the position database {} cannot be used: {}; set "
                              "RCCX_DB to a database file you can write",
                              x->name, file, e.what()),
                  Say::print);
    }
    rc::PositionDb& db = *opened;
    ArmSession& a = *s.arm_session;
    const std::string& robot = a.arm.kinematics().model().name;
    if (const auto stored = db.get(robot, x->name)) {
      to_c(stored->value, *trans);
      std::printf("teach: %s taken from the position database %s\n", x->name.c_str(), file.c_str());
      answer = YES;
      return RTC_OK;
    }
    std::printf("teach mode V1.0, transform %s, position %s\n", x->name.c_str(), box->name.c_str());
    std::fflush(stdout);
    rc::TeachIo io{std::cin, std::cout, &db, {}};
    io.push = [&a](std::size_t joint, double effort) { a.robot.push(joint, effort); };
    const rc::Taught taught = rc::teach_loop(a.arm, io);
    report_failures(a);
    refresh();
    if (!taught.ended_by_exit || taught.termination.ended() || taught.stopped_by_signal) {
      std::printf("teach: nothing taught for %s\n", x->name.c_str());
      return RTC_OK;
    }
    const math::Transform value = p->solve_for(*xt, taught.t6);
    rc::StoredTransform st;
    st.robot = robot;
    st.name = x->name;
    st.value = value;
    st.note = "taught for " + box->name;
    db.put(st);
    to_c(value, *trans);
    answer = YES;
    return RTC_OK;
  });
  return answer;
}

namespace {
/// The words of `what` (fx fy fz tx ty tz, and `extra` when given) with the value that follows
/// each among the arguments: what comply() and limit() read. Throws std::invalid_argument.
std::vector<std::pair<std::size_t, double>> force_words(const char* call, const std::string& text,
                                                        const std::array<double, 16>& values,
                                                        bool with_values) {
  std::vector<std::pair<std::size_t, double>> out;
  std::size_t k = 0;
  const auto take = [&](const std::string& w) {
    if (w.empty()) return;
    std::size_t axis = 6;  // "f": the force's magnitude (limit only)
    const auto it = std::find(rc::kForceAxisNames.begin(), rc::kForceAxisNames.end(), w);
    if (it != rc::kForceAxisNames.end()) {
      axis = static_cast<std::size_t>(it - rc::kForceAxisNames.begin());
    } else if (!(w == "f" && std::string_view(call) == "limit")) {
      throw std::invalid_argument(fmt::format(
          "{}(\"{}\"): unknown axis \"{}\"; the words are fx fy fz (N) and tx ty tz (N m) of "
          "the tool frame{}",
          call, text, w,
          std::string_view(call) == "limit" ? ", or f (the force's magnitude)" : ""));
    }
    double v = 0.0;
    if (with_values) {
      if (k >= values.size()) throw std::invalid_argument(fmt::format("{}: too many words", call));
      v = values[k++];
      if (!std::isfinite(v)) {
        throw std::invalid_argument(
            fmt::format("{}(\"{}\"): the value of {} is not finite", call, text, w));
      }
    }
    out.emplace_back(axis, v);
  };
  for_each_word(text, take);
  if (out.empty()) {
    throw std::invalid_argument(
        fmt::format("{}: no axis given; e.g. {}(\"fz\"{})", call, call, with_values ? ", 5." : ""));
  }
  return out;
}

/// Reads one double per word of `what` (before anything can throw).
std::array<double, 16> word_values(const char* what, std::va_list ap) {
  std::array<double, 16> values{};
  std::size_t words = 0;
  bool in_word = false;
  for (const char* c = what; c != nullptr && *c != '\0'; ++c) {
    const bool sep = *c == ' ' || *c == ',' || *c == '\t';
    if (!sep && !in_word && words < values.size()) values[words++] = va_arg(ap, double);
    in_word = !sep;
  }
  return values;
}
}  // namespace

int comply(const char* what, ...) {
  std::va_list ap;
  va_start(ap, what);
  const std::array<double, 16> values = word_values(what, ap);
  va_end(ap);
  return guarded("comply", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    rc::Compliance c = s.settings.compliance;
    for (const auto& [axis, value] : force_words("comply", what ? what : "", values, true)) {
      c.axes = static_cast<std::uint8_t>(c.axes | (1U << axis));
      c.force[axis] = value;
    }
    try {
      rc::check_compliance(c);
    } catch (const rc::MotionError& e) {
      throw std::invalid_argument(e.what());  // a bad argument: nothing changed
    }
    s.settings.compliance = c;
    return RTC_OK;
  });
}

int lock(const char* what) {
  return guarded("lock", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    const std::string text = what ? what : "";
    rc::Compliance c = s.settings.compliance;
    if (text == "all") {
      c = rc::Compliance{};
    } else {
      for (const auto& [axis, value] : force_words("lock", text, {}, false)) {
        c.axes = static_cast<std::uint8_t>(c.axes & ~(1U << axis));
        c.force[axis] = 0.0;
      }
    }
    s.settings.compliance = c;
    return RTC_OK;
  });
}

int limit(const char* what, ...) {
  std::va_list ap;
  va_start(ap, what);
  const std::array<double, 16> values = word_values(what, ap);
  va_end(ap);
  return guarded("limit", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    const std::string text = what ? what : "";
    if (text == "off" || text.empty()) {
      s.settings.guard = rc::ForceGuard{};
      return RTC_OK;
    }
    const auto words = force_words("limit", text, values, true);
    if (words.size() != 1) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("limit(\"{}\"): one axis at a time (or f, the magnitude)", text),
                  Say::print);
    }
    rc::ForceGuard g;
    g.kind = words[0].first == 6 ? rc::ForceGuard::Kind::magnitude : rc::ForceGuard::Kind::along;
    g.axis = static_cast<std::uint8_t>(words[0].first % 6);
    g.threshold = words[0].second;
    try {
      rc::check_guard(g);
    } catch (const rc::MotionError& e) {
      throw std::invalid_argument(e.what());
    }
    s.settings.guard = g;
    return RTC_OK;
  });
}

int setload(double kg, double x, double y, double z) {
  return guarded("setload", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    if (!(kg >= 0.0) || !std::isfinite(kg) || !std::isfinite(x) || !std::isfinite(y) ||
        !std::isfinite(z)) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("setload({}, {}, {}, {}): the mass is >= 0 kg and the centre of "
                              "mass finite (mm in T6)",
                              kg, x, y, z),
                  Say::print);
    }
    if (!s.arm_session) {
      return fail(RTC_E_SEQUENCE, "setload: call rccl_open() first", Say::print);
    }
    rccx::force::ToolLoad load;
    load.mass_kg = kg;
    load.com_m = {x * 1e-3, y * 1e-3, z * 1e-3};
    s.arm_session->arm.set_tool_load(load);
    return RTC_OK;
  });
}

int getcontact(POS_PTR pos, TRSF_PTR at) {
  int answer = NO;
  guarded("getcontact", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    PositionBox* box = position_of(pos, "getcontact");
    if (box == nullptr) return rtc_error;
    const std::optional<rc::Contact> c = last_contact(s, box);
    if (!c) return RTC_OK;
    if (at != nullptr) to_c(c->tool_frame, *at);
    answer = YES;
    return RTC_OK;
  });
  return answer;
}

TRSF_PTR updatecontact(TRSF_PTR trans, POS_PTR pos) {
  State& s = state();
  PositionBox* box = position_of(pos, "updatecontact");
  if (box == nullptr) return nullptr;
  const std::optional<rc::Contact> c = last_contact(s, box);
  if (!c) {
    fail(RTC_E_SEQUENCE,
         fmt::format("updatecontact(..., {}): the last motion to {} made no contact (set a "
                     "limit() before it, and waitfor its end)",
                     box->name, box->name),
         Say::print);
    return nullptr;
  }
  return solve_update("updatecontact", trans, pos, c->t6);
}

}  // extern "C"
