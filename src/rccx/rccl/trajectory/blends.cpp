#include "rccx/rccl/trajectory/blends.hpp"

#include "rccx/rccl/paul_transition.hpp"

namespace rccx::rccl::trajectory {
namespace {

/// The pose a fraction s of the way from a to b: position on the line, rotation about the
/// fixed axis of a⁻¹ b.
math::Transform interpolate(const math::Transform& a, const math::Transform& b, double s) noexcept {
  const math::Rot3 rel = a.R.transposed() * b.R;
  math::Vec3 axis;
  double angle = 0.0;
  rel.to_axis_angle(axis, angle);
  return {a.R * math::Rot3::about(axis, s * angle), a.p + (b.p - a.p) * s};
}

/// The transition's parameter: 0 at its start, 1 at its end.
double blend_parameter(const Transition& tr, double t) noexcept {
  return (t - (tr.tB - tr.tau)) / (2.0 * tr.tau);
}

}  // namespace

Blend blend_between(const Segment& a, const Segment* b) noexcept {
  using K = Segment::Kind;
  const bool a_linear = a.kind == K::joint || a.kind == K::rest;
  if (b == nullptr) return a.kind == K::cartesian ? Blend::paul_r_out : Blend::paul_joint;
  if (a_linear && b->kind != K::cartesian) return Blend::paul_joint;
  if (a.kind == K::rest && b->kind == K::cartesian) {
    // A line that starts on a moving goal moves with it from its first sample: blend it in
    // from the pose at rest, so that the goal's speed is taken up over the transition.
    return b->position->moves() ? Blend::smooth_pose : Blend::paul_r_in;
  }
  if (a.kind == K::cartesian && b->kind == K::cartesian) return Blend::smooth_pose;
  return Blend::smooth_joint;
}

bool Blender::tangents(const Segment& a, const Segment& b, const kin::JointVector& near,
                       const SampleContext& ctx, Transition& tr) const {
  const double P = segments_.model().options.period_s;
  const double tB = tr.tB;
  Tangents& out = tr.tangents;
  if (tr.blend == Blend::smooth_joint) {
    kin::JointVector qa0, qa1, qb0, qb1;
    kin::IkStatus why;
    if (!segments_.value(a, ctx, tB - P, near, qa0, why) ||
        !segments_.value(a, ctx, tB, qa0, qa1, why) ||
        !segments_.value(b, ctx, tB, qa1, qb0, why) ||
        !segments_.value(b, ctx, tB + P, qb0, qb1, why)) {
      return false;
    }
    out.va = qa0;
    out.vb = qb0;
    for (std::size_t j = 0; j < qa0.size(); ++j) {
      out.va[j] = (qa1[j] - qa0[j]) / P;
      out.vb[j] = (qb1[j] - qb0[j]) / P;
    }
    return true;
  }
  if (tr.blend == Blend::smooth_pose) {
    Pose p0, p1;
    out.va_p = {};
    if (a.kind != Segment::Kind::rest) {
      segments_.pose_at(a, at_time(ctx, tB - P), SegmentEvaluator::drive_fraction(a, tB - P), p0);
      segments_.pose_at(a, at_time(ctx, tB), SegmentEvaluator::drive_fraction(a, tB), p1);
      out.va_p = (p1.t6.p - p0.t6.p) * (1.0 / P);
    }
    segments_.pose_at(b, at_time(ctx, tB), SegmentEvaluator::drive_fraction(b, tB), p0);
    segments_.pose_at(b, at_time(ctx, tB + P), SegmentEvaluator::drive_fraction(b, tB + P), p1);
    out.vb_p = (p1.t6.p - p0.t6.p) * (1.0 / P);
  }
  return true;
}

bool Blender::value(const Segment& a, const Segment& b, const Transition& tr,
                    const SampleContext& ctx, double t, const kin::JointVector& near,
                    kin::JointVector& q, kin::IkStatus& why) const {
  const double tau = tr.tau;
  switch (tr.blend) {
    case Blend::paul_joint:
      return paul_joint(a, b, tr, ctx, t, near, q, why);
    case Blend::paul_r_in: {
      const double r = paul_transition(0.0, 0.0, tau / b.T, tau, tau, t - tr.tB).q;
      Pose p;
      segments_.pose_at(b, at_time(ctx, t), r, p);
      return segments_.solve(b, p.t6, near, q, why);
    }
    case Blend::paul_r_out: {
      const double r = paul_transition(1.0, -tau / a.T, 0.0, tau, tau, t - tr.tB).q;
      Pose p;
      segments_.pose_at(a, at_time(ctx, t), r, p);
      return segments_.solve(a, p.t6, near, q, why);
    }
    case Blend::smooth_pose:
      return smooth_pose(a, b, tr, at_time(ctx, t), t, near, q, why);
    case Blend::smooth_joint:
      return smooth_joint(a, b, tr, ctx, t, near, q, why);
  }
  return false;
}

bool Blender::paul_joint(const Segment& a, const Segment& b, const Transition& tr,
                         const SampleContext& ctx, double t, const kin::JointVector& near,
                         kin::JointVector& q, kin::IkStatus& why) const {
  // Per coordinate, from a's line onto b's (or to rest at the via point).
  const double tB = tr.tB, tau = tr.tau;
  kin::JointVector qa, qB, qc;
  const Segment stop = segments_.rest_of(a);
  const Segment& to = tr.to_next ? b : stop;
  if (!segments_.value(a, ctx, tB - tau, near, qa, why) ||
      !segments_.value(a, ctx, tB, near, qB, why) ||
      !segments_.value(to, ctx, tB + tau, qB, qc, why)) {
    return false;
  }
  q = qB;
  for (std::size_t j = 0; j < q.size(); ++j) {
    q[j] = paul_transition(qB[j], qa[j] - qB[j], qc[j] - qB[j], tau, tau, t - tB).q;
  }
  return true;
}

bool Blender::smooth_pose(const Segment& a, const Segment& b, const Transition& tr,
                          const SampleContext& c, double t, const kin::JointVector& near,
                          kin::JointVector& q, kin::IkStatus& why) const {
  const double u = blend_parameter(tr, t);
  Pose pa, pb;
  if (a.kind == Segment::Kind::rest) {
    pa.t6 = segments_.model().kin.forward(a.q1);
  } else {
    segments_.pose_at(a, c, SegmentEvaluator::drive_fraction(a, t), pa);
  }
  segments_.pose_at(b, c, SegmentEvaluator::drive_fraction(b, t), pb);
  const double s = smoothstep(u);
  const bool on_a = s < 0.5 && a.kind != Segment::Kind::rest;
  math::Transform x = interpolate(pa.t6, pb.t6, s);
  x.p = x.p + (tr.tangents.vb_p - tr.tangents.va_p) * (2.0 * tr.tau * overshoot_correction(u));
  return segments_.solve(on_a ? a : b, x, near, q, why);
}

bool Blender::smooth_joint(const Segment& a, const Segment& b, const Transition& tr,
                           const SampleContext& ctx, double t, const kin::JointVector& near,
                           kin::JointVector& q, kin::IkStatus& why) const {
  const double u = blend_parameter(tr, t);
  kin::JointVector qa, qb;
  // Each segment continued past its ends in joint space, on its tangent there: a Cartesian
  // line extended as a line may pass a singularity that the blend never comes near.
  if (!segments_.value(a, ctx, t, near, qa, why, nullptr, true) ||
      !segments_.value(b, ctx, t, near, qb, why, nullptr, true)) {
    return false;
  }
  const double s = smoothstep(u);
  const double w = 2.0 * tr.tau * overshoot_correction(u);
  q = qa;
  const Tangents& tg = tr.tangents;
  const bool corrected = tg.va.size() == q.size() && tg.vb.size() == q.size();
  for (std::size_t j = 0; j < q.size(); ++j) {
    q[j] += s * (qb[j] - qa[j]) + (corrected ? (tg.vb[j] - tg.va[j]) * w : 0.0);
  }
  return true;
}

}  // namespace rccx::rccl::trajectory
