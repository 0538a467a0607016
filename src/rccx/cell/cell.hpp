// The workcell at run time (thesis 5.2, Multi-RCCL): several robots driven from one program on
// one clock. A Cell builds, from a CellModel, each robot's simulated hardware and driver, one
// rtc::SessionGroup at the cell's base period (each robot every period_multiple-th tick) and
// one rccl::Manipulator per robot, the same motion API as a one-robot program:
//
//   cell::Cell cell(cell::load_cell_file("cells/cvarl.json"));
//   cell.start();                                    // the group's tasks, every generator
//   rccl::Manipulator& puma = cell.robot("puma");
//   puma.move(p);  cell.robot("microbo").move(q);    // both move at once
//   cell.waitfor({cell.event("puma", m.end())});     // an event: RCCL's waitfor
//   cell.wait_for(2s);                               // a duration: std's wait_for
//
// Waiting, the same rule on Session, Manipulator and Cell: `waitfor(event)` (one word, RCCL's
// `waitfor(p->end)`) waits for motion events; `wait_for(duration)` (std::condition_variable's
// spelling) lets time pass, in simulated time by running those samples. The other spelling
// with the other argument compiles with a deprecation warning naming the right one.
//
// Frames across robots: a robot's tool frame in the world, as the control task commands it,
// is a functional transform another robot's equation may use (tool_frame, in_base_of):
//
//   T6 TOOL = BASE_INV(microbo) PUMA_TOOL GRASP      the Microbo follows what the PUMA holds
//
// The control task publishes every robot's commanded T6 TOOL (in the world, with its linear
// velocity and acceleration and its angular velocity) after each tick through a seqlock; a
// reader extrapolates it to the time its own setpoint is for (up to its pipeline of two
// periods ahead), so a follower sampled at another rate does not lag; a generator planning a
// line onto it predicts it to the line's via time (at its velocity; a leader that has come to
// rest, and stopped publishing, where it is), so that the line starts where the frame will be.
//
// Safety between arms: after every tick the control task puts every robot's next setpoint
// into a CollisionWorld (the whole arm as capsules: links, joints, the cell file's shapes and
// tool; the cell's objects as solids) and, when a part of a robot comes closer than the margin
// plus the braking allowances to a part of another robot, or to an object, while approaching
// it, asks the generators to stop smoothly (TrajectoryGenerator::request_stop): their motions
// fail with a message naming the robots and parts (Manipulator::failures()). A setpoint that
// moves every close pair apart goes on, so stopped arms can be separated. The braking allowance
// is a bound on how far any point of a robot travels while it stops, see braking_m below. A
// motion's tool may touch the objects its StartWhen::touch names (objects()); a robot's base
// may rest on the object it is mounted on.
//
// A robot's fault ends its own control only: the others go on.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/cell/cell_model.hpp"
#include "rccx/cell/collision.hpp"
#include "rccx/cell/seqlock.hpp"
#include "rccx/cell/workcell.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rccl/transforms.hpp"
#include "rccx/rtc/session.hpp"
#include "rccx/rtc/simulated_robot.hpp"

