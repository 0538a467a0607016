#include "rccx/rtc/session.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <mutex>
#include <utility>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rtc/hangup.hpp"
#include "rccx/rtc/sync.hpp"

namespace rccx::rtc {

using detail::monotonic_ns;
using detail::reached;
using detail::ring;
using detail::wait_while;

namespace {

// Who owns the session: planning sets idle -> controlling and back to idle; the communication
// task sets controlling -> ending -> ended when it terminates control.
enum Phase : std::uint32_t { kIdle, kControlling, kEnding, kEnded };

// Requests from release(), carried out by the communication task at its next tick.
enum Pending : std::uint32_t { kPendingHold = 1, kPendingPowerOff = 2 };

template <std::size_t N>
void copy_text(std::array<char, N>& to, std::string_view text) noexcept {
  const std::size_t n = std::min(text.size(), N - 1);
  if (n > 0) std::memcpy(to.data(), text.data(), n);  // an empty view may hold no pointer
  to[n] = '\0';
}

// Formats into a fixed buffer: the communication task reports details without allocating.
template <std::size_t N, class... Args>
void format_text(std::array<char, N>& to, fmt::format_string<Args...> f, Args&&... args) noexcept {
  try {
    const auto r = fmt::format_to_n(to.data(), N - 1, f, std::forward<Args>(args)...);
    to[std::min(r.size, N - 1)] = '\0';
  } catch (...) {
    to[0] = '\0';
  }
}

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kLockMemory = false;  // the sanitizers' shadow memory is terabytes of mappings
#else
constexpr bool kLockMemory = true;
#endif

const char* unit_of(const kin::Joint& j) noexcept {
  return j.type == kin::JointType::revolute ? "rad" : "m";
}

void try_real_time_scheduling(std::thread& t, int priority) {
  static std::once_flag locked;
  static std::atomic<bool> told{false};
  const auto tell = [](const char* what, int err) {
    if (!told.exchange(true)) {
      fmt::print(stderr,
                 "rtc: {} not permitted ({}): timing is best effort. Run as root or grant "
                 "CAP_SYS_NICE / an rtprio limit for real-time scheduling.\n",
                 what, std::strerror(err));
    }
  };
  std::call_once(locked, [&] {
    if (kLockMemory && mlockall(MCL_CURRENT | MCL_FUTURE) != 0) tell("mlockall", errno);
    // As cyclictest does: keep the processors out of deep idle states while the process runs
    // (the request holds while the file stays open, so it is never closed).
    const int fd = open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
    if (fd >= 0) {
      const std::int32_t zero = 0;
      if (write(fd, &zero, sizeof zero) != static_cast<ssize_t>(sizeof zero)) close(fd);
    }
  });
  sched_param p{};
  p.sched_priority = priority;
  const int err = pthread_setschedparam(t.native_handle(), SCHED_FIFO, &p);
  if (err != 0) tell("SCHED_FIFO", err);
}

}  // namespace

struct Session::Shared {
  // Doorbells: each party sleeps on its own, the others ring it after changing what it watches.
  detail::Doorbell comm_bell;
  detail::Doorbell control_bell;
  mutable detail::Doorbell planning_bell;

  // Sample numbers (the first sample is 1; 0 is "none"), one counter per hand-over of figure 4.7.
  std::atomic<std::uint32_t> granted{0};       ///< simulated time: ticks the planning level let run
  std::atomic<std::uint32_t> how_ready{0};     ///< comm -> control: How of this sample is in `how`
  std::atomic<std::uint32_t> chg_ready{0};     ///< control -> comm: Chg after f1 is in `chg`
  std::atomic<std::uint32_t> chg_taken{0};     ///< comm -> control: Chg copied, control may go on
  std::atomic<std::uint32_t> control_done{0};  ///< control finished f2: the watchdog kick
  std::atomic<std::uint32_t> comm_done{0};     ///< comm finished its cycle
  std::atomic<std::uint32_t> phase{kIdle};
  std::atomic<std::uint32_t> generation{0};  ///< bumped by control(): comm resets its state
  std::atomic<std::uint32_t> pending{0};
  std::atomic<bool> control_busy{false};
  std::atomic<bool> stop{false};
  std::atomic<bool> user_hangup{false};
  std::atomic<std::int32_t> requested_code{0};
  std::atomic<std::int32_t> requested_joint{0};
  std::atomic<std::int64_t> control_end_ns{0};  ///< session time the last control cycle ended
  std::atomic<std::int64_t> simulated_now_ns{0};
  std::atomic<std::int64_t> period_ns{0};
  std::int64_t t0_ns = 0;  ///< real time: the monotonic time the session opened
  std::atomic<SampleLog*> log{nullptr};

