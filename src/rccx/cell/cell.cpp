#include "rccx/cell/cell.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "rccx/io/fixed_text.hpp"

namespace rccx::cell {

namespace {

/// A leader's published tool frame is extrapolated with its acceleration for at most this long
/// (s): past a reader's pipeline (two periods) only a prediction for planning asks further.
constexpr double kAccelerationFor_s = 0.25;
/// How far ahead (or back) a planning prediction extrapolates it at all (s).
constexpr double kPredictionHorizon_s = 10.0;

rtc::SessionOptions group_options(const CellModel& m, const CellOptions& o) {
  rtc::SessionOptions so;
  so.period = m.base_period;
  so.clock = o.clock;
  so.real_time_scheduling = o.real_time_scheduling;
  so.one_thread = o.one_thread;
  so.spin_before_tick = o.spin_before_tick;
  return so;
}

}  // namespace

double Cell::braking_m(const kin::RobotModel& model, const kin::JointVector& q0,
                       const kin::JointVector& q1, const kin::JointVector& max_acceleration,
                       double period_s, const kin::JointVector& lever_m) noexcept {
  const std::size_t n =
      std::min({q0.size(), q1.size(), max_acceleration.size(), lever_m.size(), model.dof()});
  std::array<double, kin::kMaxJoints> v{};
  double Ts = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    v[j] = std::abs(q1[j] - q0[j]) / period_s + max_acceleration[j] * period_s;
    Ts = std::max(Ts, v[j] / max_acceleration[j]);
  }
  double d = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    const double travel = v[j] * (Ts / 2.0 + period_s);
    d += model.joints[j].type == kin::JointType::prismatic ? travel : travel * lever_m[j];
  }
  return d;
}

// braking_m() on the robot's own copies of its constants, the same arithmetic in the same order
// (a lever of 1 for a prismatic joint multiplies by one exactly).
double Cell::braking_fast(const Robot& r, const kin::JointVector& q0,
                          const kin::JointVector& q1) noexcept {
  const std::size_t n =
      std::min({q0.size(), q1.size(), r.max_acceleration.size(), r.travel_factor.size(), r.dof});
  const double period_s = r.period_s;
  std::array<double, kin::kMaxJoints> v{};
  double Ts = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    v[j] = std::abs(q1[j] - q0[j]) / period_s + r.max_acceleration[j] * period_s;
    Ts = std::max(Ts, v[j] / r.max_acceleration[j]);
  }
  double d = 0.0;
  for (std::size_t j = 0; j < n; ++j) d += v[j] * (Ts / 2.0 + period_s) * r.travel_factor[j];
  return d;
}

std::vector<RobotShape> Cell::shapes_of(const CellRobot& robot) {
  std::vector<RobotShape> out;
  bool hand = false;
  for (const RobotShape& s : robot.shapes) {
    out.push_back(s);
    hand = hand || s.frame == robot.model.dof();
  }
  // A tool the file gives no shape for is a capsule to the tool point, as thick as the last
  // link: what is there is not known, so not thinner than the arm.
  if (robot.tool && !hand) {
    const double r =
        robot.link_radius_m.empty() ? own_flange_radius_m(robot.model) : robot.link_radius_m.back();
    out.push_back({"tool", robot.model.dof(), {0, 0, 0}, robot.tool->p, r, "T6 to the tool point"});
  }
  return out;
}

