// A program's view of a cell whose robots are served by other processes (`rccx serve`,
// docs/NETWORK.md): the calls of cell::Cell and rccl::Manipulator, each request a round trip
// to the robot's serve process (its answer awaited, so that a goal out of reach throws here as
// it would in one process).
//
//   net::RemoteCell cell(cell::load_cell_file("cells/cvarl.json"), {.domain = 7});
//   net::RemoteArm& puma = cell.robot("puma");              // cell.robot("puma")
//   rccl::Motion m = puma.move(puma.park());                // throws rccl::MotionError if refused
//   puma.waitfor(m.end());                                  // waitfor(park->end)
//   auto follow = cell.world_goal("microbo", "GRASP", {cell.tool_frame("puma"), grasp});
//   cell.robot("microbo").move(follow, cell.after("puma", m.start()));
//
// A robot whose serve process is silent for the detection time (NetOptions::detection, 20 ms
// by default) is lost: waits on it return failed and failures() says why; a restarted serve
// is announced on stderr and the robot can be used again. Threads: the program's calls (one
// thread, as with a Manipulator) and one middleware thread (heartbeats, states, answers,
// events) that sleeps on a Cyclone waitset: woken at once by an event or a state, else at its
// next heartbeat or a robot's loss deadline. Answers to requests are taken in Cyclone's receive
// thread (a listener) and handed straight to the waiting call.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "rccx/cell/cell.hpp"
#include "rccx/cell/cell_model.hpp"
#include "rccx/cell/workcell.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/net/dds.hpp"
#include "rccx/net/mirror.hpp"
#include "rccx/rccl/arm.hpp"
#include "rccx/rccl/manipulator.hpp"

namespace rccx::net {

class StateInbox;
namespace detail {
template <class T>
class Inbox;
}  // namespace detail

class RemoteCell;
struct RequestSample;

/// A robot's newest state as its serve process sent it.
struct RemoteState {
  std::string participant;  ///< the serve process
  std::uint64_t instance = 0;
  std::uint64_t sample = 0;
  double t_s = 0.0;
  std::int64_t stamp_ns = 0;     ///< CLOCK_REALTIME that t_s stands for (the serve's host clock)
  kin::JointVector q_commanded;  ///< rad / m
  kin::JointVector q_measured;
  cell::ToolSample tool;  ///< world <- T6 TOOL, commanded
  RobotStatus status = RobotStatus::not_started;
  int terminate_code = 0;
  std::string termination;
  std::uint64_t running = 0;
  std::uint64_t queued = 0;
  std::uint64_t started_upto = 0;
  std::uint64_t ended_upto = 0;
  bool control_ended = false;
  std::string program;             ///< the program attached to it
  std::chrono::nanoseconds age{};  ///< since it was received
};

/// Timeouts of a remote program.
struct RemoteOptions {
  /// How long the constructor waits for every robot's state (serve processes starting).
  std::chrono::nanoseconds wait_for_robots = std::chrono::seconds(10);
  /// How long a request waits for its answer (it is re-sent every 200 ms meanwhile; a
  /// repeated id is never executed twice).
  std::chrono::nanoseconds answer_timeout = std::chrono::seconds(3);
  /// The robots to use (default: every robot of the cell).
  std::vector<std::string> robots;
};

/// One robot of a RemoteCell, with the Manipulator's calls.
class RemoteArm : public rccl::Arm {
 public:
  RemoteArm(RemoteCell& cell, const cell::CellRobot& robot);
  RemoteArm(const RemoteArm&) = delete;
  RemoteArm& operator=(const RemoteArm&) = delete;

  [[nodiscard]] const std::string& name() const noexcept { return name_; }

  // --- Settings for the motions queued from now on (sent with each motion) ---------------
  void set_mode(rccl::Mode mode) override { settings_.mode = mode; }
  /// m/s, rad/s, both > 0 (MotionError otherwise, nothing changed).
  void set_velocity(double translation_m_per_s, double rotation_rad_per_s) override;
  void set_segment_time(double seconds) override;
  void set_transition_time(double seconds) override;
  /// A name of the robot's configurations ("lun" ...); empty keeps the present one.
  void set_configuration(std::string_view name) override;
  void set_guard(const rccl::ForceGuard& guard) override;
  void set_compliance(const rccl::Compliance& compliance) override;
  [[nodiscard]] const rccl::MotionSettings& settings() const noexcept override { return settings_; }

