#include "rccx/rccl/manipulator.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace rccx::rccl {

std::string_view to_string(WaitResult r) noexcept {
  switch (r) {
    case WaitResult::reached:
      return "reached";
    case WaitResult::failed:
      return "failed";
    case WaitResult::timeout:
      return "timeout";
    case WaitResult::session_ended:
      return "session ended";
  }
  return "?";
}

namespace {

GeneratorOptions generator_options(rtc::Session& session) {
  GeneratorOptions o;
  o.period_s = std::chrono::duration<double>(session.period()).count();
  const kin::RobotModel& m = session.driver().model();
  o.max_velocity = kin::JointVector(m.dof());
  for (std::size_t j = 0; j < m.dof(); ++j) {
    o.max_velocity[j] = session.driver().velocity_limit(j, o.period_s);  // work areas, ...
  }
  return o;
}

}  // namespace

Manipulator::Manipulator(rtc::Session& session)
    : session_(session),
      kinematics_(kin::make_kinematics(session.driver().model())),
      generator_(std::make_unique<TrajectoryGenerator>(*kinematics_, generator_options(session))),
      force_(*kinematics_),
      lower_(kinematics_->model().lower()),
      park_(Position::joints("park", kinematics_->model().ready())) {
  generator_->set_robot_name(kinematics_->model().name);
}

Manipulator::~Manipulator() {
  if (started_) {
    try {
      stop_control();
    } catch (...) {  // nothing sensible to do in a destructor
    }
  }
}

void Manipulator::start() {
  first_sample_ = true;
  limp_ = zero_gravity_ = false;
  session_.control({}, [this](rtc::Control& c) { run_sample(c); });
  started_ = true;
}

void Manipulator::run_sample(rtc::Control& c) {
  const rtc::How& h = c.how();
  const kin::JointVector measured = h.q();
  // The setpoint written now goes out with the next sample and is reached one period later.
  const double t_set = h.time_s + 2.0 * c.period_s();
  if (first_sample_) {
    generator_->reset(measured, t_set);
    force_.reset();
    first_sample_ = false;
  }
  if (forward_requests(c, measured, t_set)) return;
  kin::JointVector q;
  const std::uint64_t id = step_generator(h, measured, t_set, q);
  apply_force(h, id, c.period_s(), q);
  write_setpoints(c, q, id);
}

bool Manipulator::forward_requests(rtc::Control& c, const kin::JointVector& measured,
                                   double t_set) noexcept {
  if (const rtc::Request hand = hand_request_.exchange(rtc::Request::none);
      hand != rtc::Request::none) {
    c.chg().hand = hand;
  }
  if (const rtc::SettingChg set = setting_request_.exchange(rtc::SettingChg{});
      set.what != rtc::Setting::none) {
    c.chg().setting = set;
  }
  if (const rtc::Request zg = zero_gravity_request_.exchange(rtc::Request::none);
      zg != rtc::Request::none) {
    c.chg().zero_gravity = zg;
    limp_ = zg == rtc::Request::on;
    if (!limp_) generator_->reset(measured, t_set);  // at rest where the hand left it
  }
  if (limp_) c.chg().zero_gravity = rtc::Request::on;  // held every sample, as marsh does
  return limp_;
}

std::uint64_t Manipulator::step_generator(const rtc::How& h, const kin::JointVector& measured,
                                          double t_set, kin::JointVector& q) {
  const SampleContext ctx{t_set, h.sample, &h};
  return generator_->step(ctx, &measured, q);
}

void Manipulator::apply_force(const rtc::How& h, std::uint64_t id, double period_s,
                              kin::JointVector& q) noexcept {
  switch (force_.step(h, id, generator_->running_settings(id), period_s, q)) {
    case ForceControl::Outcome::none:
      break;
    case ForceControl::Outcome::contact:
      generator_->request_next();
      break;
    case ForceControl::Outcome::overload:
    case ForceControl::Outcome::unreachable:
      generator_->request_stop(std::string_view(force_.why().data()));
      break;
  }
}

void Manipulator::write_setpoints(rtc::Control& c, const kin::JointVector& q,
                                  std::uint64_t id) noexcept {
  for (std::size_t j = 0; j < q.size(); ++j) c.chg().posvel(j, q[j] - lower_[j]);
  c.chg().segment = static_cast<std::int32_t>(id);
}