kin::JointVector Cell::levers_m(const CellRobot& robot) {
  const kin::RobotModel& m = robot.model;
  const std::size_t n = m.dof();
  kin::JointVector lever(n);
  const auto link_radius = [&](std::size_t j) {  // joint j's (0-based) link radius, or 0
    if (robot.link_radius_m.empty()) return 0.0;
    return robot.link_radius_m.size() == n ? robot.link_radius_m[j] : robot.link_radius_m.front();
  };
  // How far a shape, or a capsule of the model's own, fixed in frame f reaches from that
  // frame's origin.
  std::array<double, kin::kMaxJoints + 1> reach{};
  const auto fixed_in = [&](std::size_t frame, const math::Vec3& from, const math::Vec3& to,
                            double radius) {
    if (frame > n) return;
    reach[frame] = std::max(reach[frame], std::max(from.norm(), to.norm()) + radius);
  };
  for (const RobotShape& s : shapes_of(robot)) fixed_in(s.frame, s.from_m, s.to_m, s.radius_m);
  for (const kin::LinkCapsule& c : m.collision.capsules) {
    fixed_in(c.frame, c.from_m, c.to_m, c.radius_m);
  }
  if (m.geometry == kin::Geometry::chain) {
    // Joint j+1's axis passes through its origin, |after| from frame j+1's origin (after is
    // the identity but on the last joint). Every point fixed in frames j+1 .. n is within
    // `beyond` of frame j+1's origin: what those frames carry, and the offsets out to them.
    const auto travel = [&](const kin::Joint& k) {
      return k.type == kin::JointType::prismatic ? std::max(std::abs(k.lower), std::abs(k.upper))
                                                 : 0.0;
    };
    double beyond = 0.0;
    for (std::size_t j = n; j-- > 0;) {
      const kin::ChainStep& step = m.joints[j].chain;
      // What frame j+1 carries: its shapes and capsules, the tool (T6), and the link pieces
      // of the cell's radius that start at its origin (to the next joint, or the flange).
      double carried = reach[j + 1];
      if (j + 1 == n) {
        carried = std::max(carried, step.after.p.norm() + link_radius(j));
        if (robot.tool) carried = std::max(carried, robot.tool->p.norm() + link_radius(j));
      } else {
        const kin::Joint& next = m.joints[j + 1];
        carried = std::max(carried, next.chain.origin.p.norm() + travel(next) + link_radius(j + 1));
        beyond += next.chain.origin.p.norm() + travel(next) + next.chain.after.p.norm();
      }
      beyond = std::max(beyond, carried);
      lever[j] = step.after.p.norm() + beyond;
    }
    return lever;
  }
  // Joint j's axis passes through frame j-1's origin, where link j begins: every point of the
  // links it moves is within their lengths of it, their capsules' surfaces a radius further.
  double beyond = robot.tool ? robot.tool->p.norm() : 0.0;
  double radius = 0.0;
  for (std::size_t j = n; j-- > 0;) {
    beyond = std::max(beyond, reach[j + 1]);  // the shapes of link j+1's frame
    const kin::Joint& k = m.joints[j];
    const double r = link_radius(j);
    beyond += std::max(r - radius, 0.0);  // the widest capsule so far counts once
    radius = std::max(radius, r);
    beyond += std::abs(k.dh.a_m);
    beyond += k.type == kin::JointType::prismatic
                  ? std::max(std::abs(k.dh.d_m + k.lower), std::abs(k.dh.d_m + k.upper))
                  : std::abs(k.dh.d_m);
    lever[j] = beyond;
  }
  return lever;
}

double Cell::own_flange_radius_m(const kin::RobotModel& model) noexcept {
  double in_t6 = 0.0, any = 0.0;
  for (const kin::LinkCapsule& c : model.collision.capsules) {
    any = std::max(any, c.radius_m);
    if (c.frame == model.dof()) in_t6 = std::max(in_t6, c.radius_m);
  }
  return in_t6 > 0.0 ? in_t6 : any;
}

void Cell::check_clear_at_start() const {
  // A robot that starts inside an object cannot be checked against it: the cell is wrong.
  for (std::size_t i = 0; i < world_->size(); ++i) {
    for (std::size_t k = 0; k < world_->solids().size(); ++k) {
      const SolidContact c = world_->min_solid_distance(i, k);
      if (!(c.distance_m < 0.0)) continue;
      const RobotCapsules& r = world_->robot(i);
      const Capsule& cap = r.capsules()[c.capsule];
      std::array<char, 16> buf{};
      throw CellFileError(fmt::format(
          "cell {}: robot {}'s {} lies {:.1f} mm inside object {} at its ready pose; move the "
          "robot or the object{}",
          model_.name, model_.robots[i].name, part_name(r, cap, buf), -c.distance_m * 1e3,
          model_.objects[k].name,
          cap.mounting ? fmt::format(", or say that it stands there (\"mounted_on\": \"{}\")",
                                     model_.objects[k].name)
                       : ""));
    }
  }
}

namespace {

/// A robot's capsules (whole arm, shapes, tool), mounted on its object if it has one.
void add_capsules(const CellModel& model, const CellRobot& cr, std::vector<RobotCapsules>& out) {
  out.emplace_back(cr.model, cr.link_radius_m, cr.base, Cell::shapes_of(cr));
  if (!cr.mounted_on.empty()) {
    for (std::size_t k = 0; k < model.objects.size(); ++k) {
      if (model.objects[k].name == cr.mounted_on) out.back().set_mounted_on(static_cast<int>(k));
    }
  }
}

}  // namespace

