// The trajectory generator (thesis 2.4.2, RCCL's setpoint): the RTC control function that turns
// the queue of motion requests into one joint setpoint per sample.
//
// Segments run in joint mode (joints interpolated linearly between the solved end points) or in
// Cartesian mode (the tool frame F = T6 TOOL moves on a straight line, F(t) = G(t) D(r): G the
// goal, re-evaluated every sample so that a moving goal is tracked, D(r) Paul's drive transform
// from the start, expressed in the goal's frame, to the goal; the inverse kinematics solved
// every sample in the configuration the segment started in). A Cartesian segment from rest
// onto a moving goal keeps its start where the arm stood: the goal's displacement since the
// segment began is taken back in proportion to 1 - r (a start riding on the goal would have to
// move at the goal's speed at once; a goal that turns still turns the start).
//
// Between consecutive segments, and when the arm starts from rest or comes to rest, a
// transition of 2 tau seconds centred on the via point keeps position and velocity continuous:
//   - joint coordinates on straight lines (joint mode, rest): Paul's quartic (paul_transition),
//     which stays inside the corner it cuts, so a joint never passes its end points;
//   - a Cartesian segment starting from or ending at rest: Paul's quartic on the drive fraction
//     r, so the tool stays on its line;
//   - two Cartesian segments: the blend of Lloyd and Hayward (1993), (1 - s) F1(t) + s F2(t)
//     with s the quintic smoothstep, of both segments extended past their ends, which stays
//     continuous when either goal moves; a joint-mode segment next to a Cartesian one: the same
//     blend of joint vectors, each segment continued past its ends on its joint-space tangent.
//     Both carry a correction, (v2 - v1) 2 tau w(u), that makes them Paul's quartic when the
//     segments are lines: the velocity passes from one segment's to the other's without the
//     16 % overshoot of the plain blend (which passed a joint's top speed when a fast joint move
//     followed a Cartesian one). A tool blend that cannot be solved or kept within the bounds
//     (its poses near a singularity) falls back to the joint blend.
//
// Slowing down instead of failing (the way Lloyd and Hayward's generator does): nothing is
// planned from estimates alone. Every transition is sampled as the loop will run it (its sample
// times, goals predicted at each one - a moving goal's velocity included - and the segments
// either side), and while a joint would pass its acceleration bound the transition is
// lengthened (and the next segment with it, when it must), while one would pass
// kTransitionSpeedFraction of its top speed the next segment is slowed (its velocity scales as
// 1 / T); the segment now running is never changed, and its room bounds the transition. Every
// Cartesian segment is sampled along its line (T / 1024, and every period near both ends; then
// every period, as the loop will run it) and lengthened as a whole until its joints keep within
// kPlanningSpeedFraction of their top speeds and kPlanningAccelerationFraction of their bounds.
// The planned setpoints then keep every joint within its top speed and within its acceleration
// bound times 1 + kAccelerationTolerance. A motion fails, before it starts, only when no
// slower timing helps: a line through a singularity (a joint would jump), one that leaves the
// workspace anywhere along it, one that would turn a joint past its limit, one that even
// 20 times slower would pass a bound ("too close to a singularity": the time is stretched
// uniformly, so a line that grazes a singularity near one end would otherwise crawl for
// minutes); the message says which. The sample loop's guards (top speed, twice the acceleration
// bound, limits) stay as the last defence and stop the arm smoothly with their own message.
//
// The generator owns the two lock-free queues between the planning level and the loop:
// requests in, events out. Nothing in step() allocates, locks or throws.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <string_view>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/motion_sync.hpp"
#include "rccx/rccl/position.hpp"
#include "rccx/rccl/trajectory/failure.hpp"
#include "rccx/rccl/trajectory/halt.hpp"
#include "rccx/rccl/trajectory/model.hpp"
#include "rccx/rccl/trajectory/motion_queue.hpp"
#include "rccx/rccl/trajectory/requests.hpp"

namespace rccx::rccl {

class TrajectoryGenerator {
 public:
  static constexpr std::size_t kQueueCapacity = trajectory::MotionQueue::kCapacity;
  static constexpr std::size_t kReports = trajectory::MotionQueue::kReports;

  TrajectoryGenerator(const kin::Kinematics& kinematics, GeneratorOptions options);