rtc::Termination Manipulator::stop_control() {
  started_ = false;
  return session_.release();
}

void Manipulator::set_velocity(double translation_m_per_s, double rotation_rad_per_s) {
  if (!(translation_m_per_s > 0.0) || !(rotation_rad_per_s > 0.0) ||
      !std::isfinite(translation_m_per_s) || !std::isfinite(rotation_rad_per_s)) {
    throw MotionError(fmt::format("velocities must be finite and > 0 (got {} m/s, {} rad/s)",
                                  translation_m_per_s, rotation_rad_per_s));
  }
  settings_.translation_m_per_s = translation_m_per_s;
  settings_.rotation_rad_per_s = rotation_rad_per_s;
}

void Manipulator::set_segment_time(double seconds) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) {
    throw MotionError(
        fmt::format("segment time must be >= 0 s (0: from the speeds), got {}", seconds));
  }
  settings_.segment_time_s = seconds;
}

void Manipulator::set_transition_time(double seconds) {
  if (!(seconds > 0.0) || !std::isfinite(seconds)) {
    throw MotionError(fmt::format("transition time must be > 0 s, got {}", seconds));
  }
  settings_.transition_time_s = seconds;
}

void Manipulator::set_configuration(std::string_view name) {
  if (name.empty()) {
    settings_.configuration = -1;
    return;
  }
  const auto c = kinematics_->find_configuration(name);
  if (!c) {
    std::string known;
    for (std::string_view n : kinematics_->configuration_names()) {
      known += known.empty() ? "" : ", ";
      known += n;
    }
    throw MotionError(fmt::format("robot {} has no configuration '{}' (it has: {})",
                                  kinematics_->model().name, name, known.empty() ? "none" : known));
  }
  settings_.configuration = c->index;
}

void Manipulator::check_joint_goal(const Position& p) {
  const kin::JointVector& q = p.joint_values();
  if (q.size() != kinematics_->dof()) {
    throw MotionError(fmt::format("position {} has {} joint values; robot {} has {} joints",
                                  p.name(), q.size(), kinematics_->model().name,
                                  kinematics_->dof()));
  }
  const int out = kinematics_->model().first_joint_outside_limits(q, kin::kLimitTolerance);
  if (out >= 0) {
    const kin::Joint& j = kinematics_->model().joints[static_cast<std::size_t>(out)];
    throw MotionError(
        fmt::format("position {}: joint {} ({}) = {:.6g} is outside its limits "
                    "[{:.6g}, {:.6g}]",
                    p.name(), out + 1, j.name, q[static_cast<std::size_t>(out)], j.lower, j.upper));
  }
  planned_configuration();
  queued_configuration_ = kinematics_->configuration_of(q);
}

std::int16_t Manipulator::check_reachable(const Position& p, bool starts_later) {
  if (p.in_joints()) {
    check_joint_goal(p);
    return -1;
  }
  const auto names = kinematics_->configuration_names();
  const rtc::How h = session_.how();
  const SampleContext ctx{h.time_s, h.sample, nullptr};
  const math::Transform t6 = p.moves() ? p.t6_at(ctx) : p.t6_now();
  const char* when = p.moves() ? " (its goal as it is now)" : "";
  if (names.empty()) {
    const kin::IkResult r = kinematics_->inverse(t6);
    if (!r && !starts_later) {
      throw MotionError(fmt::format("position {} cannot be reached{}: {}", p.name(), when,
                                    kin::describe(r.status)));
    }
    return -1;
  }
  const bool asked = settings_.configuration >= 0 && settings_.mode == Mode::joint;
  const kin::Configuration present = planned_configuration();
  if (settings_.mode == Mode::cartesian && settings_.configuration >= 0 &&
      settings_.configuration != present.index) {
    throw MotionError(fmt::format(
        "position {}: a Cartesian line keeps the arm's configuration ({}), it cannot change to "
        "{}: move in joint mode to change configuration",
        p.name(), kinematics_->configuration_name(present),
        names[static_cast<std::size_t>(settings_.configuration)]));
  }
  const kin::Configuration c =
      asked ? kin::Configuration{static_cast<std::uint8_t>(settings_.configuration)} : present;
  kin::IkOptions o;
  o.configuration = c;
  const kin::IkResult r = kinematics_->inverse(t6, o);
  if (r) {
    queued_configuration_ = c;
    return -1;
  }
  if (!asked && settings_.mode == Mode::joint) {
    // A joint move may change configuration: none asked, and the present one cannot reach
    // the goal, so take the configuration whose solution lies nearest the arm's joints (as a
    // program written for another arm's park pose expects, e.g. the PUMA's wrist flipped).
    kin::IkOptions nearest;
    nearest.near = session_.how().q();
    if (const kin::IkResult n = kinematics_->inverse(t6, nearest)) {
      queued_configuration_ = n.configuration;
      return static_cast<std::int16_t>(n.configuration.index);
    }
  }
  if (starts_later) return -1;
  throw_unreachable(p, t6, when, c, asked, r.status);
}