Cell::Cell(CellModel model, CellOptions options)
    : model_(std::move(model)),
      options_(options),
      group_(std::make_unique<rtc::SessionGroup>(group_options(model_, options_))) {
  validate(model_);
  for (const std::string& name : options_.local_robots) {
    if (model_.find_robot(name) == nullptr) {
      std::vector<std::string> known;
      for (const CellRobot& cr : model_.robots) known.push_back(cr.name);
      throw std::invalid_argument(
          fmt::format("cell {}: no robot \"{}\" to run here; its robots: {}", model_.name, name,
                      fmt::join(known, ", ")));
    }
  }
  const auto local = [&](const std::string& name) {
    return options_.local_robots.empty() ||
           std::find(options_.local_robots.begin(), options_.local_robots.end(), name) !=
               options_.local_robots.end();
  };
  std::vector<RobotCapsules> capsules;
  for (std::size_t i = 0; i < model_.robots.size(); ++i) {
    const CellRobot& cr = model_.robots[i];
    if (!local(cr.name)) continue;
    auto r = std::make_unique<Robot>();
    r->name = cr.name;
    r->model_index = i;
    r->hardware = rtc::make_simulated_hardware(cr.model, true, options_.ideal_servo);
    r->session = &group_->add(*r->hardware.driver, static_cast<int>(cr.period_multiple), cr.name);
    r->manipulator = std::make_unique<rccl::Manipulator>(*r->session);
    r->manipulator->generator().set_robot_name(cr.name);
    r->ledger.set_robot(cr.name);
    r->base_inverse = cr.base.inverse();
    r->tool = cr.tool.value_or(math::Transform::identity());
    r->period_s = std::chrono::duration<double>(model_.period(i)).count();
    r->lever_m = levers_m(cr);
    add_capsules(model_, cr, capsules);
    // Before its first setpoint a robot's tool frame is its ready pose.
    const kin::JointVector ready = cr.model.ready();
    ToolSample s;
    s.pose = cr.base * r->manipulator->kinematics().forward(ready) * r->tool;
    r->published.store(s);
    r->last = s;
    const rccl::GeneratorOptions& g = r->manipulator->generator().options();
    r->generator = &r->manipulator->generator();
    r->dof = cr.model.dof();
    r->max_acceleration = g.max_acceleration;
    r->travel_factor = r->lever_m;
    for (std::size_t j = 0; j < r->travel_factor.size() && j < cr.model.dof(); ++j) {
      if (cr.model.joints[j].type == kin::JointType::prismatic) r->travel_factor[j] = 1.0;
    }
    generators_.push_back(r->generator);
    robots_.push_back(std::move(r));
  }
  // The other processes' robots, after the local ones in the collision world.
  for (std::size_t i = 0; i < model_.robots.size(); ++i) {
    const CellRobot& cr = model_.robots[i];
    if (local(cr.name)) continue;
    remote_names_.push_back(cr.name);
    remote_model_index_.push_back(i);
    kin::JointVector factor = levers_m(cr);
    kin::JointVector v_max(cr.model.dof()), a_max(cr.model.dof());
    for (std::size_t j = 0; j < cr.model.dof(); ++j) {
      if (cr.model.joints[j].type == kin::JointType::prismatic) factor[j] = 1.0;
      // The generator's defaults (rccl::GeneratorOptions), as its own process runs it.
      v_max[j] = cr.model.joints[j].max_velocity;
      a_max[j] = v_max[j] / rccl::kDefaultAccelerationTime_s;
    }
    remote_travel_factor_.push_back(factor);
    remote_max_velocity_.push_back(v_max);
    remote_max_acceleration_.push_back(a_max);
    add_capsules(model_, cr, capsules);
  }
  std::vector<Solid> solids;
  for (const CellObject& o : model_.objects) {
    solids.push_back(o.shape.kind == ShapeKind::box
                         ? make_box(o.shape.size_m, o.pose)
                         : make_cylinder(o.shape.radius_m, o.shape.height_m, o.pose));
  }
  world_ = std::make_unique<CollisionWorld>(std::move(capsules), model_.collision_margin_m,
                                            std::move(solids));
  check_clear_at_start();
  threats_.resize(world_->max_threats() + 1);
  remote_age_s_.assign(remote_names_.size(), 0.0);
  group_->set_robot_hook([this](std::size_t i, std::uint32_t) { on_robot(i); });
  group_->set_cycle_hook([this](std::uint32_t tick) { on_cycle(tick); });
}