  How how;                  ///< guarded by how_ready / the next tick
  Chg chg;                  ///< guarded by chg_ready / chg_taken
  Termination termination;  ///< written while kEnding, read once kEnded
  Control control;          ///< the control task's own
  mutable detail::Latest<How> latest;
  LatencyHistogram latency;

  mutable std::mutex snapshot_mutex;  ///< planning side only
  mutable How snapshot;
};

struct Session::CommState {
  std::uint32_t k = 0;
  std::int64_t tick_ns = 0;        ///< session time of this tick
  std::int64_t next_deadline = 0;  ///< real time: monotonic ns of the next tick
  How how;
  Chg chg;
  std::uint32_t generation = 0;
  std::uint32_t last_published = 0;  ///< last sample handed to control in this session
  std::int64_t last_published_tick_ns = 0;
  std::uint32_t hangups_seen = 0;
  bool power_expected = false;
  bool ended = false;
  std::array<double, kMaxJoints> last_target{};
  std::array<bool, kMaxJoints> has_target{};
};

// ---------------------------------------------------------------------------------------------
// Control (what f1 and f2 see)

void Control::terminate(TerminateCode code) noexcept {
  session_->request_termination(code, 0);
}

void Control::message(std::string_view text) noexcept {
  copy_text(message_, text);
}

void Control::spend(std::chrono::nanoseconds d) noexcept {
  if (session_->options_.clock == ClockKind::simulated) {
    spent_ns_ += d.count();
    return;
  }
  const std::int64_t until = monotonic_ns() + d.count();
  while (monotonic_ns() < until) {
  }
}

// ---------------------------------------------------------------------------------------------
// Opening and closing

Session::Session(Driver& driver, SessionOptions options)
    : driver_(driver),
      options_(options),
      period_(options.period),
      shared_(std::make_unique<Shared>()) {
  if (driver_.model().dof() == 0 || driver_.model().dof() > kMaxJoints) {
    throw SessionError(fmt::format("robot {} has {} joints; RTC serves 1 to {}",
                                   driver_.model().name, driver_.model().dof(), kMaxJoints));
  }
  check_period(period_);
  Shared& s = *shared_;
  s.period_ns = period_.count();
  s.t0_ns = monotonic_ns();
  environment_log_ = SampleLog::from_environment(driver_.model());  // LogError names RCCX_LOG
  s.log = environment_log_.get();
  s.control.session_ = this;
  communication_thread_ = std::thread([this] { communication_task(); });
  control_thread_ = std::thread([this] { control_task(); });
  if (options_.clock == ClockKind::real_time && options_.real_time_scheduling) {
    try_real_time_scheduling(communication_thread_, 80);
    try_real_time_scheduling(control_thread_, 79);
  }
  // The first How, so that how() means something before the first wait.
  if (options_.clock == ClockKind::simulated) step_simulated_sample();
}

Session::~Session() {
  try {
    close();
  } catch (...) {  // close() only throws for misuse that a destructor cannot report
  }
}

void Session::check_period(std::chrono::nanoseconds p) const {
  const double needed_s = driver_.minimum_period_s();
  if (std::chrono::duration<double>(p).count() < needed_s) {
    throw SessionError(fmt::format(
        "sample period {} ms is too short for robot {}: its link needs {:.1f} ms a sample; "
        "choose at least that",
        std::chrono::duration<double, std::milli>(p).count(), driver_.model().name,
        needed_s * 1e3));
  }
  if (p < kMinPeriod || p > kMaxPeriod) {
    using ms = std::chrono::duration<double, std::milli>;
    throw SessionError(fmt::format("sample period {} ms is outside {} .. {} ms", ms(p).count(),
                                   ms(kMinPeriod).count(), ms(kMaxPeriod).count()));
  }
}

void Session::set_period(std::chrono::nanoseconds period) {
  check_period(period);
  if (controlling()) throw SessionError("the sample period can change only while not in control");
  period_ = period;
  shared_->period_ns = period.count();
}

void Session::close(bool power_off) {
  if (closed_) return;
  release(power_off);
  Shared& s = *shared_;
  s.stop.store(true, std::memory_order_seq_cst);
  ring(s.comm_bell);
  ring(s.control_bell);
  communication_thread_.join();
  control_thread_.join();
  closed_ = true;
  if (environment_log_) log_problem_ = environment_log_->close();
}

// ---------------------------------------------------------------------------------------------
// Planning level

void Session::control(ControlFunction f1, ControlFunction f2) {
  if (closed_) throw SessionError("the session is closed; open a new one");
  Shared& s = *shared_;
  const std::uint32_t p = s.phase.load(std::memory_order_acquire);
  if (p == kControlling) throw SessionError("control is already active: release() it first");
  if (p != kIdle) {
    throw SessionError(
        fmt::format("the last control session ended ({}); call release() before control() again",
                    to_string(s.termination.code)));
  }
  wait_control_idle();
  f1_ = std::move(f1);
  f2_ = std::move(f2);
  s.control.chg_ = Chg{};
  s.control.message_ = {};
  s.requested_code.store(0);
  s.user_hangup.store(static_cast<bool>(hangup_handler_));
  s.generation.fetch_add(1, std::memory_order_relaxed);
  detail::register_for_hangup(this);
  s.phase.store(kControlling, std::memory_order_seq_cst);
  ring(s.comm_bell);
}

Termination Session::release(bool power_off) {
  Shared& s = *shared_;
  bool ended = false;
  for (;;) {
    std::uint32_t p = s.phase.load(std::memory_order_seq_cst);
    if (p == kIdle) break;
    if (p == kControlling) {
      if (s.phase.compare_exchange_strong(p, kIdle, std::memory_order_seq_cst)) break;
      continue;
    }
    if (p == kEnded) {
      ended = true;
      break;
    }
    std::this_thread::yield();  // kEnding: the communication task is writing the termination
  }
  ring(s.control_bell);
  ring(s.comm_bell);
  Termination t = ended ? ended_termination() : Termination{};
  if (!ended) {
    wait_control_idle();
    t.message = s.control.message_;
  }
  s.phase.store(kIdle, std::memory_order_seq_cst);
  detail::unregister_for_hangup(this);

  // The arm holds where it is (and powers off if asked) from the next tick on.
  s.pending.fetch_or(kPendingHold | (power_off ? kPendingPowerOff : 0U));
  if (options_.clock == ClockKind::simulated) {
    step_simulated_sample();
  } else {
    const std::uint32_t before = s.comm_done.load(std::memory_order_acquire);
    const std::int64_t deadline = monotonic_ns() + 4 * period_.count();
    while (s.comm_done.load(std::memory_order_acquire) == before && monotonic_ns() < deadline) {
      const std::uint32_t seen = s.planning_bell.load();
      if (s.comm_done.load(std::memory_order_acquire) != before) break;
      wait_while(s.planning_bell, seen, deadline);
    }
  }
  return t;
}

void Session::terminate(TerminateCode code) noexcept {
  request_termination(code, 0);
}

void Session::request_termination(TerminateCode code, int joint) noexcept {
  Shared& s = *shared_;
  std::int32_t none = 0;
  if (s.requested_code.compare_exchange_strong(none, static_cast<std::int32_t>(code))) {
    s.requested_joint.store(joint);
  }
}

bool Session::controlling() const noexcept {
  return shared_->phase.load(std::memory_order_acquire) == kControlling;
}

void Session::wait_control_idle() const {
  const Shared& s = *shared_;
  while (s.control_busy.load(std::memory_order_seq_cst)) {
    const std::uint32_t seen = s.planning_bell.load();
    if (!s.control_busy.load(std::memory_order_seq_cst)) break;
    wait_while(s.planning_bell, seen, monotonic_ns() + 1'000'000);
  }
}

Termination Session::ended_termination() const {
  wait_control_idle();
  Termination t = shared_->termination;
  t.message = shared_->control.message_;
  return t;
}

Termination Session::termination() const {
  if (shared_->phase.load(std::memory_order_seq_cst) != kEnded) return {};
  return ended_termination();
}

How Session::how() const {
  const Shared& s = *shared_;
  std::lock_guard lock(s.snapshot_mutex);
  s.latest.take(s.snapshot);
  return s.snapshot;
}

LatencyStats Session::latency() const {
  return shared_->latency.stats();
}

void Session::set_log(SampleLog* log) {
  if (controlling()) throw SessionError("set the log before control()");
  shared_->log.store(log, std::memory_order_release);
}

void Session::set_hangup_handler(std::function<void(Session&)> handler) {
  if (controlling()) throw SessionError("set the hang-up handler before control()");
  hangup_handler_ = std::move(handler);
}

void Session::hangup() {
  if (hangup_handler_ && controlling()) hangup_handler_(*this);
}

void Session::step_simulated_sample() {
  Shared& s = *shared_;
  const std::uint32_t k = ++simulated_ticks_;
  s.simulated_now_ns.fetch_add(period_.count(), std::memory_order_relaxed);
  s.granted.store(k, std::memory_order_release);
  ring(s.comm_bell);
  const auto wait_for_counter = [&](const std::atomic<std::uint32_t>& counter,
                                    std::int64_t deadline) {
    for (;;) {
      const std::uint32_t seen = s.planning_bell.load();
      if (reached(counter.load(std::memory_order_acquire), k)) return true;
      if (deadline > 0 && monotonic_ns() >= deadline) return false;
      // No spinning: the two tasks need both processors for the sample this thread waits for.
      wait_while(s.planning_bell, seen, deadline, 0);
    }
  };
  wait_for_counter(s.comm_done, 0);
  // When the communication task handed this sample to the control task, the sample is over
  // only when the control cycle is: that keeps simulated time deterministic. A control cycle
  // that hangs is left behind; the watchdog ends the session at the next tick.
  if (s.how_ready.load(std::memory_order_acquire) == k) {
    wait_for_counter(s.control_done, monotonic_ns() + options_.hang_timeout.count() * 1'000'000);
  }
}

Termination Session::wait_for(std::chrono::nanoseconds d) {
  // A stop signal (Ctrl-C, SIGTERM) ends the wait within a period, whatever its length.
  const std::uint32_t stops = detail::hangup_count();
  const auto stopped = [&] { return detail::hangup_count() != stops; };
  if (options_.clock == ClockKind::simulated) {
    const std::int64_t until = shared_->simulated_now_ns.load() + d.count();
    while (!stopped() && shared_->simulated_now_ns.load() + period_.count() <= until) {
      step_simulated_sample();
    }
    // One more sample lets the communication task see the signal and end control.
    if (stopped() && controlling()) step_simulated_sample();
  } else {
    const std::int64_t until = monotonic_ns() + d.count();
    for (std::int64_t now = monotonic_ns(); now < until && !stopped(); now = monotonic_ns()) {
      detail::sleep_until(std::min(until, now + period_.count()));
    }
  }
  return termination();
}

Termination Session::wait_terminated(std::chrono::nanoseconds timeout) {
  Shared& s = *shared_;
  const std::uint32_t stops = detail::hangup_count();
  const auto ended = [&] {
    return s.phase.load(std::memory_order_seq_cst) == kEnded || detail::hangup_count() != stops;
  };
  if (options_.clock == ClockKind::simulated) {
    const std::int64_t until = s.simulated_now_ns.load() + timeout.count();
    while (!ended() && s.simulated_now_ns.load() + period_.count() <= until)
      step_simulated_sample();
  } else {
    const std::int64_t deadline = monotonic_ns() + timeout.count();
    while (!ended() && monotonic_ns() < deadline) {
      const std::uint32_t seen = s.planning_bell.load();
      if (ended()) break;
      wait_while(s.planning_bell, seen, std::min(deadline, monotonic_ns() + period_.count()));
    }
  }
  return termination();
}

bool Session::wait_until(const std::function<bool(const How&)>& done,
                         std::chrono::nanoseconds timeout) {
  Shared& s = *shared_;
  const bool simulated = options_.clock == ClockKind::simulated;
  const std::int64_t start = simulated ? s.simulated_now_ns.load() : monotonic_ns();
  const std::uint32_t stops = detail::hangup_count();
  for (;;) {
    if (done(how())) return true;
    if (s.phase.load(std::memory_order_seq_cst) == kEnded) return false;
    if (detail::hangup_count() != stops) return false;  // Ctrl-C, SIGTERM
    const std::int64_t now = simulated ? s.simulated_now_ns.load() : monotonic_ns();
    if (now - start >= timeout.count()) return false;
    if (simulated) {
      step_simulated_sample();
    } else {
      detail::sleep_until(monotonic_ns() + period_.count());
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The communication task

void Session::communication_task() noexcept {
  Shared& s = *shared_;
  CommState c;
  c.next_deadline = s.t0_ns + s.period_ns.load();
  for (;;) {
    ++c.k;
    if (!wait_tick(c)) return;
    communication_cycle(c);
    s.comm_done.store(c.k, std::memory_order_release);
    ring(s.planning_bell);
  }
}

// The planning level grants a simulated tick only after it has woken up; spinning for it would
// keep the processor it needs busy.
constexpr int kSpinsForGrant = 0;

bool Session::wait_tick(CommState& c) noexcept {
  Shared& s = *shared_;
  if (options_.clock == ClockKind::simulated) {
    for (;;) {
      const std::uint32_t seen = s.comm_bell.load();
      if (s.stop.load(std::memory_order_acquire)) return false;
      if (reached(s.granted.load(std::memory_order_acquire), c.k)) break;
      wait_while(s.comm_bell, seen, 0, kSpinsForGrant);
    }
    c.tick_ns = s.simulated_now_ns.load(std::memory_order_relaxed);
    return true;
  }
  const std::int64_t deadline = c.next_deadline;
  detail::sleep_until(deadline);
  if (s.stop.load(std::memory_order_acquire)) return false;
  const std::int64_t period = s.period_ns.load(std::memory_order_relaxed);
  const std::int64_t late = monotonic_ns() - deadline;
  if (options_.measure_latency) s.latency.record(late);
  // A wake-up more than a period late has missed ticks: skip them rather than run a burst.
  const std::int64_t missed = late / period;
  if (missed > 0) s.latency.record_missed(static_cast<std::uint64_t>(missed));
  c.next_deadline = deadline + (missed + 1) * period;
  c.tick_ns = deadline - s.t0_ns;
  return true;
}

void Session::communication_cycle(CommState& c) noexcept {
  Shared& s = *shared_;
  How& h = c.how;
  const double t = static_cast<double>(c.tick_ns) * 1e-9;
  driver_.read(t, h);
  h.sample = c.k;
  h.time_s = t;
  const auto& joints = driver_.model().joints;
  for (std::size_t i = 0; i < h.dof; ++i) h.joint[i].range = h.joint[i].q - joints[i].lower;

  const std::uint32_t pending = s.pending.exchange(0, std::memory_order_acq_rel);
  if ((pending & kPendingHold) != 0) driver_.hold();
  if ((pending & kPendingPowerOff) != 0) driver_.set_power(false);

  if (s.phase.load(std::memory_order_seq_cst) == kControlling) controlled_cycle(c);
  s.latest.publish(h);
}

void Session::controlled_cycle(CommState& c) noexcept {
  Shared& s = *shared_;
  How& h = c.how;
  const auto& joints = driver_.model().joints;
  const std::int64_t period = s.period_ns.load(std::memory_order_relaxed);

  const std::uint32_t generation = s.generation.load(std::memory_order_relaxed);
  if (generation != c.generation) {  // a new control session: start its state afresh
    c.generation = generation;
    c.last_published = 0;
    c.hangups_seen = detail::hangup_count();
    c.power_expected = h.power;
    c.ended = false;
    c.chg = Chg{};
    c.has_target = {};
  }
  if (c.ended) return;

  // The watchdog: the control cycle of the last sample must have finished within its period.
  if (c.last_published != 0) {
    if (s.control_done.load(std::memory_order_acquire) != c.last_published) {
      std::array<char, kMessageCapacity> d;
      format_text(d, "the control cycle of sample {} was still running at the next tick",
                  c.last_published);
      return end_control(c, TerminateCode::overrun, 0, d.data());
    }
    // Simulated time: the computing a cycle charged with spend() must fit in its period. (In
    // real time the check above is the whole story: the cycle finished before this tick was
    // processed, so its Chg was in time.)
    const std::int64_t used =
        s.control_end_ns.load(std::memory_order_relaxed) - c.last_published_tick_ns;
    if (options_.clock == ClockKind::simulated && used > period) {
      std::array<char, kMessageCapacity> d;
      format_text(d, "the control cycle of sample {} took {:.3f} ms of a {:.3f} ms period",
                  c.last_published, static_cast<double>(used) * 1e-6,
                  static_cast<double>(period) * 1e-6);
      return end_control(c, TerminateCode::overrun, 0, d.data());
    }
  }

  if (const std::int32_t code = s.requested_code.exchange(0); code != 0) {
    return end_control(c, static_cast<TerminateCode>(code), s.requested_joint.load(), "");
  }
  if (const std::uint32_t n = detail::hangup_count(); n != c.hangups_seen) {
    c.hangups_seen = n;
    if (!s.user_hangup.load(std::memory_order_relaxed)) {
      return end_control(c, TerminateCode::user_interrupt, 0, "");
    }
  }

  // Power first: losing it makes every joint report a fault.
  if (c.power_expected && !h.power) {
    return end_control(c, TerminateCode::power_failure, 0, "arm power went off");
  }
  static constexpr std::pair<JointFlag, TerminateCode> kFaults[] = {
      {kNotAnswering, TerminateCode::joint_not_answering},
      {kEncoderError, TerminateCode::encoder_error},
      {kPhaseError, TerminateCode::phase_error},
      {kJointFault, TerminateCode::joint_fault},
  };
  for (std::size_t i = 0; i < h.dof; ++i) {
    for (const auto& [flag, code] : kFaults) {
      if (h.joint[i].has(flag)) {
        return end_control(c, code, static_cast<int>(i) + 1, driver_.fault_detail(i));
      }
    }
  }

  // Observed limits.
  for (std::size_t i = 0; i < h.dof; ++i) {
    JointHow& j = h.joint[i];
    // Only calibrated joints: an uncalibrated position means nothing yet, and a calibrating
    // joint may stand on its mechanical stop, outside its range.
    if (!j.has(kCalibrated) || j.has(kCalibrating)) continue;
    const kin::Joint& m = joints[i];
    const double position_slack = 2.0 * m.resolution_per_count;  // quantisation at a hard stop
    if (!(j.q >= m.lower - position_slack && j.q <= m.upper + position_slack)) {
      j.flags |= kObservedPositionOut;
      if ((c.chg.checking & kCheckObservedPosition) != 0) {
        std::array<char, kMessageCapacity> d;
        format_text(d, "joint {} measured at {:.5f} {}, limits [{:.5f}, {:.5f}]", i + 1, j.q,
                    unit_of(m), m.lower, m.upper);
        return end_control(c, TerminateCode::observed_position, static_cast<int>(i) + 1, d.data());
      }
    }
    // Speeds come from encoder differences: allow their quantisation and a little overshoot.
    const double top = driver_.velocity_limit(i, static_cast<double>(period) * 1e-9);
    const double speed_slack = 0.05 * top + 2.0 * m.resolution_per_count / 0.010;
    if (std::abs(j.velocity) > top + speed_slack) {
      j.flags |= kObservedVelocityOut;
      if ((c.chg.checking & kCheckObservedVelocity) != 0) {
        std::array<char, kMessageCapacity> d;
        format_text(d, "joint {} measured at {:.4f} {}/s, maximum {:.4f}", i + 1, j.velocity,
                    unit_of(m), top);
        return end_control(c, TerminateCode::observed_velocity, static_cast<int>(i) + 1, d.data());
      }
    }
  }

  // Hand How over; wait for the Chg that f1 leaves (at most until the next tick).
  s.how = h;
  s.how_ready.store(c.k, std::memory_order_release);
  ring(s.control_bell);
  c.last_published = c.k;
  c.last_published_tick_ns = c.tick_ns;

  const std::int64_t deadline = options_.clock == ClockKind::real_time
                                    ? c.next_deadline
                                    : monotonic_ns() + options_.hang_timeout.count() * 1'000'000;
  for (;;) {
    const std::uint32_t seen = s.comm_bell.load();
    if (reached(s.chg_ready.load(std::memory_order_acquire), c.k)) break;
    if (s.phase.load(std::memory_order_seq_cst) != kControlling) return;  // released
    if (s.stop.load(std::memory_order_acquire)) return;
    if (monotonic_ns() >= deadline) {
      std::array<char, kMessageCapacity> d;
      format_text(d, "f1 of sample {} did not hand Chg over within its period", c.k);
      return end_control(c, TerminateCode::overrun, 0, d.data());
    }
    wait_while(s.comm_bell, seen, deadline);
  }
  c.chg = s.chg;
  s.chg_taken.store(c.k, std::memory_order_release);
  ring(s.control_bell);
  apply(c, c.chg);
  if (SampleLog* log = s.log.load(std::memory_order_acquire)) {
    LogRow row;
    row.t_s = h.time_s;
    row.segment = c.chg.segment;
    row.measured = h.q();
    row.commanded = row.measured;
    for (std::size_t i = 0; i < h.dof; ++i) {
      if (c.has_target[i]) row.commanded[i] = c.last_target[i];
    }
    log->push(row);
  }
}

void Session::apply(CommState& c, const Chg& chg) noexcept {
  How& h = c.how;
  const auto& joints = driver_.model().joints;
  const double period_s = static_cast<double>(shared_->period_ns.load()) * 1e-9;

  if (chg.power == Request::on) {
    if (!driver_.set_power(true)) {
      return end_control(c, TerminateCode::power_failure, 0, "arm power could not be turned on");
    }
    c.power_expected = true;
  } else if (chg.power == Request::off) {
    driver_.set_power(false);
    c.power_expected = false;
  }
  if (chg.hand != Request::none) driver_.set_hand_closed(chg.hand == Request::on);
  if (chg.zero_gravity != Request::none) driver_.set_zero_gravity(chg.zero_gravity == Request::on);
  if (chg.setting.what != Setting::none && chg.setting.joint < h.dof) driver_.apply(chg.setting);
  if (chg.outputs_set != 0 || chg.outputs_clear != 0) {
    driver_.set_outputs(
        static_cast<std::uint16_t>((h.outputs | chg.outputs_set) & ~chg.outputs_clear));
  }

  JointCommands commands{};
  for (std::size_t i = 0; i < h.dof; ++i) {
    const JointChg& m = chg.motion[i];
    const kin::Joint& joint = joints[i];
    JointHow& j = h.joint[i];
    const int number = static_cast<int>(i) + 1;
    if (m.set == SetMode::none) continue;
    if (m.set == SetMode::stopcal) {
      commands[i].kind = JointCommand::Kind::calibrate;
      c.has_target[i] = false;
      continue;
    }
    if (!j.has(kCalibrated)) {
      j.flags |= kNotCalibratedTarget;
      return end_control(c, TerminateCode::not_calibrated, number, "");
    }
    double target = joint.lower + m.range_target;
    if (!(target >= joint.lower - kin::kLimitTolerance &&
          target <= joint.upper + kin::kLimitTolerance)) {
      j.flags |= kTargetPositionOut;
      if ((chg.checking & kCheckTargetPosition) != 0 || !std::isfinite(target)) {
        std::array<char, kMessageCapacity> d;
        format_text(d, "joint {} commanded to {:.5f} {}, limits [{:.5f}, {:.5f}]", number, target,
                    unit_of(joint), joint.lower, joint.upper);
        return end_control(c, TerminateCode::target_position, number, d.data());
      }
      target = std::clamp(target, joint.lower, joint.upper);  // never sent outside the limits
    }
    const double from = c.has_target[i] ? c.last_target[i] : j.q;
    const double top = driver_.velocity_limit(i, period_s);  // at most the model's top speed
    double rate = m.set == SetMode::posvel
                      ? std::abs(target - from) / period_s
                      : (m.velocity > 0.0 ? m.velocity : kDefaultSpeedFraction * top);
    if (!(rate <= top * (1.0 + 1e-9))) {
      j.flags |= kTargetVelocityOut;
      if ((chg.checking & kCheckTargetVelocity) != 0 || !std::isfinite(rate)) {
        std::array<char, kMessageCapacity> d;
        format_text(d, "joint {} commanded at {:.4f} {}/s, maximum {:.4f}", number, rate,
                    unit_of(joint), top);
        return end_control(c, TerminateCode::target_velocity, number, d.data());
      }
      rate = top;  // arrives late rather than too fast
    }
    commands[i] = {JointCommand::Kind::move, target, rate};
    c.last_target[i] = target;
    c.has_target[i] = true;
  }
  driver_.send(commands);
}

void Session::end_control(CommState& c, TerminateCode code, int joint,
                          std::string_view detail) noexcept {
  Shared& s = *shared_;
  c.ended = true;
  std::uint32_t expected = kControlling;
  if (!s.phase.compare_exchange_strong(expected, kEnding, std::memory_order_seq_cst)) return;
  Termination& t = s.termination;
  t = Termination{};
  t.code = code;
  t.joint = joint;
  t.sample = c.k;
  t.time_s = static_cast<double>(c.tick_ns) * 1e-9;
  copy_text(t.detail, detail);
  if (powers_down(code)) {
    driver_.set_power(false);
  } else {
    driver_.hold();
  }
  c.power_expected = false;
  s.phase.store(kEnded, std::memory_order_seq_cst);
  ring(s.control_bell);
  ring(s.planning_bell);
}

// ---------------------------------------------------------------------------------------------
// The control task

void Session::control_task() noexcept {
  Shared& s = *shared_;
  std::uint32_t last = 0;
  for (;;) {
    const std::uint32_t seen = s.control_bell.load();
    if (s.stop.load(std::memory_order_acquire)) return;
    // Busy before looking at the phase, so that release() waiting for !busy after changing the
    // phase cannot miss a cycle that is about to start.
    s.control_busy.store(true, std::memory_order_seq_cst);
    if (s.phase.load(std::memory_order_seq_cst) == kControlling) {
      const std::uint32_t k = s.how_ready.load(std::memory_order_acquire);
      if (k != 0 && k != last) {
        last = k;
        control_cycle(k);
        s.control_busy.store(false, std::memory_order_seq_cst);
        ring(s.planning_bell);
        continue;
      }
    }
    s.control_busy.store(false, std::memory_order_seq_cst);
    wait_while(s.control_bell, seen);
  }
}

void Session::control_cycle(std::uint32_t k) noexcept {
  Shared& s = *shared_;
  Control& ctl = s.control;
  ctl.how_ = s.how;
  ctl.period_s_ = static_cast<double>(s.period_ns.load(std::memory_order_relaxed)) * 1e-9;
  ctl.spent_ns_ = 0;
  const auto run = [&](ControlFunction& f) {
    if (!f) return;
    try {
      f(ctl);
    } catch (const std::exception& e) {
      ctl.message(e.what());
      request_termination(TerminateCode::control_exception, 0);
    } catch (...) {
      ctl.message("unknown exception");
      request_termination(TerminateCode::control_exception, 0);
    }
  };

  run(f1_);
  s.chg = ctl.chg_;
  s.chg_ready.store(k, std::memory_order_release);
  ring(s.comm_bell);
  for (;;) {
    const std::uint32_t seen = s.control_bell.load();
    if (reached(s.chg_taken.load(std::memory_order_acquire), k)) break;
    if (s.phase.load(std::memory_order_seq_cst) != kControlling) return;
    if (s.stop.load(std::memory_order_acquire)) return;
    wait_while(s.control_bell, seen);
  }
  ctl.chg_.clear_commands();
  run(f2_);

  const std::int64_t tick_ns = std::llround(ctl.how_.time_s * 1e9);
  const std::int64_t end_ns = options_.clock == ClockKind::simulated
                                  ? tick_ns + ctl.spent_ns_
                                  : std::max(monotonic_ns() - s.t0_ns, tick_ns);
  s.control_end_ns.store(end_ns, std::memory_order_relaxed);
  s.control_done.store(k, std::memory_order_release);  // the watchdog kick
  ring(s.planning_bell);
}

}  // namespace rccx::rtc
