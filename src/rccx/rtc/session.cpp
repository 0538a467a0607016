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

#include "rccx/io/console.hpp"
#include "rccx/io/fixed_text.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rtc/doorbell.hpp"
#include "rccx/rtc/hangup.hpp"
#include "rccx/rtc/joint_commands.hpp"
#include "rccx/rtc/latest.hpp"
#include "rccx/rtc/sample_checks.hpp"

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

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kLockMemory = false;  // the sanitizers' shadow memory is terabytes of mappings
#else
constexpr bool kLockMemory = true;
#endif

void try_real_time_scheduling(std::thread& t, int priority) {
  static std::once_flag locked;
  static std::atomic<bool> told{false};
  const auto tell = [](const char* what, int err) {
    if (!told.exchange(true)) {
      io::eprint(
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

// The clock of one session, or of a group: the time, the two tasks, and the hand-overs of
// figure 4.7, one set per tick for every robot due at it.
struct Session::Clock {
  SessionOptions options;
  std::atomic<std::int64_t> period_ns{0};
  std::int64_t t0_ns = 0;  ///< real time: the monotonic time the clock started

  // Doorbells: each party sleeps on its own, the others ring it after changing what it watches.
  detail::Doorbell comm_bell;
  detail::Doorbell control_bell;
  mutable detail::Doorbell planning_bell;

  // Tick numbers (the first tick is 1; 0 is "none"), one counter per hand-over of figure 4.7.
  std::atomic<std::uint32_t> granted{0};       ///< simulated time: ticks the planning level let run
  std::atomic<std::uint32_t> how_ready{0};     ///< comm -> control: How of this tick handed over
  std::atomic<std::uint32_t> chg_ready{0};     ///< control -> comm: Chg after every f1 is there
  std::atomic<std::uint32_t> chg_taken{0};     ///< comm -> control: Chg copied, control goes on
  std::atomic<std::uint32_t> control_done{0};  ///< control finished every f2: the watchdog kick
  std::atomic<std::uint32_t> comm_done{0};     ///< comm finished its cycle
  std::atomic<std::int64_t> handed_tick_ns{0};  ///< clock time of the tick handed to control
  std::atomic<std::int64_t> control_end_ns{0};  ///< clock time the last control cycle ended
  std::atomic<std::int64_t> simulated_now_ns{0};
  std::atomic<bool> control_busy{false};
  std::atomic<bool> stop{false};
  LatencyHistogram latency;
  LatencyHistogram compute;  ///< each tick: its start to the end of its control cycle
  std::atomic<std::int64_t> tick_started_ns{0};  ///< monotonic: the communication task woke

  std::vector<Session*> sessions;                 ///< fixed once the tasks run
  std::function<void(std::uint32_t)> cycle_hook;  ///< after every f2 of a tick (a group's)
  std::function<void(std::size_t, std::uint32_t)> robot_hook;  ///< after each robot's f2
  std::thread communication_thread;
  std::thread control_thread;
  bool running = false;
  bool stopped = false;

  // Planning side: one thread at a time steps simulated time.
  std::mutex step_mutex;
  std::uint32_t simulated_ticks = 0;

  // The communication task's own.
  std::uint32_t last_published = 0;  ///< last tick handed to control
  std::int64_t nominal_ns = 0;       ///< real time: the last sample's time (see wait_tick)
  std::int64_t last_published_tick_ns = 0;

  [[nodiscard]] bool simulated() const noexcept { return options.clock == ClockKind::simulated; }
  [[nodiscard]] std::int64_t now_ns() const noexcept {
    return simulated() ? simulated_now_ns.load() : monotonic_ns() - t0_ns;
  }

  void start();
  void stop_tasks();
  void communication_task() noexcept;
  bool wait_tick(std::uint32_t k, std::int64_t& next_deadline, std::int64_t& tick_ns) noexcept;
  void watchdog(std::uint32_t k, std::int64_t tick_ns) noexcept;
  void control_task() noexcept;
  void control_cycle(std::uint32_t k) noexcept;
  /// Pieces of a control cycle: every f1 of tick k; every f2 and the cycle hook, then the
  /// watchdog kick.
  void run_f1s(std::uint32_t k) noexcept;
  void finish_cycle(std::uint32_t k) noexcept;
  /// After every f2 of tick k (`spent_ns` charged by them): the cycle hook, the watchdog kick.
  void end_cycle(std::uint32_t k, std::int64_t spent_ns) noexcept;
  /// The robot hook for `s`, guarded.
  void after_f2(Session* s, std::uint32_t k) noexcept;
  /// One thread: tick k, robot after robot (see SessionOptions::one_thread).
  void one_thread_tick(std::uint32_t k, std::int64_t tick_ns, std::int64_t started) noexcept;
  /// The communication task's side after the f1s: every Chg of tick k taken (or, not
  /// `in_time`, control ended with overrun), every How published.
  void take_chgs(std::uint32_t k, bool in_time) noexcept;
  /// A robot of tick k whose control still runs.
  [[nodiscard]] static bool in_cycle(const Session* s, std::uint32_t k) noexcept;
  void step_simulated_sample();
};

struct Session::CommState {
  How how;
  Chg chg;
  std::uint32_t k = 0;
  std::int64_t tick_ns = 0;
  std::uint32_t generation = 0;
  std::uint32_t hangups_seen = 0;
  bool power_expected = false;
  bool ended = false;
  JointTargets targets;
};

// One robot's side: what the planning level, the communication task and the control task
// exchange for it.
// Hot first: what every tick touches (the flags, the communication task's How and Chg, the
// control task's), then what the planning level reads.
struct Session::Shared {
  std::atomic<std::uint32_t> phase{kIdle};
  std::atomic<std::uint32_t> generation{0};  ///< bumped by control(): comm resets its state
  std::atomic<std::uint32_t> pending{0};
  std::atomic<std::uint32_t> in_cycle{0};  ///< the tick whose control cycle includes this robot
  std::atomic<bool> user_hangup{false};
  std::atomic<std::int32_t> requested_code{0};
  std::atomic<std::int32_t> requested_joint{0};
  std::atomic<SampleLog*> log{nullptr};
  std::atomic<SampleTap*> tap{nullptr};
  std::atomic<bool> tap_busy{false};  ///< the communication task is in (or about to call) the tap

  // Each task's own on lines of their own (with two tasks they run on two processors).
  alignas(64) CommState comm;   ///< the communication task's own
  alignas(64) Control control;  ///< the control task's own
  How how;                      ///< two tasks: guarded by the clock's how_ready / the next tick
  Chg chg;                      ///< two tasks: guarded by the clock's chg_ready / chg_taken
  mutable detail::Latest<How> latest;
  Termination termination;  ///< written while kEnding, read once kEnded

  mutable std::mutex snapshot_mutex;  ///< planning side only
  mutable How snapshot;
};

// ---------------------------------------------------------------------------------------------
// Control (what f1 and f2 see)

void Control::terminate(TerminateCode code) noexcept {
  session_->request_termination(code, 0);
}

void Control::message(std::string_view text) noexcept {
  io::copy_fixed(message_, text);
}

void Control::spend(std::chrono::nanoseconds d) noexcept {
  if (session_->clock_->simulated()) {
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
    : driver_(driver), clock_(std::make_shared<Clock>()), owns_clock_(true) {
  clock_->options = options;
  clock_->period_ns = options.period.count();
  open_channel({});
  clock_->sessions.push_back(this);
  clock_->start();
}

Session::Session(Driver& driver, std::shared_ptr<Clock> clock, int multiple, std::string log_suffix)
    : driver_(driver), clock_(std::move(clock)), multiple_(multiple) {
  open_channel(log_suffix);
}

void Session::open_channel(const std::string& log_suffix) {
  if (driver_.model().dof() == 0 || driver_.model().dof() > kMaxJoints) {
    throw SessionError(fmt::format("robot {} has {} joints; RTC serves 1 to {}",
                                   driver_.model().name, driver_.model().dof(), kMaxJoints));
  }
  check_period(period());
  shared_ = std::make_unique<Shared>();
  comm_ = &shared_->comm;
  if (log_suffix.empty()) {
    environment_log_ = SampleLog::from_environment(driver_.model());  // LogError names RCCX_LOG
  } else {
    environment_log_ = SampleLog::from_environment(driver_.model(), log_suffix);
  }
  shared_->log = environment_log_.get();
  shared_->control.session_ = this;
}

Session::~Session() {
  try {
    close();
  } catch (...) {  // close() only throws for misuse that a destructor cannot report
  }
}

std::chrono::nanoseconds Session::period() const noexcept {
  return std::chrono::nanoseconds(clock_->period_ns.load() * multiple_);
}

ClockKind Session::clock() const noexcept {
  return clock_->options.clock;
}

bool Session::due(std::uint32_t k) const noexcept {
  return multiple_ == 1 || (k - 1) % static_cast<std::uint32_t>(multiple_) == 0;
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
  if (!owns_clock_) {
    throw SessionError("a robot of a group keeps the group's clock; its period cannot change");
  }
  check_period(period);
  if (controlling()) throw SessionError("the sample period can change only while not in control");
  clock_->period_ns = period.count();
}

void Session::close(bool power_off) {
  if (closed_) return;
  release(power_off);
  if (owns_clock_) clock_->stop_tasks();
  closed_ = true;
  if (environment_log_) log_problem_ = environment_log_->close();
}

void Session::Clock::start() {
  if (running) return;
  t0_ns = monotonic_ns();
  running = true;
  communication_thread = std::thread([this] { communication_task(); });
  if (!options.one_thread) control_thread = std::thread([this] { control_task(); });
  if (options.clock == ClockKind::real_time && options.real_time_scheduling) {
    try_real_time_scheduling(communication_thread, 80);
    if (control_thread.joinable()) try_real_time_scheduling(control_thread, 79);
  }
  // The first How, so that how() means something before the first wait.
  if (simulated()) step_simulated_sample();
}

void Session::Clock::stop_tasks() {
  if (!running || stopped) return;
  stop.store(true, std::memory_order_seq_cst);
  ring(comm_bell);
  ring(control_bell);
  communication_thread.join();
  if (control_thread.joinable()) control_thread.join();
  stopped = true;
}

// ---------------------------------------------------------------------------------------------
// A group

SessionGroup::SessionGroup(SessionOptions options) : clock_(std::make_shared<Session::Clock>()) {
  if (options.period < kMinPeriod || options.period > kMaxPeriod) {
    using ms = std::chrono::duration<double, std::milli>;
    throw SessionError(fmt::format("the clock's period {} ms is outside {} .. {} ms",
                                   ms(options.period).count(), ms(kMinPeriod).count(),
                                   ms(kMaxPeriod).count()));
  }
  clock_->options = options;
  clock_->period_ns = options.period.count();
}

SessionGroup::~SessionGroup() {
  for (auto& s : sessions_) {
    try {
      s->release();
    } catch (...) {
    }
  }
  clock_->stop_tasks();
  sessions_.clear();  // their logs close after the tasks have stopped
}

Session& SessionGroup::add(Driver& driver, int multiple) {
  if (clock_->running) throw SessionError("add every robot before start()");
  if (multiple < 1 || multiple > 1000) {
    throw SessionError(fmt::format("robot {}: a period multiple of {}; give 1 to 1000",
                                   driver.model().name, multiple));
  }
  auto s =
      std::unique_ptr<Session>(new Session(driver, clock_, multiple, "-" + driver.model().name));
  s->index_ = clock_->sessions.size();
  clock_->sessions.push_back(s.get());
  sessions_.push_back(std::move(s));
  return *sessions_.back();
}

void SessionGroup::set_cycle_hook(std::function<void(std::uint32_t tick)> hook) {
  if (clock_->running) throw SessionError("set the cycle hook before start()");
  clock_->cycle_hook = std::move(hook);
}

void SessionGroup::set_robot_hook(std::function<void(std::size_t, std::uint32_t)> hook) {
  if (clock_->running) throw SessionError("set the robot hook before start()");
  clock_->robot_hook = std::move(hook);
}

void SessionGroup::start() {
  if (sessions_.empty()) throw SessionError("a group needs at least one robot: add() it first");
  clock_->start();
}

std::chrono::nanoseconds SessionGroup::period() const noexcept {
  return std::chrono::nanoseconds(clock_->period_ns.load());
}

LatencyStats SessionGroup::latency() const {
  return clock_->latency.stats();
}

LatencyStats SessionGroup::compute() const {
  return clock_->compute.stats();
}

void SessionGroup::wait_for(std::chrono::nanoseconds d) {
  if (sessions_.empty() || !clock_->running) throw SessionError("start() the group first");
  sessions_.front()->wait_for(d);
}

// ---------------------------------------------------------------------------------------------
// Planning level

void Session::control(ControlFunction f1, ControlFunction f2) {
  if (closed_) throw SessionError("the session is closed; open a new one");
  if (!clock_->running) throw SessionError("the group is not started: call start() first");
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
  ring(clock_->comm_bell);
}

Termination Session::release(bool power_off) {
  Shared& s = *shared_;
  Clock& clk = *clock_;
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
  ring(clk.control_bell);
  ring(clk.comm_bell);
  Termination t = ended ? ended_termination() : Termination{};
  if (!ended) {
    wait_control_idle();
    t.message = s.control.message_;
  }
  s.phase.store(kIdle, std::memory_order_seq_cst);
  detail::unregister_for_hangup(this);
  if (!clk.running || clk.stopped) return t;

  // The arm holds where it is (and powers off if asked) from the next tick on.
  s.pending.fetch_or(kPendingHold | (power_off ? kPendingPowerOff : 0U));
  if (clk.simulated()) {
    clk.step_simulated_sample();
  } else {
    const std::uint32_t before = clk.comm_done.load(std::memory_order_acquire);
    const std::int64_t deadline = monotonic_ns() + 4 * clk.period_ns.load();
    while (clk.comm_done.load(std::memory_order_acquire) == before && monotonic_ns() < deadline) {
      const std::uint32_t seen = clk.planning_bell.load();
      if (clk.comm_done.load(std::memory_order_acquire) != before) break;
      wait_while(clk.planning_bell, seen, deadline);
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

TerminateCode Session::ended_code() const noexcept {
  // The termination is written while kEnding and not again until the next control().
  if (shared_->phase.load(std::memory_order_acquire) != kEnded) return TerminateCode::none;
  return shared_->termination.code;
}

void Session::wait_control_idle() const {
  const Clock& clk = *clock_;
  while (clk.control_busy.load(std::memory_order_seq_cst)) {
    const std::uint32_t seen = clk.planning_bell.load();
    if (!clk.control_busy.load(std::memory_order_seq_cst)) break;
    wait_while(clk.planning_bell, seen, monotonic_ns() + 1'000'000);
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
  return clock_->latency.stats();
}

void Session::set_tap(SampleTap* tap) noexcept {
  shared_->tap.store(tap);
  if (tap != nullptr) return;
  while (shared_->tap_busy.load()) std::this_thread::yield();
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

void Session::Clock::step_simulated_sample() {
  std::lock_guard lock(step_mutex);
  const std::uint32_t k = ++simulated_ticks;
  simulated_now_ns.fetch_add(period_ns.load(), std::memory_order_relaxed);
  granted.store(k, std::memory_order_release);
  ring(comm_bell);
  const auto wait_for_counter = [&](const std::atomic<std::uint32_t>& counter,
                                    std::int64_t deadline) {
    for (;;) {
      const std::uint32_t seen = planning_bell.load();
      if (reached(counter.load(std::memory_order_acquire), k)) return true;
      if (deadline > 0 && monotonic_ns() >= deadline) return false;
      // No spinning: the two tasks need both processors for the sample this thread waits for.
      wait_while(planning_bell, seen, deadline, 0);
    }
  };
  wait_for_counter(comm_done, 0);
  // When the communication task handed this tick to the control task, the tick is over only
  // when the control cycle is: that keeps simulated time deterministic. A control cycle that
  // hangs is left behind; the watchdog ends the session at the next tick.
  if (how_ready.load(std::memory_order_acquire) == k) {
    wait_for_counter(control_done, monotonic_ns() + options.hang_timeout.count() * 1'000'000);
  }
}

Termination Session::wait_for(std::chrono::nanoseconds d) {
  // A stop signal (Ctrl-C, SIGTERM) ends the wait within a period, whatever its length.
  Clock& clk = *clock_;
  const std::uint32_t stops = detail::hangup_count();
  const auto stopped = [&] { return detail::hangup_count() != stops; };
  if (clk.simulated()) {
    const std::int64_t until = clk.simulated_now_ns.load() + d.count();
    while (!stopped() && clk.simulated_now_ns.load() + clk.period_ns.load() <= until) {
      clk.step_simulated_sample();
    }
    // One more tick lets the communication task see the signal and end control.
    if (stopped() && controlling()) {
      for (int i = 0; i < multiple_ && controlling(); ++i) clk.step_simulated_sample();
    }
  } else {
    const std::int64_t until = monotonic_ns() + d.count();
    for (std::int64_t now = monotonic_ns(); now < until && !stopped(); now = monotonic_ns()) {
      detail::sleep_until(std::min(until, now + clk.period_ns.load()));
    }
  }
  return termination();
}

Termination Session::wait_terminated(std::chrono::nanoseconds timeout) {
  Shared& s = *shared_;
  Clock& clk = *clock_;
  const std::uint32_t stops = detail::hangup_count();
  const auto ended = [&] {
    return s.phase.load(std::memory_order_seq_cst) == kEnded || detail::hangup_count() != stops;
  };
  if (clk.simulated()) {
    const std::int64_t until = clk.simulated_now_ns.load() + timeout.count();
    while (!ended() && clk.simulated_now_ns.load() + clk.period_ns.load() <= until) {
      clk.step_simulated_sample();
    }
  } else {
    const std::int64_t deadline = monotonic_ns() + timeout.count();
    while (!ended() && monotonic_ns() < deadline) {
      const std::uint32_t seen = clk.planning_bell.load();
      if (ended()) break;
      wait_while(clk.planning_bell, seen, std::min(deadline, monotonic_ns() + period().count()));
    }
  }
  return termination();
}

bool Session::wait_until(const std::function<bool(const How&)>& done,
                         std::chrono::nanoseconds timeout) {
  Shared& s = *shared_;
  Clock& clk = *clock_;
  const bool simulated = clk.simulated();
  const std::int64_t start = simulated ? clk.simulated_now_ns.load() : monotonic_ns();
  const std::uint32_t stops = detail::hangup_count();
  std::uint64_t seen_sample = ~std::uint64_t{0};
  for (;;) {
    // A robot sampled every k-th tick has a new How only every k-th tick.
    const How h = how();
    if (h.sample != seen_sample) {
      seen_sample = h.sample;
      if (done(h)) return true;
    }
    if (s.phase.load(std::memory_order_seq_cst) == kEnded) return false;
    if (detail::hangup_count() != stops) return false;  // Ctrl-C, SIGTERM
    const std::int64_t now = simulated ? clk.simulated_now_ns.load() : monotonic_ns();
    if (now - start >= timeout.count()) return false;
    if (simulated) {
      clk.step_simulated_sample();
    } else {
      detail::sleep_until(monotonic_ns() + clk.period_ns.load());
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The communication task

void Session::Clock::communication_task() noexcept {
  std::int64_t next_deadline = t0_ns + period_ns.load();
  for (std::uint32_t k = 1;; ++k) {
    std::int64_t tick_ns = 0;
    if (!wait_tick(k, next_deadline, tick_ns)) return;
    const std::int64_t started = monotonic_ns();
    tick_started_ns.store(started, std::memory_order_relaxed);
    watchdog(k, tick_ns);

    if (options.one_thread) {
      one_thread_tick(k, tick_ns, started);
      comm_done.store(k, std::memory_order_release);
      ring(planning_bell);
      continue;
    }
    bool handed = false;
    for (Session* s : sessions) {
      if (s->communication_cycle(*s->comm_, k, tick_ns)) handed = true;
    }
    if (handed) {
      // Hand How over for every robot at once; wait for the Chg their f1s leave (at most until
      // the next tick).
      handed_tick_ns.store(tick_ns, std::memory_order_relaxed);
      how_ready.store(k, std::memory_order_release);
      ring(control_bell);
      last_published = k;
      last_published_tick_ns = tick_ns;
      const std::int64_t deadline = options.clock == ClockKind::real_time
                                        ? next_deadline
                                        : monotonic_ns() + options.hang_timeout.count() * 1'000'000;
      bool in_time = true;
      for (;;) {
        const std::uint32_t seen = comm_bell.load();
        if (reached(chg_ready.load(std::memory_order_acquire), k)) break;
        if (stop.load(std::memory_order_acquire)) return;
        if (monotonic_ns() >= deadline) {
          in_time = false;
          break;
        }
        wait_while(comm_bell, seen, deadline);
      }
      take_chgs(k, in_time);
      chg_taken.store(k, std::memory_order_release);
      ring(control_bell);
    } else {
      compute.record(monotonic_ns() - started);  // no control this tick: reading was all
    }
    comm_done.store(k, std::memory_order_release);
    ring(planning_bell);
  }
}

namespace {
// The next robot's first lines, while this one is worked on: the loops over the robots touch
// each robot's data once a tick, and with hundreds of robots those are rarely in the cache.
inline void prefetch(const void* p) noexcept {
  __builtin_prefetch(p, 1, 3);
}
}  // namespace

void Session::Clock::one_thread_tick(std::uint32_t k, std::int64_t tick_ns,
                                     std::int64_t started) noexcept {
  // Busy before the phases are looked at, as control_task() is: release() waits for it.
  control_busy.store(true, std::memory_order_seq_cst);
  handed_tick_ns.store(tick_ns, std::memory_order_relaxed);
  bool handed = false;
  std::int64_t spent_ns = 0;
  const std::size_t n = sessions.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (i + 2 < n) prefetch(sessions[i + 2]);  // its shared_, read next time round
    if (i + 1 < n) {
      const Shared* next = sessions[i + 1]->shared_.get();
      prefetch(next);
      prefetch(&next->comm);
      prefetch(&next->control);
    }
    Session* s = sessions[i];
    if (!s->communication_cycle(*s->comm_, k, tick_ns)) continue;
    if (!handed) {
      handed = true;
      last_published = k;
      last_published_tick_ns = tick_ns;
      how_ready.store(k, std::memory_order_release);
    }
    spent_ns += s->run_cycle_in_place(k);
  }
  if (handed) {
    chg_ready.store(k, std::memory_order_release);
    chg_taken.store(k, std::memory_order_release);
    end_cycle(k, spent_ns);
  } else {
    compute.record(monotonic_ns() - started);  // no control this tick: reading was all
  }
  control_busy.store(false, std::memory_order_seq_cst);
}

std::int64_t Session::run_cycle_in_place(std::uint32_t k) noexcept {
  // What the two tasks do for this robot (run_f1s, take_chgs, finish_cycle), without the
  // copies between them: f1 reads the communication task's How, its Chg is taken from the
  // control task's at once.
  Shared& s = *shared_;
  CommState& c = *comm_;
  std::int64_t spent_ns = 0;
  if (Clock::in_cycle(this, k)) {
    Control& ctl = s.control;
    ctl.how_ = c.how;
    ctl.period_s_ = std::chrono::duration<double>(period()).count();
    ctl.spent_ns_ = 0;
    run_guarded(f1_);
    if (!c.ended && s.phase.load(std::memory_order_seq_cst) == kControlling) {
      c.chg = ctl.chg_;
      apply_taken(c);
    }
  }
  s.latest.publish(c.how);  // with the flags the Chg set
  if (Clock::in_cycle(this, k)) {
    spent_ns = run_f2();
    clock_->after_f2(this, k);
  }
  return spent_ns;
}

void Session::Clock::take_chgs(std::uint32_t k, bool in_time) noexcept {
  for (Session* s : sessions) {
    if (s->shared_->in_cycle.load(std::memory_order_relaxed) != k) continue;
    if (!s->comm_->ended && s->shared_->phase.load(std::memory_order_seq_cst) == kControlling) {
      if (in_time) {
        s->take_chg(*s->comm_);
      } else {
        std::array<char, kMessageCapacity> d;
        io::format_fixed(d, "f1 of sample {} did not hand Chg over within its period", k);
        s->end_control(*s->comm_, TerminateCode::overrun, 0, d.data());
      }
    }
    s->shared_->latest.publish(s->comm_->how);  // with the flags the Chg set
  }
}

// The planning level grants a simulated tick only after it has woken up; spinning for it would
// keep the processor it needs busy.
constexpr int kSpinsForGrant = 0;

bool Session::Clock::wait_tick(std::uint32_t k, std::int64_t& next_deadline,
                               std::int64_t& tick_ns) noexcept {
  if (simulated()) {
    for (;;) {
      const std::uint32_t seen = comm_bell.load();
      if (stop.load(std::memory_order_acquire)) return false;
      if (reached(granted.load(std::memory_order_acquire), k)) break;
      wait_while(comm_bell, seen, 0, kSpinsForGrant);
    }
    tick_ns = simulated_now_ns.load(std::memory_order_relaxed);
    return true;
  }
  const std::int64_t deadline = next_deadline;
  const std::int64_t spin_ns = options.spin_before_tick.count();
  if (spin_ns > 0) {
    detail::sleep_until(deadline - spin_ns);
    while (monotonic_ns() < deadline) {
#if defined(__x86_64__) || defined(__i386__)
      __builtin_ia32_pause();
#endif
    }
  } else {
    detail::sleep_until(deadline);
  }
  if (stop.load(std::memory_order_acquire)) return false;
  const std::int64_t period = period_ns.load(std::memory_order_relaxed);
  const std::int64_t late = monotonic_ns() - deadline;
  if (options.measure_latency) latency.record(late);
  // A wake-up more than a period late has missed ticks: skip them rather than run a burst.
  const std::int64_t missed = late / period;
  if (missed > 0) latency.record_missed(static_cast<std::uint64_t>(missed));
  next_deadline = deadline + (missed + 1) * period;
  // The sample's time is its nominal one, a period after the last sample's: the skipped
  // deadlines are not samples, so a stall delays the motions by its length rather than making
  // their next setpoints jump over it (which would exceed the joints' top speeds). Without a
  // stall this is the deadline's own time.
  nominal_ns += period;
  tick_ns = nominal_ns;
  return true;
}

// The watchdog: the control cycle of the last tick must have finished within its period; when
// it did not, every robot whose functions ran in it ends with `overrun`.
void Session::Clock::watchdog(std::uint32_t k, std::int64_t tick_ns) noexcept {
  if (last_published == 0) return;
  const std::uint32_t cycle = last_published;
  last_published = 0;
  std::array<char, kMessageCapacity> d{};
  if (control_done.load(std::memory_order_acquire) != cycle) {
    io::format_fixed(d, "the control cycle of sample {} was still running at the next tick", cycle);
  } else if (simulated()) {
    // Simulated time: the computing a cycle charged with spend() must fit in its period. (In
    // real time the check above is the whole story: the cycle finished before this tick was
    // processed, so its Chg was in time.)
    const std::int64_t period = period_ns.load(std::memory_order_relaxed);
    const std::int64_t used =
        control_end_ns.load(std::memory_order_relaxed) - last_published_tick_ns;
    if (used <= period) return;
    io::format_fixed(d, "the control cycle of sample {} took {:.3f} ms of a {:.3f} ms period",
                     cycle, static_cast<double>(used) * 1e-6, static_cast<double>(period) * 1e-6);
  } else {
    return;
  }
  for (Session* s : sessions) {
    if (s->shared_->in_cycle.load(std::memory_order_relaxed) != cycle) continue;
    if (s->comm_->ended || s->shared_->phase.load(std::memory_order_seq_cst) != kControlling) {
      continue;
    }
    s->comm_->k = k;  // found at this tick
    s->comm_->tick_ns = tick_ns;
    s->end_control(*s->comm_, TerminateCode::overrun, 0, d.data());
  }
}

bool Session::communication_cycle(CommState& c, std::uint32_t k, std::int64_t tick_ns) noexcept {
  Shared& s = *shared_;
  // Requests from release() are carried out at the next tick, whether or not the robot is due.
  const std::uint32_t pending = s.pending.exchange(0, std::memory_order_acq_rel);
  if ((pending & kPendingHold) != 0) driver_.hold();
  if ((pending & kPendingPowerOff) != 0) driver_.set_power(false);
  if (!due(k)) return false;

  How& h = c.how;
  c.k = k;
  c.tick_ns = tick_ns;
  const double t = static_cast<double>(tick_ns) * 1e-9;
  driver_.read(t, h);
  h.sample = k;
  h.time_s = t;
  const auto& joints = driver_.model().joints;
  for (std::size_t i = 0; i < h.dof; ++i) h.joint[i].range = h.joint[i].q - joints[i].lower;

  bool handed = false;
  if (s.phase.load(std::memory_order_seq_cst) == kControlling) handed = controlled_cycle(c, k);
  if (!handed) s.latest.publish(h);  // a handed How is published once its Chg is applied
  return handed;
}

bool Session::controlled_cycle(CommState& c, std::uint32_t k) noexcept {
  Shared& s = *shared_;
  How& h = c.how;
  const std::int64_t period = this->period().count();

  const std::uint32_t generation = s.generation.load(std::memory_order_relaxed);
  if (generation != c.generation) {  // a new control session: start its state afresh
    c.generation = generation;
    c.hangups_seen = detail::hangup_count();
    c.power_expected = h.power;
    c.ended = false;
    c.chg = Chg{};
    c.targets.has = {};
  }
  if (c.ended) return false;

  EndRequests requests;
  requests.code = static_cast<TerminateCode>(s.requested_code.exchange(0));
  requests.joint = s.requested_joint.load();
  requests.hangups = detail::hangup_count();
  requests.user_hangup = s.user_hangup.load(std::memory_order_relaxed);
  std::optional<Stop> stop = check_requests(requests, c.hangups_seen);
  if (!stop) stop = check_faults(h, c.power_expected, driver_);
  if (!stop) stop = check_force(h.force, c.chg.checking);
  if (!stop) stop = check_observed_limits(h, driver_, period, c.chg.checking);
  if (stop) {
    end_control(c, stop->code, stop->joint, stop->detail_view());
    return false;
  }

  // This robot's How for the control task; the clock hands every robot's over at once. (One
  // thread: f1 reads the communication task's own, run_cycle_in_place.)
  if (!clock_->options.one_thread) s.how = h;
  s.in_cycle.store(k, std::memory_order_relaxed);
  return true;
}

void Session::take_chg(CommState& c) noexcept {
  c.chg = shared_->chg;
  apply_taken(c);
}

void Session::apply_taken(CommState& c) noexcept {
  Shared& s = *shared_;
  const How& h = c.how;
  apply(c, c.chg);
  if (SampleLog* log = s.log.load(std::memory_order_acquire)) {
    LogRow row;
    row.t_s = h.time_s;
    row.segment = c.chg.segment;
    row.measured = h.q();
    row.commanded = c.targets.commanded(row.measured);
    log->push(row);
  }
  if (s.tap.load(std::memory_order_relaxed) != nullptr) {
    // set_tap(nullptr) waits while tap_busy: busy is raised before the pointer is read again
    // (sequentially consistent, as the detaching side's store and load are).
    s.tap_busy.store(true);
    if (SampleTap* tap = s.tap.load()) tap->on_sample(h, c.targets.commanded(h.q()), c.chg.segment);
    s.tap_busy.store(false, std::memory_order_release);
  }
}

void Session::apply(CommState& c, const Chg& chg) noexcept {
  How& h = c.how;
  const double period_s = std::chrono::duration<double>(period()).count();

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
  if (const std::optional<Stop> stop =
          to_joint_commands(chg, driver_, period_s, h, c.targets, commands)) {
    return end_control(c, stop->code, stop->joint, stop->detail_view());
  }
  driver_.send(commands);
}

void Session::end_control(CommState& c, TerminateCode code, int joint,
                          std::string_view detail) noexcept {
  Shared& s = *shared_;
  Clock& clk = *clock_;
  c.ended = true;
  std::uint32_t expected = kControlling;
  if (!s.phase.compare_exchange_strong(expected, kEnding, std::memory_order_seq_cst)) return;
  Termination& t = s.termination;
  t = Termination{};
  t.code = code;
  t.joint = joint;
  t.sample = c.k;
  t.time_s = static_cast<double>(c.tick_ns) * 1e-9;
  io::copy_fixed(t.detail, detail);
  if (powers_down(code)) {
    driver_.set_power(false);
  } else {
    driver_.hold();
  }
  c.power_expected = false;
  s.phase.store(kEnded, std::memory_order_seq_cst);
  ring(clk.control_bell);
  ring(clk.planning_bell);
}

// ---------------------------------------------------------------------------------------------
// The control task

void Session::Clock::control_task() noexcept {
  std::uint32_t last = 0;
  for (;;) {
    const std::uint32_t seen = control_bell.load();
    if (stop.load(std::memory_order_acquire)) return;
    // Busy before looking at the robots' phases, so that release() waiting for !busy after
    // changing a phase cannot miss a cycle that is about to start.
    control_busy.store(true, std::memory_order_seq_cst);
    const std::uint32_t k = how_ready.load(std::memory_order_acquire);
    if (k != 0 && k != last) {
      last = k;
      control_cycle(k);
      control_busy.store(false, std::memory_order_seq_cst);
      ring(planning_bell);
      continue;
    }
    control_busy.store(false, std::memory_order_seq_cst);
    wait_while(control_bell, seen);
  }
}

bool Session::Clock::in_cycle(const Session* s, std::uint32_t k) noexcept {
  return s->shared_->in_cycle.load(std::memory_order_relaxed) == k &&
         s->shared_->phase.load(std::memory_order_seq_cst) == kControlling;
}

void Session::Clock::run_f1s(std::uint32_t k) noexcept {
  for (Session* s : sessions) {
    if (in_cycle(s, k)) s->run_f1(k);
  }
}

void Session::Clock::control_cycle(std::uint32_t k) noexcept {
  run_f1s(k);
  chg_ready.store(k, std::memory_order_release);
  ring(comm_bell);
  for (;;) {
    const std::uint32_t seen = control_bell.load();
    if (reached(chg_taken.load(std::memory_order_acquire), k)) break;
    if (stop.load(std::memory_order_acquire)) return;
    wait_while(control_bell, seen);
  }
  finish_cycle(k);
}

void Session::Clock::finish_cycle(std::uint32_t k) noexcept {
  std::int64_t spent_ns = 0;
  for (Session* s : sessions) {
    if (!in_cycle(s, k)) continue;
    spent_ns += s->run_f2();
    after_f2(s, k);
  }
  end_cycle(k, spent_ns);
}

void Session::Clock::after_f2(Session* s, std::uint32_t k) noexcept {
  if (!robot_hook) return;
  try {
    robot_hook(s->index_, k);
  } catch (...) {
    s->request_termination(TerminateCode::control_exception, 0);
  }
}

void Session::Clock::end_cycle(std::uint32_t k, std::int64_t spent_ns) noexcept {
  if (cycle_hook) {
    try {
      cycle_hook(k);
    } catch (...) {
      for (Session* s : sessions) {
        if (in_cycle(s, k)) s->request_termination(TerminateCode::control_exception, 0);
      }
    }
  }
  const std::int64_t tick_ns = handed_tick_ns.load(std::memory_order_relaxed);
  const std::int64_t end_ns =
      simulated() ? tick_ns + spent_ns : std::max(monotonic_ns() - t0_ns, tick_ns);
  control_end_ns.store(end_ns, std::memory_order_relaxed);
  compute.record(monotonic_ns() - tick_started_ns.load(std::memory_order_relaxed));
  control_done.store(k, std::memory_order_release);  // the watchdog kick
  ring(planning_bell);
}

// A control function that throws ends this robot's control with `control_exception`, its
// message as rtc_message; nothing escapes into the control task.
void Session::run_guarded(ControlFunction& f) noexcept {
  if (!f) return;
  Control& ctl = shared_->control;
  try {
    f(ctl);
  } catch (const std::exception& e) {
    ctl.message(e.what());
    request_termination(TerminateCode::control_exception, 0);
  } catch (...) {
    ctl.message("unknown exception");
    request_termination(TerminateCode::control_exception, 0);
  }
}

void Session::run_f1(std::uint32_t k) noexcept {
  (void)k;
  Shared& s = *shared_;
  Control& ctl = s.control;
  ctl.how_ = s.how;
  ctl.period_s_ = std::chrono::duration<double>(period()).count();
  ctl.spent_ns_ = 0;
  run_guarded(f1_);
  s.chg = ctl.chg_;
}

std::int64_t Session::run_f2() noexcept {
  Control& ctl = shared_->control;
  ctl.chg_.clear_commands();
  run_guarded(f2_);
  return ctl.spent_ns_;
}

}  // namespace rccx::rtc
