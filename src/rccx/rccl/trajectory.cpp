#include "rccx/rccl/trajectory.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "rccx/io/fixed_text.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/paul_transition.hpp"
#include "rccx/rccl/trajectory/text.hpp"
#include "rccx/rtc/types.hpp"

namespace rccx::rccl {
namespace {

using kin::JointVector;
using trajectory::GateState;
using trajectory::text;

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

/// The context for evaluating goals at time t: the sample's own, or a prediction (functional
/// transforms called afresh for that time).
SampleContext at_time(const SampleContext& ctx, double t) noexcept {
  if (std::abs(t - ctx.t_s) < 1e-12) return ctx;
  SampleContext c = ctx;
  c.t_s = t;
  c.predicted = true;
  return c;
}

/// Peak acceleration of a transition per unit change of velocity and unit 1/tau: Paul's quartic
/// 0.75, the smoothstep blend of two lines 1.875 (its (2u - 1) s(u) has |d2/du2| <= 7.5 at
/// u = 1/2, and d/dt = d/du / 2 tau).
constexpr double kPaulPeak = 0.75;
constexpr double kSmoothPeak = 1.875;
/// The sample loop stops the arm rather than command a joint acceleration above this multiple
/// of its bound: planned motions stay within the bound; only a singularity or a jump passes it.
constexpr double kAccelerationGuard = 2.0;
/// A segment is slowed at most this much to fit the transition into it.
constexpr double kMaxStretch = 8.0;
/// A transition is sampled and replanned at most this many times.
constexpr int kPlanningPasses = 6;
/// A Cartesian segment is sampled at most this many times when it is planned.
constexpr double kSegmentChecks = 1024.0;
/// A Cartesian segment is slowed at most this much for its own sake (its joints' speeds and
/// accelerations along the line); one that would need more is refused as too close to a
/// singularity.
constexpr double kMaxSegmentStretch = 20.0;
/// ... and its first and last this many periods, every period.
constexpr double kEndChecks = 32.0;

/// The pose a fraction s of the way from a to b: position on the line, rotation about the
/// fixed axis of a⁻¹ b.
math::Transform interpolate(const math::Transform& a, const math::Transform& b, double s) noexcept {
  const math::Rot3 rel = a.R.transposed() * b.R;
  math::Vec3 axis;
  double angle = 0.0;
  rel.to_axis_angle(axis, angle);
  return {a.R * math::Rot3::about(axis, s * angle), a.p + (b.p - a.p) * s};
}

double rotation_angle(const math::Rot3& r) noexcept {
  math::Vec3 axis;
  double angle = 0.0;
  r.to_axis_angle(axis, angle);
  return angle;
}

/// Distance from point p to the segment [a, b], m.
double distance_to_segment(const math::Vec3& p, const math::Vec3& a, const math::Vec3& b) noexcept {
  const math::Vec3 ab = b - a;
  const double len2 = dot(ab, ab);
  const double s = len2 > 0.0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + ab * s)).norm();
}

}  // namespace

TrajectoryGenerator::TrajectoryGenerator(const kin::Kinematics& kinematics,
                                         GeneratorOptions options)
    : model_(kinematics, std::move(options)) {
  reset(model_.kin.model().ready(), 0.0);
}

// --- Segment values ------------------------------------------------------------------------------

double TrajectoryGenerator::fraction(const Segment& s, double t) const noexcept {
  return (t - s.ts) / s.T;
}

void TrajectoryGenerator::pose_at(const Segment& s, const SampleContext& ctx, double r,
                                  Pose& out) const {
  if (s.position->in_joints()) {
    out.goal = s.fixed_goal;
    out.tool = math::Transform::identity();
  } else {
    s.position->evaluate(ctx, s.holds, out.goal, out.tool);
    const Segment& owner = tr_.active && tr_.to_next ? next_ : cur_;
    if (!ctx.predicted && s.id == owner.id && s.position == owner.position) {
      // The present segment's goal as the loop sees it, once a sample: how far its step
      // changed names a goal that jumped when a guard stops the arm.
      GoalTrack& g = goal_track_;
      if (g.position != s.position) {  // (a motion's end keeps it: the arm tracks on)
        g = GoalTrack{};
        g.position = s.position;
      }
      if (!(ctx.t_s <= g.t_s + 1e-9) || g.samples == 0) {
        g.jump_m = g.samples >= 2 ? ((out.goal.p - g.p[1]) - (g.p[1] - g.p[0])).norm() : 0.0;
        g.p[0] = g.p[1];
        g.p[1] = out.goal.p;
        g.t_s = ctx.t_s;
        g.samples = std::min(g.samples + 1, 2);
      }
    }
  }
  out.frame = out.goal * s.drive.at(r);
  // From rest onto a moving goal: the start stays where the arm stood, the end rides on the
  // goal (the goal's displacement since the start, taken back in proportion to 1 - r).
  if (s.fixed_start) out.frame.p += (s.start_goal_p - out.goal.p) * (1.0 - r);
  out.t6 = out.frame * out.tool.inverse();
}

bool TrajectoryGenerator::solve(const Segment& s, const math::Transform& t6,
                                const JointVector& near, JointVector& q,
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

bool TrajectoryGenerator::segment_value(const Segment& s, const SampleContext& ctx, double t,
                                        const JointVector& near, JointVector& q, kin::IkStatus& why,
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
    case Segment::Kind::cartesian: {
      const SampleContext c = at_time(ctx, t);
      const double r = drive_fraction(s, t);
      Pose p;
      pose_at(s, c, r, p);
      if (pose) *pose = p;
      const bool inside = r >= 0.0 && r <= 1.0;
      if ((inside || !linear_past_ends) && solve(s, p.t6, near, q, why)) return true;
      if (inside) return false;
      // Past its ends (a transition blends the segments extended beyond them) the line may
      // leave the workspace or a joint's limits although the blend does not, and a moving goal
      // may carry it out of reach (a conveyor's part the arm is leaving): continue it in joint
      // space from where it is at its end, at the velocity it has there (its drive's and its
      // goal's), from a value a step before, under a period: the tangent must be the
      // derivative at the end, or the blend's velocity jumps where the line takes over (near a
      // singularity the joints' rates change fast along the line).
      const double r_end = r < 0.0 ? 0.0 : 1.0;
      const double t_end = r < 0.0 ? s.ts : s.ts + s.T;
      const double step = std::min(0.01 * s.T, 0.5 * model_.options.period_s);
      const double t_in = r < 0.0 ? t_end + step : t_end - step;
      Pose pe, pi;
      pose_at(s, at_time(ctx, t_end), r_end, pe);
      pose_at(s, at_time(ctx, t_in), fraction(s, t_in), pi);
      JointVector q_end, q_in;
      if (!solve(s, pe.t6, near, q_end, why) || !solve(s, pi.t6, q_end, q_in, why)) return false;
      q = q_end;
      for (std::size_t j = 0; j < q.size(); ++j) {
        q[j] += (q_in[j] - q_end[j]) / (t_in - t_end) * (t - t_end);
      }
      return true;
    }
  }
  return false;
}