std::unique_ptr<Cell> Cell::load(const std::filesystem::path& path, CellOptions options) {
  return std::make_unique<Cell>(load_cell_file(path), options);
}

Cell::~Cell() {
  // Every robot's control first, then the group's tasks, so that the cycle hook has stopped
  // before the manipulators (which it reads) and the hardware go.
  for (auto& r : robots_) {
    try {
      r->manipulator->stop_control();
    } catch (...) {  // nothing sensible to do in a destructor
    }
  }
  group_.reset();
}

void Cell::start() {
  if (started_) throw rtc::SessionError("the cell has started already");
  group_->start();
  for (auto& r : robots_) r->manipulator->start();
  started_ = true;
}

void Cell::wait_for(std::chrono::nanoseconds d) {
  group_->wait_for(d);
}

// --- Synchronisation -----------------------------------------------------------------------------

rccl::EventGate Cell::event(std::string_view robot, const rccl::Event& e) {
  Robot& r = find(robot);
  rccl::EventGate g = r.manipulator->gate(e);  // resolves completed() to a motion id
  g.ledger = &r.ledger;
  return g;
}

Together Cell::together(const std::vector<std::string>& robots, bool end_together) {
  if (robots.empty() || robots.size() > rccl::Rendezvous::kMaxParticipants) {
    throw std::invalid_argument(fmt::format("a joint start takes 1 to {} robots (got {})",
                                            rccl::Rendezvous::kMaxParticipants, robots.size()));
  }
  std::vector<const rccl::MotionLedger*> ledgers;
  for (const std::string& name : robots) {
    const Robot& r = find(name);
    if (std::find(ledgers.begin(), ledgers.end(), &r.ledger) != ledgers.end()) {
      throw std::invalid_argument(fmt::format("robot {} is named twice in a joint start", name));
    }
    ledgers.push_back(&r.ledger);
  }
  return {std::make_shared<rccl::Rendezvous>(robots.size(), end_together, std::move(ledgers)),
          robots};
}

rccl::StartWhen Together::when(std::string_view robot, std::vector<rccl::EventGate> after) const {
  const auto it = std::find(robots.begin(), robots.end(), robot);
  if (it == robots.end()) {
    throw std::invalid_argument(fmt::format("robot {} does not take part in this joint start ({})",
                                            robot, fmt::join(robots, ", ")));
  }
  rccl::StartWhen w;
  w.after = std::move(after);
  w.together = rendezvous;
  w.slot = static_cast<std::size_t>(it - robots.begin());
  return w;
}

rccl::WaitResult Cell::waitfor(const std::vector<rccl::EventGate>& gates,
                               std::chrono::nanoseconds timeout) {
  const auto answer = [&] {
    bool all = true;
    for (const rccl::EventGate& g : gates) {
      const rccl::GateAnswer a = g.answer();
      if (a == rccl::GateAnswer::never) return rccl::GateAnswer::never;
      all = all && a == rccl::GateAnswer::yes;
    }
    return all ? rccl::GateAnswer::yes : rccl::GateAnswer::not_yet;
  };
  const auto deadline = std::chrono::steady_clock::now() + timeout;  // real time
  std::chrono::nanoseconds left = timeout;
  for (;;) {
    if (const rccl::GateAnswer a = answer(); a != rccl::GateAnswer::not_yet) {
      return a == rccl::GateAnswer::yes ? rccl::WaitResult::reached : rccl::WaitResult::failed;
    }
    // Any robot under control carries the cell's clock; another one once it ends.
    rtc::Session* carrier = nullptr;
    for (auto& r : robots_) {
      if (r->session->controlling()) {
        carrier = r->session;
        break;
      }
    }
    if (carrier == nullptr) return rccl::WaitResult::session_ended;
    const auto t0 = std::chrono::duration<double>(carrier->how().time_s);
    const bool done = carrier->wait_until(
        [&](const rtc::How&) { return answer() != rccl::GateAnswer::not_yet; }, left);
    if (done) continue;
    if (carrier->controlling()) return rccl::WaitResult::timeout;
    // Its control ended: take off the time spent (simulated: the cell's) and go on.
    const auto spent = std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double>(carrier->how().time_s) - t0);
    left -= std::max(spent, std::chrono::nanoseconds(0));
    if (options_.clock == rtc::ClockKind::real_time) {
      left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline -
                                                                  std::chrono::steady_clock::now());
    }
    if (left <= std::chrono::nanoseconds(0)) return rccl::WaitResult::timeout;
  }
}