void Manipulator::throw_unreachable(const Position& p, const math::Transform& t6, const char* when,
                                    kin::Configuration c, bool asked, kin::IkStatus status) {
  const kin::IkSolutions all = kinematics_->inverse_all(t6);
  std::string others;
  std::string first;
  for (const kin::IkResult& s : all.solutions()) {
    const std::string_view n = kinematics_->configuration_name(s.configuration);
    others += others.empty() ? "" : ", ";
    others += n;
    if (first.empty()) first = n;
  }
  const std::string_view cname = kinematics_->configuration_name(c);
  if (others.empty()) {
    throw MotionError(fmt::format("position {} cannot be reached{} in any configuration: {}",
                                  p.name(), when, kin::describe(all.status)));
  }
  throw MotionError(fmt::format(
      "position {} cannot be reached{} in configuration {} ({}; {}): {}; it can in {}: "
      "set_configuration(\"{}\") then move in joint mode",
      p.name(), when, cname, asked ? "the one asked for" : "the arm's",
      settings_.mode == Mode::cartesian ? "a Cartesian line keeps it" : "a joint move keeps it",
      kin::describe(status), others, first));
}

kin::Configuration Manipulator::planned_configuration() {
  // Nothing queued or moving: the arm's configuration as it stands.
  if (happened(completed()))
    queued_configuration_ = kinematics_->configuration_of(session_.how().q());
  return queued_configuration_;
}

Motion Manipulator::submit(MotionRequest r, const PositionPtr& keep, const StartWhen& when,
                           std::int16_t configuration) {
  if (!started_) throw MotionError("call start() (rccl_control) before queuing motions");
  if (zero_gravity_) throw MotionError("zero gravity is on: set_zero_gravity(false) first");
  r.id = next_id_;
  r.settings = settings_;
  r.settings.may_touch = when.touch;
  if (configuration >= 0) r.settings.configuration = configuration;
  if (when.after.size() > StartWhen::kMaxGates) {
    throw MotionError(
        fmt::format("a motion waits for at most {} events (got {}); wait for the "
                    "others in the program first (Cell::waitfor)",
                    StartWhen::kMaxGates, when.after.size()));
  }
  for (const EventGate& g : when.after) {
    if (g.ledger == nullptr) throw MotionError("a start condition has no robot (a null gate)");
    if (g.ledger == &generator_->ledger() && g.id >= r.id) {
      throw MotionError(
          fmt::format("motion {} of {} would wait for its own motion {}, which "
                      "cannot start before it",
                      r.id, g.ledger->robot(), g.id));
    }
    r.after[r.gates++] = g;
  }
  if (when.together) {
    if (when.slot >= when.together->participants()) {
      throw MotionError(fmt::format("rendezvous slot {} of {} participants", when.slot,
                                    when.together->participants()));
    }
    // Another robot's place would start this one with the wrong partner and leave its own
    // place empty: the joint start would never come.
    const MotionLedger* holder = when.together->participant(when.slot);
    if (holder != nullptr && holder->robot() != generator_->ledger().robot()) {
      throw MotionError(fmt::format(
          "this joint start's place {} is robot {}'s: give robot {}'s motion together.when(\"{}\")",
          when.slot, holder->robot(), generator_->ledger().robot(), generator_->ledger().robot()));
    }
    if (when.together->start_s() >= 0.0 || !when.together->withdrawn().empty()) {
      throw MotionError("this rendezvous has been used (or broken) already: make a new one");
    }
    r.together = when.together.get();
    r.slot = static_cast<std::uint8_t>(when.slot);
    if (std::find(keep_rendezvous_.begin(), keep_rendezvous_.end(), when.together) ==
        keep_rendezvous_.end()) {
      keep_rendezvous_.push_back(when.together);
    }
  }
  if (keep && std::find(keep_.begin(), keep_.end(), keep) == keep_.end()) keep_.push_back(keep);
  if (keep) keep->pending_ends.fetch_add(1, std::memory_order_acq_rel);
  if (!generator_->submit(r)) {
    if (keep) keep->pending_ends.fetch_sub(1, std::memory_order_acq_rel);
    throw MotionError(fmt::format("the motion queue is full ({} requests); waitfor some to end",
                                  TrajectoryGenerator::kQueueCapacity));
  }
  ++next_id_;
  return {r.id};
}

