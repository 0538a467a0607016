#include "rccx/net/remote_cell.hpp"
#include "rccx/net/middleware.hpp"

#include <fmt/format.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <stdexcept>

#include "rccx/io/console.hpp"
#include "rccx/net/codec.hpp"
#include "rccx/net/states.hpp"

namespace rccx::net {

namespace {

using namespace std::chrono_literals;
using detail::Inbox;
using detail::ms_of;
using detail::raise_priority;
using detail::random_instance;

rccl::MotionEvent to_event(const rccx_net_MotionEvent& e) {
  rccl::MotionEvent m;
  m.kind = e.kind <= 3 ? static_cast<rccl::EventKind>(e.kind) : rccl::EventKind::failed;
  m.id = e.motion;
  m.t_s = e.t_s;
  const std::string_view text = text_of(e.text);
  const std::size_t n = std::min(text.size(), m.text.size() - 1);
  std::copy_n(text.data(), n, m.text.data());
  m.text[n] = '\0';
  return m;
}

/// A motion's gates into its request; MotionError (nothing written) for more than the wire's
/// bound or a gate without a ledger.
void encode_gates(const rccl::StartWhen& when, RequestSample& r) {
  if (when.after.size() > kGates) {
    throw rccl::MotionError(fmt::format("at most {} gates a motion cross processes, not {}", kGates,
                                        when.after.size()));
  }
  for (const rccl::EventGate& g : when.after) {
    if (g.ledger == nullptr) throw rccl::MotionError("a gate without a ledger");
  }
  for (const rccl::EventGate& g : when.after) {
    rccx_net_Gate& out = r.add_gate();
    copy_to(out.robot, g.ledger->robot());
    out.kind = g.kind == rccl::EventGate::Kind::started ? 0 : 1;
    out.motion = g.id;
  }
}

/// A request of `kind` with the settings it is queued with (every request carries them).
RequestSample request_of(RequestKind kind, const rccl::MotionSettings& settings) {
  RequestSample r;
  r.msg.kind = static_cast<std::uint8_t>(kind);
  encode_settings(settings, r.msg);
  return r;
}

rccl::MotionEvent lost_event(std::uint64_t id, std::string_view why) {
  rccl::MotionEvent m;
  m.kind = rccl::EventKind::failed;
  m.id = id;
  const std::size_t n = std::min(why.size(), m.text.size() - 1);
  std::copy_n(why.data(), n, m.text.data());
  m.text[n] = '\0';
  return m;
}

std::string robots_of(const cell::CellModel& model) {
  std::string s;
  for (const auto& r : model.robots) s += (s.empty() ? "" : ", ") + r.name;
  return s;
}

}  // namespace

// --- RemoteArm -------------------------------------------------------------------------------

RemoteArm::RemoteArm(RemoteCell& cell, const cell::CellRobot& robot)
    : cell_(cell),
      name_(robot.name),
      kinematics_(kin::make_kinematics(robot.model)),
      park_(rccl::Position::joints("park", robot.model.ready())),
      mirror_(std::make_unique<RobotMirror>(robot.name)) {}

void RemoteArm::set_velocity(double translation_m_per_s, double rotation_rad_per_s) {
  if (!(translation_m_per_s > 0.0) || !(rotation_rad_per_s > 0.0) ||
      !std::isfinite(translation_m_per_s) || !std::isfinite(rotation_rad_per_s)) {
    throw rccl::MotionError(
        fmt::format("set_velocity({}, {}): both speeds must be finite and > 0 (m/s, rad/s)",
                    translation_m_per_s, rotation_rad_per_s));
  }
  settings_.translation_m_per_s = translation_m_per_s;
  settings_.rotation_rad_per_s = rotation_rad_per_s;
}

void RemoteArm::set_segment_time(double seconds) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) {
    throw rccl::MotionError(
        fmt::format("set_segment_time({}): give s >= 0 (0: from the speeds)", seconds));
  }
  settings_.segment_time_s = seconds;
}

void RemoteArm::set_transition_time(double seconds) {
  if (!(seconds > 0.0) || !std::isfinite(seconds)) {
    throw rccl::MotionError(fmt::format("set_transition_time({}): give s > 0", seconds));
  }
  settings_.transition_time_s = seconds;
}