  // --- Requests: each waits for the serve process's answer ------------------------------
  /// Queues a motion; throws rccl::MotionError with the serve's reason when it is refused,
  /// when the serve does not answer in time, when the robot is lost, or for a position that
  /// cannot be sent (a functional transform without a network name).
  rccl::Motion move(const rccl::PositionPtr& position, const rccl::StartWhen& when = {}) override;
  rccl::Motion dwell(double seconds, const rccl::StartWhen& when = {}) override;
  /// Stops smoothly where the arm is and cancels everything queued.
  void halt() override;
  /// RCCL's nextmove: ends the running motion where the arm is; the queue goes on.
  void nextmove();
  void set_hand(bool closed) override;
  /// Takes the robot for this program without moving it: its loss now stops the robot.
  void attach();

  // --- Waiting and what happened ----------------------------------------------------------
  /// The robot's ready pose, in joints.
  [[nodiscard]] const rccl::PositionPtr& park() const noexcept override { return park_; }
  /// Waits (real time) for `event`: reached; failed when its motion failed or was cancelled,
  /// control ended, or the robot was lost (failures() says why); timeout.
  rccl::WaitResult waitfor(const rccl::Event& event,
                           std::chrono::nanoseconds timeout = std::chrono::hours(24)) override;
  /// Lets `d` pass (real time). Returns how control ended (from the robot's state: its
  /// terminate code and reason) if it has ended, an empty one otherwise.
  rtc::Termination wait_for(std::chrono::nanoseconds d) override;
  [[nodiscard]] bool happened(const rccl::Event& event) const noexcept override;
  /// Failures and cancellations so far (from the events), and the robot's loss. The reference
  /// stays valid until the next call.
  [[nodiscard]] const std::vector<rccl::MotionEvent>& failures() override;
  /// Every event received since the last call.
  std::vector<rccl::MotionEvent> take_events() override;
  /// When motion `m` started and ended (the serve's clock, s) and whether it failed, from its
  /// events; the path errors of a local report are not sent.
  [[nodiscard]] rccl::SegmentReport report(const rccl::Motion& m) const noexcept override;
  /// The last motion queued on the robot (by this program, or as its state said at start).
  [[nodiscard]] std::uint64_t last_queued() const noexcept override { return last_queued_; }
  /// The newest state and its age. Throws rccl::MotionError before any.
  [[nodiscard]] RemoteState state() const;
  [[nodiscard]] const kin::Kinematics& kinematics() const noexcept override { return *kinematics_; }
  /// The ledger kept from the robot's states (gates, waits).
  [[nodiscard]] const RobotMirror& mirror() const noexcept { return *mirror_; }

 private:
  friend class RemoteCell;
  /// Sends `r` (its robot, program and id filled here) and waits for the answer; throws
  /// MotionError for a refusal or no answer.
  rccx_net_MotionAck request(RequestSample& r);
  [[nodiscard]] rccl::GateAnswer answer(const rccl::Event& e) const;

  RemoteCell& cell_;
  std::string name_;
  std::unique_ptr<kin::Kinematics> kinematics_;
  rccl::PositionPtr park_;
  rccl::MotionSettings settings_;
  std::uint64_t next_request_ = 1;
  std::uint64_t last_queued_ = 0;
  std::map<const rccl::Position*, std::uint64_t> position_last_;  ///< position_end
  std::unique_ptr<RobotMirror> mirror_;
  // Middleware thread -> program, under the cell's mutex.
  std::optional<rccx_net_RobotState> state_;
  std::int64_t state_received_ns_ = 0;
  std::vector<rccl::MotionEvent> events_, failures_;
  std::vector<rccl::MotionEvent> failures_copy_;  ///< program side: what failures() returned
  /// Program side's record of each motion's start and end times (s) from its events.
  std::map<std::uint64_t, rccl::SegmentReport> reports_;
  std::string lost_;       ///< why the robot is lost ("" while it is alive)
  bool end_said_ = false;  ///< its control's end is in failures_ already
};

/// A stream a program writes for its robots' equations ("stream:<name>", FrameSample).
class FrameStream {
 public:
  FrameStream(RemoteCell& cell, std::string name);
  /// Writes a sample: the frame in the world (m) and its motion, stamped now.
  void set(const math::Transform& pose, const math::Vec3& velocity_m_per_s = {},
           const math::Vec3& angular_velocity_rad_s = {});
  /// A functional transform with the reference "stream:<name>": locally the last pose set.
  [[nodiscard]] const rccl::TransformPtr& transform() const noexcept { return transform_; }