Motion Manipulator::move(const PositionPtr& position, const StartWhen& when) {
  if (!position) throw MotionError("move(): the position is null");
  if ((settings_.guard.on() || settings_.compliance.any()) && started_ &&
      !session_.how().force.present) {
    throw MotionError(fmt::format(
        "a guarded or compliant motion needs a wrist force sensor, and this {} has none: "
        "simulate it on the MuJoCo plant (\"plant\": \"mujoco\" in its robot file)",
        kinematics_->model().name));
  }
  const std::int16_t configuration =
      check_reachable(*position, position->moves() && (!when.after.empty() || when.together));
  MotionRequest r;
  r.kind = RequestKind::move;
  r.position = position.get();
  const math::Transform saved_tool = settings_.tool;
  settings_.tool = position->in_joints() ? math::Transform{} : position->tool_now();
  const Motion m = [&] {
    try {
      return submit(r, position, when, configuration);
    } catch (...) {
      settings_.tool = saved_tool;
      throw;
    }
  }();
  settings_.tool = saved_tool;
  if (move_observer_) move_observer_(m, position);
  return m;
}

void check_guard(const ForceGuard& guard) {
  if (guard.on()) {
    if (!std::isfinite(guard.threshold) || guard.threshold == 0.0) {
      throw MotionError(
          fmt::format("a force guard's threshold must be finite and not 0 (N or "
                      "N m), got {}",
                      guard.threshold));
    }
    if (guard.kind == ForceGuard::Kind::along && guard.axis > 5) {
      throw MotionError(
          fmt::format("a force guard's axis is 0..5 (fx fy fz tx ty tz), got {}", guard.axis));
    }
    if (guard.kind == ForceGuard::Kind::magnitude && guard.threshold < 0.0) {
      throw MotionError("a force guard on the magnitude needs a threshold > 0 N");
    }
  }
}

void Manipulator::set_guard(const ForceGuard& guard) {
  check_guard(guard);
  settings_.guard = guard;
}

void check_compliance(const Compliance& c) {
  const auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
  for (std::size_t i = 0; i < 6; ++i) {
    const bool ok = std::isfinite(c.force[i]) && std::isfinite(c.stiffness[i]) &&
                    c.stiffness[i] >= 0.0 && std::isfinite(c.damping[i]) && c.damping[i] >= 0.0;
    if (!ok) {
      throw MotionError(fmt::format(
          "compliance on {}: the force must be finite, the stiffness and damping finite and "
          ">= 0 (0: the default damping)",
          kForceAxisNames[i]));
    }
  }
  if (!positive(c.max_speed_m_per_s) || !positive(c.max_rotation_rad_per_s) ||
      !positive(c.max_offset_m) || !positive(c.max_offset_rad) || !positive(c.max_force_N) ||
      !positive(c.max_torque_N_m)) {
    throw MotionError("compliance: its speed, offset and force limits must all be > 0");
  }
  if (c.axes > 0x3f) throw MotionError("compliance: the axes are bits 0..5 (fx .. tz)");
  for (std::size_t i = 0; i < 3; ++i) {
    if (c.compliant(i) && std::abs(c.force[i]) >= c.max_force_N) {
      throw MotionError(fmt::format("compliance: {} {:.1f} N is beyond the force limit {:.1f} N",
                                    kForceAxisNames[i], c.force[i], c.max_force_N));
    }
  }
}

void Manipulator::set_compliance(const Compliance& c) {
  check_compliance(c);
  settings_.compliance = c;
}

std::optional<Contact> Manipulator::contact(const Motion& m) const noexcept {
  if (!happened(m.end())) return std::nullopt;
  const Contact c = force_.contact(m.id);
  if (c.motion != m.id) return std::nullopt;
  return c;
}