void Cell::publish_ledgers() noexcept {
  for (auto& rp : robots_) {
    Robot& r = *rp;
    const bool controlling = r.session->controlling();
    if (controlling) {
      r.was_controlling = true;
      if (r.ledger.control_ended()) r.ledger.set_control_ended(false);
      continue;
    }
    if (!r.was_controlling) continue;
    r.was_controlling = false;
    r.ledger.set_control_ended(true);
    const rtc::TerminateCode code = r.session->ended_code();
    if (!options_.stop_others_on_fault || code == rtc::TerminateCode::none ||
        code == rtc::TerminateCode::user_request || code == rtc::TerminateCode::user_interrupt) {
      continue;
    }
    io::format_fixed(message_, "stopped: {}'s control ended ({}: {}); the cell holds every arm",
                     r.name, rtc::to_string(code), rtc::describe(code));
    for (auto& other : robots_) {
      if (other.get() != &r) other->manipulator->generator().request_stop(message_.data());
    }
  }
}

const Cell::Robot& Cell::find(std::string_view name) const {
  return *robots_[index(name)];
}
Cell::Robot& Cell::find(std::string_view name) {
  return *robots_[index(name)];
}

std::size_t Cell::index(std::string_view name) const {
  for (std::size_t i = 0; i < robots_.size(); ++i) {
    if (robots_[i]->name == name) return i;
  }
  if (std::find(remote_names_.begin(), remote_names_.end(), name) != remote_names_.end()) {
    throw std::invalid_argument(
        fmt::format("cell {}: robot \"{}\" is served by another process; this one runs {}",
                    model_.name, name, fmt::join(robot_names(), ", ")));
  }
  throw std::invalid_argument(fmt::format("cell {}: no robot \"{}\"; its robots: {}", model_.name,
                                          name, fmt::join(robot_names(), ", ")));
}

rccl::Manipulator& Cell::robot(std::string_view name) {
  return *find(name).manipulator;
}
rtc::Session& Cell::session(std::string_view name) {
  return *find(name).session;
}
rtc::SimulatedHardware& Cell::hardware(std::string_view name) {
  return find(name).hardware;
}

std::vector<std::string> Cell::robot_names() const {
  std::vector<std::string> names;
  for (const auto& r : robots_) names.push_back(r->name);
  return names;
}

bool Cell::finish_logs(std::string_view program) {
  bool whole = true;
  for (const auto& r : robots_) {
    rtc::Session& s = session(r->name);
    s.close();
    if (!s.log_problem().empty()) {
      fmt::print(stderr, "{}: robot {}'s sample log is lost: {}\n", program, r->name,
                 s.log_problem());
      whole = false;
    }
  }
  return whole;
}

ToolSample Cell::tool_sample(std::string_view name) const {
  ToolSample s;
  find(name).published.load(s);
  return s;
}

