// The clock of one RTC session, or of a group of them: the time (simulated or real), the two
// tasks of thesis figure 4.7 (communication and control), their hand-overs through tick counters
// and doorbells, and the watchdog. Each tick it runs every robot's channel (robot_channel.hpp)
// due at it: one set of hand-overs a tick whatever the number of robots. The pipeline of one
// sample, step by step, is in session.hpp; Session and SessionGroup are its planning level.
//
//   auto clock = std::make_shared<rtc::SampleClock>(options);
//   clock->add(channel);            // each robot, before start()
//   clock->start();                 // the two tasks; robots are read every tick from now on
//   clock->step_simulated_sample(); // planning level, simulated time: one tick runs
//   clock->stop_tasks();
//
// The tasks never allocate, lock or throw; the planning level's calls may (start, add).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "rccx/rtc/doorbell.hpp"
#include "rccx/rtc/latency.hpp"
#include "rccx/rtc/session.hpp"

namespace rccx::rtc {

class RobotChannel;

class SampleClock {
 public:
  explicit SampleClock(const SessionOptions& options);
  SampleClock(const SampleClock&) = delete;
  SampleClock& operator=(const SampleClock&) = delete;

  // Setting up, planning level: robots and hooks before start() (see SessionGroup).
  void add(RobotChannel& robot);
  [[nodiscard]] std::size_t size() const noexcept { return robots_.size(); }
  void set_cycle_hook(std::function<void(std::uint32_t)> hook);
  void set_robot_hook(std::function<void(std::size_t, std::uint32_t)> hook);
  /// Starts both tasks (one with SessionOptions::one_thread); in simulated time runs the first
  /// tick, so that a How is there at once.
  void start();
  /// Stops and joins the tasks (once).
  void stop_tasks();
  [[nodiscard]] bool running() const noexcept { return running_; }
  [[nodiscard]] bool stopped() const noexcept { return stopped_; }

  // Time.
  [[nodiscard]] const SessionOptions& options() const noexcept { return options_; }
  [[nodiscard]] bool simulated() const noexcept { return options_.clock == ClockKind::simulated; }
  [[nodiscard]] bool one_thread() const noexcept { return options_.one_thread; }
  /// The base period, ns.
  [[nodiscard]] std::int64_t period_ns() const noexcept { return period_ns_.load(); }
  void set_period_ns(std::int64_t ns) noexcept { period_ns_ = ns; }
  /// Simulated time: the present tick's time, ns since the start.
  [[nodiscard]] std::int64_t simulated_now_ns() const noexcept { return simulated_now_ns_.load(); }
  [[nodiscard]] LatencyStats latency() const { return latency_.stats(); }
  [[nodiscard]] LatencyStats compute() const { return compute_.stats(); }

  // The planning level's waits.
  /// Simulated time: one tick runs, to the end of its control cycle (or the hang timeout).
  void step_simulated_sample();
  /// Returns once the control task is out of its cycle (release and control wait for that).
  void wait_control_idle() const;
  /// Real time: waits until the communication task has finished a tick (at most 4 periods).
  void wait_tick_done();
  /// The planning doorbell: read it, check a condition, then wait while it shows what was read.
  [[nodiscard]] std::uint32_t planning_rings() const noexcept { return planning_bell_.load(); }
  void wait_planning(std::uint32_t seen, std::int64_t deadline_ns) const noexcept {
    detail::wait_while(planning_bell_, seen, deadline_ns);
  }

  // Doorbells a robot's channel rings after changing what that party watches.
  void ring_communication() noexcept { detail::ring(comm_bell_); }
  void ring_control() noexcept { detail::ring(control_bell_); }
  void ring_planning() noexcept { detail::ring(planning_bell_); }

