#include "rccx/rccl/trajectory/segment_builder.hpp"

#include <algorithm>
#include <cmath>

#include "rccx/math/units.hpp"
#include "rccx/rccl/trajectory/loop_state.hpp"
#include "rccx/rccl/trajectory/text.hpp"

namespace rccx::rccl::trajectory {
namespace {

double rotation_angle(const math::Rot3& r) noexcept {
  math::Vec3 axis;
  double angle = 0.0;
  r.to_axis_angle(axis, angle);
  return angle;
}

/// The shortest stop at a segment's end: a period, or half its transition time (s).
double base_stop_tau(const Segment& s, double period_s) noexcept {
  return std::max(period_s, 0.5 * s.settings.transition_time_s);
}

}  // namespace

std::optional<Failure> SegmentBuilder::build(const MotionRequest& r, const SampleContext& ctx,
                                             double t_via, Segment& s) const {
  s.id = r.id;
  s.position = r.position;
  s.settings = r.settings;
  s.ts = t_via;
  const Via via = via_point(ctx, t_via);
  s.q0 = via.q;
  if (r.kind == RequestKind::dwell) {
    dwell(r, s);
    return std::nullopt;
  }
  const Position& pos = *r.position;
  if (auto f = check_goal(pos, s)) return f;
  choose_configuration(s, via.q);
  // The goal where it will be at the via time, as the arm's pose there is: the line starts at
  // F(ts) = G(ts) D(0), so a moving goal taken now would shift its start by the goal's motion
  // over the look-ahead (a part on a belt: the descent onto it swept along the belt).
  Pose goal;
  segments().pose_at(s, at_time(ctx, t_via), 1.0, goal);  // drive is identity so far: F = G
  Timing timing;
  if (s.settings.mode == Mode::joint) {
    if (auto f = joint_goal(pos, goal, s, timing)) return f;
    s.T = segment_time(s, via.t6, goal, timing);
    // A joint line ends on fixed joints: onto a moving goal, those of the goal where it will be
    // when the line ends (its time depends on them: a few rounds settle it).
    for (int round = 0; round < 3 && pos.moves() && !pos.in_joints(); ++round) {
      segments().pose_at(s, at_time(ctx, t_via + s.T), 1.0, goal);
      timing = Timing{};
      if (auto f = joint_goal(pos, goal, s, timing)) return f;
      s.T = segment_time(s, via.t6, goal, timing);
    }
  } else {
    const math::Transform frameB = via.t6 * goal.tool;
    s.kind = Segment::Kind::cartesian;
    s.drive = math::DriveTransform(goal.goal.inverse_times(frameB), math::Transform::identity());
    s.start_in_goal = s.drive.at(0.0);
    s.fixed_start = segments().loop().cur.kind == Segment::Kind::rest && pos.moves();
    s.start_world = frameB;
    s.start_goal_p = goal.goal.p;
    // Walked as it stands at its start (the seed is the arm there); the goal's own motion
    // along it is sampled by stretch_line, at the times the loop will run it.
    if (auto f = walk_line(s, at_time(ctx, t_via), via.q, timing)) return f;
    s.T = segment_time(s, via.t6, goal, timing);
    if (auto f = stretch_line(s, ctx, via.q)) return f;
  }
  plan_stop(s, ctx, timing.end_step);
  return std::nullopt;
}

bool SegmentBuilder::aim_at_end(Segment& s, const SampleContext& ctx) const {
  if (s.kind != Segment::Kind::joint || s.position == nullptr || s.borrowed_position ||
      !s.position->moves() || s.position->in_joints()) {
    return false;
  }
  Pose goal;
  segments().pose_at(s, at_time(ctx, s.ts + s.T), 1.0, goal);
  kin::JointVector q1;
  kin::IkStatus why = kin::IkStatus::ok;
  if (!segments().solve(s, goal.t6, s.q1, q1, why)) return false;
  if (model().kin.model().first_joint_outside_limits(q1, kin::kLimitTolerance) >= 0) return false;
  s.q1 = q1;
  plan_stop(s, ctx, {});
  return true;
}

double SegmentBuilder::segment_time(const Segment& s, const math::Transform& t6_via,
                                    const Pose& goal, const Timing& timing) const {
  // From the tool's speeds along the motion (RCCL computes it so in both modes), unless the
  // motion's time is set, and never less than the joints and the transitions need.
  const math::Transform offset = goal.goal.inverse_times(t6_via * goal.tool);
  const double by_speed =
      std::max(offset.p.norm() / std::max(s.settings.translation_m_per_s, 1e-9),
               rotation_angle(offset.R) / std::max(s.settings.rotation_rad_per_s, 1e-9));
  const double T = s.settings.segment_time_s > 0.0 ? s.settings.segment_time_s : by_speed;
  return std::max({T, timing.by_joints, timing.by_acceleration, s.settings.transition_time_s,
                   2.0 * model().options.period_s});
}

SegmentBuilder::Via SegmentBuilder::via_point(const SampleContext& ctx, double t_via) const {
  // The present segment's end, its goal where it will be then (a moving goal has moved on by
  // the via time).
  const LoopState& loop = segments().loop();
  Via via{loop.last_q, {}};
  if (loop.cur.kind == Segment::Kind::cartesian) {
    Pose p;
    segments().pose_at(loop.cur, at_time(ctx, t_via), 1.0, p);
    via.t6 = p.t6;
    kin::IkStatus why = kin::IkStatus::ok;
    if (!segments().solve(loop.cur, via.t6, loop.last_q, via.q, why)) via.q = loop.last_q;
  } else {
    via.q = loop.cur.q1;
    via.t6 = model().kin.forward(via.q);
  }
  return via;
}

void SegmentBuilder::dwell(const MotionRequest& r, Segment& s) const {
  const Segment& cur = segments().loop().cur;
  const double P = model().options.period_s;
  s.kind = Segment::Kind::joint;
  s.q1 = s.q0;
  if (cur.kind == Segment::Kind::cartesian && cur.position != nullptr && cur.position->moves()) {
    // RCCL's stop(): the arm stays on the last position for the time, and a position that
    // moves (a conveyor) is tracked meanwhile: the same equation, its drive at its end.
    s.kind = Segment::Kind::cartesian;
    s.position = cur.position;
    s.borrowed_position = true;
    s.holds = cur.holds;
    s.fixed_goal = cur.fixed_goal;
    s.drive = math::DriveTransform(math::Transform::identity(), math::Transform::identity());
    s.start_in_goal = math::Transform::identity();
    s.configuration = cur.configuration;
    s.has_configuration = cur.has_configuration;
  }
  s.dwell = true;
  // The arm is still for the time asked rounded up to whole samples, at least 3: the sample it
  // comes to rest on (the motion before stopped there) and the one it leaves from (the motion
  // after starts from rest) are still too, besides the dwell's own. Nothing to stop.
  s.T = std::max(std::ceil(r.dwell_s / P - 1e-9) - 2.0, 1.0) * P;
  s.stop_tau = 0.0;
}

std::optional<Failure> SegmentBuilder::check_goal(const Position& pos, Segment& s) const {
  if (!pos.in_joints()) {
    pos.latch(s.holds);
    return std::nullopt;
  }
  const char* name = pos.name().c_str();
  const std::size_t n = model().kin.dof();
  const kin::JointVector& g = pos.joint_values();
  if (g.size() != n) {
    return Failure{kin::IkStatus::bad_input, 0,
                   text("position {} has {} joint values, the robot {}", name, g.size(), n)};
  }
  const int out = model().kin.model().first_joint_outside_limits(g, kin::kLimitTolerance);
  if (out >= 0) {
    return Failure{kin::IkStatus::joint_limits, out + 1,
                   text("position {}: joint {} is outside its limits", name, out + 1)};
  }
  s.fixed_goal = model().kin.forward(g);
  return std::nullopt;
}

void SegmentBuilder::choose_configuration(Segment& s, const kin::JointVector& qB) const {
  // The one asked for, else the one the arm is in.
  const kin::Kinematics& kin = model().kin;
  if (kin.configuration_names().empty()) return;
  s.has_configuration = true;
  s.configuration = s.settings.configuration >= 0
                        ? kin::Configuration{static_cast<std::uint8_t>(s.settings.configuration)}
                        : kin.configuration_of(qB);
}

std::optional<Failure> SegmentBuilder::joint_goal(const Position& pos, const Pose& goal, Segment& s,
                                                  Timing& timing) const {
  s.kind = Segment::Kind::joint;
  kin::IkStatus why = kin::IkStatus::ok;
  if (pos.in_joints()) {
    s.q1 = pos.joint_values();
  } else if (!segments().solve(s, goal.t6, s.q0, s.q1, why)) {
    return Failure{why, 0,
                   text("position {} cannot be reached in joint mode: {}", pos.name().c_str(),
                        kin::describe(why))};
  }
  add_joint_time(s.q0, s.q1, 1.0, timing);
  return std::nullopt;
}

std::optional<Failure> SegmentBuilder::walk_line(Segment& s, const SampleContext& ctx,
                                                 const kin::JointVector& qB, Timing& timing) const {
  // Walk the line before moving: a point out of reach or out of limits, or a joint that would
  // need more than its speed, is reported now rather than in the middle of the motion.
  constexpr int kChecks = 16;
  const std::size_t n = model().kin.dof();
  kin::JointVector q_prev = qB, q;
  kin::IkStatus why = kin::IkStatus::ok;
  timing.end_step = kin::JointVector(n);
  for (int k = 1; k <= kChecks; ++k) {
    Pose p;
    segments().pose_at(s, ctx, static_cast<double>(k) / kChecks, p);
    if (!segments().solve(s, p.t6, q_prev, q, why)) {
      return Failure{why, 0,
                     text("the straight line to {} leaves the workspace {:.0f}% of the way: {}",
                          s.position->name().c_str(), 100.0 * k / kChecks, kin::describe(why))};
    }
    bool at_limit = false;
    const int jumping = find_jump(s, ctx, static_cast<double>(k - 1) / kChecks,
                                  static_cast<double>(k) / kChecks, q_prev, q, at_limit);
    if (jumping > 0) return jump_failure(s, jumping, at_limit, k, q_prev, q);
    add_joint_time(q_prev, q, kChecks, timing);
    for (std::size_t j = 0; j < n; ++j) timing.end_step[j] = (q[j] - q_prev[j]) * kChecks;
    q_prev = q;
  }
  s.q1 = q;
  return std::nullopt;
}

Failure SegmentBuilder::jump_failure(const Segment& s, int joint, bool at_limit, int k,
                                     const kin::JointVector& q_prev,
                                     const kin::JointVector& q) const {
  constexpr int kChecks = 16;  // walk_line's
  const char* name = s.position->name().c_str();
  if (at_limit) {
    const auto J = static_cast<std::size_t>(joint - 1);
    const bool revolute = model().kin.model().joints[J].type == kin::JointType::revolute;
    const double limit = q_prev[J] < q[J] ? model().lower[J] : model().upper[J];
    return Failure{kin::IkStatus::joint_limits, joint,
                   text("the straight line to {} turns joint {} past its limit ({:.1f} {}) about "
                        "{:.0f}% of the way (the line takes the shorter way round); move in joint "
                        "mode, which turns it the other way, or add a via point",
                        name, joint, revolute ? math::rad_to_deg(limit) : limit * 1000.0,
                        revolute ? "deg" : "mm", 100.0 * (k - 0.5) / kChecks)};
  }
  return Failure{kin::IkStatus::singular, joint,
                 text("the straight line to {} passes through a singularity about {:.0f}% of the "
                      "way: joint {} would jump there; go round it (another line or a via point) "
                      "or move in joint mode",
                      name, 100.0 * (k - 0.5) / kChecks, joint)};
}

std::optional<Failure> SegmentBuilder::stretch_line(Segment& s, const SampleContext& ctx,
                                                    const kin::JointVector& qB) const {
  // The walk sees the line at 16 points; near a singularity the joints' speed and acceleration
  // (from the curvature of the path in joint space) peak between them. Sample the line as it
  // will run and slow it down (a longer T: speed falls as 1 / T, acceleration as 1 / T^2) until
  // it keeps within the planning fractions of both bounds. The coarse sweeps (T / 1024)
  // converge fast; the last word is a sweep every period, which is what the loop will run (a
  // stretched line's peak near a singularity can fall between coarse samples).
  const Position& pos = *s.position;
  const char* name = pos.name().c_str();
  const double T0 = s.T;
  bool every_period = false;
  for (int pass = 0;; ++pass) {
    const Peaks pk = planner_.segment_peaks(s, ctx, qB, every_period);
    if (!pk.ok) {
      // Between the walk's points the line has no solution (it grazes the workspace's edge or
      // a singularity there): it cannot be run at any speed.
      return Failure{
          pk.why, 0,
          text("the straight line to {} leaves the workspace about {:.0f}% of the way: "
               "{}",
               name, 100.0 * std::clamp(pk.unsolved_s / s.T, 0.0, 1.0), kin::describe(pk.why))};
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
      return Failure{kin::IkStatus::singular, 0,
                     text("the straight line to {} passes too close to a singularity: even {:.0f} "
                          "times slower a joint would need {:.1f} times its bound; go round it "
                          "(another line or a via point) or move in joint mode",
                          name, s.T / T0, k)};
    }
    if (pos.moves() && (pass == 2 * kPlanningPasses || s.T >= kMaxSegmentStretch * T0)) break;
    s.T *= std::min(1.02 * k, kMaxSegmentStretch * T0 / s.T);
  }
  return std::nullopt;
}

void SegmentBuilder::plan_stop(Segment& s, const SampleContext& ctx,
                               const kin::JointVector& end_step) const {
  const std::size_t n = model().kin.dof();
  s.stop_tau = base_stop_tau(s, model().options.period_s);
  for (std::size_t j = 0; j < n; ++j) {
    // The velocity at the end, where the arm stops: a Cartesian line's is not its average.
    double v = std::abs(s.q1[j] - s.q0[j]) / s.T;
    if (end_step.size() == n) v = std::max(v, std::abs(end_step[j]) / s.T);
    s.stop_tau = std::max(s.stop_tau, kPaulPeak * v / model().planning_acceleration(j));
  }
  s.stop_tau = std::min(s.stop_tau, 0.5 * s.T);
  // As for transitions between segments (transition_tau): check the stop as the loop will run
  // it, and lengthen it (and the segment, if need be) while a joint would pass its bound.
  const double planned_T = s.T;
  for (int pass = 0; pass < 3; ++pass) {
    const Transition stop{blend_between(s, nullptr), false, s.ts + s.T, s.stop_tau, {}};
    const double worst = planner_.blend_peaks(s, s, stop, s.q1, ctx).ratio_or_failed();
    if (!(worst > 1.0)) break;
    // A transition's acceleration falls as 1 / tau; a far larger ratio means a singularity on
    // the way, which lengthening does not cure (the loop will stop the arm there).
    s.stop_tau = std::min(s.stop_tau * std::min(worst * 1.05, 2.0), kMaxStretch * planned_T / 2.0);
    s.T = std::max(s.T, 2.0 * s.stop_tau);
  }
}

void SegmentBuilder::add_joint_time(const kin::JointVector& a, const kin::JointVector& b,
                                    double scale, Timing& timing) const noexcept {
  for (std::size_t j = 0; j < model().kin.dof(); ++j) {
    const double d = std::abs(b[j] - a[j]) * scale;
    timing.by_joints =
        std::max(timing.by_joints, d / (kPlanningSpeedFraction * model().options.max_velocity[j]));
    // Room for the transitions in and out at the acceleration bound: the part of each that
    // this segment's own velocity v = d / T causes, tau = 1.875 v / a (the smooth blend),
    // takes at most a quarter of T, leaving the rest for its neighbours' velocities.
    timing.by_acceleration =
        std::max(timing.by_acceleration,
                 std::sqrt(4.0 * kSmoothPeak * d / model().planning_acceleration(j)));
  }
}

int SegmentBuilder::find_jump(const Segment& s, const SampleContext& ctx, double r0, double r1,
                              const kin::JointVector& q0, const kin::JointVector& q1,
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
  kin::JointVector lo = q0, hi = q1, mid;
  kin::IkStatus why;
  for (int i = 0; i < 12; ++i) {  // 4096 times shorter
    const double rm = 0.5 * (r0 + r1);
    Pose p;
    segments().pose_at(s, ctx, rm, p);
    if (!segments().solve(s, p.t6, lo, mid, why)) return 0;  // the caller's checks report it
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
    return std::abs(v - model().lower[J]) < kAtLimit || std::abs(v - model().upper[J]) < kAtLimit;
  };
  at_limit = near_limit(lo[J]) || near_limit(hi[J]);
  return joint + 1;
}

}  // namespace rccx::rccl::trajectory