rccl::TransformPtr Cell::tool_frame(std::string_view leader) const {
  const Robot* r = &find(leader);
  // The Robot outlives the transform only while the cell lives: a transform used after the
  // cell is gone is a misuse, as a session's would be.
  rccl::TransformPtr t = rccl::functional(r->name + "_TOOL", [r](const rccl::SampleContext& ctx) {
    ToolSample s;
    r->published.load(s);
    // Extrapolated to the time the reader's setpoint is for (a follower sampled more slowly,
    // or later in the tick); a reader without a time (the planning level) takes it as it is.
    const double dt = ctx.t_s - s.t_s;
    if (ctx.how == nullptr) return s.pose;
    if (!(std::abs(dt) < kAccelerationFor_s)) {
      // Beyond the pipeline's reach only a generator planning ahead asks (where a line onto
      // the frame will start, at its via time), and only a leader that goes on publishing
      // (one that has come to rest stops: its last sample, a while old, is where it stays)
      // is predicted: at its velocity, the acceleration (a moment's: one that brakes to rest
      // would run it backwards) counted only for the pipeline's reach, so that the
      // prediction joins the one within it.
      const double age_s = ctx.sample_time_s() - s.t_s;
      if (!ctx.predicted || !(age_s < kAccelerationFor_s) ||
          !(std::abs(dt) < kPredictionHorizon_s)) {
        return s.pose;
      }
    }
    const double accelerating = std::clamp(dt, -kAccelerationFor_s, kAccelerationFor_s);
    math::Transform p = s.pose;
    p.p = p.p + s.velocity_m_per_s * dt +
          s.acceleration_m_per_s2 * (accelerating * accelerating / 2.0);
    p.R = math::rotated_by(p.R, s.angular_velocity_rad_s, dt);
    return p;
  });
  t->set_reference("frame:" + r->name);  // a serve process resolves it by the robot's name
  return t;
}

void Cell::set_cycle_observer(std::function<void(std::uint32_t)> observer) {
  if (started_) throw rtc::SessionError("set_cycle_observer: only before start()");
  observer_ = std::move(observer);
}

void Cell::on_robot(std::size_t i) noexcept {
  Robot& r = *robots_[i];
  const rccl::TrajectoryGenerator& g = *r.generator;
  const kin::JointVector& q = g.last_setpoint();
  if (q.size() != r.dof) return;  // no setpoint yet
  const double t = g.last_setpoint_time_s();
  if (r.valid && t == r.last_t_s) return;  // nothing new
  // The tool frame, for followers (published at the tick's end, so that the robots after this
  // one in the tick see the last tick's, as they would in any order): from the capsules' link
  // frames, which the collision world computes from q anyway; velocities from the last two
  // published samples.
  ToolSample s;
  if (world_->set_configuration(i, q)) {
    s.pose = world_->robot(i).link_frame(r.dof - 1) * r.tool;
  } else {  // a setpoint that is not finite: the capsules keep the last one
    s.pose = model_.robots[r.model_index].base * r.manipulator->kinematics().forward(q) * r.tool;
  }
  s.t_s = t;
  const ToolSample& before = r.last;
  const double dt = t - r.last_t_s;
  if (r.valid && dt > 0.0) {
    // Differences of the setpoints: the backward difference is the velocity half a period
    // back; the change of it over the period, the acceleration.
    const math::Vec3 v_back = (s.pose.p - before.pose.p) * (1.0 / dt);
    s.acceleration_m_per_s2 = (v_back - r.velocity_back) * (1.0 / dt);
    s.velocity_m_per_s = v_back + s.acceleration_m_per_s2 * (dt / 2.0);
    r.velocity_back = v_back;
    math::Vec3 axis;
    double angle = 0.0;
    (s.pose.R * before.pose.R.transposed()).to_axis_angle(axis, angle);
    s.angular_velocity_rad_s = axis * (angle / dt);
  }
  r.next = s;
  r.fresh = true;
  r.last_t_s = t;
  r.braking_m = braking_fast(r, g.previous_setpoint(), q);
  world_->set_allowance(i, r.braking_m);
  // The running motion's touch set; after the last motion ended, still its own until another
  // starts: the arm settles at rest where that motion left it (and nothing else moves it).
  if (const std::uint64_t id = g.last_motion(); id != 0) {
    const rccl::MotionSettings* settings = g.running_settings(id);
    r.touch = settings != nullptr ? settings->may_touch : 0;
  }
  world_->set_touch(i, r.touch);
  r.valid = true;
}

void Cell::on_cycle(std::uint32_t tick) noexcept {
  const std::size_t n = robots_.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (i + 2 < n) {  // the next robots' lines this pass reads, ahead of use
      __builtin_prefetch(robots_[i + 2].get(), 1, 3);
      __builtin_prefetch(&generators_[i + 2]->ledger(), 0, 3);
    }
    Robot& r = *robots_[i];
    r.ledger.copy_from(r.generator->ledger());  // for the gates of the next tick
    if (r.fresh) {
      r.published.store(r.next);
      r.last = r.next;
      r.fresh = false;
    }
  }
  if (!remote_names_.empty()) place_remote_robots();
  if (options_.collision_checks) check_collisions();
  publish_ledgers();
  if (observer_) observer_(tick);
}