 private:
  // The communication task: wait for the tick, the watchdog, every robot read and checked, How
  // handed over, the Chg taken.
  void communication_task() noexcept;
  /// Waits for tick k; its time, ns since the start, into `tick_ns`. False when stopping.
  bool wait_tick(std::uint32_t k, std::int64_t& next_deadline, std::int64_t& tick_ns) noexcept;
  /// Simulated time: until the planning level grants tick k.
  bool wait_granted(std::uint32_t k, std::int64_t& tick_ns) noexcept;
  /// Real time: until `next_deadline` (monotonic), which it moves on past any missed ticks.
  bool sleep_to_deadline(std::int64_t& next_deadline, std::int64_t& tick_ns) noexcept;
  /// The control cycle of the last tick must have finished within its period; when it did not,
  /// every robot whose functions ran in it ends with `overrun`.
  void watchdog(std::uint32_t k, std::int64_t tick_ns) noexcept;
  /// Every robot's communication cycle at tick k; true when one handed its How over.
  bool read_robots(std::uint32_t k, std::int64_t tick_ns) noexcept;
  /// Two tasks: every How of tick k to the control task; false when the tasks are stopping.
  bool hand_over(std::uint32_t k, std::int64_t tick_ns, std::int64_t next_deadline) noexcept;
  enum class ChgWait : std::uint8_t { in_time, late, stopping };
  /// Waits for the Chg of tick k's f1s until `deadline_ns` (monotonic).
  ChgWait wait_chg(std::uint32_t k, std::int64_t deadline_ns) noexcept;
  /// One thread: tick k, robot after robot (see SessionOptions::one_thread).
  void one_thread_tick(std::uint32_t k, std::int64_t tick_ns, std::int64_t started) noexcept;

  // The control task: every f1, hand Chg over, every f2 and the hooks, the watchdog kick.
  void control_task() noexcept;
  void control_cycle(std::uint32_t k) noexcept;
  void run_f1s(std::uint32_t k) noexcept;
  void finish_cycle(std::uint32_t k) noexcept;
  /// f2 and the robot hook of `robot` when its control runs in tick k; what f2 spent.
  std::int64_t run_f2_and_hook(RobotChannel& robot, std::uint32_t k) noexcept;
  /// After every f2 of tick k (`spent_ns` charged by them): the cycle hook, the watchdog kick.
  void end_cycle(std::uint32_t k, std::int64_t spent_ns) noexcept;

  SessionOptions options_;
  std::atomic<std::int64_t> period_ns_{0};
  std::int64_t t0_ns_ = 0;  ///< real time: the monotonic time the clock started

  // Doorbells: each party sleeps on its own, the others ring it after changing what it watches.
  detail::Doorbell comm_bell_;
  detail::Doorbell control_bell_;
  mutable detail::Doorbell planning_bell_;

  // Tick numbers (the first tick is 1; 0 is "none"), one counter per hand-over of figure 4.7.
  std::atomic<std::uint32_t> granted_{0};    ///< simulated time: ticks the planning level let run
  std::atomic<std::uint32_t> how_ready_{0};  ///< comm -> control: How of this tick handed over
  std::atomic<std::uint32_t> chg_ready_{0};  ///< control -> comm: Chg after every f1 is there
  std::atomic<std::uint32_t> chg_taken_{0};  ///< comm -> control: Chg copied, control goes on
  std::atomic<std::uint32_t> control_done_{0};   ///< control finished every f2: the watchdog kick
  std::atomic<std::uint32_t> comm_done_{0};      ///< comm finished its cycle
  std::atomic<std::int64_t> handed_tick_ns_{0};  ///< clock time of the tick handed to control
  std::atomic<std::int64_t> control_end_ns_{0};  ///< clock time the last control cycle ended
  std::atomic<std::int64_t> simulated_now_ns_{0};
  std::atomic<bool> control_busy_{false};
  std::atomic<bool> stop_{false};
  LatencyHistogram latency_;
  LatencyHistogram compute_;  ///< each tick: its start to the end of its control cycle
  std::atomic<std::int64_t> tick_started_ns_{0};  ///< monotonic: the communication task woke

  std::vector<RobotChannel*> robots_;              ///< fixed once the tasks run
  std::function<void(std::uint32_t)> cycle_hook_;  ///< after every f2 of a tick (a group's)
  std::function<void(std::size_t, std::uint32_t)> robot_hook_;  ///< after each robot's f2
  std::thread communication_thread_;
  std::thread control_thread_;
  bool running_ = false;
  bool stopped_ = false;

  // Planning side: one thread at a time steps simulated time.
  std::mutex step_mutex_;
  std::uint32_t simulated_ticks_ = 0;

  // The communication task's own.
  std::uint32_t last_published_ = 0;  ///< last tick handed to control
  std::int64_t nominal_ns_ = 0;       ///< real time: the last sample's time (see wait_tick)
  std::int64_t last_published_tick_ns_ = 0;
};

}  // namespace rccx::rtc