namespace rccx::cell {

struct CellOptions {
  rtc::ClockKind clock = rtc::ClockKind::simulated;
  /// Real time only: SCHED_FIFO and mlockall when allowed.
  bool real_time_scheduling = true;
  /// Stop two arms before their capsules come within the cell's margin.
  bool collision_checks = true;
  /// Every robot on an ideal servo (hw::IdealArm) instead of its plant (the PUMA's PID on
  /// its dynamics, the Microbo's RCU): for load tests of the cycle itself.
  bool ideal_servo = false;
  /// When a robot's control ends by a fault (any terminate code but user_request and
  /// user_interrupt), every other robot stops smoothly and holds, its motion failed with the
  /// reason; false: the others go on (their motions that wait on it are cancelled still).
  bool stop_others_on_fault = true;
  /// Both tasks of the group on one thread (rtc::SessionOptions::one_thread): no hand-overs
  /// between processors, no watchdog for a hung control function. For load tests.
  bool one_thread = false;
  /// Real time only: rtc::SessionOptions::spin_before_tick.
  std::chrono::nanoseconds spin_before_tick{0};
  /// The robots this process runs (names of the model's robots); empty: all of them. The
  /// others are served by other processes (net::RobotServer): they are not simulated or
  /// controlled here, but stay in the collision check, placed from their newest state
  /// (Cell::set_remote_source) with the margin grown by its age.
  std::vector<std::string> local_robots;
};

/// Where the robots of other processes are read from (the network layer's newest states), for
/// the collision check. Called by the control task after every tick: noexcept, no lock, no
/// allocation, no wait.
class RemoteRobotSource {
 public:
  virtual ~RemoteRobotSource() = default;
  /// Remote robot `remote` (an index of Cell::remote_names()): its newest commanded joints
  /// (rad / m), their speeds (rad/s / m/s) and their age now (s). False when none has come yet.
  virtual bool latest(std::size_t remote, kin::JointVector& q, kin::JointVector& qd,
                      double& age_s) const noexcept = 0;
};

/// Motions of several robots that start in the same sample (Cell::together).
struct Together {
  std::shared_ptr<rccl::Rendezvous> rendezvous;
  std::vector<std::string> robots;
  /// What `robot`'s motion of this joint start passes to move() / dwell(), with events it also
  /// waits for. Throws std::invalid_argument for a robot not taking part.
  [[nodiscard]] rccl::StartWhen when(std::string_view robot,
                                     std::vector<rccl::EventGate> after = {}) const;
};

/// A robot's commanded tool frame in the world at one instant, as the control task publishes it.
struct ToolSample {
  math::Transform pose;               ///< world <- T6 TOOL, m
  math::Vec3 velocity_m_per_s;        ///< of pose.p
  math::Vec3 acceleration_m_per_s2;   ///< of pose.p
  math::Vec3 angular_velocity_rad_s;  ///< of pose.R, world frame
  double t_s = 0.0;                   ///< the time the setpoint is for, s
};

class Cell : public Workcell {
 public:
  /// Builds every robot (simulated hardware, driver, session of the group, manipulator).
  /// Throws CellFileError for an invalid model, std::invalid_argument for a robot that cannot
  /// be simulated, rtc::SessionError for a period a driver cannot serve.
  explicit Cell(CellModel model, CellOptions options = {});
  static std::unique_ptr<Cell> load(const std::filesystem::path& path, CellOptions options = {});
  /// Stops every robot's control, then the group's tasks.
  ~Cell() override;
  Cell(const Cell&) = delete;
  Cell& operator=(const Cell&) = delete;

  /// Starts the group's tasks and every robot's trajectory generator (rccl_control).
  void start() override;
  /// Lets `d` pass for the whole cell (simulated time: runs those ticks).
  void wait_for(std::chrono::nanoseconds d) override;
  [[deprecated("waitfor waits for events; let time pass with wait_for(duration)")]] void waitfor(
      std::chrono::nanoseconds d) {
    wait_for(d);
  }

  /// A robot's motion API. Throws std::invalid_argument naming the cell's robots for an
  /// unknown name.
  [[nodiscard]] rccl::Manipulator& robot(std::string_view name) override;
  [[nodiscard]] rtc::Session& session(std::string_view name);
  /// The simulated hardware below a robot's driver (a servo arm, or the Microbo's RCU), for
  /// tests that push or fault it between samples of simulated time.
  [[nodiscard]] rtc::SimulatedHardware& hardware(std::string_view name);
  /// The robots run in this process (all of the model's unless CellOptions::local_robots).
  [[nodiscard]] std::vector<std::string> robot_names() const override;
  /// The model's robots run by other processes (CellOptions::local_robots), in model order.
  [[nodiscard]] const std::vector<std::string>& remote_names() const noexcept {
    return remote_names_;
  }
  /// Where the remote robots' states come from (kept by the caller while the cell runs);
  /// before start() only. A remote robot no state has come for yet (none served it so far,
  /// nothing commands it) stands at its ready pose; once heard of, its margin grows with its
  /// newest state's age (remote_allowance_m).
  void set_remote_source(const RemoteRobotSource* source);
  /// How far any point of a remote robot may have moved in `age_s` (s) since a state that
  /// gave its joints' speeds `qd`: each joint at most |qd| age + a age^2 / 2 (a its generator's
  /// acceleration bound), never beyond its top speed times age, times its lever; m. The
  /// allowance its capsules get in the collision check.
  [[nodiscard]] double remote_allowance_m(std::size_t remote, const kin::JointVector& qd,
                                          double age_s) const noexcept;
  /// Closes every robot's session, its RCCX_LOG log put in place (one file a robot, named by its
  /// name in the cell). True when every log is whole (or there is none); a lost one (a full
  /// disk, an I/O error) is said on stderr as "<program>: robot <name>'s sample log is lost: ..."
  /// so that a program's exit code can check it: `return cell.finish_logs("demo") ? 0 : 1;`.
  bool finish_logs(std::string_view program);
  /// The index of a robot among those run here (the model's order, remote robots left out);
  /// throws like robot().
  [[nodiscard]] std::size_t index(std::string_view name) const;
  [[nodiscard]] const CellModel& model() const noexcept override { return model_; }
  [[nodiscard]] rtc::SessionGroup& group() noexcept { return *group_; }