void RemoteArm::set_configuration(std::string_view name) {
  if (name.empty()) {
    settings_.configuration = -1;
    return;
  }
  const auto names = kinematics_->configuration_names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) {
      settings_.configuration = static_cast<std::int16_t>(i);
      return;
    }
  }
  std::string known;
  for (const auto n : names) known += (known.empty() ? "" : ", ") + std::string(n);
  throw rccl::MotionError(fmt::format("robot {} has no configuration \"{}\"; it has: {}", name_,
                                      name, known.empty() ? "none" : known));
}

void RemoteArm::set_guard(const rccl::ForceGuard& guard) {
  rccl::check_guard(guard);
  settings_.guard = guard;
}

void RemoteArm::set_compliance(const rccl::Compliance& compliance) {
  rccl::check_compliance(compliance);
  settings_.compliance = compliance;
}

rccx_net_MotionAck RemoteArm::request(RequestSample& sample) {
  RemoteCell& c = cell_;
  rccx_net_MotionRequest& r = sample.msg;
  copy_to(r.robot, name_);
  copy_to(r.program, c.participant_name_);
  r.program_instance = c.instance_;
  r.request = next_request_++;
  const auto send = [&] { check(dds_write(c.request_writer_.get(), &r), "a motion request"); };
  {
    std::lock_guard lock(c.mutex_);
    if (!lost_.empty()) throw rccl::MotionError(lost_);
  }
  send();
  const std::int64_t start = steady_ns();
  std::int64_t resend = start + 200'000'000;
  std::unique_lock lock(c.mutex_);
  for (;;) {
    for (auto it = c.acks_.begin(); it != c.acks_.end(); ++it) {
      if (it->request != r.request || text_of(it->robot) != name_) continue;
      const rccx_net_MotionAck ack = *it;
      c.acks_.erase(it);
      if (ack.result == static_cast<std::uint8_t>(AckResult::refused)) {
        throw rccl::MotionError(std::string(text_of(ack.message)));
      }
      return ack;
    }
    if (!lost_.empty()) throw rccl::MotionError(lost_);
    const std::int64_t now = steady_ns();
    if (now - start > c.options_.answer_timeout.count()) {
      throw rccl::MotionError(fmt::format(
          "robot {}: its serve process {} did not answer request {} within {:.0f} ms (is it "
          "running on domain {}?)",
          name_, mirror_->participant(), r.request, ms_of(now - start), c.participant_->domain()));
    }
    if (now >= resend) {  // the same id again: executed once at most
      lock.unlock();
      send();
      lock.lock();
      resend = now + 200'000'000;
    }
    c.changed_.wait_for(lock, 2ms);
  }
}

rccl::Motion RemoteArm::move(const rccl::PositionPtr& position, const rccl::StartWhen& when) {
  if (!position) throw rccl::MotionError(fmt::format("robot {}: move(nullptr)", name_));
  if (when.together) {
    throw rccl::MotionError(
        "a joint start (Cell::together) across processes is not supported yet: use gates "
        "(cell.after(robot, event))");
  }
  rccl::MotionSettings s = settings_;
  s.may_touch = when.touch;
  RequestSample r = request_of(RequestKind::move, s);
  try {
    encode_position(*position, r);
  } catch (const CodecError& e) {
    throw rccl::MotionError(
        fmt::format("robot {}: move({}): {}", name_, position->name(), e.what()));
  }
  encode_gates(when, r);
  const rccx_net_MotionAck ack = request(r);
  last_queued_ = std::max(last_queued_, ack.motion);
  position_last_[position.get()] = ack.motion;
  return rccl::Motion{ack.motion};
}

rccl::Motion RemoteArm::dwell(double seconds, const rccl::StartWhen& when) {
  if (when.together) throw rccl::MotionError("a joint start across processes: not supported yet");
  rccl::MotionSettings s = settings_;
  s.may_touch = when.touch;
  RequestSample r = request_of(RequestKind::dwell, s);
  r.msg.value = seconds;
  encode_gates(when, r);
  const rccx_net_MotionAck ack = request(r);
  last_queued_ = std::max(last_queued_, ack.motion);
  return rccl::Motion{ack.motion};
}

