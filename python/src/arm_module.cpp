// The names Python sees for position equations and robots (rccx.Transform, rccx.Position,
// rccx.Robot, rccx.Cell ...) and their docstrings; the package's rccx/motion.py adds the
// equation operators. Called from module.cpp.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <memory>

#include "arm.hpp"
#include "kin.hpp"
#include "rccl.hpp"
#include "rccx/cell/cell_model.hpp"
#include "rccx/rtc/sample_log.hpp"

namespace py = pybind11;

namespace rccx::python {

namespace {

py::dict motion_event_dict(const rccl::MotionEvent& e) {
  py::dict d;
  d["kind"] = std::string(rccl::to_string(e.kind));
  d["id"] = e.id;
  d["t"] = e.t_s;
  d["sample"] = e.sample;
  d["joint"] = e.joint;
  d["message"] = std::string(e.message());
  return d;
}

py::list motion_events(const std::vector<rccl::MotionEvent>& events) {
  py::list l;
  for (const auto& e : events) l.append(motion_event_dict(e));
  return l;
}

py::dict report_dict(const rccl::SegmentReport& r) {
  py::dict d;
  d["id"] = r.id;
  d["mode"] = std::string(rccl::to_string(r.mode));
  d["start"] = r.start_s;
  d["end"] = r.end_s;
  d["duration"] = r.duration_s;
  d["max_commanded_path_error"] = r.max_commanded_path_error_m;
  d["max_measured_path_error"] = r.max_measured_path_error_m;
  d["max_approach_error"] = r.max_approach_error_rad;
  d["peak_tool_speed"] = r.peak_tool_speed_m_per_s;
  d["straight_samples"] = r.straight_samples;
  d["failed"] = r.failed;
  return d;
}

/// `after`: None, one When / Gate, or a list of them.
std::vector<WhenObject> whens(const py::object& after) {
  std::vector<WhenObject> out;
  if (after.is_none()) return out;
  const auto one = [&](const py::handle& h) {
    if (py::isinstance<WhenObject>(h)) {
      out.push_back(h.cast<WhenObject>());
    } else if (py::isinstance<GateObject>(h)) {
      const auto g = h.cast<GateObject>();
      WhenObject w;
      w.when.after.push_back(g.gate);
      w.owner = g.owner;
      out.push_back(std::move(w));
    } else {
      throw py::type_error(
          "after: give a cell's event (cell.event(robot, motion.end)), cell.after(...), "
          "cell.touching(...), together.when(robot), or a list of them");
    }
  };
  if (py::isinstance<py::list>(after) || py::isinstance<py::tuple>(after)) {
    for (const py::handle h : after) one(h);
  } else {
    one(after);
  }
  return out;
}

constexpr const char* kMoveDoc = R"(Queues a motion to `position` and returns at once (RCCL's move).

The goal is checked now: raises rccx.MotionError (queuing nothing) when it cannot be reached
within limits in the configuration the motion will use, saying which configurations do.
after: what the motion waits for before it starts (robots of a cell): cell.event(robot, ev),
cell.after(robot, ev), cell.touching([...]), together.when(robot), or a list of them.
Returns the Motion (its .id, .start and .end events).)";

constexpr const char* kWaitforDoc = R"(Waits for `event` (RCCL's waitfor): "reached", "failed"
(the motion failed or was cancelled: failures() says why), "timeout" or "session_ended".

timeout: s, None for no limit. In simulated time the wait runs the samples; in real time it
blocks. The GIL is released; Ctrl-C halts the robot, ends control and raises
KeyboardInterrupt.)";

}  // namespace

