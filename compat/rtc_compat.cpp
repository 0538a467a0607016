// RTC's C names (compat/rtc.h, the real-time level): the 1983 manual's control(fn1, fn2),
// release(msg), how, chg, terminate and mess, and the thesis's rtc_open, rtc_control,
// rtc_release, rtc_close, rtc_message, user_hangup and print_terminate_code, over one
// rtc::Session on a simulated robot (rtc::SimulatedRobot).
//
// The C control functions run inside two C++ control functions on the session's control
// thread: before fn1 the library copies the sample's rtc::How into `how` (range values in rad
// or mm); after each C function it translates `chg` into the session's rtc::Chg (mm to m),
// clears chg's one-shot commands, and passes `terminate` and `rtc_message` on. `terminate` is
// written by the library with atomic stores only: by the program's thread in the calls that
// wait or release, and in real time by a watcher thread that polls the session's end, so that a
// program busy-waiting on it sees control end. No exception leaves this file.
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <string_view>
#include <thread>

#include "rccx/io/parse.hpp"
#include "rccx/rtc/hangup.hpp"
#include "rccx/rtc/session.hpp"
#include "rccx/rtc/simulated_robot.hpp"
#include "rccx/rtc/types.hpp"

// After rccx's headers (their local names `how` must not meet the globals). The globals of
// rtc.h are declared for C++ here, which defines them.
#define RCCX_RTC_GLOBALS
// clang-format off
#include "compat_internal.hpp"
#include "compat_shared.hpp"
#include "rtc_internal.hpp"
// clang-format on

namespace rccx::compat {
namespace {

static_assert(RTC_MAX_JOINTS == kin::kMaxJoints);
static_assert(RTC_TERM_USER_REQUEST == static_cast<int>(rtc::TerminateCode::user_request));
static_assert(RTC_TERM_USER_INTERRUPT == static_cast<int>(rtc::TerminateCode::user_interrupt));
static_assert(RTC_TERM_CONTROL_EXCEPTION ==
              static_cast<int>(rtc::TerminateCode::control_exception));
static_assert(RTC_TERM_OVERRUN == static_cast<int>(rtc::TerminateCode::overrun));
static_assert(RTC_TERM_OBSERVED_POSITION ==
              static_cast<int>(rtc::TerminateCode::observed_position));
static_assert(RTC_TERM_TARGET_POSITION == static_cast<int>(rtc::TerminateCode::target_position));
static_assert(RTC_TERM_OBSERVED_VELOCITY ==
              static_cast<int>(rtc::TerminateCode::observed_velocity));
static_assert(RTC_TERM_TARGET_VELOCITY == static_cast<int>(rtc::TerminateCode::target_velocity));
static_assert(RTC_TERM_NOT_CALIBRATED == static_cast<int>(rtc::TerminateCode::not_calibrated));
static_assert(RTC_TERM_JOINT_NOT_ANSWERING ==
              static_cast<int>(rtc::TerminateCode::joint_not_answering));
static_assert(RTC_TERM_ENCODER_ERROR == static_cast<int>(rtc::TerminateCode::encoder_error));
static_assert(RTC_TERM_POWER_FAILURE == static_cast<int>(rtc::TerminateCode::power_failure));
static_assert(RTC_TERM_PHASE_ERROR == static_cast<int>(rtc::TerminateCode::phase_error));
static_assert(RTC_TERM_JOINT_FAULT == static_cast<int>(rtc::TerminateCode::joint_fault));
static_assert(RTC_TERM_FORCE_SATURATED == static_cast<int>(rtc::TerminateCode::force_saturated));
static_assert(RTC_TERM_FORCE_FROZEN == static_cast<int>(rtc::TerminateCode::force_frozen));
static_assert(RTC_F_CALIBRATED == rtc::kCalibrated && RTC_F_JOINT_FAULT == rtc::kJointFault &&
              RTC_F_TGT_POS_OUT == rtc::kTargetPositionOut);
static_assert(RTC_CHECK_OBS_POS == rtc::kCheckObservedPosition &&
              RTC_CHECK_TGT_VEL == rtc::kCheckTargetVelocity &&
              RTC_CHECK_FORCE == rtc::kCheckForce && RTC_CHECK_ALL == rtc::kCheckAll);

/// The one RTC session of a C program.
struct Rtc {
  std::unique_ptr<rtc::SimulatedRobot> robot;
  std::size_t dof = 0;
  std::array<double, kin::kMaxJoints> to_c{};   ///< C units per SI unit: 1 (rad) or 1000 (mm)
  std::array<double, kin::kMaxJoints> ang_c{};  ///< deg per rad, or mm per m
  bool controlled = false;                      ///< control() without release() yet
  bool opened_by_control = false;
  // Read by the control thread; written only while control is not active.
  RTC_FN fn1 = nullptr;
  RTC_FN fn2 = nullptr;
  std::thread watcher;  ///< real time: publishes the end of control to `terminate`
  std::atomic<bool> stop_watching{false};
  rtc::Termination last;  ///< how the last control session ended
  bool at_exit_registered = false;
  std::int64_t carry_ns = 0;  ///< simulated time: what rtc_wait() owes short of a sample

