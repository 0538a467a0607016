#include "rccx/rccl/trajectory/generator.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "rccx/rccl/trajectory/setpoint_guard.hpp"
#include "rccx/rccl/trajectory/text.hpp"
#include "rccx/rtc/types.hpp"

namespace rccx::rccl {
namespace {

using kin::JointVector;
using trajectory::GateState;
using trajectory::text;

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

// --- One sample ----------------------------------------------------------------------------------

std::uint64_t TrajectoryGenerator::step(const SampleContext& ctx, const JointVector* measured,
                                        JointVector& q) {
  assert(phase_consistent());
  pose_valid_ = false;
  handle_stops(ctx);  // halt(), request_stop(), nextmove: fail or end what moves, then halt
  queue_.take();      // the next request, when none waits
  schedule(ctx);      // start from rest, join the next segment, begin the transition that is due
  const trajectory::Transition& tr = loop_.tr;
  if (loop_.phase == Phase::transition && ctx.t_s >= tr.tB + tr.tau - 1e-9) finish_transition(ctx);
  if (evaluate(ctx, q)) guard(ctx, q);  // the phase's setpoint; a failure halts the arm
  trajectory::clamp_to_limits(model_, q);
  record(ctx, q, measured);  // the path report
  loop_.prev_q = loop_.last_q;
  loop_.last_q = q;
  loop_.last_t = ctx.t_s;
  last_motion_ = loop_.present().id;
  return last_motion_;
}

void TrajectoryGenerator::handle_stops(const SampleContext& ctx) noexcept {
  if (halt_requested_.exchange(false, std::memory_order_acq_rel) && !at_rest()) {
    fail(moving_id(), ctx, kin::IkStatus::ok, 0, text("halted by the program"));
  }
  if (stop_requested_) {
    stop_requested_ = false;
    if (loop_.phase != Phase::halting && !at_rest()) {
      fail(moving_id(), ctx, kin::IkStatus::ok, 0, stop_text_);
    } else if (loop_.phase == Phase::tracking) {
      // Its motion has ended already: no motion to fail, only the tracking to stop.
      queue_.emit(EventKind::failed, 0, ctx, kin::IkStatus::ok, 0,
                  std::string_view(stop_text_.data()));
      start_halt();
    }
  }
  if (next_requested_.exchange(false, std::memory_order_acq_rel)) next_motion(ctx);
}

void TrajectoryGenerator::schedule(const SampleContext& ctx) {
  switch (loop_.phase) {
    case Phase::rest:
    case Phase::tracking:
      if (queue_.waiting() != nullptr) start_or_cancel(ctx);
      return;
    case Phase::segment:
      join_or_end(ctx);
      return;
    case Phase::transition:
    case Phase::halting:
      return;
  }
}

void TrajectoryGenerator::start_or_cancel(const SampleContext& ctx) {
  Text why{};
  switch (queue_.gate_state(why)) {
    case GateState::open:
      start_waiting(ctx, ctx.t_s);
      break;
    case GateState::cancel:
      fail(queue_.waiting()->id, ctx, kin::IkStatus::ok, 0, why);
      break;
    case GateState::closed:
      break;
  }
}

void TrajectoryGenerator::join_or_end(const SampleContext& ctx) {
  const double t = ctx.t_s;
  const double eps = 1e-9;
  const Segment& cur = loop_.cur;
  const double te = cur.ts + cur.T;
  // A gated motion joins its predecessor only when it may start already; one with a
  // rendezvous always starts from rest, where the others can wait for it.
  Text why{};
  const MotionRequest* w = queue_.waiting();
  // A stop (dwell) is never blended: the motion before it comes to rest, and the one after it
  // starts from rest, so that the arm is still for the stop's whole time.
  const bool may_join = w != nullptr && w->together == nullptr && w->kind != RequestKind::dwell &&
                        !cur.dwell && (w->gates == 0 || queue_.gate_state(why) == GateState::open);
  if (!loop_.has_next && may_join && t < te - cur.stop_tau - eps) {
    if (build(*w, ctx, te)) {
      queue_.join();
      const auto plan = [&] {
        loop_.next_tau = planner_.transition_tau(
            cur, loop_.next, trajectory::blend_between(cur, &loop_.next), te, ctx);
      };
      plan();
      // Planning may have slowed it: a joint line onto a moving goal aims anew at its end.
      for (int round = 0; round < 2 && builder_.aim_at_end(loop_.next, ctx); ++round) plan();
      // Decided late: the window must not have begun already.
      loop_.next_tau = std::min(loop_.next_tau, te - t);
    }
  }
  if (loop_.has_next && t >= te - loop_.next_tau - eps) {
    begin_transition(ctx, te, loop_.next_tau, loop_.next.blend_in, true);
  } else if (!loop_.has_next && t >= te - cur.stop_tau - eps) {
    begin_transition(ctx, te, cur.stop_tau, trajectory::blend_between(cur, nullptr), false);
  }
}

bool TrajectoryGenerator::evaluate(const SampleContext& ctx, JointVector& q) {
  const double t = ctx.t_s;
  kin::IkStatus why = kin::IkStatus::ok;
  if (loop_.phase == Phase::halting) {
    halt_value(t, q);
    return false;
  }
  if (!value(ctx, t, q, why)) {
    fail(loop_.present().id, ctx, why, 0,
         text("the path cannot be followed at t = {:.3f} s: {}", t, kin::describe(why)));
    halt_value(t, q);
    return false;
  }
  return true;
}

bool TrajectoryGenerator::value(const SampleContext& ctx, double t, JointVector& q,
                                kin::IkStatus& why) {
  const Segment& cur = loop_.cur;
  if (loop_.phase != Phase::transition) {
    trajectory::Pose p;
    const bool ok = segments_.value(cur, ctx, t, loop_.last_q, q, why, &p);
    if (ok && loop_.phase == Phase::segment && cur.kind == Segment::Kind::cartesian) {
      pose_ = p;
      pose_valid_ = true;
    }
    return ok;
  }
  const trajectory::Transition& tr = loop_.tr;
  return blends_.value(cur, tr.to_next ? loop_.next : cur, tr, ctx, t, loop_.last_q, q, why);
}

void TrajectoryGenerator::guard(const SampleContext& ctx, JointVector& q) noexcept {
  trajectory::GuardTrip trip;
  if (!trajectory::guard_trips(model_, q, loop_.last_q, loop_.prev_q, trip)) return;
  const Segment& present = loop_.present();
  const trajectory::Failure f = trajectory::describe(trip, model_, goal_track_, present, ctx.t_s);
  fail(present.id, ctx, f.status, f.joint, f.text);
  halt_value(ctx.t_s, q);
}

void TrajectoryGenerator::record(const SampleContext& ctx, const JointVector& q,
                                 const JointVector* measured) noexcept {
  const Segment& cur = loop_.cur;
  if (loop_.phase != Phase::segment || cur.id == 0) return;
  SegmentReport& rep = queue_.report_slot(cur.id);
  if (rep.id != cur.id || !pose_valid_) return;
  const double P = model_.options.period_s;
  // The line as it stands for the present goal: from the start to the goal, in base frame.
  const math::Vec3 from = cur.fixed_start ? cur.start_world.p : (pose_.goal * cur.start_in_goal).p;
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
      ctx.t_s >= cur.ts + cur.tau_in + 3.0 * P) {
    const math::Transform frame = model_.kin.forward(*measured) * pose_.tool;
    rep.max_measured_path_error_m =
        std::max(rep.max_measured_path_error_m, distance_to_segment(frame.p, from, to));
    const double c = std::clamp(dot(frame.R.a, pose_.frame.R.a), -1.0, 1.0);
    rep.max_approach_error_rad = std::max(rep.max_approach_error_rad, std::acos(c));
  }
  last_frame_p_ = pose_.frame.p;
  have_last_frame_ = true;
}

// --- Starting motions and transitions ------------------------------------------------------------

bool TrajectoryGenerator::build(const MotionRequest& r, const SampleContext& ctx, double t_via) {
  Segment s;
  if (const std::optional<trajectory::Failure> f = builder_.build(r, ctx, t_via, s)) {
    fail(r.id, ctx, f->status, f->joint, f->text);
    return false;
  }
  loop_.next = s;
  loop_.has_next = true;
  return true;
}

void TrajectoryGenerator::start_waiting(const SampleContext& ctx, double t) {
  Rendezvous* rv = queue_.waiting()->together;
  const double eps = 1e-9;
  // Samples are for the tick's time (How); the setpoint time runs the pipeline ahead of it.
  const double now = ctx.how != nullptr ? ctx.sample_time_s() : t;
  if (rv != nullptr && !(rv->start_s() >= 0.0 && now >= rv->start_s() - eps)) {
    tell_rendezvous(ctx, t, now);
    return;
  }
  const MotionRequest r = *queue_.waiting();
  if (loop_.phase == Phase::tracking) {
    // Tracking the last motion's goal, which has just jumped (a varb given a new value right
    // before this move()): start from where the arm stands, not from the goal's new place.
    // (Evaluating the goal for this sample is what records its step in goal_track_.)
    trajectory::Pose p;
    segments_.pose_at(loop_.cur, ctx, 1.0, p);
    if (goal_track_.jumped(loop_.cur.position)) rest_at(loop_.last_q);
  }
  // From rest: the transition begins now; the straight part tau later (a stop's at once: the
  // arm is at rest already).
  if (!build(r, ctx, t)) return;
  queue_.started();
  Segment& next = loop_.next;
  const auto plan = [&] {
    next.ts = t;
    const double tau_in =
        next.dwell ? 0.0
                   : planner_.transition_tau(loop_.cur, next,
                                             trajectory::blend_between(loop_.cur, &next), t, ctx);
    if (rv != nullptr && rv->end_together()) {
      // Slowed to the slowest: the straight part takes the time left between both transitions
      // (planned for the faster motion, so they stay within the bounds for the slower one).
      next.T = std::max(next.T, rv->duration_s() - tau_in - next.stop_tau);
    }
    next.ts = t + tau_in;
    return tau_in;
  };
  double tau = plan();
  // Its straight part starts tau later and planning may have slowed it: a joint line onto a
  // moving goal aims anew at where the goal will be at its end.
  for (int round = 0; round < 2 && builder_.aim_at_end(next, ctx); ++round) tau = plan();
  begin_transition(ctx, t + tau, tau, next.blend_in, true);
}

void TrajectoryGenerator::tell_rendezvous(const SampleContext& ctx, double t, double now) {
  Rendezvous* rv = queue_.waiting()->together;
  if (queue_.rendezvous_ready() || rv->start_s() >= 0.0) return;  // the others', or the start
  // Plan as if starting now, to tell the others how long this motion takes; build again at
  // the start (a goal may move meanwhile).
  const MotionRequest r = *queue_.waiting();
  if (!build(r, ctx, t)) return;  // failed: fail() withdrew it
  Segment& next = loop_.next;
  const double tau =
      planner_.transition_tau(loop_.cur, next, trajectory::blend_between(loop_.cur, &next), t, ctx);
  loop_.has_next = false;
  queue_.set_rendezvous_ready();
  rv->ready(r.slot, now, tau + next.T + next.stop_tau, model_.options.period_s);
}

void TrajectoryGenerator::begin_transition(const SampleContext& ctx, double tB, double tau,
                                           trajectory::Blend blend, bool to_next) {
  trajectory::Transition tr{blend, to_next, tB, tau, {}};
  // Before the phase changes: the goals the tangents evaluate are still cur's (GoalTrack).
  if (to_next) blends_.tangents(loop_.cur, loop_.next, loop_.last_q, ctx, tr);
  loop_.tr = tr;
  loop_.phase = Phase::transition;
  have_last_frame_ = false;
  if (!to_next) return;
  Segment& next = loop_.next;
  next.tau_in = tau;
  ledger_.mark_started(next.id);
  queue_.emit(EventKind::started, next.id, ctx);
  SegmentReport& rep = queue_.report_slot(next.id);
  rep = SegmentReport{};
  rep.id = next.id;
  rep.mode = next.kind == Segment::Kind::cartesian ? Mode::cartesian : Mode::joint;
  rep.start_s = ctx.sample_time_s();
  rep.duration_s = next.T;
}

void TrajectoryGenerator::finish_transition(const SampleContext& ctx) {
  // On cur until what follows is decided: the present segment is cur (GoalTrack).
  loop_.phase = Phase::segment;
  Segment& cur = loop_.cur;
  if (loop_.tr.to_next) {
    end_motion(cur, ctx);
    cur = loop_.next;
    loop_.has_next = false;
    return;
  }
  // Came to rest at the end of cur: exactly its end point, or tracking its moving goal.
  end_motion(cur, ctx);
  if (cur.kind == Segment::Kind::cartesian && cur.position->moves()) {
    cur.resting = true;
    cur.id = 0;
    loop_.phase = Phase::tracking;
    return;
  }
  JointVector q = cur.q1;
  kin::IkStatus why;
  if (cur.kind == Segment::Kind::cartesian) {
    trajectory::Pose p;
    segments_.pose_at(cur, ctx, 1.0, p);
    if (!segments_.solve(cur, p.t6, loop_.last_q, q, why)) q = loop_.last_q;
  }
  rest_at(q);
}

// --- Ending, failing, halting --------------------------------------------------------------------

void TrajectoryGenerator::end_motion(const Segment& s, const SampleContext& ctx,
                                     std::string_view text) noexcept {
  if (s.id == 0) return;
  SegmentReport& rep = queue_.report_slot(s.id);
  if (rep.id == s.id) rep.end_s = ctx.sample_time_s();
  trajectory::release_position(s.position, s.borrowed_position);
  queue_.emit(EventKind::ended, s.id, ctx, kin::IkStatus::ok, 0, text);
  ledger_.mark_ended(s.id);
}

void TrajectoryGenerator::next_motion(const SampleContext& ctx) noexcept {
  const Phase phase = loop_.phase;
  if (phase != Phase::segment && phase != Phase::transition) return;  // nothing moves
  if (phase == Phase::transition && loop_.tr.to_next) {
    // Between two motions: the one ending and the one beginning both end here.
    end_motion(loop_.cur, ctx, kNextmoveText);
    end_motion(loop_.next, ctx, kNextmoveText);
  } else {
    end_motion(loop_.cur, ctx, kNextmoveText);  // on its straight part or stopping at its end
    // Joined but not begun: it starts from rest once the arm has stopped, before the request
    // taken after it.
    if (loop_.has_next) queue_.put_back_joined();
  }
  queue_.drop_joined();
  loop_.has_next = false;
  loop_.cur.id = 0;
  start_halt();
}

void TrajectoryGenerator::fail(std::uint64_t id, const SampleContext& ctx, kin::IkStatus status,
                               int joint, const Text& text) noexcept {
  SegmentReport& rep = queue_.report_slot(id);
  rep.id = id;
  rep.failed = true;
  rep.end_s = ctx.sample_time_s();
  queue_.emit(EventKind::failed, id, ctx, status, joint, std::string_view(text.data()));
  // Everything from the motion running now to the last one queued ends here.
  std::uint64_t last = id;
  const auto cancel = [&](std::uint64_t s_id, const Position* position, bool borrowed) {
    if (s_id == 0) return;
    if (s_id != id) queue_.emit(EventKind::cancelled, s_id, ctx);
    trajectory::release_position(position, borrowed);
    last = std::max(last, s_id);
  };
  const Segment& cur = loop_.cur;
  if (cur.kind != Segment::Kind::rest) cancel(cur.id, cur.position, cur.borrowed_position);
  if (loop_.has_next) cancel(loop_.next.id, loop_.next.position, loop_.next.borrowed_position);
  queue_.cancel_all(text, [&](const MotionRequest& r) { cancel(r.id, r.position, false); });
  loop_.has_next = false;
  ledger_.mark_failed(id, last);
  start_halt();
}

std::uint64_t TrajectoryGenerator::moving_id() const noexcept {
  if (loop_.cur.id != 0) return loop_.cur.id;
  return loop_.has_next ? loop_.next.id : 0;
}

void TrajectoryGenerator::start_halt() noexcept {
  loop_.halt.start(model_, loop_.last_q, loop_.prev_q, loop_.last_t);
  loop_.phase = Phase::halting;
}

void TrajectoryGenerator::halt_value(double t, JointVector& q) noexcept {
  if (!loop_.halt.value(t, q)) rest_at(q);
}

void TrajectoryGenerator::rest_at(const JointVector& q) noexcept {
  loop_.cur = Segment{};
  loop_.cur.kind = Segment::Kind::rest;
  loop_.cur.q1 = q;
  loop_.phase = Phase::rest;
  pose_valid_ = false;
}

// --- Outside the steps ---------------------------------------------------------------------------

void TrajectoryGenerator::reset(const JointVector& q, double t_s) noexcept {
  queue_.reset(text("its robot's control started again"));
  next_requested_.store(false);
  loop_.has_next = false;
  loop_.tr = trajectory::Transition{};
  loop_.halt = trajectory::Halt{};
  halt_requested_.store(false);
  stop_requested_ = false;
  last_motion_ = 0;
  rest_at(q);
  loop_.last_q = loop_.prev_q = q;
  loop_.last_t = t_s - model_.options.period_s;
}

bool TrajectoryGenerator::at_rest() const noexcept {
  return loop_.resting() && !loop_.has_next && queue_.idle();
}

const MotionSettings* TrajectoryGenerator::running_settings(std::uint64_t id) const noexcept {
  if (id == 0) return nullptr;
  if (loop_.cur.id == id) return &loop_.cur.settings;
  if (loop_.has_next && loop_.next.id == id) return &loop_.next.settings;
  return nullptr;
}

void TrajectoryGenerator::request_stop(std::string_view why) noexcept {
  io::copy_fixed(stop_text_, why);
  stop_requested_ = true;
}

bool TrajectoryGenerator::phase_consistent() const noexcept {
  const Segment& c = loop_.cur;
  switch (loop_.phase) {
    case Phase::rest:
      return c.kind == Segment::Kind::rest && !c.resting && !loop_.has_next;
    case Phase::tracking:
      return c.kind == Segment::Kind::cartesian && c.resting && !loop_.has_next;
    case Phase::segment:
      return c.kind != Segment::Kind::rest && !c.resting;
    case Phase::transition:
      return loop_.has_next == loop_.tr.to_next;
    case Phase::halting:
      return !loop_.has_next;
  }
  return false;
}

}  // namespace rccx::rccl