  // --- Frames across robots ------------------------------------------------------------------
  /// A functional transform: `leader`'s commanded T6 TOOL in the world (its cell tool, or T6
  /// without one), extrapolated to the sample's time. Before its first setpoint: its ready pose.
  [[nodiscard]] rccl::TransformPtr tool_frame(std::string_view leader) const override;
  /// The last published tool frame of a robot (any thread).
  [[nodiscard]] ToolSample tool_sample(std::string_view name) const;

  // --- Synchronisation (Multi-RCCL) ----------------------------------------------------------
  /// An event of `robot`'s motions, for another robot's motion to wait for (StartWhen::after,
  /// Together::when) or the program (waitfor). Read from a copy the control task makes after
  /// every tick: a motion waiting on it starts at its first sample after the tick the event
  /// happened in, whatever the robots' order. Event::completed() means the last motion `robot`
  /// has queued so far. Throws like robot(); rccl::MotionError for a position's end.
  [[nodiscard]] rccl::EventGate event(std::string_view robot, const rccl::Event& e) override;
  /// A joint start: one motion of each of `robots` (each queued with Together::when) starts in
  /// the same sample, the first all of them are sampled in once every one is at rest and
  /// ready; with `end_together`, all end (come to rest) in the same sample too, the faster
  /// motions slowed to the slowest. A participant's motion that fails or is cancelled before
  /// the start, or its robot's control ending, cancels the others' with the reason. One use.
  [[nodiscard]] Together together(const std::vector<std::string>& robots,
                                  bool end_together = false);
  /// Waits for every gate (in simulated time: runs the cell's ticks until then). reached;
  /// failed when a gate can no longer open (its motion failed or was cancelled, its robot's
  /// control ended); timeout; session_ended when no robot's control is running.
  rccl::WaitResult waitfor(const std::vector<rccl::EventGate>& gates,
                           std::chrono::nanoseconds timeout = std::chrono::hours(24)) override;
  [[deprecated("wait_for lets time pass; wait for events with waitfor(gates)")]] rccl::WaitResult
  wait_for(const std::vector<rccl::EventGate>& gates,
           std::chrono::nanoseconds timeout = std::chrono::hours(24)) {
    return waitfor(gates, timeout);
  }

  // --- Sample loop -----------------------------------------------------------------------------
  /// A function the control task runs after each tick's collision check (tests, monitors).
  /// Before start() only; it must not block. Inside it, collision_world() holds every robot's
  /// next setpoint, and each generator's last_setpoint() may be read.
  void set_cycle_observer(std::function<void(std::uint32_t tick)> observer);
  /// The control task's collision world: read it from the cycle observer only.
  [[nodiscard]] const CollisionWorld& collision_world() const noexcept { return *world_; }
  /// How many times the check has stopped a pair of robots (any thread).
  [[nodiscard]] std::uint64_t collision_stops() const noexcept {
    return collision_stops_.load(std::memory_order_acquire);
  }

  /// A bound on how far any point of a robot's links (and capsules) travels from setpoint q1
  /// (with q0 the setpoint one period P before) until it stands, when asked to stop now: the
  /// generator's halt decelerates every joint at its bound a_j within one common time. The check
  /// passes q1 only when the pair stays apart by this much, so that the stop may still begin
  /// one setpoint later, from q2: with v_j = |q1_j - q0_j| / P + a_j P (q2's speed at most)
  /// and Ts = max v_j / a_j, joint j travels at most v_j P to q2 and v_j Ts / 2 while it stops,
  /// and a point moves at most lever_m[j] per rad of it (1 m per m of a prismatic joint), m.
  static double braking_m(const kin::RobotModel& model, const kin::JointVector& q0,
                          const kin::JointVector& q1, const kin::JointVector& max_acceleration,
                          double period_s, const kin::JointVector& lever_m) noexcept;
  /// How far a point of the links joint j moves (or of their capsules) can be from its axis:
  /// the lengths of links j.. (|a| + |d|, a prismatic d at its farther end), the tool's offset,
  /// the reach of the shapes those links carry and the largest capsule radius, m. For a
  /// general chain (a URDF's): the offsets from joint j's origin out to each later frame
  /// (|origin|, |after|, a prismatic joint's farther limit) plus what that frame carries (its
  /// shapes, the model's own capsules, the link capsules and the tool).
  static kin::JointVector levers_m(const CellRobot& robot);
  /// A robot's named capsules for the collision check: the cell file's shapes and, for a tool
  /// without a shape in T6, a capsule from T6's origin to the tool's, the last link's radius
  /// (for a robot with no link radii, its own capsules' in T6, or their largest).
  static std::vector<RobotShape> shapes_of(const CellRobot& robot);
  /// The radius of a robot's own capsules in T6 (the largest), else of any of them; 0: none.
  static double own_flange_radius_m(const kin::RobotModel& model) noexcept;

