#include "rccx/rccl/trajectory/segment.hpp"

#include <algorithm>

#include "rccx/rccl/trajectory/loop_state.hpp"

namespace rccx::rccl::trajectory {

void GoalTrack::see(const Position* at, const math::Vec3& goal_p, double t) noexcept {
  if (position != at) {  // (a motion's end keeps it: the arm tracks on)
    *this = GoalTrack{};
    position = at;
  }
  if (!(t <= t_s + 1e-9) || samples == 0) {
    jump_m = samples >= 2 ? ((goal_p - p[1]) - (p[1] - p[0])).norm() : 0.0;
    p[0] = p[1];
    p[1] = goal_p;
    t_s = t;
    samples = std::min(samples + 1, 2);
  }
}

void SegmentEvaluator::pose_at(const Segment& s, const SampleContext& ctx, double r,
                               Pose& out) const {
  if (s.position->in_joints()) {
    out.goal = s.fixed_goal;
    out.tool = math::Transform::identity();
  } else {
    s.position->evaluate(ctx, s.holds, out.goal, out.tool);
    const Segment& owner = loop_.present();
    // The present segment's goal as the loop sees it, once a sample: how far its step changed
    // names a goal that jumped when a guard stops the arm.
    if (!ctx.predicted && s.id == owner.id && s.position == owner.position) {
      goals_.see(s.position, out.goal.p, ctx.t_s);
    }
  }
  out.frame = out.goal * s.drive.at(r);
  // From rest onto a moving goal: the start stays where the arm stood, the end rides on the
  // goal (the goal's displacement since the start, taken back in proportion to 1 - r).
  if (s.fixed_start) out.frame.p += (s.start_goal_p - out.goal.p) * (1.0 - r);
  out.t6 = out.frame * out.tool.inverse();
}

bool SegmentEvaluator::solve(const Segment& s, const math::Transform& t6,
                             const kin::JointVector& near, kin::JointVector& q,
                             kin::IkStatus& why) const noexcept {
  kin::IkOptions o;
  if (s.has_configuration) o.configuration = s.configuration;
  o.near = near;
  const kin::IkResult r = model_.kin.inverse(t6, o);
  if (!r) {
    why = r.status;
    return false;
  }
  q = r.q;
  return true;
}

bool SegmentEvaluator::value(const Segment& s, const SampleContext& ctx, double t,
                             const kin::JointVector& near, kin::JointVector& q, kin::IkStatus& why,
                             Pose* pose, bool linear_past_ends) const {
  switch (s.kind) {
    case Segment::Kind::rest:
      q = s.q1;
      return true;
    case Segment::Kind::joint: {
      const double r = fraction(s, t);
      q = s.q0;
      for (std::size_t j = 0; j < q.size(); ++j) q[j] += (s.q1[j] - s.q0[j]) * r;
      return true;
    }
    case Segment::Kind::cartesian:
      return cartesian_value(s, ctx, t, near, q, why, pose, linear_past_ends);
  }
  return false;
}

bool SegmentEvaluator::cartesian_value(const Segment& s, const SampleContext& ctx, double t,
                                       const kin::JointVector& near, kin::JointVector& q,
                                       kin::IkStatus& why, Pose* pose,
                                       bool linear_past_ends) const {
  const SampleContext c = at_time(ctx, t);
  const double r = drive_fraction(s, t);
  Pose p;
  pose_at(s, c, r, p);
  if (pose) *pose = p;
  const bool inside = r >= 0.0 && r <= 1.0;
  if ((inside || !linear_past_ends) && solve(s, p.t6, near, q, why)) return true;
  if (inside) return false;
  return past_end_value(s, ctx, t, r, near, q, why);
}

bool SegmentEvaluator::past_end_value(const Segment& s, const SampleContext& ctx, double t,
                                      double r, const kin::JointVector& near, kin::JointVector& q,
                                      kin::IkStatus& why) const {
  // Past its ends (a transition blends the segments extended beyond them) the line may leave
  // the workspace or a joint's limits although the blend does not, and a moving goal may carry
  // it out of reach (a conveyor's part the arm is leaving): continue it in joint space from
  // where it is at its end, at the velocity it has there (its drive's and its goal's), from a
  // value a step before, under a period: the tangent must be the derivative at the end, or the
  // blend's velocity jumps where the line takes over (near a singularity the joints' rates
  // change fast along the line).
  const double r_end = r < 0.0 ? 0.0 : 1.0;
  const double t_end = r < 0.0 ? s.ts : s.ts + s.T;
  const double step = std::min(0.01 * s.T, 0.5 * model_.options.period_s);
  const double t_in = r < 0.0 ? t_end + step : t_end - step;
  Pose pe, pi;
  pose_at(s, at_time(ctx, t_end), r_end, pe);
  pose_at(s, at_time(ctx, t_in), fraction(s, t_in), pi);
  kin::JointVector q_end, q_in;
  if (!solve(s, pe.t6, near, q_end, why) || !solve(s, pi.t6, q_end, q_in, why)) return false;
  q = q_end;
  for (std::size_t j = 0; j < q.size(); ++j) {
    q[j] += (q_in[j] - q_end[j]) / (t_in - t_end) * (t - t_end);
  }
  return true;
}

Segment SegmentEvaluator::rest_of(const Segment& a) const noexcept {
  Segment r;
  r.kind = Segment::Kind::rest;
  r.q1 = a.kind == Segment::Kind::joint ? a.q1 : loop_.last_q;
  return r;
}

}  // namespace rccx::rccl::trajectory
