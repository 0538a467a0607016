// One robot's side of RTC: what the planning level, the communication task and the control task
// exchange for it (its phase, How and Chg, requests, termination), the communication task's
// cycle for it (read the arm, check, hand How over; take Chg, turn it into joint commands, log),
// its f1 and f2, and the end of its control. The clock (sample_clock.hpp) calls these for every
// robot due at a tick, and only these; the channel reaches the arm through its Driver, which the
// tests replace by fakes. The pipeline of one sample, step by step, is in session.hpp.
//
//   RobotChannel robot(driver, clock, multiple, index, log);   // a Session owns one
//   robot.prepare_control(f1, f2, false);  robot.begin_control();   // planning level
//   // communication task, tick k:
//   if (robot.communication_cycle(k, tick_ns)) { /* the clock hands How over */ }
//   robot.run_f1();                        // control task, robot.in_cycle(k)
//   robot.take_chg(k, true);               // communication task: joint commands sent
//   robot.run_f2();                        // control task
//   Termination t = robot.release();       // planning level
//
// The cycle calls never allocate, lock or throw; the planning level's may.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>

#include "rccx/rtc/driver.hpp"
#include "rccx/rtc/joint_commands.hpp"
#include "rccx/rtc/latest.hpp"
#include "rccx/rtc/sample_checks.hpp"
#include "rccx/rtc/sample_log.hpp"
#include "rccx/rtc/session.hpp"
#include "rccx/rtc/types.hpp"

namespace rccx::rtc {

class SampleClock;

class RobotChannel {
 public:
  /// The robot of `driver`, sampled every `multiple`-th tick of `clock`, `index`-th of it (the
  /// robot hook's number), logging to `log` (may be null).
  RobotChannel(Driver& driver, SampleClock& clock, int multiple, std::size_t index, SampleLog* log);
  RobotChannel(const RobotChannel&) = delete;
  RobotChannel& operator=(const RobotChannel&) = delete;

  [[nodiscard]] Driver& driver() noexcept { return driver_; }
  [[nodiscard]] int multiple() const noexcept { return multiple_; }
  [[nodiscard]] std::size_t index() const noexcept { return index_; }
  /// The clock's period times the multiple.
  [[nodiscard]] std::chrono::nanoseconds period() const noexcept;
  [[nodiscard]] bool simulated() const noexcept;

  // The planning level (Session).
  /// control(), before the hang-up registration: throws SessionError while control is active
  /// or ended without release(); waits for the control task to be idle; new f1 and f2, Chg and
  /// message; the communication task starts its state afresh at the next tick.
  void prepare_control(ControlFunction f1, ControlFunction f2, bool user_hangup);
  /// control(), after it: control runs from the next tick on.
  void begin_control() noexcept;
  /// Stops control (or takes the end the communication task wrote) and returns the termination
  /// (code none when control was still running); the phase is idle after it.
  Termination release();
  /// The arm holds (and powers off) at the next tick, whether or not the robot is due then.
  void request_hold(bool power_off) noexcept;
  /// The `terminate` variable: the communication task ends control at its next tick.
  void request_termination(TerminateCode code, int joint) noexcept;
  [[nodiscard]] bool controlling() const noexcept;
  [[nodiscard]] bool ended() const noexcept;
  [[nodiscard]] TerminateCode ended_code() const noexcept;
  /// The termination once control ended (with rtc_message), else an empty one.
  [[nodiscard]] Termination termination() const;
  [[nodiscard]] How how() const;
  void set_log(SampleLog* log) noexcept { log_.store(log, std::memory_order_release); }
  void set_tap(SampleTap* tap) noexcept;

  // The communication task.
  /// Tick k: release()'s requests carried out; when due, the arm read and, in control, checked
  /// and How left for the control task (true: the clock is to hand it over).
  bool communication_cycle(std::uint32_t k, std::int64_t tick_ns) noexcept;
  /// Two tasks, after tick k's f1s (`in_time`, else control ends with overrun): this robot's
  /// Chg into joint commands, then its How published.
  void take_chg(std::uint32_t k, bool in_time) noexcept;
  /// The watchdog at tick k (`tick_ns`): ends control with `stop` when it ran in tick `cycle`.
  void end_overrun(std::uint32_t cycle, std::uint32_t k, std::int64_t tick_ns,
                   const Stop& stop) noexcept;
  /// Asks the processor for the lines the next cycle of this robot touches first.
  void prefetch() const noexcept;

