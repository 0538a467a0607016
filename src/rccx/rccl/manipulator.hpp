// The RCCL of one arm (thesis 2.4): the planning level's motion calls over an RTC session whose
// control function is the trajectory generator.
//
//   rccl::Manipulator arm(session);            // rccl_open: the session is open already
//   arm.start();                               // rccl_control: the generator runs every sample
//   arm.set_velocity(0.1, 100_deg);            // setvel: m/s, rad/s
//   auto m = arm.move(arm.park());             // queues a request and returns at once
//   arm.waitfor(m.end());                      // waitfor(park->end)
//   arm.set_mode(rccl::Mode::cartesian);       // setmod('c')
//   for (auto& p : corners) arm.move(p);       // transitions join the queued segments
//   arm.waitfor(arm.completed());              // waitfor(completed)
//   arm.wait_for(500ms);                       // let time pass (simulated: run the samples)
//
// Waiting, as on rtc::Session and cell::Cell: `waitfor(event)` (RCCL's word) waits for a motion
// event, `wait_for(duration)` (std's) lets time pass; the other spelling with the other
// argument compiles with a deprecation warning naming the right one.
//
// Requests reach the sample loop through a lock-free queue; events (start, end, failure) come
// back the same way. Waiting lets simulated time run, so a simulated program is deterministic.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/arm.hpp"
#include "rccx/rccl/force_control.hpp"
#include "rccx/rccl/trajectory.hpp"
#include "rccx/rtc/session.hpp"

namespace rccx::rccl {

/// A motion that cannot be queued: a goal known now to be out of reach or out of limits, a full
/// queue, a setting out of range, or a call before start(). Nothing was queued or changed.
class MotionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throw MotionError, saying what is wrong, for a guard or a compliance that cannot be used.
void check_guard(const ForceGuard& guard);
void check_compliance(const Compliance& compliance);

class Manipulator : public Arm {
 public:
  /// The arm of `session` (its driver's robot), with its own kinematics solver.
  explicit Manipulator(rtc::Session& session);
  /// Stops control when it was started here.
  ~Manipulator() override;
  Manipulator(const Manipulator&) = delete;
  Manipulator& operator=(const Manipulator&) = delete;

  /// rccl_control: the trajectory generator becomes the session's control function (f2),
  /// starting at rest where the arm stands. Throws rtc::SessionError when control is active.
  void start();
  /// Stops the generator (rtc release); the arm holds. Returns how control ended.
  rtc::Termination stop_control();

  // --- Settings for the motions queued from now on --------------------------------------------
  void set_mode(Mode mode) override { settings_.mode = mode; }
  /// setvel: tool translation (m/s) and rotation (rad/s) speeds, both > 0.
  void set_velocity(double translation_m_per_s, double rotation_rad_per_s) override;
  /// settime: segment duration (s; 0 = from the speeds) and transition time (s, > 0).
  void set_segment_time(double seconds) override;
  void set_transition_time(double seconds) override;
  /// The configuration to reach the next goals in ("lun", "n" ...); empty keeps the present one.
  void set_configuration(std::string_view name) override;
  [[nodiscard]] const MotionSettings& settings() const noexcept override { return settings_; }

  // --- Force (a robot with a wrist sensor: How::force.present) --------------------------------
  /// The motions queued from now on end, as nextmove ends them, when the force the tool exerts
  /// passes the guard's threshold (ForceGuard: along a tool axis, or its magnitude); contact()
  /// then says where. ForceGuard{} (kind none) turns it off. Throws MotionError for a bad
  /// threshold or axis.
  void set_guard(const ForceGuard& guard) override;
  /// RCCL's comply / lock for the motions queued from now on: the compliant tool axes yield by
  /// the admittance of `compliance`; Compliance{} locks them all again. Throws MotionError for
  /// a setting out of range.
  void set_compliance(const Compliance& compliance) override;
  /// The tool's load for gravity compensation (force::ToolLoad: the sensor's bias, the tool's
  /// mass and centre of mass in T6; tool_calibration.hpp measures it), and the robot base's
  /// orientation in the world (gravity along world -z; identity: the base stands upright).
  void set_tool_load(const force::ToolLoad& load) noexcept { force_.set_tool_load(load); }
  void set_world_from_base(const math::Rot3& r) noexcept { force_.set_world_from_base(r); }
  /// Where guarded motion `m` touched, once it has ended (nullopt when its guard did not trip).
  [[nodiscard]] std::optional<Contact> contact(const Motion& m) const noexcept;
  /// RCCL's update with the contact's T6: sets transform `x` of `position` (a hold or constant
  /// one, not T6) to the value that makes the equation hold where motion `m` touched - the
  /// world model learns where the surface is. Throws MotionError without a contact.
  void update_from_contact(const Motion& m, const TransformPtr& x, const PositionPtr& position);