void RemoteArm::halt() {
  RequestSample r = request_of(RequestKind::halt, settings_);
  (void)request(r);
}

void RemoteArm::nextmove() {
  RequestSample r = request_of(RequestKind::nextmove, settings_);
  (void)request(r);
}

void RemoteArm::set_hand(bool closed) {
  RequestSample r = request_of(RequestKind::hand, settings_);
  r.msg.value = closed ? 1.0 : 0.0;
  (void)request(r);
}

void RemoteArm::attach() {
  RequestSample r = request_of(RequestKind::attach, settings_);
  const rccx_net_MotionAck ack = request(r);
  last_queued_ = std::max(last_queued_, ack.motion);
}

rccl::GateAnswer RemoteArm::answer(const rccl::Event& e) const {
  switch (e.kind) {
    case rccl::Event::Kind::motion_start:
      return mirror_->ledger.has_started(e.id);
    case rccl::Event::Kind::motion_end:
      return mirror_->ledger.has_ended(e.id);
    case rccl::Event::Kind::completed:
      return mirror_->ledger.has_ended(last_queued_);
    case rccl::Event::Kind::position_end: {
      const auto it = position_last_.find(e.position);
      return mirror_->ledger.has_ended(it == position_last_.end() ? 0 : it->second);
    }
  }
  return rccl::GateAnswer::never;
}

rccl::WaitResult RemoteArm::waitfor(const rccl::Event& event, std::chrono::nanoseconds timeout) {
  const std::int64_t until = steady_ns() + std::min<std::int64_t>(timeout.count(), INT64_MAX / 4);
  std::unique_lock lock(cell_.mutex_);
  for (;;) {
    switch (answer(event)) {
      case rccl::GateAnswer::yes:
        return rccl::WaitResult::reached;
      case rccl::GateAnswer::never:
        return rccl::WaitResult::failed;
      case rccl::GateAnswer::not_yet:
        break;
    }
    if (steady_ns() >= until) return rccl::WaitResult::timeout;
    cell_.changed_.wait_for(lock, 2ms);
  }
}

rtc::Termination RemoteArm::wait_for(std::chrono::nanoseconds d) {
  std::this_thread::sleep_for(d);
  rtc::Termination t;
  std::lock_guard lock(cell_.mutex_);
  if (state_ && state_->terminate_code != 0) {
    t.code = static_cast<rtc::TerminateCode>(state_->terminate_code);
    t.sample = state_->sample;
    t.time_s = state_->t_s;
    const std::string_view why(state_->termination);
    const std::size_t n = std::min(why.size(), t.message.size() - 1);
    std::copy_n(why.data(), n, t.message.data());
  }
  return t;
}

bool RemoteArm::happened(const rccl::Event& event) const noexcept {
  std::lock_guard lock(cell_.mutex_);
  return answer(event) == rccl::GateAnswer::yes;
}

const std::vector<rccl::MotionEvent>& RemoteArm::failures() {
  std::lock_guard lock(cell_.mutex_);
  failures_copy_ = failures_;
  return failures_copy_;
}

rccl::SegmentReport RemoteArm::report(const rccl::Motion& m) const noexcept {
  std::lock_guard lock(cell_.mutex_);
  const auto it = reports_.find(m.id);
  if (it != reports_.end()) return it->second;
  rccl::SegmentReport r;
  r.id = m.id;
  return r;
}

std::vector<rccl::MotionEvent> RemoteArm::take_events() {
  std::lock_guard lock(cell_.mutex_);
  std::vector<rccl::MotionEvent> out;
  out.swap(events_);
  return out;
}