 private:
  struct Robot {
    std::string name;
    std::size_t model_index = 0;  ///< in model_.robots
    rtc::SimulatedHardware hardware;
    rtc::Session* session = nullptr;
    std::unique_ptr<rccl::Manipulator> manipulator;
    math::Transform base_inverse;
    math::Transform tool;  ///< T6 <- tool (identity without one)
    double period_s = 0.0;
    kin::JointVector lever_m;  ///< levers_m()
    SeqLock<ToolSample> published;
    // Control task only.
    const rccl::TrajectoryGenerator* generator = nullptr;
    std::size_t dof = 0;
    /// braking_m()'s inputs that do not change: the generator's acceleration bounds, and the
    /// levers with a prismatic joint's 1 m per m, kept here so that the hook does not reach
    /// into the robot model and the generator's options every tick.
    kin::JointVector max_acceleration;
    kin::JointVector travel_factor;
    double last_t_s = -1.0;  ///< the setpoint time last published
    bool valid = false;      ///< has a setpoint in the collision world
    bool fresh = false;      ///< `next` is this tick's, to be published at the tick's end
    double braking_m = 0.0;
    std::uint64_t touch = 0;    ///< the objects its tool may touch now (CollisionWorld::set_touch)
    math::Vec3 velocity_back;   ///< the tool point's last backward difference, m/s
    ToolSample last;            ///< the last sample published
    ToolSample next;            ///< this tick's, computed after the robot's f2
    rccl::MotionLedger ledger;  ///< the generator's, as of the end of the last tick
    bool was_controlling = false;
  };

  [[nodiscard]] const Robot& find(std::string_view name) const;
  [[nodiscard]] Robot& find(std::string_view name);
  void on_cycle(std::uint32_t tick) noexcept;
  /// Robot i's part of the tick's checks, right after its f2 (SessionGroup's robot hook): its
  /// capsules, its tool frame (kept for the tick's end) and its braking allowance.
  void on_robot(std::size_t i) noexcept;
  [[nodiscard]] static double braking_fast(const Robot& r, const kin::JointVector& q0,
                                           const kin::JointVector& q1) noexcept;
  void check_collisions() noexcept;
  /// Places the remote robots in the collision world from their newest states, each with the
  /// allowance its state's age calls for.
  void place_remote_robots() noexcept;
  /// Throws CellFileError when a robot's ready pose lies inside an object it may not touch.
  void check_clear_at_start() const;
  void publish_ledgers() noexcept;

  CellModel model_;
  CellOptions options_;
  // Declared before the group: the cycle hook uses them until the group's tasks stop.
  std::vector<std::unique_ptr<Robot>> robots_;
  /// Remote robots: their names, model indices and what bounds their travel (levers, top
  /// speeds, acceleration bounds); their collision-world indices follow the local robots'.
  std::vector<std::string> remote_names_;
  std::vector<std::size_t> remote_model_index_;
  std::vector<kin::JointVector> remote_travel_factor_;     ///< m per rad (1 per m prismatic)
  std::vector<kin::JointVector> remote_max_velocity_;      ///< rad/s / m/s
  std::vector<kin::JointVector> remote_max_acceleration_;  ///< the generator's bound
  const RemoteRobotSource* remote_source_ = nullptr;
  std::vector<double> remote_age_s_;  ///< control task: each remote state's age at the last tick
  /// Each robot's generator, side by side, so that the tick's last pass can fetch the next
  /// robots' ahead of use.
  std::vector<const rccl::TrajectoryGenerator*> generators_;
  std::unique_ptr<CollisionWorld> world_;
  std::vector<Threat> threats_;  ///< the check's buffer: one per robot pair, robot and object
  std::array<char, rccl::kEventText> message_{};
  std::function<void(std::uint32_t)> observer_;
  std::atomic<std::uint64_t> collision_stops_{0};
  /// Last: its tasks (and the cycle hook) stop first, see ~Cell.
  std::unique_ptr<rtc::SessionGroup> group_;
  bool started_ = false;
};

}  // namespace rccx::cell
