// An RTC session (thesis 2.3 and 4.5): open it on a robot's driver, start control with two
// user functions run once per sample, release, control again, close. Two threads serve it,
// as the thesis's two processors did (figure 4.7). The pipeline, one sample in order:
//
//   communication task                          control task
//   1 wait for the tick
//   2 watchdog: did the last control cycle
//     finish within its period?
//   3 each robot due: release()'s requests;
//     read the arm into How; in control,
//     the checks (requests, faults, force
//     sensor, observed limits)
//   4 hand every How over                  ->   5 each robot: copy How, run f1
//   7 each robot: take Chg, turn it into   <-   6 hand every Chg over
//     joint commands and send them; log,
//     tap; publish How
//   8 "Chg taken"; the tick is done        ->   9 each robot: f2 (then the robot hook)
//                                               10 the cycle hook; kick the watchdog (2)
//
// (sample_clock.hpp: 1, 2, 4, 6, 8, 10 and the loops over the robots; robot_channel.hpp: each
// robot's 3, 5, 7, 9, with sample_checks.hpp and joint_commands.hpp. With
// SessionOptions::one_thread, the communication task does 3, 5, 7, 9 robot after robot.)
//
// The tasks exchange How and Chg through sequence counters (acquire/release atomics and futex
// waits): no mutex, no allocation in the sample loop. A termination (limit, fault, overrun,
// Ctrl-C, or a request) leaves the arm holding where it is, or powered down for power and
// communication faults, and is reported to the planning level by the wait functions.
//
// Time is a `ClockKind`: real time (absolute-deadline sleeps, SCHED_FIFO and locked memory when
// allowed), or simulated time, which advances one sample at a time and only while the program
// waits in this class's wait functions, so a simulated run is deterministic and fast.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "rccx/rtc/driver.hpp"
#include "rccx/rtc/latency.hpp"
#include "rccx/rtc/sample_log.hpp"
#include "rccx/rtc/types.hpp"