/// A goal whose step changes by more than this in one sample has jumped (m).
constexpr double kGoalJump_m = 2e-3;

// --- Building segments
// -----------------------------------------------------------------------------

bool TrajectoryGenerator::build(const MotionRequest& r, const SampleContext& ctx, double t_via) {
  const std::size_t n = model_.kin.dof();
  Segment s;
  s.id = r.id;
  s.position = r.position;
  s.settings = r.settings;
  s.ts = t_via;
  kin::IkStatus why = kin::IkStatus::ok;

  // Where the arm will be at the via point: the present segment's end, its goal where it will
  // be then (a moving goal has moved on by the via time).
  JointVector qB = last_q_;
  math::Transform t6B;
  if (cur_.kind == Segment::Kind::cartesian) {
    Pose p;
    pose_at(cur_, at_time(ctx, t_via), 1.0, p);
    t6B = p.t6;
    if (!solve(cur_, t6B, last_q_, qB, why)) qB = last_q_;
  } else {
    qB = cur_.q1;
    t6B = model_.kin.forward(qB);
  }
  s.q0 = qB;

  if (r.kind == RequestKind::dwell) {
    s.kind = Segment::Kind::joint;
    s.q1 = qB;
    if (cur_.kind == Segment::Kind::cartesian && cur_.position != nullptr &&
        cur_.position->moves()) {
      // RCCL's stop(): the arm stays on the last position for the time, and a position that
      // moves (a conveyor) is tracked meanwhile: the same equation, its drive at its end.
      s.kind = Segment::Kind::cartesian;
      s.position = cur_.position;
      s.borrowed_position = true;
      s.holds = cur_.holds;
      s.fixed_goal = cur_.fixed_goal;
      s.drive = math::DriveTransform(math::Transform::identity(), math::Transform::identity());
      s.start_in_goal = math::Transform::identity();
      s.configuration = cur_.configuration;
      s.has_configuration = cur_.has_configuration;
    }
    s.T = std::max(r.dwell_s, model_.options.period_s);
    s.stop_tau = std::max(model_.options.period_s, 0.5 * s.settings.transition_time_s);
    next_ = s;
    has_next_ = true;
    return true;
  }

  const Position& pos = *r.position;
  const char* name = pos.name().c_str();
  if (pos.in_joints()) {
    const JointVector& g = pos.joint_values();
    if (g.size() != n) {
      fail(r.id, ctx, kin::IkStatus::bad_input, 0,
           text("position {} has {} joint values, the robot {}", name, g.size(), n));
      return false;
    }
    const int out = model_.kin.model().first_joint_outside_limits(g, kin::kLimitTolerance);
    if (out >= 0) {
      fail(r.id, ctx, kin::IkStatus::joint_limits, out + 1,
           text("position {}: joint {} is outside its limits", name, out + 1));
      return false;
    }
    s.fixed_goal = model_.kin.forward(g);
  } else {
    pos.latch(s.holds);
  }

  // The configuration: the one asked for, else the one the arm is in.
  if (!model_.kin.configuration_names().empty()) {
    s.has_configuration = true;
    s.configuration = s.settings.configuration >= 0
                          ? kin::Configuration{static_cast<std::uint8_t>(s.settings.configuration)}
                          : model_.kin.configuration_of(qB);
  }
  Pose goal;
  pose_at(s, ctx, 1.0, goal);  // drive is identity so far: frame = goal
  const math::Transform frameB = t6B * goal.tool;
  const math::Transform offset = goal.goal.inverse_times(frameB);
  // Time from the tool's speeds along the motion (RCCL computes it so in both modes).
  const double by_speed =
      std::max(offset.p.norm() / std::max(s.settings.translation_m_per_s, 1e-9),
               rotation_angle(offset.R) / std::max(s.settings.rotation_rad_per_s, 1e-9));
  double by_joints = 0.0;  // the time the joints' top speeds allow, s
  JointVector end_step;    // cartesian: the joints' change over the line's last part, per unit r
  double by_acceleration = 0.0;
  const auto joint_time = [&](const JointVector& a, const JointVector& b, double scale) {
    for (std::size_t j = 0; j < n; ++j) {
      const double d = std::abs(b[j] - a[j]) * scale;
      by_joints =
          std::max(by_joints, d / (kPlanningSpeedFraction * model_.options.max_velocity[j]));
      // Room for the transitions in and out at the acceleration bound: the part of each that
      // this segment's own velocity v = d / T causes, tau = 1.875 v / a (the smooth blend),
      // takes at most a quarter of T, leaving the rest for its neighbours' velocities.
      by_acceleration = std::max(
          by_acceleration, std::sqrt(4.0 * kSmoothPeak * d / model_.planning_acceleration(j)));
    }
  };

  if (s.settings.mode == Mode::joint) {
    s.kind = Segment::Kind::joint;
    if (pos.in_joints()) {
      s.q1 = pos.joint_values();
    } else if (!solve(s, goal.t6, qB, s.q1, why)) {
      fail(r.id, ctx, why, 0,
           text("position {} cannot be reached in joint mode: {}", name, kin::describe(why)));
      return false;
    }
    joint_time(s.q0, s.q1, 1.0);
  } else {
    s.kind = Segment::Kind::cartesian;
    s.drive = math::DriveTransform(offset, math::Transform::identity());
    s.start_in_goal = s.drive.at(0.0);
    s.fixed_start = cur_.kind == Segment::Kind::rest && pos.moves();
    s.start_world = frameB;
    s.start_goal_p = goal.goal.p;
    // Walk the line before moving: a point out of reach or out of limits, or a joint that would
    // need more than its speed, is reported now rather than in the middle of the motion.
    constexpr int kChecks = 16;
    JointVector q_prev = qB, q;
    end_step = JointVector(n);
    for (int k = 1; k <= kChecks; ++k) {
      Pose p;
      pose_at(s, ctx, static_cast<double>(k) / kChecks, p);
      if (!solve(s, p.t6, q_prev, q, why)) {
        fail(r.id, ctx, why, 0,
             text("the straight line to {} leaves the workspace {:.0f}% of the way: {}", name,
                  100.0 * k / kChecks, kin::describe(why)));
        return false;
      }
      bool at_limit = false;
      const int jumping = find_jump(s, ctx, static_cast<double>(k - 1) / kChecks,
                                    static_cast<double>(k) / kChecks, q_prev, q, at_limit);
      if (jumping > 0 && at_limit) {
        const auto J = static_cast<std::size_t>(jumping - 1);
        const bool revolute = model_.kin.model().joints[J].type == kin::JointType::revolute;
        const double limit = q_prev[J] < q[J] ? model_.lower[J] : model_.upper[J];
        fail(r.id, ctx, kin::IkStatus::joint_limits, jumping,
             text("the straight line to {} turns joint {} past its limit ({:.1f} {}) about "
                  "{:.0f}% of the way (the line takes the shorter way round); move in joint "
                  "mode, which turns it the other way, or add a via point",
                  name, jumping, revolute ? math::rad_to_deg(limit) : limit * 1000.0,
                  revolute ? "deg" : "mm", 100.0 * (k - 0.5) / kChecks));
        return false;
      }
      if (jumping > 0) {
        fail(r.id, ctx, kin::IkStatus::singular, jumping,
             text("the straight line to {} passes through a singularity about {:.0f}% of the "
                  "way: joint {} would jump there; go round it (another line or a via point) "
                  "or move in joint mode",
                  name, 100.0 * (k - 0.5) / kChecks, jumping));
        return false;
      }
      joint_time(q_prev, q, kChecks);
      for (std::size_t j = 0; j < n; ++j) end_step[j] = (q[j] - q_prev[j]) * kChecks;
      q_prev = q;
    }
    s.q1 = q;
  }
  s.T = s.settings.segment_time_s > 0.0 ? s.settings.segment_time_s : by_speed;
  s.T = std::max({s.T, by_joints, by_acceleration, s.settings.transition_time_s,
                  2.0 * model_.options.period_s});
  if (s.kind == Segment::Kind::cartesian) {
    // The checks above see the line at 16 points; near a singularity the joints' speed and
    // acceleration (from the curvature of the path in joint space) peak between them. Sample
    // the line as it will run and slow it down (a longer T: speed falls as 1 / T, acceleration
    // as 1 / T^2) until it keeps within the planning fractions of both bounds.
    // The coarse sweeps (T / 1024) converge fast; the last word is a sweep every period, which
    // is what the loop will run (a stretched line's peak near a singularity can fall between
    // coarse samples).
    const double T0 = s.T;
    bool every_period = false;
    for (int pass = 0;; ++pass) {
      const Peaks pk = segment_peaks(s, ctx, qB, every_period);
      if (!pk.ok) {
        // Between the checks above the line has no solution (it grazes the workspace's edge
        // or a singularity there): it cannot be run at any speed.
        fail(r.id, ctx, pk.why, 0,
             text("the straight line to {} leaves the workspace about {:.0f}% of the way: {}", name,
                  100.0 * std::clamp(pk.unsolved_s / s.T, 0.0, 1.0), kin::describe(pk.why)));
        return false;
      }
      const double k = std::max(pk.speed / kPlanningSpeedFraction,
                                std::sqrt(pk.acceleration / kPlanningAccelerationFraction));
      if (!(k > 1.0)) {
        if (every_period || pos.moves()) break;
        every_period = true;
        continue;
      }
      // (A moving goal's own motion is not the line's: it cannot be slowed, and the loop's guards
      // judge it as it comes.)
      if ((s.T >= kMaxSegmentStretch * T0 || pass >= 3 * kPlanningPasses) && !pos.moves()) {
        // No speed the line may be taken at keeps the joints within their bounds: it runs too
        // close to a singularity (or the edge of the workspace).
        fail(r.id, ctx, kin::IkStatus::singular, 0,
             text("the straight line to {} passes too close to a singularity: even {:.0f} "
                  "times slower a joint would need {:.1f} times its bound; go round it (another "
                  "line or a via point) or move in joint mode",
                  name, s.T / T0, k));
        return false;
      }
      if (pos.moves() && (pass == 2 * kPlanningPasses || s.T >= kMaxSegmentStretch * T0)) break;
      s.T *= std::min(1.02 * k, kMaxSegmentStretch * T0 / s.T);
    }
  }
  s.stop_tau = std::max(model_.options.period_s, 0.5 * s.settings.transition_time_s);
  for (std::size_t j = 0; j < n; ++j) {
    // The velocity at the end, where the arm stops: a Cartesian line's is not its average.
    double v = std::abs(s.q1[j] - s.q0[j]) / s.T;
    if (end_step.size() == n) v = std::max(v, std::abs(end_step[j]) / s.T);
    s.stop_tau = std::max(s.stop_tau, kPaulPeak * v / model_.planning_acceleration(j));
  }
  s.stop_tau = std::min(s.stop_tau, 0.5 * s.T);
  // As for transitions between segments (transition_tau): check the stop as the loop will run
  // it, and lengthen it (and the segment, if need be) while a joint would pass its bound.
  const double planned_T = s.T;
  for (int pass = 0; pass < 3; ++pass) {
    const double worst =
        blend_peaks(s, s, false, blend_between(s, nullptr), s.ts + s.T, s.stop_tau, s.q1, ctx)
            .ratio_or_failed();
    if (!(worst > 1.0)) break;
    // A transition's acceleration falls as 1 / tau; a far larger ratio means a singularity on
    // the way, which lengthening does not cure (the loop will stop the arm there).
    s.stop_tau = std::min(s.stop_tau * std::min(worst * 1.05, 2.0), kMaxStretch * planned_T / 2.0);
    s.T = std::max(s.T, 2.0 * s.stop_tau);
  }
  next_ = s;
  has_next_ = true;
  return true;
}