RemoteState RemoteArm::state() const {
  std::lock_guard lock(cell_.mutex_);
  if (!state_) throw rccl::MotionError(fmt::format("robot {}: no state received yet", name_));
  const rccx_net_RobotState& s = *state_;
  RemoteState out;
  out.participant = text_of(s.participant);
  out.instance = s.instance;
  out.sample = s.sample;
  out.t_s = s.t_s;
  out.stamp_ns = s.stamp_ns;
  out.q_commanded = kin::JointVector(std::min<std::size_t>(s.dof, 8));
  out.q_measured = kin::JointVector(std::min<std::size_t>(s.dof, 8));
  for (std::size_t j = 0; j < out.q_commanded.size(); ++j) {
    out.q_commanded[j] = s.q_commanded[j];
    out.q_measured[j] = s.q_measured[j];
  }
  out.tool.pose = from_pose(s.tool);
  out.tool.velocity_m_per_s = {s.velocity[0], s.velocity[1], s.velocity[2]};
  out.tool.acceleration_m_per_s2 = {s.acceleration[0], s.acceleration[1], s.acceleration[2]};
  out.tool.angular_velocity_rad_s = {s.angular_velocity[0], s.angular_velocity[1],
                                     s.angular_velocity[2]};
  out.tool.t_s = s.t_s;
  out.status = static_cast<RobotStatus>(s.status);
  out.terminate_code = s.terminate_code;
  out.termination = text_of(s.termination);
  out.running = s.running;
  out.queued = s.queued;
  out.started_upto = s.started_upto;
  out.ended_upto = s.ended_upto;
  out.control_ended = s.control_ended;
  out.program = text_of(s.program);
  out.age = std::chrono::nanoseconds(steady_ns() - state_received_ns_);
  return out;
}

// --- FrameStream -----------------------------------------------------------------------------

FrameStream::FrameStream(RemoteCell& cell, std::string name)
    : cell_(cell),
      name_(std::move(name)),
      last_(std::make_shared<cell::SeqLock<math::Transform>>()) {
  if (name_.empty() || name_.size() > 31) {
    throw std::invalid_argument(fmt::format("stream name \"{}\": 1 .. 31 characters", name_));
  }
  transform_ = rccl::functional(name_, [last = last_](const rccl::SampleContext&) {
    math::Transform t;
    return last->load(t) ? t : math::Transform::identity();
  });
  transform_->set_reference("stream:" + name_);
}

void FrameStream::set(const math::Transform& pose, const math::Vec3& velocity_m_per_s,
                      const math::Vec3& angular_velocity_rad_s) {
  rccx_net_FrameSample s{};
  copy_to(s.name, name_);
  copy_to(s.program, cell_.participant_name_);
  s.seq = ++seq_;
  s.stamp_ns = wall_ns();
  to_pose(pose, s.pose);
  s.velocity[0] = velocity_m_per_s.x;
  s.velocity[1] = velocity_m_per_s.y;
  s.velocity[2] = velocity_m_per_s.z;
  s.angular_velocity[0] = angular_velocity_rad_s.x;
  s.angular_velocity[1] = angular_velocity_rad_s.y;
  s.angular_velocity[2] = angular_velocity_rad_s.z;
  last_->store(pose);
  check(dds_write(cell_.frame_writer_.get(), &s), fmt::format("stream {}", name_));
}

// --- RemoteCell ------------------------------------------------------------------------------