  Rtc() = default;
  Rtc(const Rtc&) = delete;
  Rtc& operator=(const Rtc&) = delete;
  ~Rtc();
  void stop_watcher() noexcept;
  /// Closes the session; what went wrong with RCCX_LOG's log ("" when whole or none).
  std::string close_now(bool power_off) noexcept;
};

std::atomic<bool> g_open{false};

Rtc& rtc_state() {
  // The hang-up registry first, so that it is destroyed after this state (whose session
  // unregisters from it when it closes).
  static Rtc& s = []() -> Rtc& {
    rtc::detail::unregister_for_hangup(nullptr);
    static Rtc r;
    return r;
  }();
  return s;
}

void Rtc::stop_watcher() noexcept {
  stop_watching.store(true);
  if (watcher.joinable()) watcher.join();
  stop_watching.store(false);
}

std::string Rtc::close_now(bool power_off) noexcept {
  stop_watcher();
  std::string lost;
  if (robot) {
    try {
      robot->session->close(power_off);
      lost = robot->finish();  // already said on stderr
    } catch (...) {
      lost = "the log could not be closed";
    }
    robot.reset();
  }
  controlled = false;
  opened_by_control = false;
  g_open.store(false);
  return lost;
}

Rtc::~Rtc() {
  (void)close_now(false);
}

// ------------------------------------------------------------------------------------------
// terminate

long load_terminate() noexcept {
  return __atomic_load_n(&terminate, __ATOMIC_SEQ_CST);
}

void store_terminate(long v) noexcept {
  __atomic_store_n(&terminate, v, __ATOMIC_SEQ_CST);
}

/// Control has ended with `code`: terminate says so (a value the program set is kept when the
/// program asked for the end).
void publish_end(rtc::TerminateCode code) noexcept {
  if (code == rtc::TerminateCode::none) return;
  const long v = static_cast<long>(code);
  if (code == rtc::TerminateCode::user_request) {
    long zero = 0;
    __atomic_compare_exchange_n(&terminate, &zero, v, false, __ATOMIC_SEQ_CST, __ATOMIC_SEQ_CST);
  } else {
    store_terminate(v);
  }
}

void watch(Rtc* s) noexcept {
  const rtc::Session& session = *s->robot->session;
  while (!s->stop_watching.load()) {
    const rtc::TerminateCode code = session.ended_code();
    if (code != rtc::TerminateCode::none) {
      publish_end(code);
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

// ------------------------------------------------------------------------------------------
// The sample loop's side: how in, chg out

void fill_how(const Rtc& s, const rtc::How& h, double period_ms) noexcept {
  how.sample = static_cast<long>(h.sample);
  how.time_ms = h.time_s * 1e3;
  how.period_ms = period_ms;
  how.dof = static_cast<int>(s.dof);
  unsigned all = 0;
  for (std::size_t j = 0; j < s.dof; ++j) {
    const rtc::JointHow& jh = h.joint[j];
    how.pos[j] = jh.range * s.to_c[j];
    how.vel[j] = jh.velocity * s.to_c[j];
    how.ang[j] = jh.q * s.ang_c[j];
    how.flags[j] = jh.flags;
    all |= jh.flags;
  }
  how.allflags = all;
  how.power = h.power ? 1 : 0;
  how.hand = h.hand_closed ? 1 : 0;
  how.calibrated = h.all_calibrated ? 1 : 0;
  how.outputs = h.outputs;
}

/// The robot's constant entries of `how`, and the rest cleared.
void fill_model(const Rtc& s, const kin::RobotModel& model) noexcept {
  how = rtc_how{};
  for (std::size_t j = 0; j < s.dof; ++j) {
    const kin::Joint& joint = model.joints[j];
    how.range[j] = (joint.upper - joint.lower) * s.to_c[j];
    how.lower[j] = joint.lower * s.ang_c[j];
    how.vmax[j] = joint.max_velocity * s.to_c[j];
    how.type[j] = joint.type == kin::JointType::prismatic ? RTC_PRISMATIC : RTC_REVOLUTE;
  }
  how.dof = static_cast<int>(s.dof);
}

rtc::Request request(int v, int on, int off) noexcept {
  if (v == on) return rtc::Request::on;
  if (v == off) return rtc::Request::off;
  return rtc::Request::none;
}

/// Ends control for a chg the library cannot send (the arm holds), saying why in rtc_message.
void refuse(rtc::Control& c, rtc::TerminateCode code, const std::string& why) noexcept {
  c.message(why);
  c.terminate(code);
}

/// After a C control function: chg into the session's Chg, the one-shot commands cleared,
/// terminate and rtc_message passed on.
void after_function(const Rtc& s, rtc::Control& c) noexcept {
  rtc::Chg& out = c.chg();
  for (std::size_t j = 0; j < s.dof; ++j) {
    rtc_motion& m = chg.i.motion[j];
    if (m.set == RTC_NOCMD) continue;
    const double target = m.valir / s.to_c[j];
    const double speed = m.vel / s.to_c[j];
    const int set = m.set;
    m.set = RTC_NOCMD;
    if (set == RTC_STOPCAL) {
      out.stopcal(j);
      continue;
    }
    if (set != RTC_POS && set != RTC_POSVEL) {
      try {
        refuse(c, rtc::TerminateCode::control_exception,
               fmt::format("chg.i.motion[{}].set = {}: not RTC_NOCMD, POS, POSVEL or STOPCAL", j,
                           set));
      } catch (...) {
        refuse(c, rtc::TerminateCode::control_exception, "chg: an unknown set value");
      }
      continue;
    }
    if (!std::isfinite(target) || !std::isfinite(speed) || speed < 0.0) {
      try {
        refuse(c, rtc::TerminateCode::target_position,
               fmt::format("chg.i.motion[{}]: valir {} or vel {} is not a finite position "
                           "and speed >= 0",
                           j, m.valir, m.vel));
      } catch (...) {
        refuse(c, rtc::TerminateCode::target_position, "chg: a target that is not finite");
      }
      continue;
    }
    if (set == RTC_POS) {
      out.pos(j, target, speed);
    } else {
      out.posvel(j, target);
    }
  }
  if (chg.power != 0) out.power = request(chg.power, RTC_POWER_ON, RTC_POWER_OFF);
  if (chg.hand != 0) out.hand = request(chg.hand, RTC_HAND_CLOSE, RTC_HAND_OPEN);
  if (chg.zerog != 0) out.zero_gravity = request(chg.zerog, RTC_ZEROG_ON, RTC_ZEROG_OFF);
  out.outputs_set = static_cast<std::uint16_t>(out.outputs_set | (chg.outset & 0xffffU));
  out.outputs_clear = static_cast<std::uint16_t>(out.outputs_clear | (chg.outclr & 0xffffU));
  out.checking = static_cast<std::uint8_t>(static_cast<unsigned>(chg.checking) & rtc::kCheckAll);
  chg.power = chg.hand = chg.zerog = 0;
  chg.outset = chg.outclr = 0;
  if (rtc_message != nullptr) {
    c.message(std::string_view(rtc_message, strnlen(rtc_message, rtc::kMessageCapacity)));
  }
  if (terminate != 0) c.terminate(rtc::TerminateCode::user_request);
}

// ------------------------------------------------------------------------------------------
// The planning side

/// Records an error quietly or on stderr as "rtc: ...".
int rtc_fail(int code, std::string_view text, bool print = true) noexcept {
  fail(code, text, Say::quiet);
  if (print) std::fprintf(stderr, "rtc: %.*s\n", static_cast<int>(text.size()), text.data());
  return code;
}

/// Runs `body`; an exception becomes an error code (`invalid`: for std::invalid_argument),
/// said on stderr as the body's own refusals are.
template <class F>
int rtc_guarded(const char* call, F&& body, int invalid = RTC_E_INTERNAL) noexcept {
  bool returned = false;
  const int rc = guarded(call, Say::quiet, invalid, [&] {
    const int r = body();
    returned = true;
    return r;
  });
  if (!returned) std::fprintf(stderr, "rtc: %s\n", rtc_error_message());
  return rc;
}

rtc::ClockKind clock_from_environment() {
  const char* env = std::getenv("RCCX_CLOCK");
  const std::string_view v = env != nullptr ? env : "";
  if (v.empty() || v == "real" || v == "realtime" || v == "real_time") {
    return rtc::ClockKind::real_time;
  }
  if (v == "simulated") return rtc::ClockKind::simulated;
  throw rtc::SessionError(
      fmt::format("RCCX_CLOCK is {}; write RCCX_CLOCK=simulated (time passes in rtc_wait) or "
                  "RCCX_CLOCK=real (the default)",
                  io::quoted(v)));
}

int open_session(const char* call) {
  Rtc& s = rtc_state();
  if (s.robot) {
    return rtc_fail(RTC_E_SEQUENCE,
                    fmt::format("{}: the RTC session is open already; rtc_close() it first", call));
  }
  if (rccl_session_open()) {
    return rtc_fail(RTC_E_SEQUENCE,
                    fmt::format("{}: an RCCL session is open (rccl_open or rccl_cell_open); "
                                "rccl_close() or rcclRelease() it before using RTC directly",
                                call));
  }
  rtc::SimulatedRobotOptions options;
  options.clock = clock_from_environment();
  auto robot = std::make_unique<rtc::SimulatedRobot>(choose_robot(nullptr), options);
  s.dof = robot->model.dof();
  for (std::size_t j = 0; j < s.dof; ++j) {
    const bool prismatic = robot->model.joints[j].type == kin::JointType::prismatic;
    s.to_c[j] = prismatic ? 1e3 : 1.0;
    s.ang_c[j] = prismatic ? 1e3 : 180.0 / std::numbers::pi;
  }
  s.robot = std::move(robot);
  s.controlled = false;
  s.opened_by_control = false;
  s.last = {};
  s.carry_ns = 0;
  g_open.store(true);
  fill_model(s, s.robot->model);
  rtc::Session& session = *s.robot->session;
  if (session.clock() == rtc::ClockKind::real_time) {  // the first reading of the arm
    (void)session.wait_until([](const rtc::How& h) { return h.sample >= 1; },
                             10 * session.period());
  }
  fill_how(s, session.how(), s.robot->period_s() * 1e3);
  return RTC_OK;
}

void run_at_exit() {
  (void)rtc_state().close_now(false);  // too late to return it: said on stderr
}

int start_control(const char* call, RTC_FN f1, RTC_FN f2) {
  Rtc& s = rtc_state();
  if (s.controlled) {
    return rtc_fail(RTC_E_SEQUENCE,
                    fmt::format("{}: control is active already; release() or rtc_release() it "
                                "before starting it again",
                                call));
  }
  rtc::Session& session = *s.robot->session;
  s.fn1 = f1;
  s.fn2 = f2;
  chg = rtc_chg{};
  chg.checking = RTC_CHECK_ALL;
  store_terminate(0);
  fill_model(s, s.robot->model);
  fill_how(s, session.how(), s.robot->period_s() * 1e3);
  if (RTC_HANGUP h = user_hangup; h != nullptr) {
    session.set_hangup_handler([h](rtc::Session&) { h(); });
  } else {
    session.set_hangup_handler({});
  }
  const double period_ms = s.robot->period_s() * 1e3;
  Rtc* sp = &s;
  session.control(
      [sp, period_ms](rtc::Control& c) {
        fill_how(*sp, c.how(), period_ms);
        if (sp->fn1 != nullptr) sp->fn1();
        after_function(*sp, c);
      },
      [sp](rtc::Control& c) {
        if (sp->fn2 != nullptr) sp->fn2();
        after_function(*sp, c);
      });
  s.controlled = true;
  s.last = {};
  if (!s.at_exit_registered) {
    // After the first control(): the hang-up registry and the session's own statics exist,
    // and are destroyed after this handler closes the session.
    s.at_exit_registered = std::atexit(run_at_exit) == 0;
  }
  if (session.clock() == rtc::ClockKind::real_time) {
    s.watcher = std::thread(watch, sp);
  }
  return RTC_OK;
}

/// Stops control; returns how it ended (user_request when it was still running) and says it
/// in terminate.
rtc::Termination stop_control(bool power_off) {
  Rtc& s = rtc_state();
  s.stop_watcher();
  rtc::Termination t = s.robot->session->release(power_off);
  if (!t.ended()) {
    const rtc::How h = s.robot->session->how();
    t.code = rtc::TerminateCode::user_request;
    t.sample = h.sample;
    t.time_s = h.time_s;
    std::snprintf(t.detail.data(), t.detail.size(), "released by the program");
  }
  publish_end(t.code);
  s.controlled = false;
  s.last = t;
  fill_how(s, s.robot->session->how(), s.robot->period_s() * 1e3);
  return t;
}

/// RTC_OK for an end the program asked for, else RTC_E_TERMINATED with the reason.
int end_result(const char* call, const rtc::Termination& t) {
  if (t.code == rtc::TerminateCode::user_request) return RTC_OK;
  return rtc_fail(RTC_E_TERMINATED, fmt::format("{}: {}", call, describe_end(t)), false);
}

/// What a call that closed the session returns: `rc`, else RTC_E_LOG when the log is `lost`
/// (its problem, said on stderr already by the log).
int closed(const char* call, int rc, const std::string& lost) {
  if (rc != RTC_OK || lost.empty()) return rc;
  return rtc_fail(RTC_E_LOG, fmt::format("{}: the sample log is lost: {}", call, lost), false);
}

}  // namespace

bool rtc_session_open() noexcept {
  return g_open.load();
}

rtc::Session* rtc_session() noexcept {
  Rtc& s = rtc_state();
  return s.robot ? s.robot->session.get() : nullptr;
}

}  // namespace rccx::compat

using namespace rccx::compat;

extern "C" {

struct rtc_how how = {};
struct rtc_chg chg = {};
volatile long terminate = 0;
char* mess = nullptr;
char* rtc_message = nullptr;
RTC_HANGUP user_hangup = nullptr;

int rtc_open(void) {
  return rtc_guarded(
      "rtc_open", [] { return open_session("rtc_open"); }, RTC_E_ROBOT);
}

int rtc_control(RTC_FN fn1, RTC_FN fn2) {
  return rtc_guarded("rtc_control", [&] {
    if (!rtc_state().robot) {
      return rtc_fail(RTC_E_SEQUENCE, "rtc_control: call rtc_open() first");
    }
    return start_control("rtc_control", fn1, fn2);
  });
}

int control(RTC_FN fn1, RTC_FN fn2) {
  return rtc_guarded(
      "control",
      [&] {
        Rtc& s = rtc_state();
        if (!s.robot) {
          if (const int rc = open_session("control"); rc != RTC_OK) return rc;
          s.opened_by_control = true;
        }
        const int rc = start_control("control", fn1, fn2);
        if (rc != RTC_OK && s.opened_by_control && !s.controlled) (void)s.close_now(false);
        return rc;
      },
      RTC_E_ROBOT);
}

int rtc_release(int power_off) {
  return rtc_guarded("rtc_release", [&] {
    Rtc& s = rtc_state();
    if (!s.controlled) {
      return rtc_fail(RTC_E_SEQUENCE,
                      "rtc_release: control is not active; call rtc_control() first");
    }
    return end_result("rtc_release", stop_control(power_off != 0));
  });
}

int release(const char* msg) {
  return rtc_guarded("release", [&] {
    Rtc& s = rtc_state();
    if (!s.controlled) {
      return rtc_fail(RTC_E_SEQUENCE, "release: control is not active; call control() first");
    }
    const rtc::Termination t = stop_control(false);
    if (msg != nullptr) std::printf("%s\n", msg);
    if (mess != nullptr) std::printf("%s\n", mess);
    std::fflush(stdout);
    const int rc = end_result("release", t);
    return closed("release", rc, s.close_now(false));
  });
}

int rtc_close(int power_off) {
  return rtc_guarded("rtc_close", [&] {
    Rtc& s = rtc_state();
    if (!s.robot) return rtc_fail(RTC_E_SEQUENCE, "rtc_close: no RTC session is open");
    int rc = RTC_OK;
    if (s.controlled) rc = end_result("rtc_close", stop_control(power_off != 0));
    return closed("rtc_close", rc, s.close_now(power_off != 0));
  });
}

int rtc_wait(double ms) {
  return rtc_guarded("rtc_wait", [&] {
    if (!(ms >= 0.0) || !std::isfinite(ms)) {
      return rtc_fail(RTC_E_ARGUMENT,
                      fmt::format("rtc_wait({}): the time is a number of ms >= 0", ms));
    }
    const auto d = std::chrono::nanoseconds(std::llround(ms * 1e6));
    Rtc& s = rtc_state();
    if (!s.robot) {
      // Nothing open: real time sleeps; simulated time has nothing to run.
      if (clock_from_environment() == rtc::ClockKind::real_time) std::this_thread::sleep_for(d);
      return RTC_OK;
    }
    rtc::Session& session = *s.robot->session;
    rtc::Termination t;
    if (session.clock() == rtc::ClockKind::simulated) {
      // Whole samples run; the rest of a wait shorter than the period is carried to the next
      // call, so that `while (!terminate) rtc_wait(10.);` moves on at a 28 ms period too.
      const std::int64_t period = session.period().count();
      const std::int64_t total = s.carry_ns + d.count();
      s.carry_ns = total % period;
      t = session.wait_for(std::chrono::nanoseconds(total - s.carry_ns));
    } else {
      t = session.wait_for(d);
    }
    if (!s.controlled) return RTC_OK;
    if (!t.ended()) return RTC_OK;
    s.stop_watcher();  // its store is over before the program reads terminate
    publish_end(t.code);
    s.last = t;
    return rtc_fail(RTC_E_TERMINATED, fmt::format("rtc_wait: {}", describe_end(t)), false);
  });
}

long rtc_wait_terminated(double timeout_ms) {
  long result = -1;
  rtc_guarded("rtc_wait_terminated", [&] {
    if (std::isnan(timeout_ms)) {
      return rtc_fail(RTC_E_ARGUMENT, "rtc_wait_terminated(NaN): give a time in ms (< 0: none)");
    }
    Rtc& s = rtc_state();
    if (!s.controlled) {
      if (s.robot && s.last.ended()) {  // ended and released: say how
        result = static_cast<long>(s.last.code);
        return RTC_OK;
      }
      return rtc_fail(RTC_E_SEQUENCE,
                      "rtc_wait_terminated: control is not active; call control() or "
                      "rtc_control() first");
    }
    rtc::Session& session = *s.robot->session;
    rtc::Termination t;
    if (timeout_ms < 0.0 || std::isinf(timeout_ms)) {
      while (!(t = session.wait_terminated(std::chrono::seconds(1))).ended()) {
      }
    } else {
      t = session.wait_terminated(std::chrono::nanoseconds(std::llround(timeout_ms * 1e6)));
    }
    if (t.ended()) {
      s.stop_watcher();  // its store is over before the program reads terminate
      publish_end(t.code);
      s.last = t;
    }
    result = t.ended() ? load_terminate() : 0;
    return RTC_OK;
  });
  return result;
}

const char* rtc_terminate_name(long code) {
  for (const rccx::rtc::TerminateCode c : rccx::rtc::all_terminate_codes()) {
    if (static_cast<long>(c) == code) return rccx::rtc::to_string(c).data();
  }
  return code == 0 ? "none" : "unknown";
}

void print_terminate_code(void) {
  const long code = load_terminate();
  Rtc& s = rtc_state();
  if (s.controlled) {
    try {
      if (rccx::rtc::Termination t = s.robot->session->termination(); t.ended()) s.last = t;
    } catch (...) {  // the short form below
    }
  }
  if (code == 0) {
    std::printf("rtc: terminate 0: %s\n",
                s.controlled ? "control is running" : "control not ended");
  } else if (s.last.ended() && (static_cast<long>(s.last.code) == code ||
                                s.last.code == rccx::rtc::TerminateCode::user_request)) {
    if (static_cast<long>(s.last.code) != code) {
      std::printf("rtc: terminate %ld (set by the program): ", code);
    }
    rccx::rtc::print_terminate_code(s.last, stdout);
  } else {
    std::printf("rtc: terminate %ld (%s)\n", code, rtc_terminate_name(code));
  }
  std::fflush(stdout);
}

}  // extern "C"
