// The transitions' timing, and the peak sweeps that check a plan as the loop will run it.
// Nothing is planned from estimates alone: a transition's half time tau starts from the change
// of joint velocity at the via point (Paul's quartic: peak acceleration 0.75 dv / tau), then the
// transition is sampled every period - its goals predicted at each sample's time - and while a
// joint would pass its acceleration bound tau grows, while one would pass
// kTransitionSpeedFraction of its top speed the next segment is slowed (its velocity scales as
// 1 / T). The segment running is never changed; its room left bounds the transition.
//
//   const TransitionPlanner planner(segments, blends);
//   double tau = planner.transition_tau(cur, next, blend_between(cur, &next), tB, ctx);
//   Peaks pk = planner.segment_peaks(line, ctx, q_start);   // bound multiples, or !pk.ok
#pragma once

#include "rccx/rccl/trajectory/blends.hpp"
#include "rccx/rccl/trajectory/segment.hpp"

namespace rccx::rccl::trajectory {

/// A segment is slowed at most this much to fit the transition into it.
inline constexpr double kMaxStretch = 8.0;
/// A transition is sampled and replanned at most this many times.
inline constexpr int kPlanningPasses = 6;
/// A Cartesian segment is sampled at most this many times when it is planned ...
inline constexpr double kSegmentChecks = 1024.0;
/// ... and its first and last this many periods, every period.
inline constexpr double kEndChecks = 32.0;

/// A transition's or a segment's peaks as sampled, as multiples of the joints' bounds.
struct Peaks {
  bool ok = false;  ///< false: a sample has no solution
  double speed = 0.0, acceleration = 0.0;
  kin::IkStatus why = kin::IkStatus::ok;  ///< !ok: the kinematics' reason
  double unsolved_s = 0.0;                ///< !ok: the sample's time from the segment's start
  [[nodiscard]] double ratio_or_failed() const noexcept { return ok ? acceleration : -1.0; }
};

class TransitionPlanner {
 public:
  TransitionPlanner(const SegmentEvaluator& segments, const Blender& blends) noexcept
      : segments_(segments), blends_(blends) {}

  [[nodiscard]] const SegmentEvaluator& segments() const noexcept { return segments_; }
  [[nodiscard]] const Blender& blends() const noexcept { return blends_; }

  /// Half the transition from a into b at via time tB (s), from the change of joint velocity
  /// and the acceleration bound; lengthens b (not started yet) when a has too little room left.
  /// Sets b.blend_in to the blend chosen (`blend`, or the joint blend when a smooth pose blend
  /// cannot be solved or kept within the bounds).
  double transition_tau(const Segment& a, Segment& b, Blend blend, double tB,
                        const SampleContext& ctx) const;
  /// The largest joint speed and acceleration of transition tr from a into b (or to rest),
  /// sampled every period as the loop will run it (goals predicted at each sample's time, the
  /// segments' values either side of the window included), as multiples of the joints'
  /// bounds. `near`: joint values close to its start, to seed the inverse kinematics.
  Peaks blend_peaks(const Segment& a, const Segment& b, Transition tr, const kin::JointVector& near,
                    const SampleContext& ctx) const;
  /// The same for segment s's straight part (ts .. ts + T), seeded with `near` at its start:
  /// every T / kSegmentChecks and every period near both ends, or (every_period) every period.
  Peaks segment_peaks(const Segment& s, const SampleContext& ctx, const kin::JointVector& near,
                      bool every_period = false) const;

 private:
  /// How much b has been slowed so far (b.T grows by at most kMaxStretch in all).
  struct Stretch {
    Segment& b;
    double total = 1.0;
    void by(double k) noexcept {
      b.T *= k;
      total *= k;
    }
  };
  /// transition_tau for one blend; `pk`: the transition's peaks as planned.
  double plan(const Segment& a, Segment& b, Blend blend, double tB, const SampleContext& ctx,
              Peaks& pk) const;
  /// The shortest transition time at the planning acceleration.
  [[nodiscard]] double base_tau(const Segment& a, const Segment& b) const noexcept;
  /// The joint velocities of a and b either side of tB, from values one period apart.
  bool via_velocities(const Segment& a, const Segment& b, double tB, const SampleContext& ctx,
                      kin::JointVector& va, kin::JointVector& vb) const;
  /// The half time Paul's quartic needs for the change from va to vb, s.
  [[nodiscard]] double needed_tau(const kin::JointVector& va,
                                  const kin::JointVector& vb) const noexcept;
  /// Slows b until the change of velocity fits in a's room left (s).
  void fit_room(double room, const kin::JointVector& va, kin::JointVector& vb,
                Stretch& stretch) const noexcept;
  /// Samples the transition and lengthens it (and b) until it keeps within the bounds.
  double check_as_run(const Segment& a, Blend blend, double tB, double tau, double room,
                      Stretch& stretch, const SampleContext& ctx, Peaks& pk) const;
  /// Folds the speeds and accelerations of three setpoints h apart into pk (bound multiples).
  void add_peaks(const kin::JointVector& q0, const kin::JointVector& q1, const kin::JointVector& q2,
                 double h, Peaks& pk) const noexcept;

  const SegmentEvaluator& segments_;
  const Blender& blends_;
};

}  // namespace rccx::rccl::trajectory