  // --- Planning level (one thread) ----------------------------------------------------------
  /// Queues a request; false when the queue is full.
  bool submit(const MotionRequest& request) noexcept { return queue_.submit(request); }
  /// The next event, if any.
  std::optional<MotionEvent> next_event() noexcept { return queue_.next_event(); }
  /// Asks the loop to stop smoothly where it is and cancel everything queued.
  void request_halt() noexcept { halt_requested_.store(true, std::memory_order_release); }
  /// RCCL's nextmove (a guarded motion): ends the motion running now where the arm is. The
  /// arm stops smoothly (every joint within its acceleration bound, as a halt), that motion
  /// ends with the event text kNextmoveText (not a failure), and the queue goes on from rest
  /// there. Nothing happens at rest. May be called from any thread, the loop's included.
  void request_next() noexcept { next_requested_.store(true, std::memory_order_release); }
  /// Highest id started / ended (ended includes failed and cancelled), in queue order.
  [[nodiscard]] std::uint64_t started_upto() const noexcept { return ledger_.started_upto(); }
  [[nodiscard]] std::uint64_t ended_upto() const noexcept { return ledger_.ended_upto(); }
  /// The same, with the failures, for other robots' motions to wait on (sync.hpp).
  [[nodiscard]] const MotionLedger& ledger() const noexcept { return ledger_; }
  /// The robot's name in messages about gates; before the loop runs.
  void set_robot_name(std::string_view name) noexcept { ledger_.set_robot(name); }
  /// The report of motion `id`, once ended_upto() >= id (and fewer than kReports later).
  [[nodiscard]] SegmentReport report(std::uint64_t id) const noexcept { return queue_.report(id); }

  // --- Sample loop ---------------------------------------------------------------------------
  /// Starts at rest at q (rad / m), the arm's measured joints; queued requests stay queued.
  void reset(const kin::JointVector& q, double t_s) noexcept;
  /// The setpoint for time ctx.t_s into q (rad / m); `measured` (may be null) is the arm as
  /// read this sample, for the path report. Returns the id of the motion the setpoint belongs
  /// to (0 at rest). Allocates, locks and throws nothing itself; it passes on what a
  /// functional transform's function throws.
  std::uint64_t step(const SampleContext& ctx, const kin::JointVector* measured,
                     kin::JointVector& q);
  [[nodiscard]] bool at_rest() const noexcept;
  /// The settings of motion `id` while it runs (the id step() returned), else null.
  [[nodiscard]] const MotionSettings* running_settings(std::uint64_t id) const noexcept;
  /// The id the last step() returned: the motion the last setpoint belongs to (0 at rest).
  [[nodiscard]] std::uint64_t last_motion() const noexcept { return last_motion_; }
  [[nodiscard]] const kin::Kinematics& kinematics() const noexcept { return model_.kin; }
  [[nodiscard]] const GeneratorOptions& options() const noexcept { return model_.options; }

  // --- Sample loop, between steps (the control thread only: f2, a SessionGroup cycle hook) --
  /// The last setpoint step() returned (rad / m; empty before the first reset) and the one
  /// before it, and the time the last is for (s): what goes out to the arm next.
  [[nodiscard]] const kin::JointVector& last_setpoint() const noexcept { return last_q_; }
  [[nodiscard]] const kin::JointVector& previous_setpoint() const noexcept { return prev_q_; }
  [[nodiscard]] double last_setpoint_time_s() const noexcept { return last_t_; }
  /// Asks the next step() to stop smoothly (each joint within its acceleration bound) when the
  /// arm moves - a motion, a transition, or a Cartesian rest tracking a moving goal - failing
  /// the motion with `why` (truncated to kEventText - 1 characters) and cancelling the queue.
  /// Ignored when the arm is at rest or already stopping. What a cell's collision check uses.
  void request_stop(std::string_view why) noexcept;

