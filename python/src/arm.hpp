// Driving robots from Python (docs/PYTHON.md, "Driving a robot"): one arm's RCCL motion API
// (rccl::Manipulator) over a simulated robot of its own (RobotObject) or one robot of a cell
// (CellObject). Plain C++ over arrays.hpp; arm_module.cpp names it for Python.
//
// Threads: every call into C++ releases the GIL and takes the owner's planning lock (the
// Manipulator's planning level is one thread; a robot and the robots of one cell share one
// lock), so that Python threads may share a robot. Waits run in slices of at most
// kWaitSlice (two periods when those are longer), taking the GIL between slices to check for
// signals: a Ctrl-C halts every robot of the owner, stops control and raises KeyboardInterrupt.
// The sample loop never calls Python.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "kin.hpp"
#include "rccx/cell/cell.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/simulated_robot.hpp"

namespace rccx::python {

/// The longest a wait runs without looking for a signal (simulated or real time).
inline constexpr std::chrono::milliseconds kWaitSlice{100};

/// What the robots of one owner (a simulated robot, a cell) share.
struct Owner {
  std::mutex planning;              ///< one planning thread at a time in C++
  std::atomic<bool> closed{false};  ///< close() ran: calls raise SessionError
  /// Halts every robot and stops control (a Ctrl-C in a wait); the planning lock held.
  std::function<void()> interrupt;
  std::shared_ptr<void> keep;  ///< the C++ objects
  /// rccx's stop signals seen (io::stop_count()): during control rccx's SIGINT handler stands in
  /// for Python's (it halts the arms, see RobotObject), so a wait raises KeyboardInterrupt for it.
  std::uint32_t stops_seen = 0;
};

/// A motion event a program may wait for (rccl::Event), with the position it names kept alive.
struct EventObject {
  rccl::Event event;
  rccl::PositionPtr position;
  /// A motion's start or end: the arm whose motion it is (motion ids are an arm's own), so
  /// that another arm's wait refuses it; null for completed() and ended(p).
  const rccl::Manipulator* arm = nullptr;
  std::string robot{};
  [[nodiscard]] std::string repr() const;
};

struct MotionObject {
  rccl::Motion motion;
  const rccl::Manipulator* arm = nullptr;  ///< the arm that queued it
  std::string robot{};
  [[nodiscard]] EventObject start() const { return {motion.start(), nullptr, arm, robot}; }
  [[nodiscard]] EventObject end() const { return {motion.end(), nullptr, arm, robot}; }
};

/// What a queued motion waits for (rccl::StartWhen): other robots' events, a joint start, the
/// objects its tool may touch; the cell it refers to kept alive.
struct WhenObject {
  rccl::StartWhen when;
  std::shared_ptr<Owner> owner;
};

class ArmObject {
 public:
  ArmObject(std::shared_ptr<Owner> owner, rccl::Manipulator& arm, std::string name);

  void set_mode(const std::string& mode);
  [[nodiscard]] std::string mode() const;
  void set_velocity(double translation_m_per_s, double rotation_rad_per_s);
  void set_segment_time(double seconds);
  void set_transition_time(double seconds);
  void set_configuration(const std::string& name);
  void set_guard(const std::optional<std::string>& kind, const py::object& axis, double threshold);
  void set_compliance(const std::vector<py::object>& axes, const std::optional<InArray>& force,
                      const std::optional<InArray>& stiffness,
                      const std::optional<InArray>& damping, double max_speed_m_per_s,
                      double max_force_N);

  MotionObject move(const rccl::PositionPtr& position, const std::vector<WhenObject>& when);
  MotionObject dwell(double seconds, const std::vector<WhenObject>& when);
  void halt();
  void nextmove();
  void set_hand(bool closed);
  [[nodiscard]] rccl::PositionPtr park() const;

  [[nodiscard]] EventObject completed() const { return {rccl::Arm::completed(), nullptr}; }
  [[nodiscard]] EventObject ended(const rccl::PositionPtr& p) const;
  /// "reached", "failed", "timeout" or "session_ended".
  std::string waitfor(const EventObject& event, std::optional<double> timeout_s);
  /// None while control runs, else how it ended.
  std::optional<std::string> wait_for(double seconds);
  [[nodiscard]] bool happened(const EventObject& event);

  std::vector<rccl::MotionEvent> failures();
  std::vector<rccl::MotionEvent> take_events();
  [[nodiscard]] rccl::SegmentReport report(const MotionObject& m);
  [[nodiscard]] std::uint64_t last_queued();
  [[nodiscard]] KinematicsObject kinematics() const;
  [[nodiscard]] bool controlling() const;
  /// The last sample read: its time (s since the session opened) and measured joints.
  [[nodiscard]] double time_s() const;
  [[nodiscard]] OutArray joints() const;
  /// The hand as the last sample read it (How::hand_closed): set_hand's effect, a sample on.
  [[nodiscard]] bool hand_closed() const;
  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] std::string repr() const;
  /// For rccx.view (view.cpp): what keeps the arm alive, and the arm.
  [[nodiscard]] const std::shared_ptr<Owner>& owner() const noexcept { return owner_; }
  [[nodiscard]] rccl::Manipulator& manipulator() const noexcept { return *arm_; }

  // Force (issue 15) from Python (python/examples/touch_and_wipe.py): a robot with a wrist
  // sensor (rccx.Robot(plant="mujoco")).
  /// The tool's weight and the sensor's bias, taken out of the readings guards and compliance
  /// use (force::ToolLoad): kg, m in T6, (6,) N and N m.
  void set_tool_load(double mass_kg, const std::optional<InArray>& com_m,
                     const std::optional<InArray>& bias);
  /// Where motion `m`'s guard tripped (rccl::Contact), None without a contact.
  [[nodiscard]] std::optional<rccl::Contact> contact(const MotionObject& m);
  void update_from_contact(const MotionObject& m, const rccl::TransformPtr& x,
                           const rccl::PositionPtr& position);
  /// The last sample's sensor reading (6,), N and N m about T6 in T6's axes; None without a
  /// sensor.
  [[nodiscard]] std::optional<OutArray> wrench() const;

