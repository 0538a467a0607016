// The trajectory generator (thesis 2.4.2, RCCL's setpoint): the RTC control function that turns
// the queue of motion requests into one joint setpoint per sample. docs/TRAJECTORY.md describes
// the algorithm; this class is the page of steps a sample runs through, over the folder's parts:
//
//   TrajectoryGenerator gen(kinematics, {.period_s = 0.01});
//   gen.reset(q_measured, t0);                    // at rest where the arm is
//   gen.submit(request);                          // planning level: a move or a dwell
//   for (;;) {                                    // sample loop, every period_s
//     const std::uint64_t id = gen.step(ctx, &q_measured, q_setpoint);
//     while (auto e = gen.next_event()) { ... }   // planning level: started, ended, failed
//   }
//
// The state lives in a constant GeneratorModel (model.hpp), the loop's LoopState (loop_state.hpp:
// an explicit Phase, the segments, the transition, the halt) and the MotionQueue
// (motion_queue.hpp); the evaluator, the blends, the planner and the builder read them.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string_view>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/motion_sync.hpp"
#include "rccx/rccl/trajectory/blends.hpp"
#include "rccx/rccl/trajectory/failure.hpp"
#include "rccx/rccl/trajectory/loop_state.hpp"
#include "rccx/rccl/trajectory/model.hpp"
#include "rccx/rccl/trajectory/motion_queue.hpp"
#include "rccx/rccl/trajectory/requests.hpp"
#include "rccx/rccl/trajectory/segment.hpp"
#include "rccx/rccl/trajectory/segment_builder.hpp"
#include "rccx/rccl/trajectory/transition_planner.hpp"

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
  /// The same, with the failures, for other robots' motions to wait on (motion_sync.hpp).
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
  [[nodiscard]] const kin::JointVector& last_setpoint() const noexcept { return loop_.last_q; }
  [[nodiscard]] const kin::JointVector& previous_setpoint() const noexcept { return loop_.prev_q; }
  [[nodiscard]] double last_setpoint_time_s() const noexcept { return loop_.last_t; }
  /// The last setpoint belongs to a halt: the arm is stopping smoothly (a halt(), a failure, a
  /// nextmove, a stop request such as a cell's collision stop or a lost link).
  [[nodiscard]] bool halting() const noexcept { return loop_.phase == Phase::halting; }
  /// Asks the next step() to stop smoothly (each joint within its acceleration bound) when the
  /// arm moves - a motion, a transition, or a Cartesian rest tracking a moving goal - failing
  /// the motion with `why` (truncated to kEventText - 1 characters) and cancelling the queue.
  /// Ignored when the arm is at rest or already stopping. What a cell's collision check uses.
  void request_stop(std::string_view why) noexcept;

 private:
  using Segment = trajectory::Segment;
  using Phase = trajectory::Phase;
  using Text = trajectory::Text;

  // The steps of a sample, in the order step() runs them. Inline (defined in generator.cpp, the
  // only place that calls them): one sample costs what it cost as one function.
  inline void handle_stops(const SampleContext& ctx) noexcept;
  inline void schedule(const SampleContext& ctx);
  void start_or_cancel(const SampleContext& ctx);
  inline void join_or_end(const SampleContext& ctx);
  /// The phase's setpoint at ctx.t_s; false when it is the halt's (nothing to guard).
  inline bool evaluate(const SampleContext& ctx, kin::JointVector& q);
  inline bool value(const SampleContext& ctx, double t, kin::JointVector& q, kin::IkStatus& why);
  inline void guard(const SampleContext& ctx, kin::JointVector& q) noexcept;
  void record(const SampleContext& ctx, const kin::JointVector& q,
              const kin::JointVector* measured) noexcept;

  // Starting motions and transitions.
  /// Builds request r's segment into loop_.next (has_next), its straight part from t_via;
  /// false: the motion failed (fail() has run).
  bool build(const MotionRequest& r, const SampleContext& ctx, double t_via);
  /// From rest: builds the waiting request and begins its transition in at t (through its
  /// rendezvous, when it has one).
  void start_waiting(const SampleContext& ctx, double t);
  /// A rendezvous not due yet: plans the waiting motion as if it started now, to tell the
  /// others how long it takes.
  void tell_rendezvous(const SampleContext& ctx, double t, double now);
  void begin_transition(const SampleContext& ctx, double tB, double tau, trajectory::Blend blend,
                        bool to_next);
  void finish_transition(const SampleContext& ctx);

  // Ending, failing, halting.
  void end_motion(const Segment& s, const SampleContext& ctx, std::string_view text = {}) noexcept;
  /// request_next(): ends the motion running now and stops where the arm is.
  void next_motion(const SampleContext& ctx) noexcept;
  /// Fails motion `id` and cancels the queue behind it; the arm halts.
  void fail(std::uint64_t id, const SampleContext& ctx, kin::IkStatus status, int joint,
            const Text& text) noexcept;
  /// The motion a halt or a stop request fails: the one running, else the one beginning.
  [[nodiscard]] std::uint64_t moving_id() const noexcept;
  void start_halt() noexcept;
  void halt_value(double t, kin::JointVector& q) noexcept;
  void rest_at(const kin::JointVector& q) noexcept;
  /// The phase invariants that let it stand for the old flags (assert only).
  [[nodiscard]] bool phase_consistent() const noexcept;

  const trajectory::GeneratorModel model_;
  trajectory::MotionQueue queue_{ledger_};
  std::atomic<bool> halt_requested_{false};
  std::atomic<bool> next_requested_{false};
  bool stop_requested_ = false;    ///< request_stop(): same thread as step()
  std::uint64_t last_motion_ = 0;  ///< what step() returned last
  Text stop_text_{};

  trajectory::LoopState loop_;
  MotionLedger ledger_;  ///< beside loop_.last_q: a cell's cycle hook reads both every tick
  /// cur's frames this sample, when it is a Cartesian segment outside transitions, and the
  /// tool point's at the last one recorded: the path report's.
  trajectory::Pose pose_;
  bool pose_valid_ = false;
  math::Vec3 last_frame_p_;
  bool have_last_frame_ = false;
  trajectory::GoalTrack goal_track_;

  // The algorithms over model_ and loop_ (const: they change neither).
  const trajectory::SegmentEvaluator segments_{model_, loop_, goal_track_};
  const trajectory::Blender blends_{segments_};
  const trajectory::TransitionPlanner planner_{segments_, blends_};
  const trajectory::SegmentBuilder builder_{planner_};
};

}  // namespace rccx::rccl