namespace rccx::rtc {

enum class ClockKind : std::uint8_t {
  simulated,  ///< deterministic; advances only while the program waits in the session
  /// The monotonic clock. A sample's time (How::time_s) is its nominal one, its number of
  /// periods since the start: a wake-up a period or more late skips the deadlines it missed
  /// (counted as missed) but not time, so after a stall the samples' times lag the clock by it.
  real_time,
};

/// The sample periods RTC accepts (the thesis ran 28 and 56 ms; modern controllers 1 ms).
inline constexpr std::chrono::nanoseconds kMinPeriod{250'000};
inline constexpr std::chrono::nanoseconds kMaxPeriod{56'000'000};
/// A POS command without a velocity moves the joint at this fraction of its maximum speed.
inline constexpr double kDefaultSpeedFraction = 0.25;

struct SessionOptions {
  std::chrono::nanoseconds period{std::chrono::milliseconds(10)};  ///< 0.25 ms .. 56 ms
  ClockKind clock = ClockKind::simulated;
  /// Real time only: ask for SCHED_FIFO and mlockall (said once on stderr when not allowed).
  bool real_time_scheduling = true;
  /// Simulated time only: a control cycle still running after this much wall time is taken
  /// as hung and the session ends with `overrun`.
  std::chrono::milliseconds hang_timeout{std::chrono::seconds(5)};
  /// Real time only: record wake-up latency of the communication task.
  bool measure_latency = true;
  /// Real time only: the communication task sleeps until this long before each deadline and
  /// spins the rest (0: sleeps through), so that the wake-up's own latency is hidden when it
  /// is shorter. Costs that much processor time a period.
  std::chrono::nanoseconds spin_before_tick{0};
  /// Both tasks on one thread: the communication task runs each tick's control cycle itself,
  /// robot after robot: it reads one robot, runs its f1 on the How it read, applies its Chg,
  /// runs its f2, then goes on to the next robot (each robot's data are touched once a tick,
  /// while in the cache), and runs the cycle hook after the last. Each robot sees the same
  /// sequence as with two tasks (f2 after its Chg is applied; the cycle hook after every f2);
  /// what differs is only the interleaving between robots, which a control function must not
  /// depend on (it sees no other robot's How or Chg). No hand-over between threads or
  /// processors. For loads of many robots on one core; there is no watchdog then for a control
  /// function that hangs (a cycle longer than the period makes the next ticks late, counted as
  /// missed), so not for real arms.
  bool one_thread = false;
};

/// A misuse of the session or a bad option: says what to do instead.
class SessionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Session;
class RobotChannel;
class SampleClock;

/// What a control function sees: the How of its sample, the Chg it may write, and the
/// session's `terminate` and `rtc_message`.
class Control {
 public:
  [[nodiscard]] const How& how() const noexcept { return how_; }
  [[nodiscard]] Chg& chg() noexcept { return chg_; }
  [[nodiscard]] double period_s() const noexcept { return period_s_; }
  /// Ends the session (the `terminate` variable); the arm holds.
  void terminate(TerminateCode code = TerminateCode::user_request) noexcept;
  /// Sets rtc_message, the text the planning level gets with the termination (truncated to
  /// kMessageCapacity - 1 characters).
  void message(std::string_view text) noexcept;
  /// Charges `d` of computing to this cycle: in simulated time it counts toward the period
  /// (so an overrun can be simulated deterministically); in real time it busy-waits.
  void spend(std::chrono::nanoseconds d) noexcept;

 private:
  friend class RobotChannel;
  How how_;
  Chg chg_;
  double period_s_ = 0.0;
  std::int64_t spent_ns_ = 0;
  RobotChannel* channel_ = nullptr;
  std::array<char, kMessageCapacity> message_{};
};

/// A control function, f1 or f2. It must return within the sample period; it may throw (the
/// session ends with `control_exception`) but should not.
using ControlFunction = std::function<void(Control&)>;

class SessionGroup;

class Session {
 public:
  /// rtc_open: starts the communication task (the arm is read every period from now on) and
  /// the idle control task. Throws SessionError for a period outside [kMinPeriod, kMaxPeriod].
  Session(Driver& driver, SessionOptions options = {});
  /// rtc_close without powering down.
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// rtc_control: starts calling f1 and f2 every sample, from the next sample on; returns at
  /// once. Either may be empty. Throws SessionError when control is already active.
  void control(ControlFunction f1, ControlFunction f2);
  /// rtc_release: stops control (the arm holds) and returns how it ended (`code` none if it
  /// was still running). Control may be started again after it.
  Termination release(bool power_off = false);
  /// rtc_close: releases, stops both tasks (a session of a group: only this robot's control;
  /// the group's tasks stop with the group), and puts RCCX_LOG's log in place. Called by the
  /// destructor.
  void close(bool power_off = false);
  /// After close(): empty when RCCX_LOG's log (if any) is complete, else what went wrong (a
  /// write that failed, rows dropped), already said on stderr.
  [[nodiscard]] const std::string& log_problem() const noexcept { return log_problem_; }

  /// Ends the session from the planning level (the `terminate` variable).
  void terminate(TerminateCode code = TerminateCode::user_request) noexcept;

  /// Lets `d` of time pass (in simulated time: runs those samples). Returns the termination
  /// if control ended meanwhile (or before), an empty one otherwise. Every wait function ends
  /// within a period when SIGINT or SIGTERM arrives (rccx::io::stop_count() changes). In a
  /// group, simulated time is the group's: every robot of it moves on with the wait.
  Termination wait_for(std::chrono::nanoseconds d);
  /// Waits until control ends or `timeout` passes; returns the termination (code none on
  /// timeout).
  Termination wait_terminated(std::chrono::nanoseconds timeout);
  /// Waits until `done(how)` holds for a sample's How, control ends, or `timeout` passes.
  /// True when the condition held.
  bool wait_until(const std::function<bool(const How&)>& done, std::chrono::nanoseconds timeout);

  /// The last How the communication task read (copied; safe from the planning level).
  [[nodiscard]] How how() const;
  [[nodiscard]] bool controlling() const noexcept;
  /// The termination of the present or last control session (code none while it runs).
  [[nodiscard]] Termination termination() const;
  /// The terminate code once control has ended, else none: lock-free, for the sample loop (a
  /// cell's checks between robots).
  [[nodiscard]] TerminateCode ended_code() const noexcept;
  /// This robot's sample period: the clock's period times its multiple (see SessionGroup).
  [[nodiscard]] std::chrono::nanoseconds period() const noexcept;
  /// Changes the sample period; only while control is not active, and not in a group.
  void set_period(std::chrono::nanoseconds period);
  [[nodiscard]] ClockKind clock() const noexcept;
  [[nodiscard]] Driver& driver() noexcept { return driver_; }
  /// The robot's name: its model's alone, in a group the name add() gave it. What its log's
  /// header and, in a group, its RCCX_LOG file are named by.
  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  /// Records every controlled sample to `log` (commanded and measured joints, the commanded
  /// tool pose); nullptr stops. Only while not in control. Without a call, a session logs to
  /// the file named by the environment variable RCCX_LOG, if any (a robot of a group: that
  /// name with "-<name()>" before the extension).
  void set_log(SampleLog* log);
  /// Calls `tap` every controlled sample from the communication task (the view's tap, see
  /// SampleTap); nullptr stops. Any time, from the planning level: a tap set while in control
  /// sees the next sample; set_tap(nullptr) returns once the communication task is out of the
  /// last call, so the tap may be destroyed then. One tap a session.
  void set_tap(SampleTap* tap) noexcept;
  /// Wake-up latency of the communication task (real time only).
  [[nodiscard]] LatencyStats latency() const;
  /// Computing time of each tick (SessionGroup::compute(): the clock's, shared by its robots).
  [[nodiscard]] LatencyStats compute() const;

  /// user_hangup: replaces what Ctrl-C does during control (default: terminate with
  /// user_interrupt). Runs on a helper thread, not in the sample loop.
  void set_hangup_handler(std::function<void(Session&)> handler);
  /// Called by the hang-up watcher thread.
  void hangup();

 private:
  friend class SessionGroup;

  /// A robot of a group, `name`d: sampled every `multiple`-th tick of `clock`.
  Session(Driver& driver, std::shared_ptr<SampleClock> clock, int multiple,
          const std::string& name);
  void open_channel(int multiple, const std::string& name, const std::string& log_suffix);
  void check_period(std::chrono::nanoseconds p) const;

  Driver& driver_;
  std::string name_;
  std::shared_ptr<SampleClock> clock_;
  bool owns_clock_ = false;
  std::unique_ptr<SampleLog> environment_log_;  ///< RCCX_LOG's, when set
  std::unique_ptr<RobotChannel> channel_;       ///< this robot's side of the sample loop
  std::function<void(Session&)> hangup_handler_;
  std::string log_problem_;
  bool closed_ = false;
};

/// Several robots on one clock (the workcell, thesis 5.2): one communication task and one
/// control task sample every robot of the group at the same ticks, whatever their number. A
/// robot may be sampled every k-th tick (the Microbo at 28 ms beside a PUMA at 7 ms: a 7 ms
/// clock, multiples 4 and 1). Each robot has its own Session, with its own How / Chg, control
/// functions, limits, faults and termination: one robot's fault ends that robot's control
/// only. The control functions of all robots due at a tick run one after the other within
/// that tick's period; the watchdog ends the control of every robot of a cycle that overruns.
///
///   rtc::SessionGroup group({.period = 7ms});
///   rtc::Session& puma = group.add(puma_driver);
///   rtc::Session& microbo = group.add(microbo_driver, 4);
///   group.start();                 // the two tasks; then control() each as usual
class SessionGroup {
 public:
  /// `options`: the clock (its period is the base period, simulated or real time).
  explicit SessionGroup(SessionOptions options = {});
  /// Stops the tasks (every robot's control released first).
  ~SessionGroup();
  SessionGroup(const SessionGroup&) = delete;
  SessionGroup& operator=(const SessionGroup&) = delete;

  /// Adds a robot sampled every `multiple`-th tick (1 .. 1000), called `name` (a cell's name
  /// for it; empty: its model's name, numbered -2, -3 ... when the group has one of that name
  /// already). Only before start(). Throws SessionError for a period its driver cannot serve
  /// or a `name` given twice. With RCCX_LOG=FILE set, its log is FILE with "-<name>" before
  /// the extension (RCCX_LOG=run.csv: run-left.csv, run-right.csv), one file a robot.
  Session& add(Driver& driver, int multiple = 1, std::string_view name = {});
  /// Starts the communication and control tasks; robots are read every tick from now on.
  void start();
  [[nodiscard]] std::size_t size() const noexcept { return sessions_.size(); }
  [[nodiscard]] Session& operator[](std::size_t i) { return *sessions_.at(i); }
  /// The base period of the clock.
  [[nodiscard]] std::chrono::nanoseconds period() const noexcept;
  [[nodiscard]] LatencyStats latency() const;
  /// Computing time of each tick, wall clock (simulated or real time): from the communication
  /// task's wake-up to the end of the tick's control cycle (every robot read, checked, f1 and
  /// f2 run, commands sent). `wakeups` counts the ticks; `missed_deadlines` stays 0.
  [[nodiscard]] LatencyStats compute() const;
  /// Simulated time: lets `d` pass for every robot (control of each goes on as it is).
  void wait_for(std::chrono::nanoseconds d);
  /// A function the control task runs after the f2 of every robot due at a tick, with that
  /// tick's number (the cell's checks between robots: every robot's next setpoint is known
  /// then). Only before start(). Like f1 and f2 it must not block; an exception it throws ends
  /// the control of every robot of the tick with `control_exception`.
  void set_cycle_hook(std::function<void(std::uint32_t tick)> hook);
  /// A function the control task runs right after each robot's f2, with the robot's index (the
  /// order of add()) and the tick, while that robot's data are still in the processor's cache:
  /// per-robot work of the cycle hook (a cell's forward kinematics and capsules). What it
  /// computes must not be seen by the other robots' control functions before the cycle hook
  /// (the f2s after it in the tick would otherwise see this tick's values). Only before
  /// start(); it must not block or throw (an exception ends that robot's control with
  /// `control_exception`).
  void set_robot_hook(std::function<void(std::size_t robot, std::uint32_t tick)> hook);

 private:
  std::string unique_name(const Driver& driver, std::string_view name) const;

  std::shared_ptr<SampleClock> clock_;
  std::vector<std::unique_ptr<Session>> sessions_;
};

}  // namespace rccx::rtc
