// A segment of the generator's path and its const evaluator: where the arm is to be at a time.
// A segment is a rest (the arm stays at q1), a joint segment (the joints on a straight line from
// q0 to q1) or a Cartesian one (the tool frame F = G D(r): the goal G evaluated at that time,
// Paul's drive transform D at the fraction r of the straight part, the inverse kinematics in the
// segment's configuration). docs/TRAJECTORY.md describes the whole.
//
//   const SegmentEvaluator segments(model, loop, goals);  // reads the model and the loop's state
//   kin::IkStatus why;
//   if (!segments.value(segment, ctx, t, near, q, why)) { /* no solution at t: why says why */ }
//
// The evaluator changes nothing but the GoalTrack it is given: the present segment's goal as the
// loop saw it, which names a goal that jumped when a guard stops the arm.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/math/transform.hpp"
#include "rccx/rccl/position.hpp"
#include "rccx/rccl/trajectory/model.hpp"
#include "rccx/rccl/trajectory/requests.hpp"

namespace rccx::rccl::trajectory {

/// How a transition joins two segments (blends.hpp): Paul's quartic on the joints, or on the
/// drive fraction r into / out of a Cartesian segment from / to rest; the smoothstep blend of
/// the tool's poses or of the joints.
enum class Blend : std::uint8_t { paul_joint, paul_r_in, paul_r_out, smooth_pose, smooth_joint };

struct Segment {
  enum class Kind : std::uint8_t { rest, joint, cartesian };
  Kind kind = Kind::rest;
  bool resting = false;  ///< cartesian: r stays 1 (tracking a moving goal)
  const Position* position = nullptr;
  /// RCCL's stop(ms): the arm at rest (on a moving goal, tracking it) for exactly T, never
  /// blended with the motions either side: the one before stops first, the one after starts
  /// from rest when it is over (docs/RCCL.md, "stop(ms)").
  bool dwell = false;
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
  /// The transition into it, as TransitionPlanner::transition_tau chose it (a smooth pose blend
  /// that cannot be solved or kept within the bounds falls back to the joint blend).
  Blend blend_in = Blend::paul_joint;
};

/// The motion no longer holds its position: one fewer end its owner waits for (a borrowed
/// position's end was counted by the motion that lent it).
inline void release_position(const Position* position, bool borrowed) noexcept {
  if (position != nullptr && !borrowed)
    position->pending_ends.fetch_sub(1, std::memory_order_acq_rel);
}

/// A Cartesian segment's frames at one instant.
struct Pose {
  math::Transform goal, tool, frame, t6;  ///< G, the tool product, F = G D(r), T6
};

/// A goal whose step changes by more than this in one sample has jumped (m).
inline constexpr double kGoalJump_m = 2e-3;

/// The present segment's goal at its last two samples, and how far its step changed at the
/// last, m: a goal that jumps (a varb transform set at once) is named as the cause when a guard
/// stops the arm. Kept by SegmentEvaluator::pose_at (a record of what the loop saw).
struct GoalTrack {
  const Position* position = nullptr;
  int samples = 0;
  double t_s = 0.0, jump_m = 0.0;
  math::Vec3 p[2];
  /// The goal of `at` at time t_s (s), once a sample.
  void see(const Position* at, const math::Vec3& goal_p, double t) noexcept;
  /// Whether the goal of `at` jumped at its last sample.
  [[nodiscard]] bool jumped(const Position* at) const noexcept {
    return at != nullptr && position == at && jump_m > kGoalJump_m;
  }
};

/// The context for evaluating goals at time t: the sample's own, or a prediction (functional
/// transforms called afresh for that time).
inline SampleContext at_time(const SampleContext& ctx, double t) noexcept {
  if (std::abs(t - ctx.t_s) < 1e-12) return ctx;
  SampleContext c = ctx;
  c.t_s = t;
  c.predicted = true;
  return c;
}

struct LoopState;  // loop_state.hpp

class SegmentEvaluator {
 public:
  /// `loop`: the present segment (whose goal `goals` records) and the last setpoint.
  SegmentEvaluator(const GeneratorModel& model, const LoopState& loop, GoalTrack& goals) noexcept
      : model_(model), loop_(loop), goals_(goals) {}

  [[nodiscard]] const GeneratorModel& model() const noexcept { return model_; }
  [[nodiscard]] const LoopState& loop() const noexcept { return loop_; }

  /// The fraction of segment s's straight part at time t (s); < 0 before it, > 1 after it.
  [[nodiscard]] static double fraction(const Segment& s, double t) noexcept {
    return (t - s.ts) / s.T;
  }
  /// The drive's fraction: a resting segment stays at its end.
  [[nodiscard]] static double drive_fraction(const Segment& s, double t) noexcept {
    return s.resting ? 1.0 : fraction(s, t);
  }
  /// Cartesian segment s's frames at drive fraction r, its goal evaluated for ctx.
  void pose_at(const Segment& s, const SampleContext& ctx, double r, Pose& out) const;
  /// The joints that put T6 at t6 in s's configuration, nearest `near`; false: why says why.
  bool solve(const Segment& s, const math::Transform& t6, const kin::JointVector& near,
             kin::JointVector& q, kin::IkStatus& why) const noexcept;
  /// Segment s's joints at time t (rad / m), seeded with `near`; `pose` (if not null) gets a
  /// Cartesian segment's frames. `linear_past_ends`: a Cartesian segment continues past its
  /// ends in joint space, on its tangent there (else on its line, and in joint space only where
  /// the line cannot be solved).
  bool value(const Segment& s, const SampleContext& ctx, double t, const kin::JointVector& near,
             kin::JointVector& q, kin::IkStatus& why, Pose* pose = nullptr,
             bool linear_past_ends = false) const;
  /// A rest at a's end (a joint segment's), else where the arm is (the last setpoint).
  [[nodiscard]] Segment rest_of(const Segment& a) const noexcept;

 private:
  bool cartesian_value(const Segment& s, const SampleContext& ctx, double t,
                       const kin::JointVector& near, kin::JointVector& q, kin::IkStatus& why,
                       Pose* pose, bool linear_past_ends) const;
  bool past_end_value(const Segment& s, const SampleContext& ctx, double t, double r,
                      const kin::JointVector& near, kin::JointVector& q, kin::IkStatus& why) const;

  const GeneratorModel& model_;
  const LoopState& loop_;
  GoalTrack& goals_;
};

}  // namespace rccx::rccl::trajectory
