// The transitions between segments, 2 tau seconds centred on the via point tB, which keep
// position and velocity continuous: Paul's quartic on the joints (paul_transition.hpp), or on
// the drive fraction r into or out of a Cartesian segment from or to rest; between two
// Cartesian segments the blend of Lloyd and Hayward (1993), (1 - s) F1(t) + s F2(t) with s the
// quintic smoothstep, of the tool's poses or (next to a joint segment) of the joints, with a
// correction that makes it Paul's quartic between lines (no velocity overshoot).
//
//   Transition tr{blend_between(a, &b), true, tB, tau, {}};
//   blends.tangents(a, b, near, ctx, tr);                // the smooth blends' correction
//   blends.value(a, b, tr, ctx, t, near, q, why);        // the setpoint at t in tB -+ tau
#pragma once

#include <algorithm>

#include "rccx/rccl/trajectory/segment.hpp"

namespace rccx::rccl::trajectory {

/// The quintic smoothstep of Lloyd and Hayward's blend: s(0) = 0, s(1) = 1, s' and s'' zero
/// at both ends.
constexpr double smoothstep(double u) noexcept {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
}

/// The correction that makes Lloyd and Hayward's blend of two lines free of overshoot: with it,
/// (1 - s) qa(t) + s qb(t) + (vb - va) 2 tau w(u) is Paul's quartic when a and b are lines of
/// velocities va and vb (the velocity then passes monotonically from va to vb, never beyond
/// either), and it stays exact at both ends (w and its derivatives vanish at u = 0 and 1) for
/// any va, vb: curved segments keep position, velocity and acceleration continuous. Without it
/// the blend's velocity overshoots by up to 16 % of the change of velocity (the term s' (qb - qa)).
constexpr double overshoot_correction(double u) noexcept {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * u * (1.0 - 0.5 * u) - smoothstep(u) * (u - 0.5);
}

/// Peak acceleration of a transition per unit change of velocity and unit 1/tau: Paul's quartic
/// 0.75, the smoothstep blend of two lines 1.875 (its (2u - 1) s(u) has |d2/du2| <= 7.5 at
/// u = 1/2, and d/dt = d/du / 2 tau).
inline constexpr double kPaulPeak = 0.75;
inline constexpr double kSmoothPeak = 1.875;

/// The velocities of a transition's two segments at its via point (rad/s or m/s a joint for
/// smooth_joint; T6's origin, m/s, for smooth_pose): what the blends' overshoot correction
/// needs. Taken once when the transition is planned and when it begins.
struct Tangents {
  kin::JointVector va, vb;
  math::Vec3 va_p, vb_p;
};

/// One transition from segment a: into the next segment b (to_next), or to rest at a's end.
struct Transition {
  Blend blend = Blend::paul_joint;
  bool to_next = false;  ///< false: to rest at the end of a
  double tB = 0.0;       ///< the via time, s: the window is tB - tau .. tB + tau
  double tau = 0.0;      ///< half the transition, s
  Tangents tangents;     ///< smooth blends into a next segment: Blender::tangents
};

/// The transition from a into b (b null: to rest at a's end).
[[nodiscard]] Blend blend_between(const Segment& a, const Segment* b) noexcept;

class Blender {
 public:
  explicit Blender(const SegmentEvaluator& segments) noexcept : segments_(segments) {}

  [[nodiscard]] const SegmentEvaluator& segments() const noexcept { return segments_; }
  /// tr.tangents: the velocities of a and b at the via point tr.tB, for the smooth blends;
  /// false when a value has no solution.
  bool tangents(const Segment& a, const Segment& b, const kin::JointVector& near,
                const SampleContext& ctx, Transition& tr) const;
  /// The transition's setpoint at time t (its window: tB - tau .. tB + tau); b is a for a
  /// transition to rest.
  bool value(const Segment& a, const Segment& b, const Transition& tr, const SampleContext& ctx,
             double t, const kin::JointVector& near, kin::JointVector& q, kin::IkStatus& why) const;

 private:
  bool paul_joint(const Segment& a, const Segment& b, const Transition& tr,
                  const SampleContext& ctx, double t, const kin::JointVector& near,
                  kin::JointVector& q, kin::IkStatus& why) const;
  bool smooth_pose(const Segment& a, const Segment& b, const Transition& tr, const SampleContext& c,
                   double t, const kin::JointVector& near, kin::JointVector& q,
                   kin::IkStatus& why) const;
  bool smooth_joint(const Segment& a, const Segment& b, const Transition& tr,
                    const SampleContext& ctx, double t, const kin::JointVector& near,
                    kin::JointVector& q, kin::IkStatus& why) const;

  const SegmentEvaluator& segments_;
};

}  // namespace rccx::rccl::trajectory