int TrajectoryGenerator::find_jump(const Segment& s, const SampleContext& ctx, double r0, double r1,
                                   const JointVector& q0, const JointVector& q1,
                                   bool& at_limit) const {
  // A joint that turns a lot between two points of the line is either fast there (fine, the
  // segment time allows for it) or jumping: a change of solution branch at a singularity.
  // Halving the interval tells them apart: a smooth change halves, a jump stays.
  constexpr double kLargeStep_rad = 0.3;
  int joint = -1;
  double largest = kLargeStep_rad;
  for (std::size_t j = 0; j < q0.size(); ++j) {
    if (std::abs(q1[j] - q0[j]) > largest) {
      largest = std::abs(q1[j] - q0[j]);
      joint = static_cast<int>(j);
    }
  }
  if (joint < 0) return 0;
  const auto J = static_cast<std::size_t>(joint);
  JointVector lo = q0, hi = q1, mid;
  kin::IkStatus why;
  for (int i = 0; i < 12; ++i) {  // 4096 times shorter
    const double rm = 0.5 * (r0 + r1);
    Pose p;
    pose_at(s, ctx, rm, p);
    if (!solve(s, p.t6, lo, mid, why)) return 0;  // the caller's checks report it
    if (std::abs(mid[J] - lo[J]) > std::abs(hi[J] - mid[J])) {
      r1 = rm;
      hi = mid;
    } else {
      r0 = rm;
      lo = mid;
    }
  }
  if (!(std::abs(hi[J] - lo[J]) > 0.5 * largest)) return 0;
  // A joint of several turns that the line would take past its limit: the solver gives the
  // same angle a turn the other way round, and the jump's near side sits on the limit.
  constexpr double kAtLimit = 1e-2;  // rad or m
  const auto near_limit = [&](double v) {
    return std::abs(v - model_.lower[J]) < kAtLimit || std::abs(v - model_.upper[J]) < kAtLimit;
  };
  at_limit = near_limit(lo[J]) || near_limit(hi[J]);
  return joint + 1;
}