RemoteCell::RemoteCell(cell::CellModel model, NetOptions net, RemoteOptions options)
    : model_(std::move(model)), net_(std::move(net)), options_(std::move(options)) {
  participant_name_ = "program/" + host_and_pid();
  instance_ = random_instance();
  std::vector<std::string> names = options_.robots;
  if (names.empty()) {
    for (const auto& r : model_.robots) names.push_back(r.name);
  }
  for (const std::string& n : names) {
    const cell::CellRobot* r = model_.find_robot(n);
    if (r == nullptr) {
      throw std::invalid_argument(fmt::format("cell {} has no robot \"{}\"; its robots are: {}",
                                              model_.name, n, robots_of(model_)));
    }
    arms_.push_back(std::make_unique<RemoteArm>(*this, *r));
  }
  participant_ = std::make_unique<Participant>(net_);
  hb_writer_ = participant_->writer(Topic::heartbeat);
  request_writer_ = participant_->writer(Topic::request);
  frame_writer_ = participant_->writer(Topic::frame);
  state_reader_ = participant_->reader(Topic::state, net_.detection * 10);
  states_in_ = std::make_unique<StateInbox>();
  events_in_ = std::make_unique<Inbox<rccx_net_MotionEvent>>(rccx_net_MotionEvent_desc, 16);
  ack_reader_ = participant_->reader(Topic::ack);
  event_reader_ = participant_->reader(Topic::event);
  waitset_ = Entity(check(dds_create_waitset(participant_->get()), "a waitset"));
  const auto ready = [&](const Entity& reader) {
    // Any sample the reader holds: the thread takes them all each pass.
    Entity c(check(dds_create_readcondition(reader.get(), DDS_ANY_STATE), "a read condition"));
    check(dds_waitset_attach(waitset_.get(), c.get(), 0), "a waitset's condition");
    return c;
  };
  state_ready_ = ready(state_reader_);
  event_ready_ = ready(event_reader_);
  wake_guard_ = Entity(check(dds_create_guardcondition(participant_->get()), "a guard condition"));
  check(dds_waitset_attach(waitset_.get(), wake_guard_.get(), 0), "a waitset's condition");
  {
    // Answers taken as they arrive, in Cyclone's receive thread, and handed to the waiting
    // call: one thread hand-over less a request than through the middleware thread
    // (docs/PERFORMANCE.md, "Network").
    dds_listener_t* l = dds_create_listener(this);
    dds_lset_data_available(
        l, [](dds_entity_t, void* self) { static_cast<RemoteCell*>(self)->take_acks(); });
    const dds_return_t rc = dds_set_listener(ack_reader_.get(), l);
    dds_delete_listener(l);
    check(rc, "the answers' listener");
  }
  thread_ = std::thread([this] { run(); });
  // Every robot's state, and the request readers of their serve processes matched.
  const std::int64_t until = steady_ns() + options_.wait_for_robots.count();
  std::unique_lock lock(mutex_);
  for (;;) {
    std::set<std::string> serves;
    const RemoteArm* missing = nullptr;
    for (const auto& a : arms_) {
      if (!a->state_) {
        missing = a.get();
        break;
      }
      serves.insert(std::string(text_of(a->state_->participant)));
    }
    // Outside mutex_: a request written in this process to a serve in this process delivers
    // its ack to take_acks() (which takes mutex_) while the writer's lock is held, so holding
    // mutex_ here while taking the writer's lock is the other order (ThreadSanitizer, tests/
    // net_threads_test.cpp).
    lock.unlock();
    dds_publication_matched_status_t st{};
    (void)dds_get_publication_matched_status(request_writer_.get(), &st);
    lock.lock();
    if (missing == nullptr && st.current_count >= serves.size()) break;
    if (steady_ns() >= until) {
      lock.unlock();
      (void)dds_set_listener(ack_reader_.get(), nullptr);  // before mutex_ and acks_ go
      stop_.store(true);
      (void)dds_set_guardcondition(wake_guard_.get(), true);
      thread_.join();
      if (missing != nullptr) {
        throw NetError(fmt::format(
            "robot {} is not served: start `rccx serve --cell FILE --robots {}` (domain {}{})",
            missing->name(), missing->name(), participant_->domain(),
            net_.interface.empty() ? "" : ", interface " + net_.interface));
      }
      throw NetError("the serve processes' request readers did not match within the wait");
    }
    changed_.wait_for(lock, 5ms);
  }
  // A restarted program goes on from where the robots are: their queues' last motions.
  for (auto& a : arms_) a->last_queued_ = a->state_->queued;
}

void RemoteCell::start() {
  for (auto& a : arms_) a->attach();
}

RemoteCell::~RemoteCell() {
  // Cyclone waits for a listener call under way: none runs after this (mutex_ and acks_ go
  // before the reader).
  (void)dds_set_listener(ack_reader_.get(), nullptr);
  stop_.store(true);
  (void)dds_set_guardcondition(wake_guard_.get(), true);
  if (thread_.joinable()) thread_.join();
}

RemoteArm* RemoteCell::find(std::string_view name) noexcept {
  for (auto& a : arms_) {
    if (a->name() == name) return a.get();
  }
  return nullptr;
}

RemoteArm& RemoteCell::robot(std::string_view name) {
  if (RemoteArm* a = find(name)) return *a;
  std::string known;
  for (const auto& a : arms_) known += (known.empty() ? "" : ", ") + a->name();
  throw std::invalid_argument(fmt::format("no robot \"{}\" here; the robots are: {}", name, known));
}

std::vector<std::string> RemoteCell::robot_names() const {
  std::vector<std::string> v;
  for (const auto& a : arms_) v.push_back(a->name());
  return v;
}