void Cell::check_collisions() noexcept {
  const std::size_t found = world_->threats(threats_);
  const std::size_t reported = std::min(found, threats_.size());
  const std::size_t local = robots_.size();
  for (std::size_t k = 0; k < reported; ++k) {
    const Threat& t = threats_[k];
    // Two remote robots: their own processes check them.
    if (t.robot_a >= local) continue;
    Robot& a = *robots_[t.robot_a];
    const RobotCapsules& ca = world_->robot(t.robot_a);
    const Capsule& pa = ca.capsules()[t.capsule_a];
    std::array<char, 16> buf_a{}, buf_b{};
    const std::string_view part_a = part_name(ca, pa, buf_a);
    if (t.solid) {
      io::format_fixed(message_,
                       "collision stop: {} {} would come {:.3f} m from object {} (margin {:.3f} m "
                       "+ braking {:.3f} m)",
                       a.name, part_a, t.distance_m, model_.objects[t.b].name,
                       model_.collision_margin_m, a.braking_m);
    } else if (t.b >= local) {
      const RobotCapsules& cb = world_->robot(t.b);
      const Capsule& pb = cb.capsules()[t.capsule_b];
      const std::string_view part_b = part_name(cb, pb, buf_b);
      io::format_fixed(
          message_,
          "collision stop: {} {} and {} {} (another process's, its state {:.0f} ms "
          "old) would come {:.3f} m apart (margin {:.3f} m + braking and age {:.3f} m)",
          a.name, part_a, remote_names_[t.b - local], part_b, remote_age_s_[t.b - local] * 1e3,
          t.distance_m, model_.collision_margin_m, t.limit_m - model_.collision_margin_m);
    } else {
      const Robot& b = *robots_[t.b];
      const RobotCapsules& cb = world_->robot(t.b);
      const Capsule& pb = cb.capsules()[t.capsule_b];
      const std::string_view part_b = part_name(cb, pb, buf_b);
      io::format_fixed(message_,
                       "collision stop: {} {} and {} {} would come {:.3f} m apart (margin {:.3f} "
                       "m + braking {:.3f} m)",
                       a.name, part_a, b.name, part_b, t.distance_m, model_.collision_margin_m,
                       a.braking_m + b.braking_m);
    }
    const std::string_view why(message_.data());
    a.manipulator->generator().request_stop(why);
    if (!t.solid && t.b < local) robots_[t.b]->manipulator->generator().request_stop(why);
    collision_stops_.fetch_add(1, std::memory_order_acq_rel);
  }
}

void Cell::set_remote_source(const RemoteRobotSource* source) {
  if (started_) throw rtc::SessionError("set_remote_source: only before start()");
  remote_source_ = source;
}

double Cell::remote_allowance_m(std::size_t remote, const kin::JointVector& qd,
                                double age_s) const noexcept {
  if (remote >= remote_travel_factor_.size() || !(age_s > 0.0)) return 0.0;
  const kin::JointVector& factor = remote_travel_factor_[remote];
  const kin::JointVector& v_max = remote_max_velocity_[remote];
  const kin::JointVector& a_max = remote_max_acceleration_[remote];
  double travel = 0.0;
  for (std::size_t j = 0; j < factor.size(); ++j) {
    const double v = j < qd.size() && std::isfinite(qd[j]) ? std::abs(qd[j]) : v_max[j];
    const double joint = std::min(v * age_s + 0.5 * a_max[j] * age_s * age_s, v_max[j] * age_s);
    travel += factor[j] * joint;
  }
  // Beyond 10 m it stops everything near anyway; the cap keeps the sums finite.
  return std::min(travel, 10.0);
}

void Cell::place_remote_robots() noexcept {
  const std::size_t local = robots_.size();
  for (std::size_t k = 0; k < remote_names_.size(); ++k) {
    kin::JointVector q, qd;
    double age = 0.0;
    // A robot no process has served yet stands at its ready pose (nothing commands it); once
    // heard of, it may have moved at its top speed for as long as its state is old.
    if (remote_source_ != nullptr && remote_source_->latest(k, q, qd, age)) {
      world_->set_configuration(local + k, q);
    }
    remote_age_s_[k] = age;
    world_->set_allowance(local + k, remote_allowance_m(k, qd, age));
  }
}

}  // namespace rccx::cell