// --- Transitions ---------------------------------------------------------------------------------

TrajectoryGenerator::Blend TrajectoryGenerator::blend_between(const Segment& a,
                                                              const Segment* b) const noexcept {
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

double TrajectoryGenerator::transition_tau(const Segment& a, Segment& b, Blend blend, double tB,
                                           const SampleContext& ctx) const {
  const double T0 = b.T;
  Peaks pk;
  double tau = plan_transition(a, b, blend, tB, ctx, pk);
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
    const double tau_j = plan_transition(a, alt, Blend::smooth_joint, tB, ctx, pj);
    if (score(pj) < score(pk)) {
      b.T = alt.T;
      b.blend_in = Blend::smooth_joint;
      tau = tau_j;
    }
  }
  return tau;
}

double TrajectoryGenerator::plan_transition(const Segment& a, Segment& b, Blend blend, double tB,
                                            const SampleContext& ctx, Peaks& pk) const {
  const double P = model_.options.period_s;
  const std::size_t n = model_.kin.dof();
  const Segment& owner = a.kind == Segment::Kind::rest ? b : a;
  double tau = std::max(P, 0.5 * owner.settings.transition_time_s);
  // The joint velocities either side of the via point, from values one period apart.
  JointVector qa0, qa1, qb0, qb1;
  kin::IkStatus why;
  if (!segment_value(a, ctx, tB - P, last_q_, qa0, why) ||
      !segment_value(a, ctx, tB, last_q_, qa1, why) || !segment_value(b, ctx, tB, qa1, qb0, why) ||
      !segment_value(b, ctx, tB + P, qb0, qb1, why)) {
    return tau;
  }
  JointVector va(n), vb(n);
  for (std::size_t j = 0; j < n; ++j) {
    va[j] = (qa1[j] - qa0[j]) / P;
    vb[j] = (qb1[j] - qb0[j]) / P;
  }
  // Every blend is Paul's quartic between lines (the smooth ones through their overshoot
  // correction), whose peak acceleration is 0.75 dv / tau.
  const double peak = kPaulPeak;
  const auto needed = [&] {
    double t = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      t = std::max(t, peak * std::abs(vb[j] - va[j]) / model_.planning_acceleration(j));
    }
    return t;
  };
  // The transition may not reach back past the start of a's straight part: when the change of
  // velocity needs longer than a has left, b (not started yet) is slowed down until it fits -
  // its velocity scales as 1 / T.
  // (Nor before now: a segment shorter than its transitions is joined late.)
  const double room = a.kind == Segment::Kind::rest
                          ? std::numeric_limits<double>::infinity()
                          : std::max(P, std::min(tB - (a.ts + a.tau_in), tB - ctx.t_s + 1e-9));
  double stretched = 1.0;  // b.T grows by at most kMaxStretch in all
  if (b.kind != Segment::Kind::rest && std::isfinite(room)) {
    double stretch = 1.0;
    for (std::size_t j = 0; j < n; ++j) {
      const double w = model_.planning_acceleration(j) * room / peak;  // the |dv| a's room allows
      if (std::abs(vb[j] - va[j]) <= w) continue;
      const double side = w + (vb[j] > 0.0 ? va[j] : -va[j]);  // b's bound on its side of 0
      if (side > 0.0) stretch = std::max(stretch, std::abs(vb[j]) / side);
    }
    stretch = std::min(stretch, kMaxStretch);
    b.T *= stretch;
    stretched *= stretch;
    for (std::size_t j = 0; j < n; ++j) vb[j] /= stretch;
  }
  tau = std::max(tau, needed());
  // Nor beyond half of b: b is lengthened instead (twice, as slowing b changes the need).
  for (int i = 0; i < 2 && b.kind != Segment::Kind::rest && tau > 0.5 * b.T; ++i) {
    const double stretch = std::min(2.0 * tau / b.T, kMaxStretch / stretched);
    if (!(stretch > 1.0)) break;
    b.T *= stretch;
    stretched *= stretch;
    for (std::size_t j = 0; j < n; ++j) vb[j] /= stretch;
    tau = std::max(std::max(P, 0.5 * owner.settings.transition_time_s), needed());
  }
  if (b.kind != Segment::Kind::rest) tau = std::min(tau, std::max(P, 0.5 * b.T));
  tau = std::min(tau, room);
  pk = Peaks{};
  // The estimate above is for straight lines in joint space; a Cartesian blend bends them, and
  // a moving goal adds its own velocity. Sample the transition as the loop will run it: while a
  // joint would accelerate past its bound, lengthen the transition (and b when it must); while
  // one would pass its top speed, slow b down (its velocity scales as 1 / T, the transition's
  // velocity passes between a's and b's).
  for (int pass = 0;; ++pass) {
    pk = blend_peaks(a, b, true, blend, tB, tau, last_q_, ctx);
    if (!pk.ok || pass == kPlanningPasses) break;
    bool changed = false;
    if (pk.speed > kTransitionSpeedFraction && stretched < kMaxStretch) {
      const double stretch =
          std::min(1.02 * pk.speed / kTransitionSpeedFraction, kMaxStretch / stretched);
      b.T *= stretch;
      stretched *= stretch;
      changed = true;
    }
    if (pk.acceleration > 1.0 && tau < room) {
      tau = std::min(room, tau * std::min(pk.acceleration * 1.05, 2.0));
      changed = true;
    }
    if (tau > 0.5 * b.T) {
      const double stretch = std::min(2.0 * tau / b.T, kMaxStretch / stretched);
      if (stretch > 1.0) {
        b.T *= stretch;
        stretched *= stretch;
      }
      tau = std::min(tau, 0.5 * b.T);
    }
    if (!changed) break;
  }
  return tau;
}

