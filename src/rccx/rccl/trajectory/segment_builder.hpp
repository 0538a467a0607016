// Turns a motion request into a segment, before the arm moves on it: a dwell (RCCL's stop,
// tracking a moving goal), or a move whose goal is checked (joints in their limits, a solution in
// joint mode), whose Cartesian line is walked (out of reach, a singularity or a joint's limit
// on the way are refused now rather than met in the middle of the motion), whose time comes from
// the tool's speeds and the joints' bounds, and whose line is then sampled as the loop will run
// it and stretched as a whole until its joints keep within the planning fractions of their
// bounds. Last, the stop at its end is planned and checked, as a transition to rest.
//
//   const SegmentBuilder builder(planner);
//   Segment s;
//   if (std::optional<Failure> f = builder.build(request, ctx, t_via, s)) { /* refused: f says why
//   */ }
#pragma once

#include <optional>

#include "rccx/rccl/trajectory/failure.hpp"
#include "rccx/rccl/trajectory/transition_planner.hpp"

namespace rccx::rccl::trajectory {

/// A Cartesian segment is slowed at most this much for its own sake (its joints' speeds and
/// accelerations along the line); one that would need more is refused as too close to a
/// singularity.
inline constexpr double kMaxSegmentStretch = 20.0;

class SegmentBuilder {
 public:
  explicit SegmentBuilder(const TransitionPlanner& planner) noexcept : planner_(planner) {}

  /// Builds request r's segment into s (a default Segment), its straight part to begin at the
  /// via time t_via (s), after the loop's present segment; nothing else changes. A failure says
  /// why the motion cannot be run (s is then incomplete).
  std::optional<Failure> build(const MotionRequest& r, const SampleContext& ctx, double t_via,
                               Segment& s) const;
  /// A joint segment onto a moving goal, once planning has set its start and time: its end
  /// joints become those of the goal where it will be at ts + T, and its stop is planned anew.
  /// False (nothing changed) for any other segment, or when that pose has no solution (the
  /// end built stands; the loop's guards judge the goal as it comes).
  bool aim_at_end(Segment& s, const SampleContext& ctx) const;

 private:
  /// Where the arm will be at the via point: joints and T6.
  struct Via {
    kin::JointVector q;
    math::Transform t6;
  };
  /// The time the joints allow, from their changes along the segment.
  struct Timing {
    double by_joints = 0.0;        ///< at the planning fraction of their top speeds, s
    double by_acceleration = 0.0;  ///< room for the transitions at the acceleration bound, s
    kin::JointVector end_step;     ///< cartesian: the joints' change over the line's last part,
                                   ///< per unit r
  };

  [[nodiscard]] const SegmentEvaluator& segments() const noexcept { return planner_.segments(); }
  [[nodiscard]] const GeneratorModel& model() const noexcept { return segments().model(); }
  Via via_point(const SampleContext& ctx, double t_via) const;
  /// Segment s's time from the tool's speeds (or its set time), at least what the joints and
  /// the transitions need (s); `goal`: its goal where the line ends, `t6_via`: where it starts.
  [[nodiscard]] double segment_time(const Segment& s, const math::Transform& t6_via,
                                    const Pose& goal, const Timing& timing) const;
  void dwell(const MotionRequest& r, Segment& s) const;
  std::optional<Failure> check_goal(const Position& pos, Segment& s) const;
  void choose_configuration(Segment& s, const kin::JointVector& qB) const;
  std::optional<Failure> joint_goal(const Position& pos, const Pose& goal, Segment& s,
                                    Timing& timing) const;
  std::optional<Failure> walk_line(Segment& s, const SampleContext& ctx, const kin::JointVector& qB,
                                   Timing& timing) const;
  [[nodiscard]] Failure jump_failure(const Segment& s, int joint, bool at_limit, int k,
                                     const kin::JointVector& q_prev,
                                     const kin::JointVector& q) const;
  std::optional<Failure> stretch_line(Segment& s, const SampleContext& ctx,
                                      const kin::JointVector& qB) const;
  void plan_stop(Segment& s, const SampleContext& ctx, const kin::JointVector& end_step) const;
  /// Folds the joints' change from a to b, times `scale`, into the timing.
  void add_joint_time(const kin::JointVector& a, const kin::JointVector& b, double scale,
                      Timing& timing) const noexcept;
  /// The 1-based joint whose solution jumps between drive fractions r0 and r1 of Cartesian
  /// segment s (solved as q0, q1): a singularity on the line, or (at_limit) the end of the
  /// joint's travel, where the solver turns it the other way round. 0: none.
  [[nodiscard]] int find_jump(const Segment& s, const SampleContext& ctx, double r0, double r1,
                              const kin::JointVector& q0, const kin::JointVector& q1,
                              bool& at_limit) const;

  const TransitionPlanner& planner_;
};

}  // namespace rccx::rccl::trajectory
