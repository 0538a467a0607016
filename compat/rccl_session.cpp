// RCCL's C interface (compat/rccl.h, compat/rtc.h) over rccx::rccl, its sessions: the state
// every C call shares (state(), compat_internal.hpp), errors (rtc_error, the message,
// print_rtc_error), rccl_open, rccl_control and rccl_close on a simulated robot
// (rtc::SimulatedRobot) and one rccl::Manipulator. No exception leaves these files: every entry
// point catches, sets rtc_error, keeps the message and returns an error code (or NULL).
//
// The C side sees plain values kept up to date here: POS.end and POS.code (from the positions
// each move() built and the generator's events), `completed` (every queued motion ended) and
// t6's value, refreshed by every call and after every sample waitfor() lets run. The motion
// calls are in rccl_motion.cpp, positions and teach in rccl_teach.cpp, transforms in
// rccl_transforms.cpp and rccl_algebra.cpp, the cell in rccl_cell.cpp.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

#include "compat_internal.hpp"
#include "compat_shared.hpp"

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

std::string motion_name(const ArmSession& a, std::uint64_t id) {
  const auto it = a.motion_names.find(id);
  return it == a.motion_names.end() ? fmt::format("motion {}", id)
                                    : fmt::format("motion {} (to {})", id, it->second);
}

/// rccl_close(): the motions have ended, so the arm may come to rest before control stops
/// (bounded: `completed` gives up after kSettleTimeout_s).
void settle_before_close(ArmSession& a) {
  if (!a.controlling || !a.robot.session->controlling() ||
      !a.arm.happened(rc::Manipulator::completed())) {
    return;
  }
  rtc::Session& session = *a.robot.session;
  refresh();
  while (completed == 0 && session.controlling()) {
    session.wait_for(session.period());
    refresh();
  }
}

/// What rccl_close() says of the session whose control ended with `t`: RTC_OK, or the error
/// code with `why` (the end of control, else the first failed motion, else the first refusal).
int session_verdict(ArmSession& a, const rtc::Termination& t, std::string& why) {
  const std::vector<rc::MotionEvent>& failures = a.arm.failures();
  if (t.ended()) {
    why = describe_end(t);
    return RTC_E_TERMINATED;
  }
  if (!failures.empty()) {
    const rc::MotionEvent& first = failures.front();
    why = fmt::format("{} motion(s) failed or were cancelled during the session; first {} {}{}{}",
                      failures.size(), motion_name(a, first.id), rc::to_string(first.kind),
                      first.message().empty() ? "" : ": ", first.message());
    return RTC_E_MOTION;
  }
  if (a.refusals.count > 0) {
    why = fmt::format(
        "{} call(s) to queue a motion were refused during the session; the "
        "first: {}",
        a.refusals.count, a.refusals.first);
    return a.refusals.first_code;
  }
  return RTC_OK;
}

TRSF eq_mark{};
TRSF tl_mark{};

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
      if (!cell_event_done(*m, rc::Arm::completed())) completed = 0;
    }
  } else {
    completed = 1;
  }
}

math::Transform measured_t6(const ArmSession& a) {
  return a.arm.kinematics().forward(a.robot.session->how().q());
}

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

int control_ended(ArmSession& a, std::string_view call) {
  const Say say = a.told_ended ? Say::quiet : Say::print;
  a.told_ended = true;
  return fail(RTC_E_TERMINATED,
              fmt::format("{}: {}; rccl_close() the session", call,
                          describe_end(a.robot.session->termination())),
              say);
}

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

std::vector<rc::MotionEvent> show_motion_codes(
    rc::Arm& arm, const std::map<std::uint64_t, PositionBox*>& motion_boxes) {
  std::vector<rc::MotionEvent> events = arm.take_events();
  // Contacts are known where the generator runs: a remote arm's nextmove is RCCL_NEXTMOVE.
  const auto* local = dynamic_cast<const rc::Manipulator*>(&arm);
  for (const rc::MotionEvent& e : events) {
    const auto it = motion_boxes.find(e.id);
    if (it == motion_boxes.end()) continue;
    if (e.kind == rc::EventKind::ended) {
      int code = 0;
      if (e.message() == rc::kNextmoveText) {
        code = local != nullptr && local->contact(rc::Motion{e.id}) ? RCCL_ONF : RCCL_NEXTMOVE;
      }
      it->second->shown->code = code;
    } else if (e.kind == rc::EventKind::failed || e.kind == rc::EventKind::cancelled) {
      it->second->shown->code = RTC_E_MOTION;
    }
  }
  return events;
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
    case RTC_E_LOG:
      return "RTC_E_LOG";
    default:
      return "unknown";
  }
}

const char* rtc_error_message(void) {
  return state().message.c_str();
}

void print_rtc_error(int code, int /*flags*/) {
  static constexpr std::array<const char*, 12> kMeaning = {
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
      "the sample log (RCCX_LOG) is lost",
  };
  const char* meaning = code >= 0 && code < static_cast<int>(kMeaning.size())
                            ? kMeaning[static_cast<std::size_t>(code)]
                            : "an unknown error code";
  const char* message = rtc_error_message();
  if (code != RTC_OK && code == rtc_error && message[0] != '\0') meaning = message;
  std::printf("rtc error %d (%s): %s\n", code, rtc_error_name(code), meaning);
  std::fflush(stdout);
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
    if (a.controlling) report_failures(a);
    settle_before_close(a);
    const rtc::Termination t =
        a.controlling ? a.arm.stop_control() : a.robot.session->termination();
    std::string why;
    int code = session_verdict(a, t, why);
    a.robot.session->close(power_off != 0);
    // The log last: a session that went wrong says that first; its log's problem is on stderr.
    if (const std::string lost = a.robot.finish(); !lost.empty() && code == RTC_OK) {
      code = RTC_E_LOG;
      why = fmt::format("the sample log is lost: {}", lost);
    }
    return code == RTC_OK ? RTC_OK : fail(code, "rccl_close: " + why, Say::quiet);
  });
}

}  // extern "C"