  // --- Motions ----------------------------------------------------------------------------------
  /// Queues a motion to `position` and returns at once. The goal is checked now (a position
  /// with functional transforms at their present value): throws MotionError (queuing nothing)
  /// when it cannot be reached within limits in the configuration the motion will use - the
  /// one asked for with set_configuration() in joint mode, else the one the arm will be in when
  /// the motion starts (a Cartesian line keeps it) - saying which configurations do reach it.
  /// A joint move with no configuration asked whose goal the present configuration cannot
  /// reach moves into the configuration whose solution lies nearest the arm's joints. A
  /// moving goal (functional transforms) whose motion waits for events (`when`) is refused
  /// now only when the check does not depend on where it is: out of reach now, it is judged
  /// when the motion starts, which then fails with the reason if it is still out of reach.
  /// `when`: the motion starts only once those events (other robots' motions, see
  /// cell::Cell::event) have happened, or with the others of a rendezvous; it then starts from rest
  /// (the motion before it comes to rest first unless its gates are open by then) and is cancelled
  /// with the reason when a gate cannot open.
  Motion move(const PositionPtr& position, const StartWhen& when = {}) override;
  /// Called by each move() that queued a motion (after it did; not by dwell), with the motion
  /// and its position, on the thread that called move() - never from the sample loop. What
  /// rccx::view::Server::attach shows the goals of the running equations with. One observer: a
  /// new one replaces the last, {} removes it. Must not throw (the motion is queued already).
  using MoveObserver = std::function<void(const Motion&, const PositionPtr&)>;
  void set_move_observer(MoveObserver observer) { move_observer_ = std::move(observer); }
  /// RCCL's stop(): stay where the previous motion ends for `seconds` (gated as move()).
  Motion dwell(double seconds, const StartWhen& when = {}) override;
  /// Stops smoothly where the arm is and cancels everything queued.
  void halt() override;
  /// Zero gravity ("marsh"): on, the generator stops commanding and the joints follow a push
  /// and stay; off, the generator starts again at rest where the arm was left. Only with
  /// nothing queued or moving (MotionError otherwise). Takes effect at the next sample.
  void set_zero_gravity(bool on);
  [[nodiscard]] bool zero_gravity() const noexcept { return zero_gravity_; }
  /// Closes (true) or opens the hand, at the next sample.
  void set_hand(bool closed) noexcept override;
  /// A joint controller setting (the Microbo's, e.g. Setting::examine to read its motor
  /// parameters into How), sent with the next sample.
  void send_setting(const rtc::SettingChg& setting) noexcept { setting_request_.store(setting); }
  /// The robot's park position (its ready pose, in joints).
  [[nodiscard]] const PositionPtr& park() const noexcept override { return park_; }

  // --- Synchronisation --------------------------------------------------------------------------
  /// Waits for `event` (in simulated time: runs the samples until then).
  WaitResult waitfor(const Event& event,
                     std::chrono::nanoseconds timeout = std::chrono::hours(24 * 365)) override;
  [[deprecated("wait_for lets time pass; wait for an event with waitfor(event)")]] WaitResult
  wait_for(const Event& event, std::chrono::nanoseconds timeout = std::chrono::hours(24 * 365)) {
    return waitfor(event, timeout);
  }
  /// Lets `d` pass (the session's wait_for: in simulated time, runs those samples). Returns
  /// the session's termination if control ended meanwhile, an empty one otherwise.
  rtc::Termination wait_for(std::chrono::nanoseconds d) override;
  [[deprecated(
      "waitfor waits for an event; let time pass with wait_for(duration)")]] rtc::Termination
  waitfor(std::chrono::nanoseconds d) {
    return wait_for(d);
  }
  /// True when `event` has happened.
  [[nodiscard]] bool happened(const Event& event) const noexcept override;
  /// An event of this arm as another arm's motion may wait for it (StartWhen::after), read
  /// from the generator as it runs: a motion of another robot stepped later in the same tick
  /// sees it in that tick. (A cell's Cell::event reads a copy made after each tick instead, so
  /// the order of the robots does not matter.) motion_start, motion_end and completed (the
  /// last motion queued so far); throws MotionError for position_end.
  [[nodiscard]] EventGate gate(const Event& event) const;

  // --- What happened ----------------------------------------------------------------------------
  /// Failures and cancellations so far (collected from the generator's events).
  [[nodiscard]] const std::vector<MotionEvent>& failures() override;
  /// Every event the generator sent since the last call (started, ended, failed, cancelled).
  std::vector<MotionEvent> take_events() override;
  /// How motion `m` followed its path (once it has ended).
  [[nodiscard]] SegmentReport report(const Motion& m) const noexcept override {
    return generator_->report(m.id);
  }
  [[nodiscard]] std::uint64_t last_queued() const noexcept override { return next_id_ - 1; }