void TrajectoryGenerator::add_peaks(const JointVector& q0, const JointVector& q1,
                                    const JointVector& q2, double h, Peaks& pk) const noexcept {
  for (std::size_t j = 0; j < q1.size(); ++j) {
    const double acc = std::abs(q2[j] - 2.0 * q1[j] + q0[j]) / (h * h);
    pk.acceleration = std::max(pk.acceleration, acc / model_.options.max_acceleration[j]);
    pk.speed = std::max(pk.speed, std::abs(q2[j] - q1[j]) / h / model_.options.max_velocity[j]);
  }
}

TrajectoryGenerator::Peaks TrajectoryGenerator::segment_peaks(const Segment& s,
                                                              const SampleContext& ctx,
                                                              const JointVector& near,
                                                              bool every_period) const {
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
  const auto sweep = [&](double from, double to, double h, const JointVector& seed) {
    JointVector q0, q1, q2;
    if (!segment_value(s, ctx, from, seed, q0, why)) return unsolved(from);
    if (!segment_value(s, ctx, from + h, q0, q1, why)) return unsolved(from + h);
    for (double t = from + 2.0 * h; t <= to + 1e-9; t += h) {
      if (!segment_value(s, ctx, t, q1, q2, why)) return unsolved(t);
      add_peaks(q0, q1, q2, h, pk);
      q0 = q1;
      q1 = q2;
    }
    return true;
  };
  const double P = model_.options.period_s;
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

TrajectoryGenerator::Peaks TrajectoryGenerator::blend_peaks(const Segment& a, const Segment& b,
                                                            bool to_next, Blend blend, double tB,
                                                            double tau, const JointVector& near,
                                                            const SampleContext& ctx) const {
  const double P = model_.options.period_s;
  Peaks pk;
  Tangents tg;
  if (to_next && !tangents(a, b, blend, tB, near, ctx, tg)) return pk;
  JointVector q0, q1, q2;
  kin::IkStatus why;
  // As the loop will run it: on its sample times (ctx.t_s + k P), the segments' values either
  // side of the window, so that the joins are judged too.
  const double eps = 1e-9;
  const auto at = [&](double t, const JointVector& seed, JointVector& q) {
    if (t < tB - tau - eps) return segment_value(a, ctx, t, seed, q, why);
    if (t >= tB + tau - eps && to_next) return segment_value(b, ctx, t, seed, q, why);
    return blend_value(a, b, to_next, blend, tB, tau, tg, ctx, std::min(t, tB + tau), seed, q, why);
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

void TrajectoryGenerator::begin_transition(const SampleContext& ctx, double tB, double tau,
                                           Blend blend, bool to_next) {
  tr_.tangents = Tangents{};
  if (to_next) tangents(cur_, next_, blend, tB, last_q_, ctx, tr_.tangents);
  tr_.active = true;
  tr_.tB = tB;
  tr_.tau = tau;
  tr_.blend = blend;
  tr_.to_next = to_next;
  have_last_frame_ = false;
  if (to_next) {
    next_.tau_in = tau;
    ledger_.mark_started(next_.id);
    queue_.emit(EventKind::started, next_.id, ctx);
    SegmentReport& rep = queue_.report_slot(next_.id);
    rep = SegmentReport{};
    rep.id = next_.id;
    rep.mode = next_.kind == Segment::Kind::cartesian ? Mode::cartesian : Mode::joint;
    rep.start_s = ctx.t_s;
    rep.duration_s = next_.T;
  }
}

void TrajectoryGenerator::finish_transition(const SampleContext& ctx) {
  tr_.active = false;
  if (tr_.to_next) {
    end_motion(cur_, ctx);
    cur_ = next_;
    has_next_ = false;
    return;
  }
  // Came to rest at the end of cur_: exactly its end point, or tracking its moving goal.
  end_motion(cur_, ctx);
  if (cur_.kind == Segment::Kind::cartesian && cur_.position->moves()) {
    cur_.resting = true;
    cur_.id = 0;
    return;
  }
  JointVector q = cur_.q1;
  kin::IkStatus why;
  if (cur_.kind == Segment::Kind::cartesian) {
    Pose p;
    pose_at(cur_, ctx, 1.0, p);
    if (!solve(cur_, p.t6, last_q_, q, why)) q = last_q_;
  }
  rest_at(q);
}

bool TrajectoryGenerator::value(const SampleContext& ctx, double t, JointVector& q,
                                kin::IkStatus& why) {
  if (!tr_.active) {
    Pose p;
    const bool ok = segment_value(cur_, ctx, t, last_q_, q, why, &p);
    if (ok && cur_.kind == Segment::Kind::cartesian && !cur_.resting) {
      pose_ = p;
      pose_valid_ = true;
    }
    return ok;
  }
  return blend_value(cur_, tr_.to_next ? next_ : cur_, tr_.to_next, tr_.blend, tr_.tB, tr_.tau,
                     tr_.tangents, ctx, t, last_q_, q, why);
}

bool TrajectoryGenerator::tangents(const Segment& a, const Segment& b, Blend blend, double tB,
                                   const JointVector& near, const SampleContext& ctx,
                                   Tangents& out) const {
  const double P = model_.options.period_s;
  if (blend == Blend::smooth_joint) {
    JointVector qa0, qa1, qb0, qb1;
    kin::IkStatus why;
    if (!segment_value(a, ctx, tB - P, near, qa0, why) ||
        !segment_value(a, ctx, tB, qa0, qa1, why) || !segment_value(b, ctx, tB, qa1, qb0, why) ||
        !segment_value(b, ctx, tB + P, qb0, qb1, why)) {
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
  if (blend == Blend::smooth_pose) {
    Pose p0, p1;
    out.va_p = {};
    if (a.kind != Segment::Kind::rest) {
      pose_at(a, at_time(ctx, tB - P), drive_fraction(a, tB - P), p0);
      pose_at(a, at_time(ctx, tB), drive_fraction(a, tB), p1);
      out.va_p = (p1.t6.p - p0.t6.p) * (1.0 / P);
    }
    pose_at(b, at_time(ctx, tB), drive_fraction(b, tB), p0);
    pose_at(b, at_time(ctx, tB + P), drive_fraction(b, tB + P), p1);
    out.vb_p = (p1.t6.p - p0.t6.p) * (1.0 / P);
  }
  return true;
}

bool TrajectoryGenerator::blend_value(const Segment& a, const Segment& b, bool to_next, Blend blend,
                                      double tB, double tau, const Tangents& tg,
                                      const SampleContext& ctx, double t, const JointVector& near,
                                      JointVector& q, kin::IkStatus& why) const {
  const SampleContext c = at_time(ctx, t);
  const double u = (t - (tB - tau)) / (2.0 * tau);
  switch (blend) {
    case Blend::paul_joint: {
      // Per coordinate, from a's line onto b's (or to rest at the via point).
      JointVector qa, qB, qc;
      const Segment stop = rest_of(a);
      const Segment& to = to_next ? b : stop;
      if (!segment_value(a, ctx, tB - tau, near, qa, why) ||
          !segment_value(a, ctx, tB, near, qB, why) ||
          !segment_value(to, ctx, tB + tau, qB, qc, why)) {
        return false;
      }
      q = qB;
      for (std::size_t j = 0; j < q.size(); ++j) {
        q[j] = paul_transition(qB[j], qa[j] - qB[j], qc[j] - qB[j], tau, tau, t - tB).q;
      }
      return true;
    }
    case Blend::paul_r_in: {
      const double r = paul_transition(0.0, 0.0, tau / b.T, tau, tau, t - tB).q;
      Pose p;
      pose_at(b, c, r, p);
      return solve(b, p.t6, near, q, why);
    }
    case Blend::paul_r_out: {
      const double r = paul_transition(1.0, -tau / a.T, 0.0, tau, tau, t - tB).q;
      Pose p;
      pose_at(a, c, r, p);
      return solve(a, p.t6, near, q, why);
    }
    case Blend::smooth_pose: {
      Pose pa, pb;
      if (a.kind == Segment::Kind::rest) {
        pa.t6 = model_.kin.forward(a.q1);
      } else {
        pose_at(a, c, drive_fraction(a, t), pa);
      }
      pose_at(b, c, drive_fraction(b, t), pb);
      const double s = smoothstep(u);
      const bool on_a = s < 0.5 && a.kind != Segment::Kind::rest;
      math::Transform x = interpolate(pa.t6, pb.t6, s);
      x.p = x.p + (tg.vb_p - tg.va_p) * (2.0 * tau * overshoot_correction(u));
      return solve(on_a ? a : b, x, near, q, why);
    }
    case Blend::smooth_joint: {
      JointVector qa, qb;
      // Each segment continued past its ends in joint space, on its tangent there: a Cartesian
      // line extended as a line may pass a singularity that the blend never comes near.
      if (!segment_value(a, ctx, t, near, qa, why, nullptr, true) ||
          !segment_value(b, ctx, t, near, qb, why, nullptr, true)) {
        return false;
      }
      const double s = smoothstep(u);
      const double w = 2.0 * tau * overshoot_correction(u);
      q = qa;
      const bool corrected = tg.va.size() == q.size() && tg.vb.size() == q.size();
      for (std::size_t j = 0; j < q.size(); ++j) {
        q[j] += s * (qb[j] - qa[j]) + (corrected ? (tg.vb[j] - tg.va[j]) * w : 0.0);
      }
      return true;
    }
  }
  return false;
}

TrajectoryGenerator::Segment TrajectoryGenerator::rest_of(const Segment& a) const noexcept {
  Segment r;
  r.kind = Segment::Kind::rest;
  r.q1 = a.kind == Segment::Kind::joint ? a.q1 : last_q_;
  return r;
}

// --- Ending, failing, halting --------------------------------------------------------------------

void TrajectoryGenerator::end_motion(const Segment& s, const SampleContext& ctx,
                                     std::string_view text) noexcept {
  if (s.id == 0) return;
  SegmentReport& rep = queue_.report_slot(s.id);
  if (rep.id == s.id) rep.end_s = ctx.t_s;
  if (s.position != nullptr && !s.borrowed_position) {
    s.position->pending_ends.fetch_sub(1, std::memory_order_acq_rel);
  }
  queue_.emit(EventKind::ended, s.id, ctx, kin::IkStatus::ok, 0, text);
  ledger_.mark_ended(s.id);
}

const MotionSettings* TrajectoryGenerator::running_settings(std::uint64_t id) const noexcept {
  if (id == 0) return nullptr;
  if (cur_.id == id) return &cur_.settings;
  if (has_next_ && next_.id == id) return &next_.settings;
  return nullptr;
}

void TrajectoryGenerator::next_motion(const SampleContext& ctx) noexcept {
  const bool moving = tr_.active || (cur_.kind != Segment::Kind::rest && !cur_.resting);
  if (halting_ || !moving) return;
  if (tr_.active && tr_.to_next) {
    // Between two motions: the one ending and the one beginning both end here.
    end_motion(cur_, ctx, kNextmoveText);
    end_motion(next_, ctx, kNextmoveText);
  } else {
    if (cur_.kind != Segment::Kind::rest && !cur_.resting) end_motion(cur_, ctx, kNextmoveText);
    // Joined but not begun: it starts from rest once the arm has stopped, before the request
    // taken after it.
    if (has_next_) queue_.put_back_joined();
  }
  queue_.drop_joined();
  has_next_ = false;
  tr_.active = false;
  cur_.id = 0;
  start_halt();
}

void TrajectoryGenerator::fail(std::uint64_t id, const SampleContext& ctx, kin::IkStatus status,
                               int joint, const Text& text) noexcept {
  SegmentReport& rep = queue_.report_slot(id);
  rep.id = id;
  rep.failed = true;
  rep.end_s = ctx.t_s;
  queue_.emit(EventKind::failed, id, ctx, status, joint, std::string_view(text.data()));
  // Everything from the motion running now to the last one queued ends here.
  std::uint64_t last = id;
  const auto cancel = [&](const Segment& s) {
    if (s.id == 0) return;
    if (s.id != id) queue_.emit(EventKind::cancelled, s.id, ctx);
    if (s.position != nullptr && !s.borrowed_position) {
      s.position->pending_ends.fetch_sub(1, std::memory_order_acq_rel);
    }
    last = std::max(last, s.id);
  };
  if (cur_.kind != Segment::Kind::rest) cancel(cur_);
  if (has_next_) cancel(next_);
  queue_.cancel_all(text, [&](const MotionRequest& r) {
    Segment w;
    w.id = r.id;
    w.position = r.position;
    cancel(w);
  });
  has_next_ = false;
  tr_.active = false;
  ledger_.mark_failed(id, last);
  start_halt();
}

void TrajectoryGenerator::request_stop(std::string_view why) noexcept {
  const std::size_t n = std::min(why.size(), kEventText - 1);
  std::copy_n(why.data(), n, stop_text_.data());
  stop_text_[n] = '\0';
  stop_requested_ = true;
}

void TrajectoryGenerator::start_halt() noexcept {
  halt_.start(model_, last_q_, prev_q_, last_t_);
  halting_ = true;
}

void TrajectoryGenerator::halt_value(double t, JointVector& q) noexcept {
  if (!halt_.value(t, q)) {
    halting_ = false;
    rest_at(q);
  }
}

void TrajectoryGenerator::rest_at(const JointVector& q) noexcept {
  cur_ = Segment{};
  cur_.kind = Segment::Kind::rest;
  cur_.q1 = q;
  pose_valid_ = false;
}

// --- Gates and rendezvous
// -------------------------------------------------------------------------

void TrajectoryGenerator::start_waiting(const SampleContext& ctx, double t) {
  Rendezvous* rv = queue_.waiting()->together;
  const double eps = 1e-9;
  // Samples are for the tick's time (How); the setpoint time runs the pipeline ahead of it.
  const double now = ctx.how != nullptr ? ctx.how->time_s : t;
  if (rv != nullptr && !(rv->start_s() >= 0.0 && now >= rv->start_s() - eps)) {
    if (queue_.rendezvous_ready() || rv->start_s() >= 0.0) return;  // the others', or the start
    // Plan as if starting now, to tell the others how long this motion takes; build again at
    // the start (a goal may move meanwhile).
    const MotionRequest r = *queue_.waiting();
    if (!build(r, ctx, t)) return;  // failed: fail() withdrew it
    const double tau = transition_tau(cur_, next_, blend_between(cur_, &next_), t, ctx);
    has_next_ = false;
    queue_.set_rendezvous_ready();
    rv->ready(r.slot, now, tau + next_.T + next_.stop_tau, model_.options.period_s);
    return;
  }
  const MotionRequest r = *queue_.waiting();
  if (cur_.kind == Segment::Kind::cartesian && cur_.resting) {
    // Tracking the last motion's goal, which has just jumped (a varb given a new value right
    // before this move()): start from where the arm stands, not from the goal's new place.
    // (Evaluating the goal for this sample is what records its step in goal_track_.)
    Pose p;
    pose_at(cur_, ctx, 1.0, p);
    if (goal_track_.position == cur_.position && goal_track_.jump_m > kGoalJump_m) {
      rest_at(last_q_);
    }
  }
  // From rest: the transition begins now; the straight part tau later.
  if (!build(r, ctx, t)) return;
  queue_.started();
  const double tau = transition_tau(cur_, next_, blend_between(cur_, &next_), t, ctx);
  if (rv != nullptr && rv->end_together()) {
    // Slowed to the slowest: the straight part takes the time left between both transitions
    // (planned for the faster motion, so they stay within the bounds for the slower one).
    next_.T = std::max(next_.T, rv->duration_s() - tau - next_.stop_tau);
  }
  next_.ts = t + tau;
  begin_transition(ctx, t + tau, tau, next_.blend_in, true);
}

void TrajectoryGenerator::reset(const JointVector& q, double t_s) noexcept {
  queue_.reset(text("its robot's control started again"));
  next_requested_.store(false);
  has_next_ = false;
  tr_ = Transition{};
  halt_ = trajectory::Halt{};
  halting_ = false;
  halt_requested_.store(false);
  stop_requested_ = false;
  last_motion_ = 0;
  rest_at(q);
  last_q_ = prev_q_ = q;
  last_t_ = t_s - model_.options.period_s;
}

bool TrajectoryGenerator::at_rest() const noexcept {
  return !halting_ && !tr_.active && !has_next_ && queue_.idle() &&
         (cur_.kind == Segment::Kind::rest || cur_.resting);
}

std::uint64_t TrajectoryGenerator::step(const SampleContext& ctx, const JointVector* measured,
                                        JointVector& q) {
  const double t = ctx.t_s;
  const double P = model_.options.period_s;
  const double eps = 1e-9;
  pose_valid_ = false;

  if (halt_requested_.exchange(false, std::memory_order_acq_rel) && !at_rest()) {
    const std::uint64_t id = cur_.id != 0 ? cur_.id : (has_next_ ? next_.id : 0);
    fail(id, ctx, kin::IkStatus::ok, 0, text("halted by the program"));
  }
  if (stop_requested_) {
    stop_requested_ = false;
    const bool tracking = cur_.kind == Segment::Kind::cartesian && cur_.resting;
    if (!halting_ && !at_rest()) {
      const std::uint64_t id = cur_.id != 0 ? cur_.id : (has_next_ ? next_.id : 0);
      fail(id, ctx, kin::IkStatus::ok, 0, stop_text_);
    } else if (!halting_ && tracking) {
      // Its motion has ended already: no motion to fail, only the tracking to stop.
      queue_.emit(EventKind::failed, 0, ctx, kin::IkStatus::ok, 0,
                  std::string_view(stop_text_.data()));
      start_halt();
    }
  }
  if (next_requested_.exchange(false, std::memory_order_acq_rel)) next_motion(ctx);
  queue_.take();

  if (!halting_ && !tr_.active) {
    const bool resting = cur_.kind == Segment::Kind::rest || cur_.resting;
    if (resting && queue_.waiting() != nullptr) {
      Text why{};
      switch (queue_.gate_state(why)) {
        case GateState::open:
          start_waiting(ctx, t);
          break;
        case GateState::cancel:
          fail(queue_.waiting()->id, ctx, kin::IkStatus::ok, 0, why);
          break;
        case GateState::closed:
          break;
      }
    } else if (!resting) {
      const double te = cur_.ts + cur_.T;
      // A gated motion joins its predecessor only when it may start already; one with a
      // rendezvous always starts from rest, where the others can wait for it.
      Text why{};
      const MotionRequest* w = queue_.waiting();
      const bool may_join = w != nullptr && w->together == nullptr &&
                            (w->gates == 0 || queue_.gate_state(why) == GateState::open);
      if (!has_next_ && may_join && t < te - cur_.stop_tau - eps) {
        if (build(*w, ctx, te)) {
          queue_.join();
          next_tau_ = transition_tau(cur_, next_, blend_between(cur_, &next_), te, ctx);
          // Decided late: the window must not have begun already.
          next_tau_ = std::min(next_tau_, te - t);
        }
      }
      if (has_next_ && t >= te - next_tau_ - eps) {
        begin_transition(ctx, te, next_tau_, next_.blend_in, true);
      } else if (!has_next_ && t >= te - cur_.stop_tau - eps) {
        begin_transition(ctx, te, cur_.stop_tau, blend_between(cur_, nullptr), false);
      }
    }
  }
  if (tr_.active && t >= tr_.tB + tr_.tau - eps) finish_transition(ctx);

  kin::IkStatus why = kin::IkStatus::ok;
  if (halting_) {
    halt_value(t, q);
  } else if (!value(ctx, t, q, why)) {
    const std::uint64_t id = tr_.active && tr_.to_next ? next_.id : cur_.id;
    fail(id, ctx, why, 0,
         text("the path cannot be followed at t = {:.3f} s: {}", t, kin::describe(why)));
    halt_value(t, q);
  } else {
    // Never out of limits, never faster than a joint may go, never a jump of velocity (a path
    // through a singularity, an IK solution changing branch, a goal that leapt): stop instead.
    for (std::size_t j = 0; j < q.size(); ++j) {
      const double speed = std::abs(q[j] - last_q_[j]) / P;
      const double accel = std::abs((q[j] - last_q_[j]) - (last_q_[j] - prev_q_[j])) / (P * P);
      const bool out = !(q[j] >= model_.lower[j] - kin::kLimitTolerance &&
                         q[j] <= model_.upper[j] + kin::kLimitTolerance);
      const bool fast = !(speed <= model_.options.max_velocity[j] * (1.0 + 1e-6));
      const bool jerky = !(accel <= kAccelerationGuard * model_.options.max_acceleration[j]);
      if (out || fast || jerky) {
        const std::uint64_t id = tr_.active && tr_.to_next ? next_.id : cur_.id;
        const int joint = static_cast<int>(j) + 1;
        const Segment& owner = tr_.active && tr_.to_next ? next_ : cur_;
        if (goal_track_.position == owner.position && goal_track_.jump_m > kGoalJump_m &&
            owner.position != nullptr) {
          fail(id, ctx, kin::IkStatus::ok, joint,
               text("the goal of {} jumped {:.1f} mm in a sample at t = {:.3f} s, joint {} "
                    "would follow too fast (a varb changed at once? Use hold, read at move(), "
                    "or change it in small steps)",
                    owner.position->name(), goal_track_.jump_m * 1e3, t, joint));
        } else if (out) {
          fail(id, ctx, kin::IkStatus::joint_limits, joint,
               text("joint {} would leave its limits at t = {:.3f} s", joint, t));
        } else if (fast) {
          fail(id, ctx, kin::IkStatus::singular, joint,
               text("joint {} would move at {:.3f}/s, above its top speed {:.3f}/s at t = {:.3f} "
                    "s (the path passes near a singularity?)",
                    joint, speed, model_.options.max_velocity[j], t));
        } else {
          fail(id, ctx, kin::IkStatus::singular, joint,
               text("joint {} would accelerate at {:.1f}/s^2, {:.1f} times its bound, at t = "
                    "{:.3f} s (the path passes near a singularity, or its goal jumped)",
                    joint, accel, accel / model_.options.max_acceleration[j], t));
        }
        halt_value(t, q);
        break;
      }
    }
  }
  for (std::size_t j = 0; j < q.size(); ++j)
    q[j] = std::clamp(q[j], model_.lower[j], model_.upper[j]);
  record(ctx, q, measured);
  prev_q_ = last_q_;
  last_q_ = q;
  last_t_ = t;
  last_motion_ = tr_.active && tr_.to_next ? next_.id : cur_.id;
  return last_motion_;
}

void TrajectoryGenerator::record(const SampleContext& ctx, const JointVector& q,
                                 const JointVector* measured) noexcept {
  if (tr_.active || halting_ || cur_.id == 0) return;
  SegmentReport& rep = queue_.report_slot(cur_.id);
  if (rep.id != cur_.id || !pose_valid_) return;
  const double P = model_.options.period_s;
  // The line as it stands for the present goal: from the start to the goal, in base frame.
  const math::Vec3 from =
      cur_.fixed_start ? cur_.start_world.p : (pose_.goal * cur_.start_in_goal).p;
  const math::Vec3 to = pose_.goal.p;
  ++rep.straight_samples;
  rep.max_commanded_path_error_m =
      std::max(rep.max_commanded_path_error_m, distance_to_segment(pose_.frame.p, from, to));
  if (have_last_frame_) {
    rep.peak_tool_speed_m_per_s =
        std::max(rep.peak_tool_speed_m_per_s, (pose_.frame.p - last_frame_p_).norm() / P);
  }
  // The measured arm lags the command by the pipeline (about two periods): judge it once the
  // transition in is that far behind.
  if (measured != nullptr && measured->size() == q.size() &&
      ctx.t_s >= cur_.ts + cur_.tau_in + 3.0 * P) {
    const math::Transform frame = model_.kin.forward(*measured) * pose_.tool;
    rep.max_measured_path_error_m =
        std::max(rep.max_measured_path_error_m, distance_to_segment(frame.p, from, to));
    const double c = std::clamp(dot(frame.R.a, pose_.frame.R.a), -1.0, 1.0);
    rep.max_approach_error_rad = std::max(rep.max_approach_error_rad, std::acos(c));
  }
  last_frame_p_ = pose_.frame.p;
  have_last_frame_ = true;
}

}  // namespace rccx::rccl