void Manipulator::update_from_contact(const Motion& m, const TransformPtr& x,
                                      const PositionPtr& position) {
  const std::optional<Contact> c = contact(m);
  if (!c) {
    throw MotionError(
        fmt::format("motion {} made no contact (its guard did not trip, or it "
                    "has not ended): nothing to update",
                    m.id));
  }
  if (!x || !position) throw MotionError("update_from_contact: a null transform or position");
  try {
    x->set(position->solve_for(*x, c->t6));
  } catch (const std::exception& e) {
    throw MotionError(e.what());
  }
}

Motion Manipulator::dwell(double seconds, const StartWhen& when) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) {
    throw MotionError(fmt::format("dwell time must be >= 0 s, got {}", seconds));
  }
  MotionRequest r;
  r.kind = RequestKind::dwell;
  r.dwell_s = seconds;
  return submit(r, nullptr, when);
}

void Manipulator::set_zero_gravity(bool on) {
  if (!started_) throw MotionError("call start() (rccl_control) before zero gravity");
  if (on == zero_gravity_) return;
  if (on && !happened(completed())) {
    throw MotionError("zero gravity only at rest: waitfor(completed()) first");
  }
  zero_gravity_ = on;
  zero_gravity_request_.store(on ? rtc::Request::on : rtc::Request::off);
}

void Manipulator::set_hand(bool closed) noexcept {
  hand_request_.store(closed ? rtc::Request::on : rtc::Request::off);
}

void Manipulator::halt() {
  generator_->request_halt();
}

bool Manipulator::happened(const Event& e) const noexcept {
  switch (e.kind) {
    case Event::Kind::motion_start:
      return generator_->started_upto() >= e.id;
    case Event::Kind::motion_end:
      return generator_->ended_upto() >= e.id;
    case Event::Kind::position_end:
      return e.position->pending_ends.load(std::memory_order_acquire) <= 0;
    case Event::Kind::completed:
      return generator_->ended_upto() >= next_id_ - 1;
  }
  return false;
}

EventGate Manipulator::gate(const Event& event) const {
  EventGate g;
  g.ledger = &generator_->ledger();
  switch (event.kind) {
    case Event::Kind::motion_start:
      g.kind = EventGate::Kind::started;
      g.id = event.id;
      break;
    case Event::Kind::motion_end:
      g.kind = EventGate::Kind::ended;
      g.id = event.id;
      break;
    case Event::Kind::completed:
      g.kind = EventGate::Kind::ended;
      g.id = next_id_ - 1;
      break;
    case Event::Kind::position_end:
      throw MotionError(
          "another robot cannot wait for a position's end: wait for the motion's end instead");
  }
  return g;
}

rtc::Termination Manipulator::wait_for(std::chrono::nanoseconds d) {
  return session_.wait_for(d);
}

WaitResult Manipulator::waitfor(const Event& event, std::chrono::nanoseconds timeout) {
  const bool reached =
      happened(event) ||
      session_.wait_until([&](const rtc::How&) { return happened(event); }, timeout);
  drain();
  if (!reached) return session_.controlling() ? WaitResult::timeout : WaitResult::session_ended;
  if (event.kind == Event::Kind::motion_start || event.kind == Event::Kind::motion_end) {
    if (failed_ids_.count(event.id) != 0) return WaitResult::failed;
  }
  if (event.kind == Event::Kind::completed && !failed_ids_.empty() &&
      *failed_ids_.rbegin() == next_id_ - 1) {
    return WaitResult::failed;
  }
  return WaitResult::reached;
}

void Manipulator::drain() {
  while (auto e = generator_->next_event()) {
    if (e->kind == EventKind::failed || e->kind == EventKind::cancelled) {
      failures_.push_back(*e);
      if (e->id != 0) failed_ids_.insert(e->id);  // 0: a stop of tracking, no motion
    }
    pending_events_.push_back(*e);
  }
  // A program that never takes its events keeps the newest few thousand.
  if (pending_events_.size() > 8192) {
    pending_events_.erase(pending_events_.begin(), pending_events_.begin() + 4096);
  }
}

const std::vector<MotionEvent>& Manipulator::failures() {
  drain();
  return failures_;
}

std::vector<MotionEvent> Manipulator::take_events() {
  drain();
  return std::exchange(pending_events_, {});
}

}  // namespace rccx::rccl