  // The control task.
  /// This robot's control runs in tick k.
  [[nodiscard]] bool in_cycle(std::uint32_t k) const noexcept;
  /// f1 on the How handed over; its Chg left for the communication task.
  void run_f1() noexcept;
  /// One thread, tick k: f1 on the communication task's How and its Chg into joint commands at
  /// once (no copies between the tasks), then How published.
  void run_f1_in_place(std::uint32_t k) noexcept;
  /// f2 (the Chg's commands cleared first); returns the computing it charged with spend(), ns.
  std::int64_t run_f2() noexcept;

 private:
  friend class Control;
  // Who owns the robot: planning sets idle -> controlling and back to idle; the communication
  // task sets controlling -> ending -> ended when it terminates control.
  enum Phase : std::uint32_t { kIdle, kControlling, kEnding, kEnded };
  // Requests from release(), carried out by the communication task at its next tick.
  enum Pending : std::uint32_t { kPendingHold = 1, kPendingPowerOff = 2 };

  // The communication task's own.
  struct Comm {
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

  // Steps of the communication cycle.
  [[nodiscard]] bool due(std::uint32_t k) const noexcept;
  void carry_out_pending() noexcept;
  void read_arm(std::uint32_t k, std::int64_t tick_ns) noexcept;
  bool controlled_cycle(std::uint32_t k) noexcept;
  void start_afresh_if_new() noexcept;
  [[nodiscard]] std::optional<Stop> first_stop() noexcept;
  void hand_how_over(std::uint32_t k) noexcept;
  [[nodiscard]] bool still_controlling() const noexcept;
  /// comm_.chg into the arm's requests and joint commands, then the log and the tap.
  void apply_taken() noexcept;
  /// Power, hand, zero gravity, a setting, outputs; false when control ended (power failed).
  bool apply_requests(const Chg& chg) noexcept;
  void log_sample() noexcept;
  void tap_sample() noexcept;
  void end(const Stop& stop) noexcept;
  void run_f1_on(const How& how) noexcept;
  void run_guarded(ControlFunction& f) noexcept;
  [[nodiscard]] Termination ended_termination() const;

  // What every tick reads, fixed at opening.
  Driver& driver_;
  SampleClock& clock_;
  int multiple_ = 1;
  std::size_t index_ = 0;

  // Hot first: what every tick touches (the flags, the communication task's How and Chg, the
  // control task's), then what the planning level reads.
  std::atomic<std::uint32_t> phase_{kIdle};
  std::atomic<std::uint32_t> generation_{0};  ///< bumped by control(): comm resets its state
  std::atomic<std::uint32_t> pending_{0};
  std::atomic<std::uint32_t> in_cycle_{0};  ///< the tick whose control cycle includes this robot
  std::atomic<bool> user_hangup_{false};
  std::atomic<std::int32_t> requested_code_{0};
  std::atomic<std::int32_t> requested_joint_{0};
  std::atomic<SampleLog*> log_{nullptr};
  std::atomic<SampleTap*> tap_{nullptr};
  std::atomic<bool> tap_busy_{false};  ///< the communication task is in (or about to call) tap_

  // Each task's own on lines of their own (with two tasks they run on two processors).
  alignas(64) Comm comm_;        ///< the communication task's own
  alignas(64) Control control_;  ///< the control task's own
  ControlFunction f1_, f2_;      ///< the control task's (set by the planning level while idle)
  How how_;                      ///< two tasks: guarded by the clock's how_ready / the next tick
  Chg chg_;                      ///< two tasks: guarded by the clock's chg_ready / chg_taken
  mutable detail::Latest<How> latest_;
  Termination termination_;  ///< written while kEnding, read once kEnded

  mutable std::mutex snapshot_mutex_;  ///< planning side only
  mutable How snapshot_;
};

}  // namespace rccx::rtc
