#include "rccx/net/robot_server.hpp"
#include "rccx/net/middleware.hpp"

#include <fmt/format.h>
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <deque>
#include <random>
#include <set>
#include <span>
#include <stdexcept>
#include <utility>

#include "rccx/io/console.hpp"
#include "rccx/net/codec.hpp"
#include "rccx/net/ros2_joint_state.hpp"
#include "rccx/net/states.hpp"
#include "rccx/rtc/latest.hpp"

namespace rccx::net {

namespace {

using namespace std::chrono_literals;
using detail::Inbox;
using detail::ms_of;
using detail::raise_priority;
using detail::random_instance;

/// What the control task hands the middleware thread after a tick (trivially copyable).
struct Slot {
  std::uint64_t sample = 0;
  double t_s = 0.0;
  std::uint8_t dof = 0;
  double q[8]{};
  double qd[8]{};  ///< rad/s / m/s: the setpoints' last difference over the period
  cell::ToolSample tool;
  std::uint64_t running = 0;
  bool halting = false;  ///< the setpoint is a halt's (RobotStatus::stopping)
  std::int64_t stamp_ns = 0;
};

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

/// The serve's clock so far: whether an overrun came from a late wake-up (the machine) or a
/// long cycle (the control functions) is the first thing to know about it.
std::string clock_figures(const rtc::Session& session, std::chrono::nanoseconds period) {
  const rtc::LatencyStats wake = session.latency();
  const rtc::LatencyStats cycle = session.compute();
  return fmt::format(
      "{} ticks of {:.3g} ms: cycle p50 {:.0f} us, p99 {:.0f} us, max {:.0f} us; wake-up p99 "
      "{:.0f} us, max {:.0f} us late; {} deadlines missed",
      cycle.wakeups, std::chrono::duration<double, std::milli>(period).count(), cycle.p50_us,
      cycle.p99_us, cycle.max_us, wake.p99_us, wake.max_us, wake.missed_deadlines);
}

}  // namespace

struct RobotServer::Local {
  std::string name;
  rccl::Manipulator* arm = nullptr;
  const rccl::TrajectoryGenerator* gen = nullptr;
  rtc::Session* session = nullptr;
  double period_s = 0.0;
  rtc::detail::Latest<Slot> latest;  ///< control task -> middleware thread
  // Control task only.
  double last_t_s = -1.0;
  std::uint64_t samples = 0;
  // Middleware thread only.
  Slot slot;
  bool have_slot = false;
  bool fresh = false;           ///< a new sample this pass
  std::size_t batch_index = 0;  ///< its state's place in states_out_ this pass
  bool ros2_due = false;        ///< its ROS 2 joint state to send this pass
  std::int64_t written_ns = 0;  ///< steady, last state written
  bool end_said = false;        ///< its control's end was said on stderr
  std::uint64_t restarts = 0;   ///< control restarted after overruns
  std::string program;          ///< attached program ("" none)
  std::uint64_t program_instance = 0;
  std::int64_t attached_ns = 0;
  struct Origin {
    std::string program;
    std::uint64_t request = 0;
  };
  std::map<std::uint64_t, Origin> origin;  ///< motion id -> who asked (the newest 1024)
  std::string halt_reason;
  std::uint64_t halt_upto = 0;
  std::set<std::string> follows;  ///< remote robots whose frame the last motion uses
  std::set<std::string> streams;  ///< streams the last motion uses
  /// Its ROS 2 joint state (ServeOptions::ros2_joint_states; null when off).
  std::unique_ptr<JointStatePublisher> ros2;
};

/// Room for what a pass takes off the readers, made once (a request's answer in the receive
/// thread allocates no take buffers).
struct RobotServer::Inboxes {
  Inbox<rccx_net_Heartbeat> heartbeats{rccx_net_Heartbeat_desc, 16};
  StateInbox states{4};
  Inbox<rccx_net_FrameSample> frames{rccx_net_FrameSample_desc, 8};
  Inbox<rccx_net_MotionRequest> requests{rccx_net_MotionRequest_desc, 4};
};

struct RobotServer::Dedup {
  std::uint64_t instance = 0;
  std::uint64_t highest = 0;
  std::deque<rccx_net_MotionAck> acks;  ///< the newest 256 answers
};

bool RobotServer::MirrorSource::latest(std::size_t remote, kin::JointVector& q,
                                       kin::JointVector& qd, double& age_s) const noexcept {
  if (remote >= mirrors.size()) return false;
  JointsSample j;
  mirrors[remote]->joints.load(j);
  if (j.received_ns == 0 || j.q.size() == 0) return false;
  q = j.q;
  qd = j.qd;
  age_s = static_cast<double>(steady_ns() - j.received_ns) * 1e-9;
  return true;
}

cell::CellModel served_model(const cell::CellModel& model, const std::vector<std::string>& robots) {
  std::vector<std::string> names;
  for (const auto& r : model.robots) names.push_back(r.name);
  if (robots.empty()) {
    throw std::invalid_argument(
        fmt::format("no robot to serve: give --robots with some of {}", join(names)));
  }
  cell::CellModel out = model;
  out.robots.clear();
  std::set<std::string> seen;
  for (const std::string& name : robots) {
    const cell::CellRobot* r = model.find_robot(name);
    if (r == nullptr) {
      throw std::invalid_argument(fmt::format("cell {} has no robot \"{}\"; its robots are: {}",
                                              model.name, name, join(names)));
    }
    if (!seen.insert(name).second) {
      throw std::invalid_argument(fmt::format("robot {} is named twice", name));
    }
  }
  for (const auto& r : model.robots) {  // the cell file's order
    if (seen.count(r.name) != 0) out.robots.push_back(r);
  }
  return out;
}

RobotServer::RobotServer(cell::CellModel model, std::vector<std::string> robots,
                         ServeOptions options)
    : full_model_(std::move(model)), robot_names_(std::move(robots)), options_(std::move(options)) {
  (void)served_model(full_model_, robot_names_);  // checks the names now
  participant_name_ = "serve/" + host_and_pid();
  instance_ = random_instance();
  inboxes_ = std::make_unique<Inboxes>();
}

RobotServer::~RobotServer() {
  stop();
}

void RobotServer::register_function(std::string name, rccl::TransformFunction function) {
  if (started_) throw std::logic_error("register_function: only before start()");
  if (name.empty() || name.size() > 31) {
    throw std::invalid_argument(fmt::format("function name \"{}\": 1 .. 31 characters", name));
  }
  functions_[std::move(name)] = std::move(function);
}

std::string RobotServer::banner() const {
  const bool secure = !options_.net.secure_dir.empty();
  std::string interface = options_.net.interface;
  if (interface.empty()) {
    const char* env = std::getenv("RCCX_DDS_INTERFACE");
    interface = env != nullptr && *env != '\0' ? env : "Cyclone's default";
  }
  std::string ros2 = "no ROS 2 joint states (--no-ros2)";
  if (options_.ros2_joint_states) {
    std::vector<std::string> topics;
    for (const auto& r : robot_names_) topics.push_back(ros2_joint_states_topic(r));
    ros2 = "ROS 2 joint states on " + join(topics);
  }
  return fmt::format(
      "rccx serve: {} of cell {} as {}, DDS domain {}, interface {}, {}; {}", join(robot_names_),
      full_model_.name, participant_name_, domain_of(options_.net), interface,
      secure ? fmt::format("secure (DDS Security, identity {})", options_.net.secure_identity)
             : "plain DDS: anyone on the network can read and command these robots; use "
               "--secure DIR for DDS Security",
      ros2);
}

std::string RobotServer::failure() const {
  std::lock_guard lock(failure_mutex_);
  return failure_;
}

RobotServer::Local* RobotServer::local(std::string_view robot) noexcept {
  for (auto& l : locals_) {
    if (l->name == robot) return l.get();
  }
  return nullptr;
}

// --- Claims ----------------------------------------------------------------------------------

void RobotServer::claim() {
  claim_reader_ = participant_->reader(Topic::claim);
  claim_writer_ = participant_->writer(Topic::claim);
  // Another live process's claims on our robots (a dead one's writer is gone: Cyclone drops its
  // instances, and a claim whose writer is no longer matched does not count).
  const auto others = [this] {
    std::vector<rccx_net_Claim> found;
    std::vector<rccx_net_Claim> buf(64);
    std::vector<void*> ptrs(buf.size());
    std::vector<dds_sample_info_t> info(buf.size());
    for (std::size_t i = 0; i < buf.size(); ++i) ptrs[i] = &buf[i];
    const dds_return_t n =
        dds_read_mask(claim_reader_.get(), ptrs.data(), info.data(), buf.size(),
                      static_cast<std::uint32_t>(buf.size()), DDS_ALIVE_INSTANCE_STATE);
    for (int i = 0; i < n; ++i) {
      if (!info[i].valid_data) continue;
      const rccx_net_Claim& c = buf[i];
      if (text_of(c.participant) == participant_name_) continue;
      if (std::find(robot_names_.begin(), robot_names_.end(), text_of(c.robot)) ==
          robot_names_.end()) {
        continue;
      }
      dds_builtintopic_endpoint_t* w =
          dds_get_matched_publication_data(claim_reader_.get(), info[i].publication_handle);
      if (w == nullptr) continue;  // its writer is gone
      dds_builtintopic_free_endpoint(w);
      found.push_back(c);
    }
    return found;
  };
  const auto refuse = [this](const rccx_net_Claim& c, std::string_view how) {
    return ClaimRefused(fmt::format(
        "robot {} is served already by {} (host {}, pid {}){}: stop that process first, or "
        "serve other robots (domain {})",
        text_of(c.robot), text_of(c.participant), text_of(c.host), static_cast<long>(c.pid), how,
        participant_->domain()));
  };
  std::this_thread::sleep_for(options_.claim_wait);
  if (const auto held = others(); !held.empty()) throw refuse(held.front(), "");
  const std::string host_pid = host_and_pid();
  const std::string host = host_pid.substr(0, host_pid.rfind('/'));
  const std::int64_t since = wall_ns();
  for (const std::string& robot : robot_names_) {
    rccx_net_Claim c{};
    copy_to(c.robot, robot);
    copy_to(c.participant, participant_name_);
    c.instance = instance_;
    c.since_ns = since;
    copy_to(c.host, host);
    c.pid = static_cast<std::int32_t>(getpid());
    check(dds_write(claim_writer_.get(), &c), fmt::format("the claim on robot {}", robot));
    claims_.push_back(c);
  }
  // A race: another process claimed at the same time. The earlier claim wins; at the same
  // instant, the smaller participant name.
  std::this_thread::sleep_for(options_.claim_wait);
  for (const rccx_net_Claim& c : others()) {
    const bool theirs_first =
        c.since_ns < since ||
        (c.since_ns == since && text_of(c.participant) < std::string_view(participant_name_));
    if (theirs_first) {
      release_claims();
      throw refuse(c, ", which claimed it first while this process started");
    }
  }
}

void RobotServer::release_claims() noexcept {
  for (const rccx_net_Claim& c : claims_) (void)dds_dispose(claim_writer_.get(), &c);
  claims_.clear();
}

// --- Start and stop --------------------------------------------------------------------------

void RobotServer::start() {
  if (started_) return;
  participant_ = std::make_unique<Participant>(options_.net);
  claim();
  try {
    const std::chrono::nanoseconds deadline = options_.net.detection;  // offered
    hb_writer_ = participant_->writer(Topic::heartbeat);
    hb_reader_ = participant_->reader(Topic::heartbeat);
    state_writer_ = participant_->writer(Topic::state, deadline);
    // Requested: any writer's offer up to 10 detection times matches (rccx's own freshness
    // check, not DDS's deadline, decides that a robot is lost).
    state_reader_ = participant_->reader(Topic::state, deadline * 10);
    request_reader_ = participant_->reader(Topic::request);
    ack_writer_ = participant_->writer(Topic::ack);
    event_writer_ = participant_->writer(Topic::event);
    frame_reader_ = participant_->reader(Topic::frame);
    listen();

    cell::CellOptions co;
    co.clock = rtc::ClockKind::real_time;
    co.real_time_scheduling = options_.real_time_scheduling;
    // The other robots of the cell stay in the collision check, placed from their states.
    co.local_robots = robot_names_;
    cell_ = std::make_unique<cell::Cell>(full_model_, co);
    for (const std::string& name : cell_->robot_names()) {
      auto l = std::make_unique<Local>();
      l->name = name;
      l->arm = &cell_->robot(name);
      l->gen = &l->arm->generator();
      l->session = &cell_->session(name);
      l->period_s = std::chrono::duration<double>(l->session->period()).count();
      if (options_.ros2_joint_states) {
        l->ros2 = std::make_unique<JointStatePublisher>(*participant_, name,
                                                        full_model_.find_robot(name)->model);
      }
      locals_.push_back(std::move(l));
    }
    states_out_ = std::make_unique<StateBatch>(participant_name_, instance_, locals_.size());
    for (const auto& r : full_model_.robots) {
      if (local(r.name) == nullptr) mirrors_[r.name] = std::make_unique<RobotMirror>(r.name);
    }
    for (const std::string& name : cell_->remote_names()) {
      remote_source_.mirrors.push_back(mirrors_.at(name).get());
    }
    cell_->set_remote_source(&remote_source_);
    const cell::Cell* cell = cell_.get();
    cell_->set_cycle_observer([this, cell](std::uint32_t) { on_cycle(*cell); });
    cell_->start();
  } catch (...) {
    release_claims();
    throw;
  }
  started_ = true;
  answering_.store(true);
  thread_ = std::thread([this] { run(); });
}

void RobotServer::stop() {
  if (!started_ || stopped_) return;
  stopped_ = true;
  stop_.store(true);
  rtc::detail::ring(wake_);
  if (thread_.joinable()) thread_.join();
  {
    // A request listener that came in before stop_ leaves first: the cell goes next.
    const std::lock_guard pass(serve_mutex_);
    answering_.store(false);
  }
  release_claims();
  clock_report_ = clock_report();
  cell_.reset();  // ends control
}

RobotServer::RequestCounts RobotServer::request_counts() const {
  const std::lock_guard pass(serve_mutex_);
  return {answered_in_listener_, answered_in_pass_,
          listener_handed_over_.load(std::memory_order_relaxed)};
}

std::string RobotServer::request_report() const {
  const RequestCounts c = request_counts();
  const std::uint64_t total = c.in_listener + c.in_pass;
  return fmt::format(
      "{} requests: {} answered at once in the listener, {} by the middleware thread ({:.2f} %; "
      "the listener found a pass under way {} times)",
      total, c.in_listener, c.in_pass,
      total == 0 ? 0.0 : 100.0 * static_cast<double>(c.in_pass) / static_cast<double>(total),
      c.handed_over);
}

std::string RobotServer::clock_report() const {
  if (!cell_ || locals_.empty()) return clock_report_;
  return clock_figures(*locals_.front()->session, cell_->group().period());
}

// --- The control task's part -----------------------------------------------------------------

void RobotServer::on_cycle(const cell::Cell& cell) noexcept {
  bool fresh = false;
  try {
    for (auto& lp : locals_) {
      Local& l = *lp;
      const double t = l.gen->last_setpoint_time_s();
      const kin::JointVector& q = l.gen->last_setpoint();
      if (q.empty() || t == l.last_t_s) continue;  // nothing new this tick
      l.last_t_s = t;
      Slot s;
      s.sample = ++l.samples;
      s.t_s = t;
      s.dof = static_cast<std::uint8_t>(std::min<std::size_t>(q.size(), 8));
      const kin::JointVector& q0 = l.gen->previous_setpoint();
      for (std::size_t j = 0; j < s.dof; ++j) {
        s.q[j] = q[j];
        s.qd[j] = q0.size() == q.size() ? (q[j] - q0[j]) / l.period_s : 0.0;
      }
      s.tool = cell.tool_sample(l.name);  // the seqlock: no lock, no allocation
      s.running = l.gen->last_motion();
      s.halting = l.gen->halting();
      // The setpoint is for two periods after this sample (Manipulator's pipeline).
      s.stamp_ns = wall_ns() + static_cast<std::int64_t>((t - s.tool.t_s) * 1e9) +
                   static_cast<std::int64_t>(2.0 * l.period_s * 1e9);
      l.latest.publish(s);
      fresh = true;
    }
  } catch (...) {  // tool_sample of a known robot does not throw
  }
  // One atomic add, and a futex wake only when the middleware thread sleeps: no lock, no DDS
  // call here (dds_set_guardcondition would take Cyclone's global handle lock and three more).
  if (fresh) rtc::detail::ring(wake_);
}

// --- The middleware thread -------------------------------------------------------------------

void RobotServer::run() noexcept {
  try {
    if (options_.real_time_scheduling) raise_priority();
    while (!stop_.load()) {
      // The bell's count before the pass: a ring during it makes the wait return at once.
      const std::uint32_t seen = wake_.load();
      std::int64_t wake_at = 0;
      {
        const std::lock_guard pass(serve_mutex_);
        poll();
        wake_at = next_wake();
      }
      send_states();
      // No spinning: a request comes seldom, and a tick's ring wakes the futex directly.
      rtc::detail::wait_while(wake_, seen, wake_at, 0);
    }
    // Stopping: halt every robot, let them come to rest (bounded), say so in a last state. The
    // request listener sees stop_ and leaves the requests alone from now on.
    const std::lock_guard pass(serve_mutex_);
    for (auto& l : locals_) halt_with(*l, "the serve process is stopping: stopped smoothly");
    const std::int64_t until = steady_ns() + 2'000'000'000;
    while (steady_ns() < until) {
      bool rest = true;
      for (auto& l : locals_) {
        if (l->gen->ledger().ended_upto() < l->arm->last_queued()) rest = false;
      }
      publish_events();
      publish_states(steady_ns());
      send_states();
      if (rest) break;
      std::this_thread::sleep_for(1ms);
    }
    std::this_thread::sleep_for(100ms);  // the halt's last samples
    publish_events();
    publish_states(steady_ns(), true);
    send_states();
  } catch (const std::exception& e) {
    std::lock_guard lock(failure_mutex_);
    failure_ = e.what();
  }
}

void RobotServer::poll() {
  const std::int64_t now = steady_ns();
  attached_since_pass_ = false;
  acks_backlog_.flush(ack_writer_.get(), "acknowledgement");
  events_backlog_.flush(event_writer_.get(), "motion event");
  read_heartbeats(now);
  read_states(now);
  read_frames(now);
  answered_in_pass_ += read_requests(now);
  publish_events();
  const bool heartbeat_pass = now - last_heartbeat_ns_ >= options_.net.heartbeat.count();
  publish_states(now, false, heartbeat_pass);
  restart_after_overruns();
  if (heartbeat_pass) {
    heartbeat_due_ = true;  // written by send_states()
    last_heartbeat_ns_ = now;
  }
  check_lost(now);
}

void RobotServer::restart_after_overruns() {
  if (stop_.load()) return;
  for (auto& lp : locals_) {
    Local& l = *lp;
    // Said and published first (publish_states), so the program's waits fail with the reason.
    if (!l.end_said || l.session->ended_code() != rtc::TerminateCode::overrun) continue;
    // A missed deadline ended control (RTC's rule); the arm holds where it was. A serve runs
    // on: control starts again at rest where the arm stands, as `rccx report` does.
    try {
      l.session->release();
      l.arm->start();
      l.end_said = false;
      ++l.restarts;
      io::eprint("rccx serve: robot {}: control restarted at rest after the overrun (restart {})\n",
                 l.name, l.restarts);
    } catch (const std::exception& e) {
      io::eprint("rccx serve: robot {}: control could not restart after the overrun: {}\n", l.name,
                 e.what());
      l.end_said = true;
    }
  }
}

void RobotServer::listen() {
  dds_listener_t* l = dds_create_listener(&wake_);
  // In Cyclone's receive thread: only the ring, which neither blocks nor allocates.
  dds_lset_data_available(l, [](dds_entity_t, void* bell) {
    rtc::detail::ring(*static_cast<rtc::detail::Doorbell*>(bell));
  });
  dds_listener_t* r = dds_create_listener(this);
  dds_lset_data_available(r, [](dds_entity_t, void* server) {
    static_cast<RobotServer*>(server)->answer_in_receive_thread();
  });
  // A program's heartbeat (200 a second each) is taken in the receive thread too: waking the
  // middleware thread for each cost a context switch at real-time priority (tens of us of a
  // core on a VM) and held a core from the next request. States and frames still ring it: they
  // feed the control tasks, which want them at once.
  dds_listener_t* h = dds_create_listener(this);
  dds_lset_data_available(h, [](dds_entity_t, void* server) {
    static_cast<RobotServer*>(server)->take_heartbeats_in_receive_thread();
  });
  dds_return_t rc = dds_set_listener(request_reader_.get(), r);
  if (rc >= 0) rc = dds_set_listener(hb_reader_.get(), h);
  for (const Entity* e : {&state_reader_, &frame_reader_}) {
    if (rc >= 0) rc = dds_set_listener(e->get(), l);
  }
  dds_delete_listener(r);
  dds_delete_listener(h);
  dds_delete_listener(l);
  check(rc, "a data-available listener");
}

void RobotServer::answer_in_receive_thread() noexcept {
  std::unique_lock pass(serve_mutex_, std::try_to_lock);
  if (!pass.owns_lock() || stop_.load() || !answering_.load()) {
    // The middleware thread is in a pass (or stopping): it takes the request on its next one.
    if (!pass.owns_lock()) listener_handed_over_.fetch_add(1, std::memory_order_relaxed);
    rtc::detail::ring(wake_);
    return;
  }
  try {
    // What a request may name arrives on the other readers: taken first, as in poll().
    const std::int64_t now = steady_ns();
    read_heartbeats(now);
    read_states(now);
    read_frames(now);
    answered_in_listener_ += read_requests(now);
  } catch (const std::exception& e) {  // an answer not written: the serve stops, saying why
    stop_with(e);
  }
  // The events and states an answer leads to follow the control task's ticks, which ring the
  // middleware thread; a newly attached program's loss deadline is its own (check_lost). No ring
  // otherwise: the middleware thread runs at a real-time priority and would take a core from the
  // program's receive thread just as the answer reaches it.
  if (stop_.load() || !acks_backlog_.waiting.empty() ||
      std::exchange(attached_since_pass_, false)) {
    rtc::detail::ring(wake_);
  }
}

void RobotServer::take_heartbeats_in_receive_thread() noexcept {
  std::unique_lock pass(serve_mutex_, std::try_to_lock);
  if (!pass.owns_lock() || stop_.load() || !answering_.load()) {
    rtc::detail::ring(wake_);  // the middleware thread takes them on its pass
    return;
  }
  try {
    read_heartbeats(steady_ns());
  } catch (const std::exception& e) {  // a program's first heartbeat could not be recorded
    stop_with(e);
    rtc::detail::ring(wake_);
  }
}

void RobotServer::stop_with(const std::exception& e) noexcept {
  {
    const std::lock_guard lock(failure_mutex_);
    failure_ = e.what();
  }
  stop_.store(true);
}

std::int64_t RobotServer::next_wake() const noexcept {
  const std::int64_t heartbeat = options_.net.heartbeat.count();
  // States to repeat go with the heartbeat's pass (publish_states): no wake-up of their own.
  return std::min(last_heartbeat_ns_ + heartbeat, next_loss_check_ns_);
}

void RobotServer::read_heartbeats(std::int64_t now) {
  auto& in = inboxes_->heartbeats;
  for (;;) {
    const int n = in.take(hb_reader_.get());
    for (int i = 0; i < n; ++i) {
      if (!in.valid(i) || in[i].role != static_cast<std::uint8_t>(Role::program)) continue;
      Program& p = programs_[std::string(text_of(in[i].participant))];
      p.instance = in[i].instance;
      p.seen_ns = now;
    }
    if (n < in.capacity()) break;
  }
}

void RobotServer::read_states(std::int64_t now) {
  inboxes_->states.drain(state_reader_.get(), [&](const rccx_net_RobotState& s) {
    const auto it = mirrors_.find(std::string(text_of(s.robot)));
    if (it == mirrors_.end()) return;  // ours (or not of this cell)
    RobotMirror& m = *it->second;
    const bool was_lost = m.lost();
    if (m.apply(s, now) || was_lost) {
      io::eprint("rccx serve: robot {} is served by {}{}\n", m.name(), m.participant(),
                 was_lost ? " again" : " (a new instance)");
    }
    if (was_lost) m.set_lost(false);
  });
}

void RobotServer::read_frames(std::int64_t now) {
  auto& in = inboxes_->frames;
  for (;;) {
    const int n = in.take(frame_reader_.get());
    for (int i = 0; i < n; ++i) {
      if (!in.valid(i)) continue;
      auto& slot = streams_[std::string(text_of(in[i].name))];
      if (!slot) slot = std::make_unique<Stream>();
      FrameState f;
      f.pose = from_pose(in[i].pose);
      f.velocity_m_per_s = {in[i].velocity[0], in[i].velocity[1], in[i].velocity[2]};
      f.angular_velocity_rad_s = {in[i].angular_velocity[0], in[i].angular_velocity[1],
                                  in[i].angular_velocity[2]};
      f.stamp_ns = in[i].stamp_ns;
      slot->frame.store(f);
      slot->received_ns = now;
      slot->lost = false;
    }
    if (n < in.capacity()) break;
  }
}

std::uint64_t RobotServer::read_requests(std::int64_t now) {
  auto& in = inboxes_->requests;
  std::uint64_t count = 0;
  for (;;) {
    const int n = in.take(request_reader_.get());
    for (int i = 0; i < n; ++i) {
      if (!in.valid(i)) continue;
      handle(in[i], now);
      ++count;
    }
    if (n < in.capacity()) return count;
  }
}

void RobotServer::handle(const rccx_net_MotionRequest& r, std::int64_t now) {
  Local* l = local(text_of(r.robot));
  if (l == nullptr) return;  // another process's robot
  const std::string program(text_of(r.program));
  auto& dp = dedup_[program + "|" + l->name];
  if (!dp) dp = std::make_unique<Dedup>();
  Dedup& d = *dp;
  if (d.instance != r.program_instance) {  // a restarted program counts from 1 again
    d = Dedup{};
    d.instance = r.program_instance;
  }
  if (r.request <= d.highest) {
    // Executed already: the same answer again, never the motion again.
    rccx_net_MotionAck again{};
    copy_to(again.robot, l->name);
    copy_to(again.program, program);
    again.request = r.request;
    again.result = static_cast<std::uint8_t>(AckResult::duplicate);
    copy_to(again.message, "request already executed: not executed again");
    for (const auto& a : d.acks) {
      if (a.request != r.request) continue;
      again.motion = a.motion;
      if (a.result == static_cast<std::uint8_t>(AckResult::refused)) again = a;
    }
    answer(again);
    return;
  }
  d.highest = r.request;
  // Any request attaches its program: from now on its loss stops this robot.
  if (l->program != program || l->program_instance != r.program_instance) {
    l->program = program;
    l->program_instance = r.program_instance;
    l->attached_ns = now;
    attached_since_pass_ = true;
  }
  rccx_net_MotionAck ack{};
  copy_to(ack.robot, l->name);
  copy_to(ack.program, program);
  ack.request = r.request;
  try {
    execute(*l, r, ack);
  } catch (const std::exception& e) {  // MotionError, EquationError, CodecError, ...
    ack.result = static_cast<std::uint8_t>(AckResult::refused);
    ack.motion = 0;
    copy_to(ack.message, e.what());
  }
  if (ack.result == static_cast<std::uint8_t>(AckResult::accepted) && ack.motion != 0 &&
      (r.kind == static_cast<std::uint8_t>(RequestKind::move) ||
       r.kind == static_cast<std::uint8_t>(RequestKind::dwell))) {
    l->origin[ack.motion] = {program, r.request};
    while (l->origin.size() > 1024) l->origin.erase(l->origin.begin());
  }
  d.acks.push_back(ack);
  while (d.acks.size() > 256) d.acks.pop_front();
  answer(ack);
}

void RobotServer::answer(const rccx_net_MotionAck& ack) {
  acks_backlog_.write(ack_writer_.get(), ack, "acknowledgement");
}

template <class Sample>
void RobotServer::Backlog<Sample>::write(dds_entity_t writer, const Sample& s, const char* what) {
  if (waiting.empty()) {
    const dds_return_t rc = dds_write(writer, &s);
    if (rc != DDS_RETCODE_TIMEOUT) {
      check(rc, what);
      return;
    }
  }
  if (waiting.size() >= kBacklogLimit) {
    waiting.pop_front();
    ++dropped;
  }
  waiting.push_back(s);
  if (!said) {
    said = true;
    io::eprint(
        "rccx serve: {}s wait: a reader acknowledges nothing (a program stopped in a "
        "debugger?); they go out when it reads again or its lease ends\n",
        what);
  }
}

template <class Sample>
void RobotServer::Backlog<Sample>::flush(dds_entity_t writer, const char* what) {
  while (!waiting.empty()) {
    const dds_return_t rc = dds_write(writer, &waiting.front());
    if (rc == DDS_RETCODE_TIMEOUT) return;  // still held back: the next pass tries again
    check(rc, what);
    waiting.pop_front();
  }
  if (said) {
    io::eprint("rccx serve: {}s flow again{}\n", what,
               dropped > 0 ? fmt::format(" ({} of the oldest dropped)", dropped) : std::string());
    said = false;
    dropped = 0;
  }
}

void RobotServer::execute(Local& l, const rccx_net_MotionRequest& r, rccx_net_MotionAck& ack) {
  rccl::Manipulator& arm = *l.arm;
  ack.result = static_cast<std::uint8_t>(AckResult::accepted);
  const auto kind = static_cast<RequestKind>(r.kind);
  switch (kind) {
    case RequestKind::attach:
      ack.motion = arm.last_queued();
      return;
    case RequestKind::halt:
      arm.halt();
      l.follows.clear();
      l.streams.clear();
      ack.motion = arm.last_queued();
      return;
    case RequestKind::hand:
      arm.set_hand(r.value > 0.5);
      ack.motion = arm.last_queued();
      return;
    case RequestKind::nextmove:
      arm.generator().request_next();
      ack.motion = arm.last_queued();
      return;
    case RequestKind::move:
    case RequestKind::dwell:
      break;
    default:
      throw CodecError(fmt::format("unknown request kind {}", int{r.kind}));
  }
  // The settings this motion is queued with.
  const rccl::MotionSettings s = decode_settings(r);
  arm.set_mode(s.mode);
  arm.set_velocity(s.translation_m_per_s, s.rotation_rad_per_s);
  arm.set_segment_time(s.segment_time_s);
  arm.set_transition_time(s.transition_time_s);
  const auto names = arm.kinematics().configuration_names();
  if (s.configuration >= 0 && static_cast<std::size_t>(s.configuration) >= names.size()) {
    throw CodecError(fmt::format("robot {} has no configuration {}", l.name, s.configuration));
  }
  arm.set_configuration(s.configuration < 0 ? std::string_view{} : names[s.configuration]);
  if (s.guard.on() || arm.settings().guard.on()) arm.set_guard(s.guard);
  if (s.compliance.any() || arm.settings().compliance.any()) arm.set_compliance(s.compliance);
  // The gates: this process's robots from the cell, others' from their states.
  rccl::StartWhen when;
  when.touch = s.may_touch;
  const std::uint32_t gates = r.after._buffer == nullptr ? 0 : r.after._length;
  if (gates > kGates) throw CodecError(fmt::format("{} gates; at most {}", gates, kGates));
  for (std::uint32_t i = 0; i < gates; ++i) {
    const rccx_net_Gate& g = r.after._buffer[i];
    const std::string robot(text_of(g.robot));
    const auto gk = g.kind == 0 ? rccl::EventGate::Kind::started : rccl::EventGate::Kind::ended;
    if (local(robot) != nullptr) {
      rccl::Event e;
      e.kind = g.kind == 0 ? rccl::Event::Kind::motion_start : rccl::Event::Kind::motion_end;
      e.id = g.motion;
      when.after.push_back(cell_->event(robot, e));
    } else if (const auto it = mirrors_.find(robot); it != mirrors_.end()) {
      when.after.push_back(rccl::EventGate{&it->second->ledger, gk, g.motion});
    } else {
      throw CodecError(
          fmt::format("gate on robot {}: not a robot of cell {}", robot, full_model_.name));
    }
  }
  std::set<std::string> follows, streams;
  if (kind == RequestKind::dwell) {
    ack.motion = arm.dwell(r.value, when).id;
    return;
  }
  const Resolver resolve = [&](TermKind k, std::string_view name) -> rccl::TransformPtr {
    const std::string n(name);
    switch (k) {
      case TermKind::frame:
        if (local(n) != nullptr) return cell_->tool_frame(n);
        if (const auto it = mirrors_.find(n); it != mirrors_.end()) {
          if (!it->second->has_state() || it->second->lost()) {
            throw CodecError(fmt::format(
                "frame:{}: robot {}'s state is not received here: start its serve process "
                "(rccx serve --robots {}) on domain {}",
                n, n, n, participant_->domain()));
          }
          follows.insert(n);
          return remote_frame(n + "_TOOL", "frame:" + n, &it->second->frame,
                              options_.net.detection);
        }
        throw CodecError(fmt::format("frame:{}: not a robot of cell {}", n, full_model_.name));
      case TermKind::function: {
        const auto it = functions_.find(n);
        if (it == functions_.end()) {
          std::vector<std::string> known;
          for (const auto& [k2, v] : functions_) known.push_back(k2);
          throw CodecError(fmt::format(
              "function:{} is not registered in this serve process ({}){}", n, participant_name_,
              known.empty() ? std::string(": it has none")
                            : fmt::format("; registered: {}", join(known))));
        }
        auto t = rccl::functional(n, it->second);
        t->set_reference("function:" + n);
        return t;
      }
      case TermKind::stream: {
        const auto it = streams_.find(n);
        if (it == streams_.end() || it->second->lost) {
          throw CodecError(fmt::format(
              "stream:{}: no sample received; the program writes it (RemoteCell::stream(\"{}\")"
              ".set(...)) before a motion uses it",
              n, n));
        }
        streams.insert(n);
        return remote_frame(n, "stream:" + n, &it->second->frame, options_.net.detection);
      }
      default:
        break;
    }
    throw CodecError(fmt::format("transform {}: not a functional kind", n));
  };
  const rccl::PositionPtr p = decode_position(r, resolve);
  ack.motion = arm.move(p, when).id;
  l.follows = std::move(follows);  // a Cartesian rest goes on tracking the last goal
  l.streams = std::move(streams);
}

void RobotServer::halt_with(Local& l, const std::string& why) {
  l.halt_reason = why;
  l.halt_upto = l.arm->last_queued();
  l.arm->halt();
  l.follows.clear();
  l.streams.clear();
}

void RobotServer::publish_events() {
  for (auto& lp : locals_) {
    Local& l = *lp;
    for (const rccl::MotionEvent& e : l.arm->take_events()) {
      rccx_net_MotionEvent out{};
      copy_to(out.robot, l.name);
      out.motion = e.id;
      if (const auto it = l.origin.find(e.id); it != l.origin.end()) {
        copy_to(out.program, it->second.program);
        out.request = it->second.request;
      }
      out.kind = static_cast<std::uint8_t>(e.kind);
      out.t_s = e.t_s;
      const bool bad = e.kind == rccl::EventKind::failed || e.kind == rccl::EventKind::cancelled;
      if (bad && !l.halt_reason.empty() && e.id <= l.halt_upto) {
        copy_to(out.text, l.halt_reason);
      } else {
        copy_to(out.text, e.message());
      }
      events_backlog_.write(event_writer_.get(), out, "motion event");
    }
  }
}

void RobotServer::publish_states(std::int64_t now, bool last, bool heartbeat_pass) {
  // One sample for all the robots (ServeStates), when one of them has a fresh sample, or the
  // last one again every heartbeat period: a robot sampled more slowly than the detection time
  // (the Microbo's 28 ms) still shows it is alive. Every robot is in it with its newest state, so
  // a reader that keeps the last sample only still has each robot's newest. The repeat goes with
  // the heartbeat's pass (a state older than half a period), not a wake-up of its own: a robot
  // sampled a little more slowly than the heartbeat (the PUMA's 7 ms against 5 ms) would
  // otherwise wake the thread twice a tick.
  const std::int64_t heartbeat = options_.net.heartbeat.count();
  const std::int64_t repeat_after = heartbeat_pass ? heartbeat / 2 : heartbeat;
  bool due = last;
  for (auto& lp : locals_) {
    Local& l = *lp;
    l.fresh = l.latest.take(l.slot);
    l.have_slot = l.have_slot || l.fresh;
    due = due || (l.have_slot && (l.fresh || now - l.written_ns >= repeat_after));
  }
  if (!due) return;
  const std::int64_t written_ns = wall_ns();
  for (auto& lp : locals_) {
    Local& l = *lp;
    if (!l.have_slot) continue;
    rccx_net_RobotState& s = states_out_->add();
    copy_to(s.robot, l.name);
    copy_to(s.participant, participant_name_);
    s.instance = instance_;
    s.sample = l.slot.sample;
    s.t_s = l.slot.t_s;
    s.stamp_ns = l.slot.stamp_ns;
    s.written_ns = written_ns;
    s.period_s = l.period_s;
    s.dof = l.slot.dof;
    for (std::size_t j = 0; j < l.slot.dof; ++j) {
      s.q_commanded[j] = l.slot.q[j];
      s.qd_commanded[j] = l.slot.qd[j];
    }
    const rtc::How h = l.session->how();
    for (std::size_t j = 0; j < std::min<std::size_t>(h.dof, 8); ++j) {
      s.q_measured[j] = h.q()[j];
    }
    to_pose(l.slot.tool.pose, s.tool);
    const cell::ToolSample& t = l.slot.tool;
    const math::Vec3 v[3] = {t.velocity_m_per_s, t.acceleration_m_per_s2, t.angular_velocity_rad_s};
    double* out[3] = {s.velocity, s.acceleration, s.angular_velocity};
    for (int k = 0; k < 3; ++k) {
      out[k][0] = v[k].x;
      out[k][1] = v[k].y;
      out[k][2] = v[k].z;
    }
    // The counters before the failure ranges: a failure marked before `ended` advanced is
    // seen with it (MotionLedger::mark_failed writes the range first).
    const rccl::MotionLedger& ledger = l.gen->ledger();
    s.started_upto = ledger.started_upto();
    s.ended_upto = ledger.ended_upto();
    s.control_ended = ledger.control_ended() || last;
    (void)ledger.newest_failures(s.failed_from, s.failed_to, 4);
    const rtc::TerminateCode code = l.session->ended_code();
    if (code != rtc::TerminateCode::none) {
      s.status = static_cast<std::uint8_t>(RobotStatus::ended);
      s.terminate_code = static_cast<std::int16_t>(code);
      const rtc::Termination term = l.session->termination();
      const std::string_view why =
          term.message_view().empty() ? term.detail_view() : term.message_view();
      copy_to(s.termination, why);
      s.control_ended = true;
      if (!l.end_said) {  // once: what ended it (an overrun, a fault ...) is the user's first
                          // question
        l.end_said = true;
        io::eprint("rccx serve: robot {}'s control ended: {}{}{}\n", l.name, rtc::describe(code),
                   why.empty() ? "" : ": ", why);
        if (code == rtc::TerminateCode::overrun) {
          io::eprint("rccx serve: robot {}'s clock until then: {}\n", l.name,
                     clock_figures(*l.session, cell_->group().period()));
        }
      }
    } else if (last) {
      s.status = static_cast<std::uint8_t>(RobotStatus::ended);
      copy_to(s.termination, "the serve process stopped");
    } else if (l.slot.halting) {
      s.status = static_cast<std::uint8_t>(RobotStatus::stopping);
    } else {
      s.status = static_cast<std::uint8_t>(l.slot.running != 0 ? RobotStatus::moving
                                                               : RobotStatus::at_rest);
    }
    s.running = l.slot.running;
    s.queued = l.arm->last_queued();
    copy_to(s.program, l.program);
    l.written_ns = now;
    l.batch_index = states_out_->size() - 1;
    // ROS 2's view of each new state (not the heartbeat's repeats): the measured joints (ROS's
    // convention for joint_states), the commanded speeds, stamped when they were read (the
    // state's written_ns; its stamp_ns is the commanded setpoint's time, two periods ahead).
    const std::size_t n = l.ros2 ? l.ros2->dof() : 0;
    l.ros2_due = n != 0 && (l.fresh || last) && h.dof >= n && n <= std::size(s.q_measured);
  }
}

void RobotServer::send_states() {
  if (heartbeat_due_) {
    heartbeat_due_ = false;
    rccx_net_Heartbeat hb{};
    copy_to(hb.participant, participant_name_);
    hb.role = static_cast<std::uint8_t>(Role::serve);
    hb.instance = instance_;
    hb.seq = ++heartbeat_seq_;
    hb.period_ns = options_.net.heartbeat.count();
    hb.detection_ns = options_.net.detection.count();
    copy_to(hb.robots, join(robot_names_));
    check(dds_write(hb_writer_.get(), &hb), "a heartbeat");
  }
  for (auto& lp : locals_) {
    Local& l = *lp;
    if (!std::exchange(l.ros2_due, false)) continue;
    const rccx_net_RobotState& s = (*states_out_)[l.batch_index];
    const std::size_t n = l.ros2->dof();
    l.ros2->publish(
        s.written_ns, std::span<const double>(s.q_measured, n),
        s.dof == n ? std::span<const double>(s.qd_commanded, n) : std::span<const double>{});
  }
  check(states_out_->write(state_writer_.get()), "the robots' states");
}

void RobotServer::check_lost(std::int64_t now) {
  const std::int64_t detection = options_.net.detection.count();
  // The earliest moment one of the peers below may be found lost: the thread wakes then.
  next_loss_check_ns_ = INT64_MAX;
  const auto due = [&](std::int64_t seen) {
    next_loss_check_ns_ = std::min(next_loss_check_ns_, seen + detection + 1);
  };
  // Programs: an attached program silent for the detection time is lost.
  for (auto& lp : locals_) {
    Local& l = *lp;
    if (l.program.empty()) continue;
    std::int64_t seen = l.attached_ns;
    if (const auto it = programs_.find(l.program);
        it != programs_.end() && it->second.instance == l.program_instance) {
      seen = std::max(seen, it->second.seen_ns);
    }
    if (now - seen <= detection) {
      due(seen);
      continue;
    }
    const std::string why =
        fmt::format("the program {} was lost (no heartbeat for {:.0f} ms): stopped smoothly",
                    l.program, ms_of(now - seen));
    io::eprint("rccx serve: robot {}: {}\n", l.name, why);
    halt_with(l, why);
    l.program.clear();
    l.program_instance = 0;
  }
  // Remote robots: a state older than the detection time is lost; a local robot following
  // its frame stops smoothly.
  for (auto& [name, m] : mirrors_) {
    if (!m->has_state() || m->lost()) continue;
    const std::int64_t silent = now - m->received_ns();
    if (silent <= detection) {
      due(m->received_ns());
      continue;
    }
    m->set_lost(true);
    const std::string lost =
        fmt::format("robot {} lost: its serve process {} is silent for {:.0f} ms", name,
                    m->participant(), ms_of(silent));
    io::eprint("rccx serve: {}\n", lost);
    for (auto& lp : locals_) {
      if (lp->follows.count(name) == 0) continue;
      const std::string why =
          fmt::format("robot {} follows the frame of {}: stopped smoothly", lp->name, lost);
      io::eprint("rccx serve: {}\n", why);
      halt_with(*lp, why);
    }
  }
  for (auto& [name, s] : streams_) {
    if (s->lost) continue;
    if (now - s->received_ns <= detection) {
      due(s->received_ns);
      continue;
    }
    s->lost = true;
    for (auto& lp : locals_) {
      if (lp->streams.count(name) == 0) continue;
      const std::string why =
          fmt::format("robot {} follows stream {}, silent for {:.0f} ms: stopped smoothly",
                      lp->name, name, ms_of(now - s->received_ns));
      io::eprint("rccx serve: {}\n", why);
      halt_with(*lp, why);
    }
  }
}

}  // namespace rccx::net