  /// Runs `step(slice)` (the GIL released, the planning lock taken) until it returns true or
  /// `timeout` has passed (false); between slices checks for signals (Ctrl-C: interrupts the
  /// owner, raises KeyboardInterrupt). `period`: the slowest sample period concerned.
  static bool sliced_wait(Owner& owner, std::optional<double> timeout_s,
                          std::chrono::nanoseconds period,
                          const std::function<bool(std::chrono::nanoseconds)>& step);
  /// Runs `f` with the GIL released and the planning lock taken, after checking the owner is
  /// open.
  template <class F>
  decltype(auto) locked(F&& f) const {
    const ReleaseGil release;
    const std::lock_guard lock(owner_->planning);
    check_open();
    return f();
  }

 protected:
  void check_open() const;
  rccl::StartWhen start_when(const std::vector<WhenObject>& when) const;
  /// ValueError for an event of another arm's motion (`what`: the call).
  void check_mine(const EventObject& event, const char* what) const;

  std::shared_ptr<Owner> owner_;
  rccl::Manipulator* arm_;
  std::string name_;
};

/// rccx.Robot: a simulated robot (rtc::SimulatedRobot) with its Manipulator, control started.
class RobotObject : public ArmObject {
 public:
  /// plant: "automatic", "ideal", "servo" or "mujoco"; scene_json: the MuJoCo plant's scene as
  /// a robot file's "hardware": {"mujoco": ...} block (JSON text; empty: the file's).
  /// robot: its model (a shipped robot's, a robot file's or a URDF's: rccx.kin).
  RobotObject(kin::RobotModel robot, const std::string& clock, std::optional<double> period_s,
              const std::optional<std::string>& log, const std::string& plant = "automatic",
              const std::string& scene_json = "");
  /// Stops control and closes the session, its log put in place; raises LogError for a lost
  /// log. Idempotent.
  void close();
  /// rccl_control again after a Ctrl-C ended it.
  void start();
  [[nodiscard]] double period_s() const;

 private:
  struct Parts;
  RobotObject(std::shared_ptr<Owner> owner, int);
  Parts* parts_;
};

/// A joint start of several robots of a cell (cell::Together).
struct TogetherObject {
  std::shared_ptr<cell::Together> together;
  std::shared_ptr<Owner> owner;
  [[nodiscard]] WhenObject when(const std::string& robot) const;
};

struct GateObject {
  rccl::EventGate gate;
  std::shared_ptr<Owner> owner;
};

/// rccx.Cell: cell::Cell over a cell file.
class CellObject {
 public:
  CellObject(const std::string& path, const std::string& clock, bool collision_checks);
  void start();
  ArmObject robot(const std::string& name);
  [[nodiscard]] std::vector<std::string> robot_names() const;
  /// ValueError for an event of another robot's motion than `robot`'s.
  void check_robot(const std::string& robot, const EventObject& event, const char* what);
  GateObject event(const std::string& robot, const EventObject& event);
  WhenObject after(const std::string& robot, const EventObject& event);
  WhenObject touching(const std::vector<std::string>& objects);
  std::string waitfor(const std::vector<GateObject>& gates, std::optional<double> timeout_s);
  void wait_for(double seconds);
  rccl::TransformPtr tool_frame(const std::string& robot);
  rccl::TransformPtr tool_transform(const std::string& robot);
  rccl::TransformPtr base_inv_transform(const std::string& robot);
  OutArray base(const std::string& robot);
  rccl::PositionPtr world_goal(const std::string& robot, const std::string& name,
                               const InArray& world_pose);
  /// A joint start of `robots`; its when(robot) goes to each robot's move.
  TogetherObject together(const std::vector<std::string>& robots, bool end_together);
  void close();
  // For python/examples/circuit_board.py: the cell file's frames, its clock, its collision stops.
  /// A named frame of the cell file, world <- frame (4, 4), m; KeyError when there is none.
  OutArray frame(const std::string& name);
  /// The cell's clock tick, s (each robot samples every period_multiple ticks).
  [[nodiscard]] double period_s() const;
  /// Times the collision check stopped the arms.
  [[nodiscard]] std::uint64_t collision_stops() const;
  /// For rccx.view (view.cpp): what keeps the cell alive, and the cell.
  [[nodiscard]] const std::shared_ptr<Owner>& owner() const noexcept { return owner_; }
  [[nodiscard]] cell::Cell& cell() const noexcept { return *cell_; }

 private:
  template <class F>
  decltype(auto) locked(F&& f) const {
    const ReleaseGil release;
    const std::lock_guard lock(owner_->planning);
    if (owner_->closed) throw rtc::SessionError("the cell is closed");
    return f();
  }
  std::shared_ptr<Owner> owner_;
  std::shared_ptr<cell::Cell> cell_;
};

/// force::external_wrench: the contacts' wrench (6,) about T6 from a sensor reading (6,), the
/// sensor's orientation in the world (T6 (4, 4) in a world whose z is up) and the tool's load.
OutArray external_wrench(const InArray& reading, const InArray& world_from_t6, double mass_kg,
                         const std::optional<InArray>& com_m, const std::optional<InArray>& bias);
/// force::at_tool: a wrench (6,) about T6 expressed about the tool frame (t6_from_tool (4, 4)).
OutArray wrench_at_tool(const InArray& t6_from_tool, const InArray& at_t6);

}  // namespace rccx::python
