// Driving robots from Python: rccl::Manipulator's calls with the GIL released and the owner's
// planning lock taken, waits in slices that look for Ctrl-C, C++ errors left to carry rccx's
// messages (MotionError, SessionError ... are Python exceptions, see arm_module.cpp).
#include "arm.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "rccl.hpp"
#include "rccx/cell/cell_model.hpp"
#include "rccx/force/tool_load.hpp"
#include "rccx/hw/mjcf.hpp"
#include "rccx/io/signals.hpp"
#include "rccx/kinematics/robot_model.hpp"

namespace rccx::python {

namespace {

using std::chrono::nanoseconds;

rtc::ClockKind clock_of(const std::string& clock) {
  if (clock == "simulated") return rtc::ClockKind::simulated;
  if (clock == "real_time" || clock == "real-time" || clock == "real") {
    return rtc::ClockKind::real_time;
  }
  raise_value_error(fmt::format("clock must be \"simulated\" or \"real_time\", got \"{}\"", clock));
}

nanoseconds seconds_to_ns(double s, const char* what) {
  if (!std::isfinite(s) || s < 0.0 || s > 1e9) {
    raise_value_error(fmt::format("{} must be a finite number of seconds >= 0, got {}", what, s));
  }
  return nanoseconds(std::llround(s * 1e9));
}

// Python's names for a wait's outcome are identifiers (the stubs' Literal): C++'s to_string
// gives "session ended", written for people.
std::string wait_result_name(rccl::WaitResult r) {
  return r == rccl::WaitResult::session_ended ? std::string("session_ended")
                                              : std::string(rccl::to_string(r));
}

std::string termination_text(const rtc::Termination& t) {
  std::string s = fmt::format("{}: {}", rtc::to_string(t.code), rtc::describe(t.code));
  if (!t.message_view().empty()) s += fmt::format(" ({})", t.message_view());
  if (!t.detail_view().empty()) s += fmt::format(" [{}]", t.detail_view());
  return s;
}

std::uint8_t axis_of(const py::object& axis) {
  if (py::isinstance<py::str>(axis)) {
    const auto name = axis.cast<std::string>();
    for (std::size_t i = 0; i < rccl::kForceAxisNames.size(); ++i) {
      if (rccl::kForceAxisNames[i] == name) return static_cast<std::uint8_t>(i);
    }
  } else if (py::isinstance<py::int_>(axis)) {
    const auto i = axis.cast<long>();
    if (i >= 0 && i < 6) return static_cast<std::uint8_t>(i);
  }
  raise_value_error(fmt::format(
      "a force axis is one of \"fx\" \"fy\" \"fz\" \"tx\" \"ty\" \"tz\" or 0 .. 5, got {}",
      py::repr(axis).cast<std::string>()));
}

std::array<double, 6> six(const std::optional<InArray>& a, const char* what) {
  std::array<double, 6> out{};
  if (!a) return out;
  if (ndim(*a) != 1 || extent(*a, 0) != 6) {
    raise_value_error(
        fmt::format("{} must have shape (6,) (fx fy fz in N, tx ty tz in N m), got "
                    "shape {}",
                    what, shape_text(*a)));
  }
  std::copy(a->data(), a->data() + 6, out.begin());
  return out;
}

/// A slice of a wait: at least kWaitSlice and two periods, a whole number of periods (a
/// simulated wait_for runs whole periods from now: slices that are not would lose time).
nanoseconds slice_of(nanoseconds period) {
  const nanoseconds p = std::max(period, nanoseconds(1));
  const auto n = std::max<std::int64_t>(2, (kWaitSlice.count() + p.count() - 1) / p.count());
  return p * n;
}

constexpr nanoseconds kForever = std::chrono::hours(24 * 365);

math::Vec3 vec3_of(const std::optional<InArray>& a, const char* what) {
  if (!a) return {};
  if (ndim(*a) != 1 || extent(*a, 0) != 3 || !std::isfinite(a->data()[0]) ||
      !std::isfinite(a->data()[1]) || !std::isfinite(a->data()[2])) {
    raise_value_error(
        fmt::format("{} must be 3 finite numbers (m), got shape {}", what, shape_text(*a)));
  }
  return {a->data()[0], a->data()[1], a->data()[2]};
}

math::Wrench wrench_of(const std::optional<InArray>& a, const char* what) {
  std::array<double, 6> w = six(a, what);
  for (double v : w) {
    if (!std::isfinite(v)) raise_value_error(fmt::format("{} must be finite", what));
  }
  return math::Wrench::from_array(w);
}

/// The tool's load (force::ToolLoad) from Python: kg (finite, >= 0), its centre of mass (3,) m
/// in T6, the sensor's bias (6,) N and N m.
force::ToolLoad tool_load_of(double mass_kg, const std::optional<InArray>& com_m,
                             const std::optional<InArray>& bias) {
  if (!std::isfinite(mass_kg) || mass_kg < 0.0) {
    raise_value_error(fmt::format("mass_kg must be a finite number >= 0, got {}", mass_kg));
  }
  force::ToolLoad load;
  load.mass_kg = mass_kg;
  load.com_m = vec3_of(com_m, "com_m");
  load.bias = wrench_of(bias, "bias");
  return load;
}

OutArray wrench_out(const math::Wrench& w) {
  const std::array<double, 6> a = w.to_array();
  return to_array(a);
}

hw::Plant plant_of(const std::string& plant) {
  for (hw::Plant p :
       {hw::Plant::automatic, hw::Plant::ideal, hw::Plant::servo, hw::Plant::mujoco}) {
    if (kin::to_string(p) == plant) return p;
  }
  raise_value_error(fmt::format(
      "plant must be \"automatic\", \"ideal\", \"servo\" or \"mujoco\", got \"{}\"", plant));
}

/// After a halt(): waits (at most `timeout`) until its motions have ended (the halt fails the
/// running one as it begins) and then until the arm's measured joints stand still, so that
/// control ends with the arm at rest, not while it decelerates.
void wait_at_rest(rccl::Manipulator& arm, nanoseconds timeout) {
  const auto start = std::chrono::steady_clock::now();
  (void)arm.waitfor(rccl::Arm::completed(), timeout);
  const auto left =
      timeout - std::chrono::duration_cast<nanoseconds>(std::chrono::steady_clock::now() - start);
  constexpr double kStill = 1e-3;  // rad/s or m/s
  (void)arm.session().wait_until(
      [](const rtc::How& h) {
        const kin::JointVector v = h.velocity();
        return std::all_of(v.begin(), v.end(), [](double x) { return std::abs(x) < kStill; });
      },
      std::max(left, nanoseconds(0)));
}

/// ValueError for an event of a motion of another arm than `arm` (named `name`).
void check_event_of(const EventObject& event, const rccl::Manipulator* arm, const std::string& name,
                    const char* what) {
  if (event.arm != nullptr && event.arm != arm) {
    raise_value_error(fmt::format(
        "{}: {} is an event of robot {}'s motion, not of {}'s (motion ids are each robot's "
        "own): ask {}, or wait for several robots with cell.waitfor(cell.event(robot, event))",
        what, event.repr(), event.robot, name, event.robot));
  }
}

}  // namespace

std::string EventObject::repr() const {
  switch (event.kind) {
    case rccl::Event::Kind::motion_start:
      return fmt::format("<rccx.Event start of motion {}>", event.id);
    case rccl::Event::Kind::motion_end:
      return fmt::format("<rccx.Event end of motion {}>", event.id);
    case rccl::Event::Kind::position_end:
      return fmt::format("<rccx.Event end of every motion to {}>",
                         position ? position->name() : std::string("?"));
    case rccl::Event::Kind::completed:
      break;
  }
  return "<rccx.Event completed>";
}

// --- ArmObject -------------------------------------------------------------------------------

ArmObject::ArmObject(std::shared_ptr<Owner> owner, rccl::Manipulator& arm, std::string name)
    : owner_(std::move(owner)), arm_(&arm), name_(std::move(name)) {}

void ArmObject::check_open() const {
  if (owner_->closed) throw rtc::SessionError(fmt::format("robot {} is closed", name_));
}

bool ArmObject::sliced_wait(Owner& owner, std::optional<double> timeout_s, nanoseconds period,
                            const std::function<bool(nanoseconds)>& step) {
  nanoseconds remaining = timeout_s ? seconds_to_ns(*timeout_s, "timeout") : kForever;
  const nanoseconds slice = slice_of(period);
  // Ctrl-C: Python's handler raised (no control running), or rccx's counted it (its handler
  // stands in for Python's during control, and halted the arms).
  const auto interrupted = [&owner] {
    if (const std::uint32_t n = io::stop_count(); n != owner.stops_seen) {
      owner.stops_seen = n;
      PyErr_SetNone(PyExc_KeyboardInterrupt);
      return true;
    }
    return PyErr_CheckSignals() != 0;
  };
  for (;;) {
    const nanoseconds d = std::min(slice, remaining);
    bool done = false;
    if (!interrupted()) {
      {
        const ReleaseGil release;
        const std::lock_guard lock(owner.planning);
        if (owner.closed) throw rtc::SessionError("the robot is closed");
        done = step(d);
      }
      remaining -= d;
      if (!interrupted()) {
        if (done) return true;
        if (remaining <= nanoseconds(0)) return false;
        continue;
      }
    }
    // End control cleanly, then raise.
    py::error_already_set raised;  // fetches KeyboardInterrupt
    {
      const ReleaseGil release;
      const std::lock_guard lock(owner.planning);
      if (!owner.closed && owner.interrupt) {
        try {
          owner.interrupt();
        } catch (const std::exception&) {  // KeyboardInterrupt says more than this
        }
      }
    }
    throw raised;
  }
}

void ArmObject::set_mode(const std::string& mode) {
  rccl::Mode m{};
  if (mode == "joint") {
    m = rccl::Mode::joint;
  } else if (mode == "cartesian") {
    m = rccl::Mode::cartesian;
  } else {
    raise_value_error(fmt::format("mode must be \"joint\" or \"cartesian\", got \"{}\"", mode));
  }
  locked([&] { arm_->set_mode(m); });
}

std::string ArmObject::mode() const {
  return std::string(rccl::to_string(locked([&] { return arm_->settings().mode; })));
}

void ArmObject::set_velocity(double translation_m_per_s, double rotation_rad_per_s) {
  locked([&] { arm_->set_velocity(translation_m_per_s, rotation_rad_per_s); });
}
void ArmObject::set_segment_time(double seconds) {
  locked([&] { arm_->set_segment_time(seconds); });
}
void ArmObject::set_transition_time(double seconds) {
  locked([&] { arm_->set_transition_time(seconds); });
}
void ArmObject::set_configuration(const std::string& name) {
  locked([&] { arm_->set_configuration(name); });
}

void ArmObject::set_guard(const std::optional<std::string>& kind, const py::object& axis,
                          double threshold) {
  rccl::ForceGuard g;
  if (!kind || *kind == "none") {
    g.kind = rccl::ForceGuard::Kind::none;
  } else if (*kind == "along") {
    g.kind = rccl::ForceGuard::Kind::along;
    g.axis = axis_of(axis);
  } else if (*kind == "magnitude") {
    g.kind = rccl::ForceGuard::Kind::magnitude;
  } else {
    raise_value_error(
        fmt::format("guard kind must be None, \"along\" or \"magnitude\", got \"{}\"", *kind));
  }
  g.threshold = threshold;
  locked([&] { arm_->set_guard(g); });
}

void ArmObject::set_compliance(const std::vector<py::object>& axes,
                               const std::optional<InArray>& force,
                               const std::optional<InArray>& stiffness,
                               const std::optional<InArray>& damping, double max_speed_m_per_s,
                               double max_force_N) {
  rccl::Compliance c;
  for (const py::object& a : axes) c.axes |= static_cast<std::uint8_t>(1U << axis_of(a));
  c.force = six(force, "force");
  c.stiffness = six(stiffness, "stiffness");
  c.damping = six(damping, "damping");
  c.max_speed_m_per_s = max_speed_m_per_s;
  c.max_force_N = max_force_N;
  locked([&] { arm_->set_compliance(c); });
}

void ArmObject::check_mine(const EventObject& event, const char* what) const {
  check_event_of(event, arm_, name_, what);
}

rccl::StartWhen ArmObject::start_when(const std::vector<WhenObject>& when) const {
  rccl::StartWhen w;
  for (const WhenObject& o : when) {
    // The gates point into their cell's motion ledgers: another cell's (or a cell's for a
    // robot of its own) would be read after that cell is gone, and never open meanwhile.
    if (o.owner != owner_) {
      raise_value_error(fmt::format(
          "after: an event of another cell: robot {}'s motion may wait only for robots of its "
          "own cell",
          name_));
    }
    w.after.insert(w.after.end(), o.when.after.begin(), o.when.after.end());
    w.touch |= o.when.touch;
    if (o.when.together) {
      if (w.together) raise_value_error("a motion takes part in one joint start only");
      w.together = o.when.together;
      w.slot = o.when.slot;
    }
  }
  return w;
}

MotionObject ArmObject::move(const rccl::PositionPtr& position,
                             const std::vector<WhenObject>& when) {
  if (!position) raise_value_error("move: no position given");
  const rccl::StartWhen w = start_when(when);
  return {locked([&] { return arm_->move(position, w); }), arm_, name_};
}

MotionObject ArmObject::dwell(double seconds, const std::vector<WhenObject>& when) {
  const rccl::StartWhen w = start_when(when);
  return {locked([&] { return arm_->dwell(seconds, w); }), arm_, name_};
}

void ArmObject::halt() {
  locked([&] { arm_->halt(); });
}
void ArmObject::nextmove() {
  locked([&] { arm_->generator().request_next(); });
}
void ArmObject::set_hand(bool closed) {
  locked([&] { arm_->set_hand(closed); });
}
rccl::PositionPtr ArmObject::park() const {
  return arm_->park();
}

EventObject ArmObject::ended(const rccl::PositionPtr& p) const {
  if (!p) raise_value_error("ended: no position given");
  return {rccl::Arm::ended(p), p};
}

std::string ArmObject::waitfor(const EventObject& event, std::optional<double> timeout_s) {
  check_mine(event, "waitfor");
  check_open();
  rccl::WaitResult r = rccl::WaitResult::timeout;
  sliced_wait(*owner_, timeout_s, arm_->session().period(), [&](nanoseconds d) {
    r = arm_->waitfor(event.event, d);
    return r != rccl::WaitResult::timeout;
  });
  return wait_result_name(r);
}

std::optional<std::string> ArmObject::wait_for(double seconds) {
  const nanoseconds total = seconds_to_ns(seconds, "wait_for");
  check_open();
  rtc::Termination t;
  sliced_wait(*owner_, static_cast<double>(total.count()) * 1e-9, arm_->session().period(),
              [&](nanoseconds d) {
                t = arm_->wait_for(d);
                return t.ended();
              });
  if (!t.ended()) return std::nullopt;
  return termination_text(t);
}

bool ArmObject::happened(const EventObject& event) {
  check_mine(event, "happened");
  return locked([&] { return arm_->happened(event.event); });
}

std::vector<rccl::MotionEvent> ArmObject::failures() {
  return locked([&] { return arm_->failures(); });
}
std::vector<rccl::MotionEvent> ArmObject::take_events() {
  return locked([&] { return arm_->take_events(); });
}
rccl::SegmentReport ArmObject::report(const MotionObject& m) {
  check_mine(m.end(), "report");
  return locked([&] { return arm_->report(m.motion); });
}
std::uint64_t ArmObject::last_queued() {
  return locked([&] { return arm_->last_queued(); });
}
KinematicsObject ArmObject::kinematics() const {
  return KinematicsObject(arm_->kinematics().model());
}
bool ArmObject::controlling() const {
  return !owner_->closed && arm_->session().controlling();
}
double ArmObject::time_s() const {
  return arm_->session().how().time_s;
}
OutArray ArmObject::joints() const {
  return to_array(arm_->session().how().q().span());
}
bool ArmObject::hand_closed() const {
  return arm_->session().how().hand_closed;
}
std::string ArmObject::repr() const {
  return fmt::format("<rccx robot {} ({}), {}>", name_, arm_->kinematics().model().name,
                     owner_->closed ? "closed" : (controlling() ? "in control" : "not in control"));
}

void ArmObject::set_tool_load(double mass_kg, const std::optional<InArray>& com_m,
                              const std::optional<InArray>& bias) {
  const force::ToolLoad load = tool_load_of(mass_kg, com_m, bias);
  locked([&] { arm_->set_tool_load(load); });
}

std::optional<rccl::Contact> ArmObject::contact(const MotionObject& m) {
  check_mine(m.end(), "contact");
  return locked([&] { return arm_->contact(m.motion); });
}

void ArmObject::update_from_contact(const MotionObject& m, const rccl::TransformPtr& x,
                                    const rccl::PositionPtr& position) {
  check_mine(m.end(), "update_from_contact");
  locked([&] { arm_->update_from_contact(m.motion, x, position); });
}

std::optional<OutArray> ArmObject::wrench() const {
  const rtc::How h = arm_->session().how();
  if (!h.force.present) return std::nullopt;
  return wrench_out(h.force.wrench);
}

// --- RobotObject -----------------------------------------------------------------------------

struct RobotObject::Parts {
  rtc::SimulatedRobot robot;
  rccl::Manipulator arm;
  Parts(kin::RobotModel model, const rtc::SimulatedRobotOptions& options)
      : robot(std::move(model), options), arm(*robot.session) {}
};

RobotObject::RobotObject(kin::RobotModel robot, const std::string& clock,
                         std::optional<double> period_s, const std::optional<std::string>& log,
                         const std::string& plant, const std::string& scene_json)
    : RobotObject(
          [&] {
            rtc::SimulatedRobotOptions o;
            o.clock = clock_of(clock);
            if (period_s) {
              // 0 would silently mean the robot's usual period (SessionOptions' default).
              if (!(*period_s > 0.0)) {
                raise_value_error(fmt::format(
                    "period must be > 0 s (None: the robot's usual one), got {}", *period_s));
              }
              o.period = seconds_to_ns(*period_s, "period");
            }
            if (log) o.log = *log;
            kin::RobotModel model = std::move(robot);
            o.plant = plant_of(plant);
            if (!scene_json.empty()) {
              // A scene is the MuJoCo plant's: it implies that plant, and no other takes one.
              if (o.plant == hw::Plant::automatic) o.plant = hw::Plant::mujoco;
              if (o.plant != hw::Plant::mujoco) {
                raise_value_error(
                    fmt::format("scene: only the \"mujoco\" plant has a scene, not "
                                "\"{}\"",
                                plant));
              }
              // The scene read as a robot file's would be (its keys, checks and messages).
              kin::RobotModel with_scene = model;
              with_scene.hardware_json = R"({"mujoco": )" + scene_json + "}";
              try {
                o.scene = std::make_shared<hw::Scene>(hw::scene_from_file(with_scene));
              } catch (const std::invalid_argument& e) {
                raise_value_error(fmt::format("scene: {}", e.what()));
              }
            }
            auto owner = std::make_shared<Owner>();
            std::shared_ptr<Parts> parts;
            {
              const ReleaseGil release;  // starts the session's tasks
              parts = std::make_shared<Parts>(std::move(model), o);
              // Ctrl-C during control: halt smoothly (request_halt is lock-free); the next
              // wait raises KeyboardInterrupt and ends control.
              rccl::Manipulator* a = &parts->arm;
              parts->robot.session->set_hangup_handler([a](rtc::Session&) { a->halt(); });
              parts->arm.start();
              // Real time: return once a sample has been read, so that q and the arm's
              // configuration (a joint move keeps it) are known to the first move().
              if (o.clock == rtc::ClockKind::real_time) {
                (void)parts->robot.session->wait_until([](const rtc::How& h) { return h.dof > 0; },
                                                       std::chrono::seconds(2));
              }
            }
            Parts* p = parts.get();
            owner->interrupt = [p] {
              p->arm.halt();
              wait_at_rest(p->arm, std::chrono::seconds(1));
              (void)p->arm.stop_control();
            };
            owner->keep = std::move(parts);
            owner->stops_seen = io::stop_count();
            return owner;
          }(),
          0) {}

RobotObject::RobotObject(std::shared_ptr<Owner> owner, int)
    : ArmObject(owner, static_cast<Parts*>(owner->keep.get())->arm,
                static_cast<Parts*>(owner->keep.get())->robot.model.name),
      parts_(static_cast<Parts*>(owner->keep.get())) {}

void RobotObject::start() {
  locked([&] { parts_->arm.start(); });
}

void RobotObject::close() {
  std::string problem;
  {
    const ReleaseGil release;
    const std::lock_guard lock(owner_->planning);
    if (owner_->closed) return;
    owner_->closed = true;
    (void)parts_->arm.stop_control();
    problem = parts_->robot.finish();
  }
  if (!problem.empty()) throw rtc::LogError(problem);
}

double RobotObject::period_s() const {
  return parts_->robot.period_s();
}

// --- CellObject ------------------------------------------------------------------------------

CellObject::CellObject(const std::string& path, const std::string& clock, bool collision_checks)
    : owner_(std::make_shared<Owner>()) {
  cell::CellOptions o;
  o.clock = clock_of(clock);
  o.collision_checks = collision_checks;
  {
    const ReleaseGil release;
    cell_ = std::shared_ptr<cell::Cell>(cell::Cell::load(path, o));
  }
  cell::Cell* c = cell_.get();
  owner_->interrupt = [c] {
    for (const std::string& n : c->robot_names()) c->robot(n).halt();
    // Each robot on its own: the cell's waitfor of all their gates returns as soon as one
    // fails, which the halt makes the first robot's do at once.
    for (const std::string& n : c->robot_names())
      wait_at_rest(c->robot(n), std::chrono::seconds(1));
    for (const std::string& n : c->robot_names()) (void)c->robot(n).stop_control();
  };
  owner_->keep = cell_;
  owner_->stops_seen = io::stop_count();
  for (const std::string& n : c->robot_names()) {
    rccl::Manipulator* a = &c->robot(n);
    c->session(n).set_hangup_handler([a](rtc::Session&) { a->halt(); });
  }
}

void CellObject::start() {
  locked([&] { cell_->start(); });
}

ArmObject CellObject::robot(const std::string& name) {
  rccl::Manipulator& m = locked([&]() -> rccl::Manipulator& { return cell_->robot(name); });
  return ArmObject(owner_, m, name);
}

std::vector<std::string> CellObject::robot_names() const {
  return cell_->robot_names();
}

void CellObject::check_robot(const std::string& robot, const EventObject& event, const char* what) {
  // cell_->robot names the cell's robots for an unknown name.
  const rccl::Manipulator* m = locked([&] { return &cell_->robot(robot); });
  check_event_of(event, m, robot, what);
}

GateObject CellObject::event(const std::string& robot, const EventObject& event) {
  check_robot(robot, event, "cell.event");
  return {locked([&] { return cell_->event(robot, event.event); }), owner_};
}

WhenObject CellObject::after(const std::string& robot, const EventObject& event) {
  check_robot(robot, event, "cell.after");
  return {locked([&] { return cell_->after(robot, event.event); }), owner_};
}

WhenObject CellObject::touching(const std::vector<std::string>& objects) {
  return {locked([&] { return cell_->touching(objects); }), owner_};
}

std::string CellObject::waitfor(const std::vector<GateObject>& gates,
                                std::optional<double> timeout_s) {
  std::vector<rccl::EventGate> g;
  for (const GateObject& o : gates) {
    if (o.owner != owner_) raise_value_error("waitfor: an event of another cell");
    g.push_back(o.gate);
  }
  rccl::WaitResult r = rccl::WaitResult::timeout;
  if (owner_->closed) throw rtc::SessionError("the cell is closed");
  ArmObject::sliced_wait(*owner_, timeout_s, cell_->group().period(), [&](nanoseconds d) {
    r = cell_->waitfor(g, d);
    return r != rccl::WaitResult::timeout;
  });
  return wait_result_name(r);
}

void CellObject::wait_for(double seconds) {
  const nanoseconds total = seconds_to_ns(seconds, "wait_for");
  if (owner_->closed) throw rtc::SessionError("the cell is closed");
  ArmObject::sliced_wait(*owner_, static_cast<double>(total.count()) * 1e-9,
                         cell_->group().period(), [&](nanoseconds d) {
                           cell_->wait_for(d);
                           return false;
                         });
}

rccl::TransformPtr CellObject::tool_frame(const std::string& robot) {
  return locked([&] { return cell_->tool_frame(robot); });
}
rccl::TransformPtr CellObject::tool_transform(const std::string& robot) {
  return locked([&] { return cell_->tool_transform(robot); });
}
rccl::TransformPtr CellObject::base_inv_transform(const std::string& robot) {
  return locked([&] { return cell_->base_inv_transform(robot); });
}
OutArray CellObject::base(const std::string& robot) {
  return transform_out(locked([&] { return cell_->base(robot); }));
}
rccl::PositionPtr CellObject::world_goal(const std::string& robot, const std::string& name,
                                         const InArray& world_pose) {
  const math::Transform T = transform_in(world_pose, "world_goal " + name);
  return locked([&] { return cell_->world_goal(robot, name, T); });
}

TogetherObject CellObject::together(const std::vector<std::string>& robots, bool end_together) {
  return {std::make_shared<cell::Together>(
              locked([&] { return cell_->together(robots, end_together); })),
          owner_};
}

WhenObject TogetherObject::when(const std::string& robot) const {
  return {together->when(robot), owner};
}

void CellObject::close() {
  bool whole = true;
  {
    const ReleaseGil release;
    const std::lock_guard lock(owner_->planning);
    if (owner_->closed) return;
    owner_->closed = true;
    whole = cell_->finish_logs("python");
  }
  if (!whole) throw rtc::LogError("a robot's sample log is lost (said on stderr)");
}

OutArray CellObject::frame(const std::string& name) {
  const cell::CellFrame* f = cell_->model().find_frame(name);
  if (f == nullptr) {
    std::string known;
    for (const cell::CellFrame& g : cell_->model().frames)
      known += (known.empty() ? "" : ", ") + g.name;
    raise_key_error(fmt::format("cell {} has no frame \"{}\" (it has: {})", cell_->model().name,
                                name, known.empty() ? "none" : known));
  }
  return transform_out(f->pose);
}

double CellObject::period_s() const {
  return std::chrono::duration<double>(cell_->model().base_period).count();
}

std::uint64_t CellObject::collision_stops() const {
  return cell_->collision_stops();
}

// --- force --------------------------------------------------------------------------------

OutArray external_wrench(const InArray& reading, const InArray& world_from_t6, double mass_kg,
                         const std::optional<InArray>& com_m, const std::optional<InArray>& bias) {
  const force::ToolLoad load = tool_load_of(mass_kg, com_m, bias);
  const math::Transform T = transform_in(world_from_t6, "world_from_t6");
  return wrench_out(force::external_wrench(load, T.R, wrench_of(reading, "reading")));
}

OutArray wrench_at_tool(const InArray& t6_from_tool, const InArray& at_t6) {
  const math::Transform T = transform_in(t6_from_tool, "t6_from_tool");
  return wrench_out(force::at_tool(T, wrench_of(at_t6, "wrench")));
}

}  // namespace rccx::python