  [[nodiscard]] rtc::Session& session() noexcept { return session_; }
  [[nodiscard]] const kin::Kinematics& kinematics() const noexcept override { return *kinematics_; }
  [[nodiscard]] TrajectoryGenerator& generator() noexcept { return *generator_; }

 private:
  // --- Loop side: f2, one sample, in the order it runs; nothing allocates, locks or throws
  // except what a functional transform's function throws in the generator's step. ----------
  /// The control function: the setpoint of this sample (rad / m) from the generator, the force
  /// side's correction, written into the Chg with the planning level's requests.
  void run_sample(rtc::Control& c);
  /// Hands the planning level's one-shot requests (hand, joint setting, zero gravity) to this
  /// sample's Chg; `measured` (rad / m) and `t_set` (s) restart the generator when zero gravity
  /// ends. True when the arm is limp (zero gravity): nothing is commanded this sample.
  bool forward_requests(rtc::Control& c, const kin::JointVector& measured, double t_set) noexcept;
  /// The generator's setpoint q (rad / m) for time `t_set` (s); returns the motion's id (0 at
  /// rest). Passes on what a functional transform's function throws (the session then ends
  /// control with control_exception), hence not noexcept.
  std::uint64_t step_generator(const rtc::How& h, const kin::JointVector& measured, double t_set,
                               kin::JointVector& q);
  /// Guards and compliance on q for motion `id`: a contact ends the motion (nextmove), an
  /// overload or an unreachable offset stops it.
  void apply_force(const rtc::How& h, std::uint64_t id, double period_s,
                   kin::JointVector& q) noexcept;
  /// q (rad / m) as POSVEL range values, and the motion id as the sample's segment.
  void write_setpoints(rtc::Control& c, const kin::JointVector& q, std::uint64_t id) noexcept;

  /// `configuration` >= 0: the configuration this motion moves into (chosen for it).
  Motion submit(MotionRequest r, const PositionPtr& keep, const StartWhen& when,
                std::int16_t configuration = -1);
  void drain();
  /// Refuses (MotionError) a goal the motion cannot reach. Returns the configuration a joint
  /// move with none asked must take (the present one cannot reach the goal), else -1.
  /// `starts_later`: a moving goal whose motion waits for other robots' events; where it is now
  /// says little about where it will be when the motion starts, so a goal out of reach now is
  /// left to the generator, which judges it at the start (the motion fails then, saying why).
  std::int16_t check_reachable(const Position& p, bool starts_later);
  /// check_reachable for a goal in joints: their number and limits.
  void check_joint_goal(const Position& p);
  /// The MotionError for a goal `t6` no solution in configuration `c` reaches (`status`: why),
  /// naming the configurations that do reach it. `when`: how the goal was evaluated.
  [[noreturn]] void throw_unreachable(const Position& p, const math::Transform& t6,
                                      const char* when, kin::Configuration c, bool asked,
                                      kin::IkStatus status);
  /// The configuration the arm will be in once the queued motions have run.
  kin::Configuration planned_configuration();

  rtc::Session& session_;
  std::unique_ptr<kin::Kinematics> kinematics_;
  std::unique_ptr<TrajectoryGenerator> generator_;
  ForceControl force_;  ///< the loop's force side (guards, compliance)
  kin::JointVector lower_;
  MotionSettings settings_;
  PositionPtr park_;
  std::vector<PositionPtr> keep_;  ///< positions the loop may still point to
  MoveObserver move_observer_;     ///< planning side only
  std::vector<std::shared_ptr<Rendezvous>> keep_rendezvous_;  ///< likewise
  std::uint64_t next_id_ = 1;
  bool started_ = false;
  bool first_sample_ = true;   ///< loop side: reset the generator at the arm's position
  bool zero_gravity_ = false;  ///< planning side: as last set
  // Planning -> loop, one-shot requests (Request::none once the loop has sent them).
  std::atomic<rtc::Request> zero_gravity_request_{rtc::Request::none};
  std::atomic<rtc::Request> hand_request_{rtc::Request::none};
  std::atomic<rtc::SettingChg> setting_request_{rtc::SettingChg{}};
  bool limp_ = false;  ///< loop side: zero gravity is on, nothing is commanded
  std::vector<MotionEvent> failures_;
  std::vector<MotionEvent> pending_events_;
  std::set<std::uint64_t> failed_ids_;
  /// The configuration the queued motions leave the arm in (set by move(); valid while
  /// motions are queued).
  kin::Configuration queued_configuration_;
};

}  // namespace rccx::rccl