 private:
  enum class Blend : std::uint8_t { paul_joint, paul_r_in, paul_r_out, smooth_pose, smooth_joint };
  struct Segment {
    enum class Kind : std::uint8_t { rest, joint, cartesian };
    Kind kind = Kind::rest;
    bool resting = false;  ///< cartesian: r stays 1 (tracking a moving goal)
    const Position* position = nullptr;
    /// A dwell (stop) on a moving goal: it tracks the position of the motion before it, which
    /// it does not own (that motion's end was counted already).
    bool borrowed_position = false;
    std::uint64_t id = 0;  ///< 0: not a motion (rest)
    MotionSettings settings;
    double ts = 0.0, T = 1.0;  ///< the straight part starts at ts (the via time) and lasts T, s
    double tau_in = 0.0;       ///< half the transition into it, s
    double stop_tau = 0.0;     ///< half the transition to rest at its end, s
    kin::JointVector q0, q1;   ///< joint: from, to; rest: q1 is where it stays
    LatchedHolds holds;
    math::Transform fixed_goal;     ///< a position given in joints: its T6
    math::DriveTransform drive;     ///< cartesian: from the start (in the goal's frame) to I
    math::Transform start_in_goal;  ///< cartesian: drive.at(0), the line's start in G's frame
    /// cartesian from rest onto a moving goal: the line starts where the arm stands
    /// (start_world, fixed) and ends on the goal where it is at each sample, so that the arm
    /// leaves rest without a jump of velocity (a start riding on the goal would move at once).
    bool fixed_start = false;
    math::Transform start_world;
    math::Vec3 start_goal_p;  ///< fixed_start: the goal's position when the segment was built
    kin::Configuration configuration;
    bool has_configuration = false;
    /// The transition into it, as transition_tau chose it (a smooth pose blend that cannot be
    /// solved or kept within the bounds falls back to the joint blend).
    Blend blend_in = Blend::paul_joint;
  };
  /// A Cartesian segment's frames at one instant.
  struct Pose {
    math::Transform goal, tool, frame, t6;  ///< G, the tool product, F = G D(r), T6
  };
  /// The velocities of a transition's two segments at its via point (rad/s or m/s a joint for
  /// smooth_joint; T6's origin, m/s, for smooth_pose): what the blends' overshoot correction
  /// needs. Taken once when the transition is planned and when it begins.
  struct Tangents {
    kin::JointVector va, vb;
    math::Vec3 va_p, vb_p;
  };
  /// A transition's peaks as sampled every period, as multiples of the joints' bounds.
  struct Peaks {
    bool ok = false;  ///< false: a sample has no solution
    double speed = 0.0, acceleration = 0.0;
    kin::IkStatus why = kin::IkStatus::ok;  ///< !ok: the kinematics' reason
    double unsolved_s = 0.0;                ///< !ok: the sample's time from the segment's start
    [[nodiscard]] double ratio_or_failed() const noexcept { return ok ? acceleration : -1.0; }
  };
  struct Transition {
    Tangents tangents;
    bool active = false;
    bool to_next = false;  ///< false: to rest at the end of cur_
    double tB = 0.0, tau = 0.0;
    Blend blend = Blend::paul_joint;
  };
  using Text = trajectory::Text;

  [[nodiscard]] double fraction(const Segment& s, double t) const noexcept;
  [[nodiscard]] double drive_fraction(const Segment& s, double t) const noexcept {
    return s.resting ? 1.0 : fraction(s, t);
  }
  void pose_at(const Segment& s, const SampleContext& ctx, double r, Pose& out) const;
  bool solve(const Segment& s, const math::Transform& t6, const kin::JointVector& near,
             kin::JointVector& q, kin::IkStatus& why) const noexcept;
  /// `linear_past_ends`: a Cartesian segment continues past its ends in joint space, on its
  /// tangent there (else on its line, and in joint space only where the line cannot be solved).
  bool segment_value(const Segment& s, const SampleContext& ctx, double t,
                     const kin::JointVector& near, kin::JointVector& q, kin::IkStatus& why,
                     Pose* pose = nullptr, bool linear_past_ends = false) const;
  [[nodiscard]] Segment rest_of(const Segment& a) const noexcept;

