#include "rccx/rtc/sample_clock.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "rccx/io/console.hpp"
#include "rccx/io/fixed_text.hpp"
#include "rccx/rtc/robot_channel.hpp"

namespace rccx::rtc {

using detail::monotonic_ns;
using detail::reached;
using detail::ring;
using detail::wait_while;

namespace {

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

// The planning level grants a simulated tick only after it has woken up; spinning for it would
// keep the processor it needs busy.
constexpr std::int64_t kSpinNsForGrant = 0;

}  // namespace

SampleClock::SampleClock(const SessionOptions& options)
    : options_(options), period_ns_(options.period.count()) {}

// ---------------------------------------------------------------------------------------------
// Setting up, starting and stopping (planning level)

void SampleClock::add(RobotChannel& robot) {
  robots_.push_back(&robot);
}

void SampleClock::set_cycle_hook(std::function<void(std::uint32_t)> hook) {
  cycle_hook_ = std::move(hook);
}

void SampleClock::set_robot_hook(std::function<void(std::size_t, std::uint32_t)> hook) {
  robot_hook_ = std::move(hook);
}

void SampleClock::start() {
  if (running_) return;
  t0_ns_ = monotonic_ns();
  running_ = true;
  communication_thread_ = std::thread([this] { communication_task(); });
  if (!options_.one_thread) control_thread_ = std::thread([this] { control_task(); });
  if (options_.clock == ClockKind::real_time && options_.real_time_scheduling) {
    try_real_time_scheduling(communication_thread_, 80);
    if (control_thread_.joinable()) try_real_time_scheduling(control_thread_, 79);
  }
  // The first How, so that how() means something before the first wait.
  if (simulated()) step_simulated_sample();
}

void SampleClock::stop_tasks() {
  if (!running_ || stopped_) return;
  stop_.store(true, std::memory_order_seq_cst);
  ring(comm_bell_);
  ring(control_bell_);
  communication_thread_.join();
  if (control_thread_.joinable()) control_thread_.join();
  stopped_ = true;
}

// ---------------------------------------------------------------------------------------------
// The planning level's waits

void SampleClock::step_simulated_sample() {
  std::lock_guard lock(step_mutex_);
  const std::uint32_t k = ++simulated_ticks_;
  simulated_now_ns_.fetch_add(period_ns_.load(), std::memory_order_relaxed);
  granted_.store(k, std::memory_order_release);
  ring(comm_bell_);
  const auto wait_for_counter = [&](const std::atomic<std::uint32_t>& counter,
                                    std::int64_t deadline) {
    for (;;) {
      const std::uint32_t seen = planning_bell_.load();
      if (reached(counter.load(std::memory_order_acquire), k)) return true;
      if (deadline > 0 && monotonic_ns() >= deadline) return false;
      // No spinning: the two tasks need both processors for the sample this thread waits for.
      wait_while(planning_bell_, seen, deadline, 0);
    }
  };
  wait_for_counter(comm_done_, 0);
  // When the communication task handed this tick to the control task, the tick is over only
  // when the control cycle is: that keeps simulated time deterministic. A control cycle that
  // hangs is left behind; the watchdog ends the session at the next tick.
  if (how_ready_.load(std::memory_order_acquire) == k) {
    wait_for_counter(control_done_, monotonic_ns() + options_.hang_timeout.count() * 1'000'000);
  }
}

void SampleClock::wait_control_idle() const {
  while (control_busy_.load(std::memory_order_seq_cst)) {
    const std::uint32_t seen = planning_bell_.load();
    if (!control_busy_.load(std::memory_order_seq_cst)) break;
    wait_while(planning_bell_, seen, monotonic_ns() + 1'000'000);
  }
}

void SampleClock::wait_tick_done() {
  const std::uint32_t before = comm_done_.load(std::memory_order_acquire);
  const std::int64_t deadline = monotonic_ns() + 4 * period_ns_.load();
  while (comm_done_.load(std::memory_order_acquire) == before && monotonic_ns() < deadline) {
    const std::uint32_t seen = planning_bell_.load();
    if (comm_done_.load(std::memory_order_acquire) != before) break;
    wait_while(planning_bell_, seen, deadline);
  }
}

// ---------------------------------------------------------------------------------------------
// The communication task

void SampleClock::communication_task() noexcept {
  std::int64_t next_deadline = t0_ns_ + period_ns_.load();
  for (std::uint32_t k = 1;; ++k) {
    std::int64_t tick_ns = 0;
    if (!wait_tick(k, next_deadline, tick_ns)) return;
    const std::int64_t started = monotonic_ns();
    tick_started_ns_.store(started, std::memory_order_relaxed);
    watchdog(k, tick_ns);
    if (options_.one_thread) {
      one_thread_tick(k, tick_ns, started);
    } else if (read_robots(k, tick_ns)) {
      if (!hand_over(k, tick_ns, next_deadline)) return;  // stopping
    } else {
      compute_.record(monotonic_ns() - started);  // no control this tick: reading was all
    }
    comm_done_.store(k, std::memory_order_release);
    ring(planning_bell_);
  }
}

bool SampleClock::wait_tick(std::uint32_t k, std::int64_t& next_deadline,
                            std::int64_t& tick_ns) noexcept {
  return simulated() ? wait_granted(k, tick_ns) : sleep_to_deadline(next_deadline, tick_ns);
}

bool SampleClock::wait_granted(std::uint32_t k, std::int64_t& tick_ns) noexcept {
  for (;;) {
    const std::uint32_t seen = comm_bell_.load();
    if (stop_.load(std::memory_order_acquire)) return false;
    if (reached(granted_.load(std::memory_order_acquire), k)) break;
    wait_while(comm_bell_, seen, 0, kSpinNsForGrant);
  }
  tick_ns = simulated_now_ns_.load(std::memory_order_relaxed);
  return true;
}

bool SampleClock::sleep_to_deadline(std::int64_t& next_deadline, std::int64_t& tick_ns) noexcept {
  const std::int64_t deadline = next_deadline;
  const std::int64_t spin_ns = options_.spin_before_tick.count();
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
  if (stop_.load(std::memory_order_acquire)) return false;
  const std::int64_t period = period_ns_.load(std::memory_order_relaxed);
  const std::int64_t late = monotonic_ns() - deadline;
  if (options_.measure_latency) latency_.record(late);
  // A wake-up more than a period late has missed ticks: skip them rather than run a burst.
  const std::int64_t missed = late / period;
  if (missed > 0) latency_.record_missed(static_cast<std::uint64_t>(missed));
  next_deadline = deadline + (missed + 1) * period;
  // The sample's time is its nominal one, a period after the last sample's: the skipped
  // deadlines are not samples, so a stall delays the motions by its length rather than making
  // their next setpoints jump over it (which would exceed the joints' top speeds). Without a
  // stall this is the deadline's own time.
  nominal_ns_ += period;
  tick_ns = nominal_ns_;
  return true;
}

void SampleClock::watchdog(std::uint32_t k, std::int64_t tick_ns) noexcept {
  if (last_published_ == 0) return;
  const std::uint32_t cycle = last_published_;
  last_published_ = 0;
  Stop stop{TerminateCode::overrun, 0};
  if (control_done_.load(std::memory_order_acquire) != cycle) {
    io::format_fixed(stop.detail,
                     "the control cycle of sample {} was still running at the next tick", cycle);
  } else if (simulated()) {
    // Simulated time: the computing a cycle charged with spend() must fit in its period. (In
    // real time the check above is the whole story: the cycle finished before this tick was
    // processed, so its Chg was in time.)
    const std::int64_t period = period_ns_.load(std::memory_order_relaxed);
    const std::int64_t used =
        control_end_ns_.load(std::memory_order_relaxed) - last_published_tick_ns_;
    if (used <= period) return;
    io::format_fixed(stop.detail,
                     "the control cycle of sample {} took {:.3f} ms of a {:.3f} ms period", cycle,
                     static_cast<double>(used) * 1e-6, static_cast<double>(period) * 1e-6);
  } else {
    return;
  }
  for (RobotChannel* r : robots_) r->end_overrun(cycle, k, tick_ns, stop);
}

bool SampleClock::read_robots(std::uint32_t k, std::int64_t tick_ns) noexcept {
  bool handed = false;
  for (RobotChannel* r : robots_) {
    if (r->communication_cycle(k, tick_ns)) handed = true;
  }
  return handed;
}

bool SampleClock::hand_over(std::uint32_t k, std::int64_t tick_ns,
                            std::int64_t next_deadline) noexcept {
  // Hand How over for every robot at once; wait for the Chg their f1s leave (at most until the
  // next tick).
  handed_tick_ns_.store(tick_ns, std::memory_order_relaxed);
  how_ready_.store(k, std::memory_order_release);
  ring(control_bell_);
  last_published_ = k;
  last_published_tick_ns_ = tick_ns;
  const std::int64_t deadline = options_.clock == ClockKind::real_time
                                    ? next_deadline
                                    : monotonic_ns() + options_.hang_timeout.count() * 1'000'000;
  const ChgWait chg = wait_chg(k, deadline);
  if (chg == ChgWait::stopping) return false;
  for (RobotChannel* r : robots_) r->take_chg(k, chg == ChgWait::in_time);
  chg_taken_.store(k, std::memory_order_release);
  ring(control_bell_);
  return true;
}

SampleClock::ChgWait SampleClock::wait_chg(std::uint32_t k, std::int64_t deadline_ns) noexcept {
  for (;;) {
    const std::uint32_t seen = comm_bell_.load();
    if (reached(chg_ready_.load(std::memory_order_acquire), k)) return ChgWait::in_time;
    if (stop_.load(std::memory_order_acquire)) return ChgWait::stopping;
    if (monotonic_ns() >= deadline_ns) return ChgWait::late;
    wait_while(comm_bell_, seen, deadline_ns);
  }
}

void SampleClock::one_thread_tick(std::uint32_t k, std::int64_t tick_ns,
                                  std::int64_t started) noexcept {
  // Busy before the phases are looked at, as control_task() is: release() waits for it.
  control_busy_.store(true, std::memory_order_seq_cst);
  handed_tick_ns_.store(tick_ns, std::memory_order_relaxed);
  bool handed = false;
  std::int64_t spent_ns = 0;
  const std::size_t n = robots_.size();
  for (std::size_t i = 0; i < n; ++i) {
    // The next robot's first lines, while this one is worked on: with hundreds of robots each
    // robot's data, touched once a tick, are rarely in the cache.
    if (i + 1 < n) robots_[i + 1]->prefetch();
    RobotChannel& r = *robots_[i];
    if (!r.communication_cycle(k, tick_ns)) continue;
    if (!handed) {
      handed = true;
      last_published_ = k;
      last_published_tick_ns_ = tick_ns;
      how_ready_.store(k, std::memory_order_release);
    }
    r.run_f1_in_place(k);
    spent_ns += run_f2_and_hook(r, k);
  }
  if (handed) {
    chg_ready_.store(k, std::memory_order_release);
    chg_taken_.store(k, std::memory_order_release);
    end_cycle(k, spent_ns);
  } else {
    compute_.record(monotonic_ns() - started);  // no control this tick: reading was all
  }
  control_busy_.store(false, std::memory_order_seq_cst);
}

// ---------------------------------------------------------------------------------------------
// The control task

void SampleClock::control_task() noexcept {
  std::uint32_t last = 0;
  for (;;) {
    const std::uint32_t seen = control_bell_.load();
    if (stop_.load(std::memory_order_acquire)) return;
    // Busy before looking at the robots' phases, so that release() waiting for !busy after
    // changing a phase cannot miss a cycle that is about to start.
    control_busy_.store(true, std::memory_order_seq_cst);
    const std::uint32_t k = how_ready_.load(std::memory_order_acquire);
    if (k != 0 && k != last) {
      last = k;
      control_cycle(k);
      control_busy_.store(false, std::memory_order_seq_cst);
      ring(planning_bell_);
      continue;
    }
    control_busy_.store(false, std::memory_order_seq_cst);
    wait_while(control_bell_, seen);
  }
}

void SampleClock::control_cycle(std::uint32_t k) noexcept {
  run_f1s(k);
  chg_ready_.store(k, std::memory_order_release);
  ring(comm_bell_);
  for (;;) {
    const std::uint32_t seen = control_bell_.load();
    if (reached(chg_taken_.load(std::memory_order_acquire), k)) break;
    if (stop_.load(std::memory_order_acquire)) return;
    wait_while(control_bell_, seen);
  }
  finish_cycle(k);
}

void SampleClock::run_f1s(std::uint32_t k) noexcept {
  for (RobotChannel* r : robots_) {
    if (r->in_cycle(k)) r->run_f1();
  }
}

void SampleClock::finish_cycle(std::uint32_t k) noexcept {
  std::int64_t spent_ns = 0;
  for (RobotChannel* r : robots_) spent_ns += run_f2_and_hook(*r, k);
  end_cycle(k, spent_ns);
}

std::int64_t SampleClock::run_f2_and_hook(RobotChannel& robot, std::uint32_t k) noexcept {
  if (!robot.in_cycle(k)) return 0;
  const std::int64_t spent_ns = robot.run_f2();
  if (robot_hook_) {
    try {
      robot_hook_(robot.index(), k);
    } catch (...) {
      robot.request_termination(TerminateCode::control_exception, 0);
    }
  }
  return spent_ns;
}

void SampleClock::end_cycle(std::uint32_t k, std::int64_t spent_ns) noexcept {
  if (cycle_hook_) {
    try {
      cycle_hook_(k);
    } catch (...) {
      for (RobotChannel* r : robots_) {
        if (r->in_cycle(k)) r->request_termination(TerminateCode::control_exception, 0);
      }
    }
  }
  const std::int64_t tick_ns = handed_tick_ns_.load(std::memory_order_relaxed);
  const std::int64_t end_ns =
      simulated() ? tick_ns + spent_ns : std::max(monotonic_ns() - t0_ns_, tick_ns);
  control_end_ns_.store(end_ns, std::memory_order_relaxed);
  compute_.record(monotonic_ns() - tick_started_ns_.load(std::memory_order_relaxed));
  control_done_.store(k, std::memory_order_release);  // the watchdog kick
  ring(planning_bell_);
}

}  // namespace rccx::rtc