rccl::TransformPtr RemoteCell::tool_frame(std::string_view leader) const {
  RemoteArm& a = const_cast<RemoteCell*>(this)->robot(leader);  // its mirror outlives the frame
  return remote_frame(a.name() + "_TOOL", "frame:" + a.name(), &a.mirror_->frame, net_.detection);
}

rccl::TransformPtr RemoteCell::function(std::string name) const {
  auto t = rccl::functional(name, [](const rccl::SampleContext&) {
    return math::Transform::identity();  // only the serve process can evaluate it
  });
  t->set_reference("function:" + name);
  return t;
}

FrameStream& RemoteCell::stream(std::string name) {
  auto& s = streams_[name];
  if (!s) s = std::make_unique<FrameStream>(*this, name);
  return *s;
}

rccl::EventGate RemoteCell::event(std::string_view robot_name, const rccl::Event& e) {
  RemoteArm& a = robot(robot_name);
  rccl::EventGate g;
  g.ledger = &a.mirror_->ledger;
  switch (e.kind) {
    case rccl::Event::Kind::motion_start:
      g.kind = rccl::EventGate::Kind::started;
      g.id = e.id;
      break;
    case rccl::Event::Kind::motion_end:
      g.kind = rccl::EventGate::Kind::ended;
      g.id = e.id;
      break;
    case rccl::Event::Kind::completed:
      g.kind = rccl::EventGate::Kind::ended;
      g.id = a.last_queued();
      break;
    case rccl::Event::Kind::position_end:
      throw rccl::MotionError(
          "a position's end cannot gate another robot; use the motion's end (m.end())");
  }
  return g;
}

rccl::WaitResult RemoteCell::waitfor(const std::vector<rccl::EventGate>& gates,
                                     std::chrono::nanoseconds timeout) {
  const std::int64_t until = steady_ns() + std::min<std::int64_t>(timeout.count(), INT64_MAX / 4);
  std::unique_lock lock(mutex_);
  for (;;) {
    bool all = true;
    for (const rccl::EventGate& g : gates) {
      const rccl::GateAnswer a = g.answer();
      if (a == rccl::GateAnswer::never) return rccl::WaitResult::failed;
      if (a == rccl::GateAnswer::not_yet) all = false;
    }
    if (all) return rccl::WaitResult::reached;
    if (steady_ns() >= until) return rccl::WaitResult::timeout;
    changed_.wait_for(lock, 2ms);
  }
}

void RemoteCell::wait_for(std::chrono::nanoseconds d) {
  std::this_thread::sleep_for(d);
}

void RemoteCell::run() noexcept {
  raise_priority();
  while (!stop_.load()) {
    try {
      poll(steady_ns());
    } catch (const std::exception& e) {
      io::eprint("rccx program: the network thread: {}\n", e.what());
      std::this_thread::sleep_for(1ms);  // not a busy loop on a lasting failure
    }
    if (stop_.load()) break;
    // Until data arrives (an answer is taken and handed over at once), the stop guard, or
    // the next heartbeat or loss deadline.
    const std::int64_t now = steady_ns();
    const std::int64_t until =
        std::min(last_heartbeat_ns_ + net_.heartbeat.count(), next_loss_check_ns_);
    (void)dds_waitset_wait(waitset_.get(), nullptr, 0, std::max<std::int64_t>(until - now, 0));
  }
}

void RemoteCell::take_acks() noexcept {
  try {
    rccx_net_MotionAck buf[8];
    void* ptrs[8];
    dds_sample_info_t info[8];
    for (std::size_t i = 0; i < 8; ++i) ptrs[i] = &buf[i];
    bool changed = false;
    for (;;) {
      const dds_return_t n = dds_take(ack_reader_.get(), ptrs, info, 8, 8);
      for (dds_return_t i = 0; i < n; ++i) {
        if (!info[i].valid_data || text_of(buf[i].program) != participant_name_) continue;
        std::lock_guard lock(mutex_);
        acks_.push_back(buf[i]);
        if (acks_.size() > 1024) acks_.erase(acks_.begin());
        changed = true;
      }
      if (n < 8) break;
    }
    if (changed) changed_.notify_all();
  } catch (...) {  // push_back's bad_alloc: the call's resend asks again
  }
}