void bind_rccl(py::module_& m) {
  add_exception<rccl::EquationError>(
      m, "EquationError", PyExc_ValueError,
      "A malformed position equation; the message says what is wrong and how to write it.");
  add_exception<rccl::MotionError>(
      m, "MotionError", PyExc_RuntimeError,
      "A motion or setting that cannot be queued (goal out of reach or limits, full queue, bad "
      "setting); nothing was queued or changed.");
  add_exception<rtc::SessionError>(m, "SessionError", PyExc_RuntimeError,
                                   "A session that cannot run as asked (closed, bad period).");
  add_exception<rtc::LogError>(m, "LogError", PyExc_RuntimeError,
                               "A sample log that cannot be written, or was lost.");
  add_exception<cell::CellFileError>(m, "CellFileError", PyExc_ValueError,
                                     "A cell file rccx cannot use; the message says where.");

  py::class_<rccl::Transform, rccl::TransformPtr>(
      m, "Transform",
      "A named transform of position equations (C++ rccl::Transform): constant, hold, "
      "functional (a stream, a cell's tool frame) or T6. Made by rccx.const, hold, stream, t6. "
      "Multiply them (and .inv()) and compare with == to write an equation.")
      .def_property_readonly("name", &rccl::Transform::name, "Its name in equations.")
      .def_property_readonly(
          "kind", [](const rccl::Transform& t) { return std::string(rccl::to_string(t.kind())); },
          "\"constant\", \"functional\", \"hold\" or \"T6\".")
      .def_property_readonly("value", &transform_value,
                             "(4, 4), m: a constant's value, a hold's last set, a functional's "
                             "now. ValueError for T6.")
      .def("set", &set_hold, py::arg("T"),
           "A hold transform: the value (4, 4), m, the next motion that uses it latches. "
           "TypeError for other kinds, ValueError for a T that is not a rigid transform.")
      .def("__repr__", &transform_repr);

  py::class_<StreamTransform, rccl::Transform, std::shared_ptr<StreamTransform>>(
      m, "Stream",
      "A functional transform the program feeds (rccx.stream): put() from any thread; the "
      "sample loop takes the newest pose at each sample (lock-free, no Python).")
      .def("put", &StreamTransform::put, py::arg("T"), py::kw_only(), py::arg("at") = py::none(),
           py::arg("velocity") = py::none(),
           "Publishes a pose T (4, 4), m, stamped now; the GIL is released. The loop uses it "
           "from the next sample that evaluates the stream on. With at (the session time T is "
           "for, s, on arm.time's clock) and velocity ((6,): m/s along x, y, z then rad/s about "
           "them, in the stream's parent frame), each setpoint gets T moved on to its own time, "
           "at most max_extrapolation either way: a late put() leaves the goal moving smoothly.")
      .def_property_readonly("max_extrapolation", &StreamTransform::max_extrapolation_s,
                             "How far, s, a put() with at= and velocity= is extrapolated.")
      .def_property_readonly("newest", &StreamTransform::newest,
                             "The newest pose put (the initial one before any), (4, 4).")
      .def_property_readonly("age", &StreamTransform::age,
                             "Seconds since the newest put(); None before the first.")
      .def_property_readonly("count", &StreamTransform::count, "How many put() so far.");

  m.def("t6", &rccl::t6, "T6: the robot's last link in its base frame, the equations' unknown.");
  m.def("const", &make_constant, py::arg("name"), py::arg("T"),
        "A constant transform, T (4, 4) m. ValueError when T is not a rigid transform.");
  m.def("hold", &make_hold, py::arg("name"), py::arg("T") = py::none(),
        "A hold transform starting at T (4, 4), m (default identity); .set(T) changes it for "
        "the next motion that uses it.");
  m.def("stream", &make_stream, py::arg("name"), py::arg("T") = py::none(), py::kw_only(),
        py::arg("max_extrapolation") = 0.25,
        "A functional transform fed by .put(T) (any thread); its value before the first put is "
        "T (default identity). max_extrapolation: how far, s, a pose put with its time and "
        "velocity is moved on (default 0.25; 0 to 10): past it a silent feeder's goal stands.");
  m.def("_make_position", &make_position, py::arg("name"), py::arg("lhs"), py::arg("rhs"),
        py::arg("tool") = py::none());
  m.def("joints", &make_joints, py::arg("name"), py::arg("q"),
        "A position given in joint values q (dof,), rad or m (RCCL's park).");

  py::class_<rccl::Position, rccl::PositionPtr>(
      m, "Position",
      "A position equation (C++ rccl::Position) or joint values; rccx.position, rccx.joints.")
      .def_property_readonly("name", &rccl::Position::name)
      .def_property_readonly("in_joints", &rccl::Position::in_joints,
                             "True for a position given in joints.")
      .def_property_readonly("moves", &rccl::Position::moves,
                             "True when a functional transform takes part (a moving goal).")
      .def_property_readonly("joints", &position_joints,
                             "A position in joints: its values (dof,), rad or m.")
      .def("describe", &rccl::Position::describe,
           "The equation as written, e.g. \"GET: T6 TOOL = CONV OBJ GRASP (tool TOOL)\".")
      .def("t6", &position_t6,
           "T6 (4, 4), m, that solves the equation now (holds as last set); ValueError for a "
           "moving goal or joints.")
      .def("tool", &position_tool, "The tool product T6 -> tool frame (4, 4), m.")
      .def("__repr__", [](const rccl::Position& p) {
        return "<rccx.Position " + p.name() + ": " +
               (p.in_joints() ? std::string("joints") : p.describe()) + ">";
      });

  py::class_<EventObject>(m, "Event",
                          "Something to wait for: a motion's start or end, every motion to a "
                          "position ended, or completed.")
      .def("__repr__", &EventObject::repr);
  py::class_<MotionObject>(m, "Motion", "A queued motion.")
      .def_property_readonly("id", [](const MotionObject& o) { return o.motion.id; })
      .def_property_readonly("start", &MotionObject::start, "The event of its start.")
      .def_property_readonly("end", &MotionObject::end, "The event of its end.")
      .def("__repr__", [](const MotionObject& o) {
        return "<rccx.Motion " + std::to_string(o.motion.id) + ">";
      });
  py::class_<WhenObject>(m, "When", "What a queued motion waits for (a move's after=).");
  py::class_<GateObject>(m, "Gate", "An event of a cell's robot (cell.event).");
  py::class_<TogetherObject>(m, "Together", "A joint start of several robots (cell.together).")
      .def("when", &TogetherObject::when, py::arg("robot"),
           "What `robot`'s move takes (after=) to start with the others.");

  py::class_<ArmObject>(m, "Arm",
                        "One robot's RCCL motion API (C++ rccl::Arm / Manipulator): a "
                        "rccx.Robot, or cell.robot(name). Units m, rad, s.")
      .def_property_readonly("name", &ArmObject::name)
      .def("set_mode", &ArmObject::set_mode, py::arg("mode"),
           "setmod: \"joint\" or \"cartesian\" for the motions queued from now on.")
      .def_property_readonly("mode", &ArmObject::mode)
      .def("set_velocity", &ArmObject::set_velocity, py::arg("m_per_s"), py::arg("rad_per_s"),
           "setvel: tool translation (m/s) and rotation (rad/s) speeds, both > 0.")
      .def("set_segment_time", &ArmObject::set_segment_time, py::arg("seconds"),
           "settime: segment duration, s (0: from the speeds).")
      .def("set_transition_time", &ArmObject::set_transition_time, py::arg("seconds"),
           "settime: the transition between segments, s (> 0).")
      .def("set_configuration", &ArmObject::set_configuration, py::arg("name"),
           "setconf: the configuration for the next goals (\"lun\" ...); \"\" keeps the arm's.")
      .def("set_guard", &ArmObject::set_guard, py::arg("kind") = py::none(), py::arg("axis") = "fz",
           py::arg("threshold") = 5.0,
           "End the motions queued from now on on contact: kind \"along\" (axis \"fx\" .. "
           "\"tz\" of the tool frame, threshold N or N m, its sign the way) or \"magnitude\" "
           "(N); None: off. Force robots.")
      .def("set_compliance", &ArmObject::set_compliance,
           py::arg("axes") = std::vector<py::object>{}, py::arg("force") = py::none(),
           py::arg("stiffness") = py::none(), py::arg("damping") = py::none(),
           py::arg("max_speed") = 0.02, py::arg("max_force") = 100.0,
           "comply / lock: the tool axes (\"fx\" .. \"tz\") that yield, force set (6,) N / N m, "
           "stiffness (6,), damping (6,) (0: default), max_speed m/s, max_force N; no axes: "
           "locked.")
      .def(
          "move",
          [](ArmObject& a, const rccl::PositionPtr& p, const py::object& after) {
            return a.move(p, whens(after));
          },
          py::arg("position"), py::arg("after") = py::none(), kMoveDoc)
      .def(
          "dwell",
          [](ArmObject& a, double s, const py::object& after) { return a.dwell(s, whens(after)); },
          py::arg("seconds"), py::arg("after") = py::none(),
          "RCCL's stop(): stay where the previous motion ends for `seconds`. Returns the Motion.")
      .def("halt", &ArmObject::halt, "Stops smoothly where the arm is; cancels everything queued.")
      .def("nextmove", &ArmObject::nextmove,
           "RCCL's nextmove: ends the running motion where the arm is (smoothly); the queue "
           "goes on from there.")
      .def("set_hand", &ArmObject::set_hand, py::arg("closed"),
           "Closes (True) or opens the hand at the next sample.")
      .def_property_readonly("park", &ArmObject::park, "The park position (ready pose, joints).")
      .def("completed", &ArmObject::completed, "The event: every motion queued so far ended.")
      .def("ended", &ArmObject::ended, py::arg("position"),
           "The event: every motion queued to `position` ended (RCCL's p->end).")
      .def("waitfor", &ArmObject::waitfor, py::arg("event"), py::arg("timeout") = py::none(),
           kWaitforDoc)
      .def("wait_for", &ArmObject::wait_for, py::arg("seconds"),
           "Lets `seconds` pass (simulated time: runs those samples; real time: blocks, the GIL "
           "released). Returns None, or how control ended if it did.")
      .def("happened", &ArmObject::happened, py::arg("event"), "True when `event` has happened.")
      .def(
          "failures", [](ArmObject& a) { return motion_events(a.failures()); },
          "Failures and cancellations so far: dicts kind, id, t (s), sample, joint, message.")
      .def(
          "take_events", [](ArmObject& a) { return motion_events(a.take_events()); },
          "Every event since the last call (started, ended, failed, cancelled), as failures().")
      .def(
          "report", [](ArmObject& a, const MotionObject& mo) { return report_dict(a.report(mo)); },
          py::arg("motion"),
          "How an ended motion followed its path: dict id, mode, start, end, duration (s), "
          "max_commanded_path_error, max_measured_path_error (m), max_approach_error (rad), "
          "peak_tool_speed (m/s), straight_samples, failed.")
      .def_property_readonly("last_queued", &ArmObject::last_queued)
      .def_property_readonly("kinematics", &ArmObject::kinematics,
                             "The robot's rccx.kin.Kinematics.")
      .def_property_readonly("controlling", &ArmObject::controlling,
                             "True while the trajectory generator controls the arm.")
      .def_property_readonly("time", &ArmObject::time_s,
                             "The last sample's time, s since the session opened.")
      .def_property_readonly("q", &ArmObject::joints,
                             "The measured joints of the last sample (dof,), rad or m.")
      .def("__repr__", &ArmObject::repr)
      // Force (a robot with a wrist sensor: rccx.Robot(plant="mujoco")).
      .def("set_tool_load", &ArmObject::set_tool_load, py::arg("mass_kg"),
           py::arg("com_m") = py::none(), py::arg("bias") = py::none(),
           "set_tool_load: the tool's mass (kg), centre of mass (3,) m in T6 and the sensor's "
           "bias (6,) N, N m, taken out of the readings guards and compliance use.")
      .def(
          "contact",
          [](ArmObject& a, const MotionObject& mo) -> py::object {
            const auto c = a.contact(mo);
            if (!c) return py::none();
            py::dict d;
            d["motion"] = c->motion;
            d["t"] = c->t_s;
            d["t6"] = transform_out(c->t6);
            d["tool_frame"] = transform_out(c->tool_frame);
            const std::array<double, 6> w = c->wrench.to_array();
            d["wrench"] = to_array(w);
            return d;
          },
          py::arg("motion"),
          "Where `motion`'s guard tripped: dict motion, t (s, when the force began to rise), t6 "
          "and tool_frame (4, 4) m (measured; tool_frame = T6 TOOL), wrench (6,) N, N m (tool "
          "frame). None when it made no contact or has not ended.")
      .def("update_from_contact", &ArmObject::update_from_contact, py::arg("motion"),
           py::arg("transform"), py::arg("position"),
           "RCCL's update: sets `transform` (a hold or constant of `position`) so that "
           "`position` solves with T6 where `motion`'s contact was. rccx.MotionError without a "
           "contact.")
      .def_property_readonly("wrench", &ArmObject::wrench,
                             "The last sample's wrist sensor reading (6,): N, N m about T6 in "
                             "T6's axes (bias, tool weight and contacts); None without a sensor.")
      .def_property_readonly("hand_closed", &ArmObject::hand_closed,
                             "The hand as the last sample read reports it (True: closed).");

  m.def("external_wrench", &external_wrench, py::arg("reading"), py::arg("world_from_t6"),
        py::arg("mass_kg") = 0.0, py::arg("com_m") = py::none(), py::arg("bias") = py::none(),
        "C++ force::external_wrench: what contacts put on the tool (6,) N, N m about T6, from a "
        "sensor reading (6,), T6 (4, 4) in a world whose z is up (only its rotation counts), and "
        "the tool's mass kg, centre of mass (3,) m in T6, the sensor's bias (6,).");
  m.def("wrench_at_tool", &wrench_at_tool, py::arg("t6_from_tool"), py::arg("wrench"),
        "C++ force::at_tool: a wrench (6,) about T6 in T6's axes, expressed about the tool frame "
        "(t6_from_tool (4, 4), RCCL's TOOL) in its axes.");

  py::class_<RobotObject, ArmObject>(
      m, "Robot",
      "A simulated robot (C++ rtc::SimulatedRobot + rccl::Manipulator), control started. "
      "robot: a shipped robot's name, or a rccx.kin.Kinematics (rccx.kin.robot_file, "
      "rccx.kin.urdf: a robot file's or a URDF's model, its plant and scene with it); clock: "
      "\"simulated\" (deterministic, time runs while "
      "the program waits) or \"real_time\"; period: s (None: the robot's usual one); log: a "
      "CSV of every sample (None: RCCX_LOG's, if set). close() (or with-block) ends control. "
      "plant: \"automatic\" (the robot file's), \"ideal\", \"servo\" or \"mujoco\" (a "
      "wrist sensor); scene: the MuJoCo plant's table, boxes and tool, a dict as a robot file's "
      "\"hardware\": {\"mujoco\": ...} (robots/README.md; ValueError naming a bad key).")
      .def(py::init([](const py::object& robot, const std::string& clock,
                       std::optional<double> period, const std::optional<std::string>& log,
                       const std::string& plant, const py::object& scene) {
             // A dict (the robot file's "mujoco" block) goes to C++ as its JSON text.
             std::string json;
             if (py::isinstance<py::str>(scene)) {
               json = scene.cast<std::string>();
             } else if (!scene.is_none()) {
               // NumPy arrays and numbers as lists and floats (tolist); others: TypeError.
               const py::cpp_function as_list([](const py::object& o) -> py::object {
                 if (py::hasattr(o, "tolist")) return o.attr("tolist")();
                 throw py::type_error("scene: " + py::repr(o).cast<std::string>() +
                                      " is not a number, string, list or dict");
               });
               json = py::module_::import("json")
                          .attr("dumps")(scene, py::arg("default") = as_list)
                          .cast<std::string>();
             }
             // A name, or a model from rccx.kin (robot_file, urdf: any robot rccx can load).
             kin::RobotModel model;
             if (py::isinstance<py::str>(robot)) {
               model = builtin_model(robot.cast<std::string>());
             } else if (py::isinstance<KinematicsObject>(robot)) {
               model = robot.cast<const KinematicsObject&>().model();
             } else {
               throw py::type_error(
                   "robot: a shipped robot's name or a rccx.kin.Kinematics "
                   "(rccx.kin.robot_file, rccx.kin.urdf), not " +
                   py::repr(robot).cast<std::string>());
             }
             return std::make_unique<RobotObject>(std::move(model), clock, period, log, plant,
                                                  json);
           }),
           py::arg("robot") = "microbo", py::arg("clock") = "simulated",
           py::arg("period") = py::none(), py::arg("log") = py::none(),
           py::arg("plant") = "automatic", py::arg("scene") = py::none())
      .def("close", &RobotObject::close,
           "Stops control and closes the session, its log put in place; raises rccx.LogError "
           "when the log is lost. Later calls on the robot raise rccx.SessionError.")
      .def("start", &RobotObject::start, "Starts control again (after a Ctrl-C ended it).")
      .def_property_readonly("period", &RobotObject::period_s, "The sample period, s.")
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](RobotObject& r, const py::args&) { r.close(); });

  py::class_<CellObject>(m, "Cell",
                         "A workcell (C++ cell::Cell) from a cell file (cells/*.json): its "
                         "robots on one clock. start() starts them.")
      .def(py::init<const std::string&, const std::string&, bool>(), py::arg("path"),
           py::arg("clock") = "simulated", py::arg("collision_checks") = true)
      .def("start", &CellObject::start)
      .def("robot", &CellObject::robot, py::arg("name"),
           "A robot's motion API (rccx.Arm); it keeps the cell alive.")
      .def_property_readonly("robot_names", &CellObject::robot_names)
      .def("event", &CellObject::event, py::arg("robot"), py::arg("event"),
           "`robot`'s event for cell.waitfor or another robot's move(after=).")
      .def("after", &CellObject::after, py::arg("robot"), py::arg("event"),
           "What a move takes (after=) to start once `robot`'s event happened.")
      .def("touching", &CellObject::touching, py::arg("objects"),
           "What a move takes (after=) to let its tool touch these objects.")
      .def(
          "waitfor",
          [](CellObject& c, const py::object& gates, std::optional<double> timeout) {
            std::vector<GateObject> g;
            const auto one = [&](const py::handle& h) {
              if (!py::isinstance<GateObject>(h)) {
                // An Event is a robot's own: the cell needs to know whose (cell.event).
                throw py::type_error(
                    "cell.waitfor: give a cell's events, cell.event(robot, event), or a list of "
                    "them; got " +
                    py::repr(h).cast<std::string>());
              }
              g.push_back(h.cast<GateObject>());
            };
            if (py::isinstance<py::list>(gates) || py::isinstance<py::tuple>(gates)) {
              for (const py::handle h : gates) one(h);
            } else {
              one(gates);
            }
            return c.waitfor(g, timeout);
          },
          py::arg("events"), py::arg("timeout") = py::none(),
          "Waits for every event (cell.event): \"reached\", \"failed\", \"timeout\", "
          "\"session_ended\". Sliced as Arm.waitfor (Ctrl-C halts every robot).")
      .def("wait_for", &CellObject::wait_for, py::arg("seconds"), "Lets `seconds` pass.")
      .def("tool_frame", &CellObject::tool_frame, py::arg("robot"),
           "A functional transform: `robot`'s commanded T6 TOOL in the world.")
      .def("tool_transform", &CellObject::tool_transform, py::arg("robot"),
           "The robot's cell tool as the constant <robot>_TOOL.")
      .def("base_inv_transform", &CellObject::base_inv_transform, py::arg("robot"),
           "base <- world as the constant <robot>_BASE_INV.")
      .def("base", &CellObject::base, py::arg("robot"), "world <- base (4, 4), m.")
      .def("world_goal", &CellObject::world_goal, py::arg("robot"), py::arg("name"), py::arg("T"),
           "T6 TOOL = BASE_INV NAME for a world pose T (4, 4), m.")
      .def("together", &CellObject::together, py::arg("robots"), py::arg("end_together") = false,
           "A joint start: each robot's move(after=together.when(robot)) starts in one sample.")
      .def("close", &CellObject::close, "Stops every robot; their logs put in place.")
      .def("frame", &CellObject::frame, py::arg("name"),
           "A named frame of the cell file (\"board_home\" ...), world <- frame (4, 4), m; "
           "KeyError naming the known ones.")
      .def_property_readonly("period", &CellObject::period_s,
                             "The cell's clock tick, s (a robot samples every period_multiple "
                             "ticks).")
      .def_property_readonly("collision_stops", &CellObject::collision_stops,
                             "Times the collision check stopped the arms.")
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](CellObject& c, const py::args&) { c.close(); });
}

}  // namespace rccx::python
