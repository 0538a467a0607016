#include "rccx/rccl/trajectory/transition_planner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rccx/rccl/trajectory/loop_state.hpp"

namespace rccx::rccl::trajectory {

double TransitionPlanner::transition_tau(const Segment& a, Segment& b, Blend blend, double tB,
                                         const SampleContext& ctx) const {
  const double T0 = b.T;
  Peaks pk;
  double tau = plan(a, b, blend, tB, ctx, pk);
  b.blend_in = blend;
  const auto score = [](const Peaks& p) {
    return p.ok ? std::max(p.speed, p.acceleration) : std::numeric_limits<double>::infinity();
  };
  if (blend == Blend::smooth_pose && score(pk) > 1.0) {
    // The tool's blend cannot be solved (its poses pass a singularity or leave the workspace)
    // or needs more than the bounds: blend the joints instead, Paul's way.
    Segment alt = b;
    alt.T = T0;
    Peaks pj;
    const double tau_j = plan(a, alt, Blend::smooth_joint, tB, ctx, pj);
    if (score(pj) < score(pk)) {
      b.T = alt.T;
      b.blend_in = Blend::smooth_joint;
      tau = tau_j;
    }
  }
  return tau;
}

double TransitionPlanner::plan(const Segment& a, Segment& b, Blend blend, double tB,
                               const SampleContext& ctx, Peaks& pk) const {
  const double P = segments_.model().options.period_s;
  double tau = base_tau(a, b);
  kin::JointVector va, vb;
  if (!via_velocities(a, b, tB, ctx, va, vb)) return tau;
  // The transition may not reach back past the start of a's straight part: when the change of
  // velocity needs longer than a has left, b (not started yet) is slowed down until it fits -
  // its velocity scales as 1 / T.
  // (Nor before now: a segment shorter than its transitions is joined late.)
  // (A resting segment - at rest, or tracking a moving goal - has no end: all the room.)
  const double room = a.kind == Segment::Kind::rest || a.resting
                          ? std::numeric_limits<double>::infinity()
                          : std::max(P, std::min(tB - (a.ts + a.tau_in), tB - ctx.t_s + 1e-9));
  Stretch stretch{b};
  if (b.kind != Segment::Kind::rest && std::isfinite(room)) fit_room(room, va, vb, stretch);
  tau = std::max(tau, needed_tau(va, vb));
  // Nor beyond half of b: b is lengthened instead (twice, as slowing b changes the need).
  for (int i = 0; i < 2 && b.kind != Segment::Kind::rest && tau > 0.5 * b.T; ++i) {
    const double k = std::min(2.0 * tau / b.T, kMaxStretch / stretch.total);
    if (!(k > 1.0)) break;
    stretch.by(k);
    for (std::size_t j = 0; j < vb.size(); ++j) vb[j] /= k;
    tau = std::max(base_tau(a, b), needed_tau(va, vb));
  }
  if (b.kind != Segment::Kind::rest) tau = std::min(tau, std::max(P, 0.5 * b.T));
  tau = std::min(tau, room);
  pk = Peaks{};
  return check_as_run(a, blend, tB, tau, room, stretch, ctx, pk);
}

double TransitionPlanner::base_tau(const Segment& a, const Segment& b) const noexcept {
  const Segment& owner = a.kind == Segment::Kind::rest ? b : a;
  return std::max(segments_.model().options.period_s, 0.5 * owner.settings.transition_time_s);
}

bool TransitionPlanner::via_velocities(const Segment& a, const Segment& b, double tB,
                                       const SampleContext& ctx, kin::JointVector& va,
                                       kin::JointVector& vb) const {
  const double P = segments_.model().options.period_s;
  const std::size_t n = segments_.model().kin.dof();
  const kin::JointVector& last_q = segments_.loop().last_q;
  kin::JointVector qa0, qa1, qb0, qb1;
  kin::IkStatus why;
  if (!segments_.value(a, ctx, tB - P, last_q, qa0, why) ||
      !segments_.value(a, ctx, tB, last_q, qa1, why) ||
      !segments_.value(b, ctx, tB, qa1, qb0, why) ||
      !segments_.value(b, ctx, tB + P, qb0, qb1, why)) {
    return false;
  }
  va = kin::JointVector(n);
  vb = kin::JointVector(n);
  for (std::size_t j = 0; j < n; ++j) {
    va[j] = (qa1[j] - qa0[j]) / P;
    vb[j] = (qb1[j] - qb0[j]) / P;
  }
  return true;
}

double TransitionPlanner::needed_tau(const kin::JointVector& va,
                                     const kin::JointVector& vb) const noexcept {
  // Every blend is Paul's quartic between lines (the smooth ones through their overshoot
  // correction), whose peak acceleration is 0.75 dv / tau.
  double t = 0.0;
  for (std::size_t j = 0; j < va.size(); ++j) {
    t = std::max(t,
                 kPaulPeak * std::abs(vb[j] - va[j]) / segments_.model().planning_acceleration(j));
  }
  return t;
}

void TransitionPlanner::fit_room(double room, const kin::JointVector& va, kin::JointVector& vb,
                                 Stretch& stretch) const noexcept {
  double k = 1.0;
  for (std::size_t j = 0; j < va.size(); ++j) {
    // The |dv| a's room allows.
    const double w = segments_.model().planning_acceleration(j) * room / kPaulPeak;
    if (std::abs(vb[j] - va[j]) <= w) continue;
    const double side = w + (vb[j] > 0.0 ? va[j] : -va[j]);  // b's bound on its side of 0
    if (side > 0.0) k = std::max(k, std::abs(vb[j]) / side);
  }
  k = std::min(k, kMaxStretch);
  stretch.by(k);
  for (std::size_t j = 0; j < vb.size(); ++j) vb[j] /= k;
}

double TransitionPlanner::check_as_run(const Segment& a, Blend blend, double tB, double tau,
                                       double room, Stretch& stretch, const SampleContext& ctx,
                                       Peaks& pk) const {
  // The estimate is for straight lines in joint space; a Cartesian blend bends them, and a
  // moving goal adds its own velocity. Sample the transition as the loop will run it: while a
  // joint would accelerate past its bound, lengthen the transition (and b when it must); while
  // one would pass its top speed, slow b down (its velocity scales as 1 / T, the transition's
  // velocity passes between a's and b's).
  Segment& b = stretch.b;
  for (int pass = 0;; ++pass) {
    pk = blend_peaks(a, b, Transition{blend, true, tB, tau, {}}, segments_.loop().last_q, ctx);
    if (!pk.ok || pass == kPlanningPasses) break;
    bool changed = false;
    if (pk.speed > kTransitionSpeedFraction && stretch.total < kMaxStretch) {
      stretch.by(std::min(1.02 * pk.speed / kTransitionSpeedFraction, kMaxStretch / stretch.total));
      changed = true;
    }
    if (pk.acceleration > 1.0 && tau < room) {
      tau = std::min(room, tau * std::min(pk.acceleration * 1.05, 2.0));
      changed = true;
    }
    if (tau > 0.5 * b.T) {
      const double k = std::min(2.0 * tau / b.T, kMaxStretch / stretch.total);
      if (k > 1.0) stretch.by(k);
      tau = std::min(tau, 0.5 * b.T);
    }
    if (!changed) break;
  }
  return tau;
}

void TransitionPlanner::add_peaks(const kin::JointVector& q0, const kin::JointVector& q1,
                                  const kin::JointVector& q2, double h, Peaks& pk) const noexcept {
  const GeneratorOptions& o = segments_.model().options;
  for (std::size_t j = 0; j < q1.size(); ++j) {
    const double acc = std::abs(q2[j] - 2.0 * q1[j] + q0[j]) / (h * h);
    pk.acceleration = std::max(pk.acceleration, acc / o.max_acceleration[j]);
    pk.speed = std::max(pk.speed, std::abs(q2[j] - q1[j]) / h / o.max_velocity[j]);
  }
}

Peaks TransitionPlanner::segment_peaks(const Segment& s, const SampleContext& ctx,
                                       const kin::JointVector& near, bool every_period) const {
  // Every period, or T / kSegmentChecks when that is longer (a bounded cost per segment: the
  // second difference over a longer step still sees a peak, somewhat smoothed); and both ends
  // every period, where a line that starts or ends near a singularity bends most.
  Peaks pk;
  kin::IkStatus why;
  const auto unsolved = [&](double t) {
    pk.why = why;
    pk.unsolved_s = t - s.ts;
    return false;
  };
  const auto sweep = [&](double from, double to, double h, const kin::JointVector& seed) {
    kin::JointVector q0, q1, q2;
    if (!segments_.value(s, ctx, from, seed, q0, why)) return unsolved(from);
    if (!segments_.value(s, ctx, from + h, q0, q1, why)) return unsolved(from + h);
    for (double t = from + 2.0 * h; t <= to + 1e-9; t += h) {
      if (!segments_.value(s, ctx, t, q1, q2, why)) return unsolved(t);
      add_peaks(q0, q1, q2, h, pk);
      q0 = q1;
      q1 = q2;
    }
    return true;
  };
  const double P = segments_.model().options.period_s;
  if (every_period) {
    if (!sweep(s.ts, s.ts + s.T, P, near)) return pk;
    pk.ok = true;
    return pk;
  }
  const double h = std::max(P, s.T / kSegmentChecks);
  const double end = std::min(s.T, kEndChecks * P);
  if (!sweep(s.ts, s.ts + s.T, h, near) || !sweep(s.ts, s.ts + end, P, near) ||
      !sweep(s.ts + s.T - end, s.ts + s.T, P, s.q1)) {
    return pk;
  }
  pk.ok = true;
  return pk;
}

Peaks TransitionPlanner::blend_peaks(const Segment& a, const Segment& b, Transition tr,
                                     const kin::JointVector& near, const SampleContext& ctx) const {
  const double P = segments_.model().options.period_s;
  const double tB = tr.tB, tau = tr.tau;
  Peaks pk;
  tr.tangents = Tangents{};
  if (tr.to_next && !blends_.tangents(a, b, near, ctx, tr)) return pk;
  kin::JointVector q0, q1, q2;
  kin::IkStatus why;
  // As the loop will run it: on its sample times (ctx.t_s + k P), the segments' values either
  // side of the window, so that the joins are judged too.
  const double eps = 1e-9;
  const auto at = [&](double t, const kin::JointVector& seed, kin::JointVector& q) {
    if (t < tB - tau - eps) return segments_.value(a, ctx, t, seed, q, why);
    if (t >= tB + tau - eps && tr.to_next) return segments_.value(b, ctx, t, seed, q, why);
    return blends_.value(a, b, tr, ctx, std::min(t, tB + tau), seed, q, why);
  };
  double t = ctx.t_s + std::floor((tB - tau - ctx.t_s) / P + eps) * P;  // the last before
  if (!at(t - P, near, q0) || !at(t, q0, q1)) return pk;
  for (; t <= tB + tau + P; t += P) {
    if (!at(t + P, q1, q2)) return pk;
    add_peaks(q0, q1, q2, P, pk);
    q0 = q1;
    q1 = q2;
  }
  pk.ok = true;
  return pk;
}

}  // namespace rccx::rccl::trajectory