void RemoteCell::poll(std::int64_t now) {
  if (now - last_heartbeat_ns_ >= net_.heartbeat.count()) {
    rccx_net_Heartbeat hb{};
    copy_to(hb.participant, participant_name_);
    hb.role = static_cast<std::uint8_t>(Role::program);
    hb.instance = instance_;
    hb.seq = ++heartbeat_seq_;
    hb.period_ns = net_.heartbeat.count();
    hb.detection_ns = net_.detection.count();
    std::string robots;
    for (const auto& a : arms_) robots += (robots.empty() ? "" : ",") + a->name();
    copy_to(hb.robots, robots);
    check(dds_write(hb_writer_.get(), &hb), "a heartbeat");
    last_heartbeat_ns_ = now;
  }
  bool changed = false;
  {
    states_in_->drain(state_reader_.get(), [&](const rccx_net_RobotState& s) {
      RemoteArm* a = find(text_of(s.robot));
      if (a == nullptr) return;
      std::lock_guard lock(mutex_);
      const bool restarted = a->mirror_->apply(s, now);
      a->state_ = s;
      a->state_received_ns_ = now;
      if (!a->lost_.empty() || restarted) {
        io::eprint("rccx program: robot {} is served {}by {}\n", a->name(),
                   restarted ? "by a new serve process: " : "again ", text_of(s.participant));
        a->lost_.clear();
        a->mirror_->set_lost(false);
      }
      // Control ended on the serve (an overrun, a fault): the waits that now fail say why.
      // A new serve, or control running again (restarted after an overrun): a later end is
      // a new failure.
      if (restarted || s.terminate_code == 0) a->end_said_ = false;
      if (s.terminate_code != 0 && !a->end_said_) {
        a->end_said_ = true;
        const std::string why = fmt::format("robot {}'s control ended on its serve process: {}",
                                            a->name(), text_of(s.termination));
        a->failures_.push_back(lost_event(a->last_queued_, why));
        io::eprint("rccx program: {}\n", why);
      }
      changed = true;
    });
  }
  {
    Inbox<rccx_net_MotionEvent>& in = *events_in_;
    for (;;) {
      const int n = in.take(event_reader_.get());
      for (int i = 0; i < n; ++i) {
        if (!in.valid(i)) continue;
        RemoteArm* a = find(text_of(in[i].robot));
        if (a == nullptr) continue;
        const rccl::MotionEvent e = to_event(in[i]);
        std::lock_guard lock(mutex_);
        rccl::SegmentReport& r = a->reports_[e.id];
        r.id = e.id;
        if (e.kind == rccl::EventKind::started) r.start_s = e.t_s;
        if (e.kind != rccl::EventKind::started) r.end_s = e.t_s;
        r.failed = e.kind == rccl::EventKind::failed || e.kind == rccl::EventKind::cancelled;
        if (a->reports_.size() > 4096) a->reports_.erase(a->reports_.begin());
        a->events_.push_back(e);
        if (a->events_.size() > 4096) a->events_.erase(a->events_.begin());
        if (e.kind == rccl::EventKind::failed || e.kind == rccl::EventKind::cancelled) {
          a->failures_.push_back(e);
        }
        changed = true;
      }
      if (n < in.capacity()) break;
    }
  }
  // A robot whose serve process is silent for the detection time is lost.
  next_loss_check_ns_ = INT64_MAX;
  for (auto& a : arms_) {
    std::lock_guard lock(mutex_);
    if (!a->state_ || !a->lost_.empty()) continue;
    const std::int64_t silent = now - a->mirror_->received_ns();
    if (silent <= net_.detection.count()) {
      next_loss_check_ns_ =
          std::min(next_loss_check_ns_, a->mirror_->received_ns() + net_.detection.count() + 1);
      continue;
    }
    a->lost_ = fmt::format("robot {} lost: its serve process {} is silent for {:.0f} ms", a->name(),
                           a->mirror_->participant(), ms_of(silent));
    a->mirror_->set_lost(true);
    a->failures_.push_back(lost_event(a->last_queued_, a->lost_));
    io::eprint("rccx program: {}\n", a->lost_);
    changed = true;
  }
  if (changed) changed_.notify_all();
}

}  // namespace rccx::net