 private:
  RemoteCell& cell_;
  std::string name_;
  std::uint64_t seq_ = 0;
  std::shared_ptr<cell::SeqLock<math::Transform>> last_;
  rccl::TransformPtr transform_;
};

class RemoteCell : public cell::Workcell {
 public:
  /// Joins the domain, heartbeats, and waits for every robot's state (NetError naming the
  /// robot and the serve command to start when one does not come).
  RemoteCell(cell::CellModel model, NetOptions net = {}, RemoteOptions options = {});
  /// Stops the middleware thread (the serve processes then see this program lost).
  ~RemoteCell() override;
  RemoteCell(const RemoteCell&) = delete;
  RemoteCell& operator=(const RemoteCell&) = delete;

  /// Throws std::invalid_argument naming the robots for an unknown name.
  [[nodiscard]] RemoteArm& robot(std::string_view name) override;
  [[nodiscard]] std::vector<std::string> robot_names() const override;
  [[nodiscard]] const cell::CellModel& model() const noexcept override { return model_; }
  /// Attaches this program to every robot (kind attach): from now on, its loss stops them.
  void start() override;
  [[nodiscard]] const std::string& participant() const noexcept { return participant_name_; }
  [[nodiscard]] const NetOptions& net() const noexcept { return net_; }

  // --- Frames (as cell::Cell has them) -------------------------------------------------
  /// `leader`'s commanded T6 TOOL in the world, reference "frame:<leader>"; locally its newest
  /// state's tool pose.
  [[nodiscard]] rccl::TransformPtr tool_frame(std::string_view leader) const override;
  /// A function registered in the serve processes ("function:<name>"); locally the identity.
  [[nodiscard]] rccl::TransformPtr function(std::string name) const;
  /// A stream this program writes ("stream:<name>").
  [[nodiscard]] FrameStream& stream(std::string name);

  // --- Synchronisation -----------------------------------------------------------------
  [[nodiscard]] rccl::EventGate event(std::string_view robot, const rccl::Event& e) override;
  rccl::WaitResult waitfor(const std::vector<rccl::EventGate>& gates,
                           std::chrono::nanoseconds timeout = std::chrono::hours(24)) override;
  void wait_for(std::chrono::nanoseconds d) override;

 private:
  friend class RemoteArm;
  friend class FrameStream;
  void run() noexcept;
  void poll(std::int64_t now);
  /// Takes this program's answers into acks_ and wakes the waiting call; run by Cyclone's
  /// receive thread (a data-available listener on ack_reader_).
  void take_acks() noexcept;
  [[nodiscard]] RemoteArm* find(std::string_view name) noexcept;

  cell::CellModel model_;
  NetOptions net_;
  RemoteOptions options_;
  std::string participant_name_;
  std::uint64_t instance_ = 0;
  std::unique_ptr<Participant> participant_;
  Entity hb_writer_, request_writer_, frame_writer_, state_reader_, ack_reader_, event_reader_;
  std::unique_ptr<StateInbox> states_in_;  ///< made once: room for 2 samples of 256 states
  std::unique_ptr<detail::Inbox<rccx_net_MotionEvent>> events_in_;  ///< made once
  std::vector<std::unique_ptr<RemoteArm>> arms_;
  std::map<std::string, std::unique_ptr<FrameStream>> streams_;

  mutable std::mutex mutex_;  ///< arms' states, events, answers
  std::condition_variable changed_;
  std::vector<rccx_net_MotionAck> acks_;  ///< answers not yet taken
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::int64_t last_heartbeat_ns_ = 0;
  std::uint64_t heartbeat_seq_ = 0;
  std::int64_t next_loss_check_ns_ = INT64_MAX;  ///< steady: the earliest a robot may be lost
  // The middleware thread's waitset: read conditions on the state and event readers, and a
  // guard condition the destructor triggers. After the readers: deleted before them.
  Entity waitset_, state_ready_, event_ready_, wake_guard_;
};

}  // namespace rccx::net