  bool build(const MotionRequest& r, const SampleContext& ctx, double t_via);
  /// From rest: builds the waiting request and begins its transition in at t (through its
  /// rendezvous, when it has one).
  void start_waiting(const SampleContext& ctx, double t);
  /// The 1-based joint whose solution jumps between drive fractions r0 and r1 of Cartesian
  /// segment s (solved as q0, q1): a singularity on the line, or (at_limit) the end of the
  /// joint's travel, where the solver turns it the other way round. 0: none.
  [[nodiscard]] int find_jump(const Segment& s, const SampleContext& ctx, double r0, double r1,
                              const kin::JointVector& q0, const kin::JointVector& q1,
                              bool& at_limit) const;
  [[nodiscard]] Blend blend_between(const Segment& a, const Segment* b) const noexcept;
  /// Half the transition from a into b at via time tB, from the change of joint velocity and
  /// the acceleration bound; lengthens b (not started yet) when a has too little room left.
  /// Sets b.blend_in to the blend chosen.
  double transition_tau(const Segment& a, Segment& b, Blend blend, double tB,
                        const SampleContext& ctx) const;
  /// transition_tau for one blend; `peaks`: the transition's as planned.
  double plan_transition(const Segment& a, Segment& b, Blend blend, double tB,
                         const SampleContext& ctx, Peaks& peaks) const;
  /// The largest joint speed and acceleration of the transition from a into b, sampled every
  /// period as the loop will run it (goals predicted at each sample's time), as multiples of the
  /// joints' bounds. `near`: joint values close to the transition's start, to seed the inverse
  /// kinematics.
  /// Folds the speeds and accelerations of three setpoints h apart into pk (bound multiples).
  void add_peaks(const kin::JointVector& q0, const kin::JointVector& q1, const kin::JointVector& q2,
                 double h, Peaks& pk) const noexcept;
  Peaks blend_peaks(const Segment& a, const Segment& b, bool to_next, Blend blend, double tB,
                    double tau, const kin::JointVector& near, const SampleContext& ctx) const;
  /// The same for segment s's straight part (ts .. ts + T), seeded with `near` at its start:
  /// every T / kSegmentChecks and every period near both ends, or (every_period) every period.
  Peaks segment_peaks(const Segment& s, const SampleContext& ctx, const kin::JointVector& near,
                      bool every_period = false) const;
  /// The velocities of a and b at the via point tB, for the smooth blends; false when a value
  /// has no solution.
  bool tangents(const Segment& a, const Segment& b, Blend blend, double tB,
                const kin::JointVector& near, const SampleContext& ctx, Tangents& out) const;
  /// The transition's setpoint at time t (its window: tB - tau .. tB + tau).
  bool blend_value(const Segment& a, const Segment& b, bool to_next, Blend blend, double tB,
                   double tau, const Tangents& tangents, const SampleContext& ctx, double t,
                   const kin::JointVector& near, kin::JointVector& q, kin::IkStatus& why) const;
  void begin_transition(const SampleContext& ctx, double tB, double tau, Blend blend, bool to_next);
  void finish_transition(const SampleContext& ctx);
  bool value(const SampleContext& ctx, double t, kin::JointVector& q, kin::IkStatus& why);

  void end_motion(const Segment& s, const SampleContext& ctx, std::string_view text = {}) noexcept;
  /// request_next(): ends the motion running now and stops where the arm is.
  void next_motion(const SampleContext& ctx) noexcept;
  void fail(std::uint64_t id, const SampleContext& ctx, kin::IkStatus status, int joint,
            const Text& text) noexcept;
  void start_halt() noexcept;
  void halt_value(double t, kin::JointVector& q) noexcept;
  void rest_at(const kin::JointVector& q) noexcept;
  void record(const SampleContext& ctx, const kin::JointVector& q,
              const kin::JointVector* measured) noexcept;

  const trajectory::GeneratorModel model_;

  /// Requests in (waiting, joined, put back), events out, reports.
  trajectory::MotionQueue queue_{ledger_};
  std::atomic<bool> halt_requested_{false};
  std::atomic<bool> next_requested_{false};
  bool stop_requested_ = false;    ///< request_stop(): same thread as step()
  std::uint64_t last_motion_ = 0;  ///< what step() returned last
  Text stop_text_{};

  // Loop state.
  Segment cur_, next_;
  bool has_next_ = false;
  double next_tau_ = 0.0;  ///< half the transition from cur_ into next_, s
  Transition tr_;
  trajectory::Halt halt_;
  bool halting_ = false;              ///< halt_ runs
  kin::JointVector last_q_, prev_q_;  ///< the last two setpoints
  MotionLedger ledger_;               ///< beside last_q_: a cell's cycle hook reads both every tick
  double last_t_ = 0.0;
  Pose pose_;  ///< cur_'s frames this sample, when it is a Cartesian segment outside transitions
  bool pose_valid_ = false;
  math::Vec3 last_frame_p_;
  bool have_last_frame_ = false;
  /// The present segment's goal at its last two samples, and how far its step changed at the
  /// last, m: a goal that jumps (a varb transform set at once) is named as the cause when a
  /// guard stops the arm. Kept by pose_at (const: a record of what the loop saw).
  struct GoalTrack {
    const Position* position = nullptr;
    int samples = 0;
    double t_s = 0.0, jump_m = 0.0;
    math::Vec3 p[2];
  };
  mutable GoalTrack goal_track_;
};

}  // namespace rccx::rccl
