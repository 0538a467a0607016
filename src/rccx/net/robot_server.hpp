// A serve process's heart (`rccx serve`, docs/NETWORK.md): some robots of a cell, their RTC
// sessions, generators and collision check in this process on its real-time clock, commanded
// over DDS by programs in other processes.
//
//   net::ServeOptions o;  o.net.domain = 7;  o.net.interface = "lo";
//   net::RobotServer serve(cell::load_cell_file("cells/cvarl.json"), {"puma"}, o);
//   serve.register_function("CONV", conveyor);        // "function:CONV" in a program's equation
//   serve.start();                                    // claims, control, the middleware thread
//   while (!stopped) ...;
//   serve.stop();                                     // halts smoothly, gives the claims back
//
// Threads: the cell's control task (never calls DDS: after each tick its cycle observer copies
// each robot's setpoint into a triple buffer and rings a doorbell) and one middleware thread,
// woken by that doorbell, by data arriving (Cyclone listeners ring the same doorbell) or by its
// next deadline (heartbeat, a peer's loss): it writes states (and each robot's ROS 2 joint state)
// and heartbeats, takes requests, answers them at once, publishes the motions' events, and stops
// the robots of a lost program or of a lost leader smoothly (Manipulator::halt) saying why.
// A request is usually answered before that thread wakes: the request reader's listener, in
// Cyclone's receive thread, takes and answers it itself when the middleware thread is not in a
// pass (ddsperf's pong answers the same way), saving a thread wake-up per round trip. Both run
// under serve_mutex_ (the listener only tries it, never waits), so the Manipulator calls and the
// serve's tables still have one caller at a time.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "rccx/cell/cell.hpp"
#include "rccx/cell/cell_model.hpp"
#include "rccx/net/dds.hpp"
#include "rccx/net/mirror.hpp"
#include "rccx/rccl/transforms.hpp"
#include "rccx/rtc/doorbell.hpp"

namespace rccx::net {

class StateBatch;

/// Another serve process holds a robot asked for (or won the race for it); the message names it.
class ClaimRefused : public NetError {
 public:
  using NetError::NetError;
};

struct ServeOptions {
  NetOptions net;
  /// How long to listen for other processes' claims before claiming (discovery time), and
  /// again after claiming (a race).
  std::chrono::nanoseconds claim_wait = std::chrono::milliseconds(300);
  /// SCHED_FIFO and mlockall for the control task when allowed.
  bool real_time_scheduling = true;
  /// Each served robot's joint state also as ROS 2's sensor_msgs/JointState on
  /// "rt/<robot>/joint_states" (net::JointStatePublisher; `rccx serve --no-ros2` turns it off).
  bool ros2_joint_states = true;
};

/// The part of `model` a serve process of `robots` runs: those robots only, its objects and
/// frames. Throws std::invalid_argument naming the cell's robots for an unknown or repeated
/// name, or for none. The one place a serve's cell is cut out (later: the others as remote
/// robots in the collision check, CellOptions::local_robots).
cell::CellModel served_model(const cell::CellModel& model, const std::vector<std::string>& robots);

class RobotServer {
 public:
  /// Checks the robots (std::invalid_argument as served_model); nothing runs yet.
  RobotServer(cell::CellModel model, std::vector<std::string> robots, ServeOptions options);
  /// stop().
  ~RobotServer();
  RobotServer(const RobotServer&) = delete;
  RobotServer& operator=(const RobotServer&) = delete;

  /// A functional transform programs may name "function:<name>". Before start() only.
  void register_function(std::string name, rccl::TransformFunction function);

  /// Joins the domain, claims the robots (ClaimRefused when another live process holds one),
  /// builds and starts the cell in real time, then the middleware thread. Throws NetError,
  /// ClaimRefused, what the cell throws.
  void start();
  /// Halts every robot smoothly (up to 2 s to come to rest), says so in a last state, gives the
  /// claims back and ends control. Idempotent.
  void stop();

  /// One line: what it serves, the domain, interface, plain or secure, ROS 2 joint states.
  [[nodiscard]] std::string banner() const;
  [[nodiscard]] const std::string& participant() const noexcept { return participant_name_; }
  /// Set when the middleware thread stopped on an error (what went wrong); "" while all is well.
  [[nodiscard]] std::string failure() const;
  [[nodiscard]] cell::Cell& cell() noexcept { return *cell_; }
  /// The control clock's figures so far (after stop(): until then): ticks, the cycle's
  /// computing time and the wake-up latency (us), deadlines missed.
  [[nodiscard]] std::string clock_report() const;
  /// How the requests were answered so far: in the listener at once, or by the middleware
  /// thread's next pass because the listener found a pass under way (the slower way).
  struct RequestCounts {
    std::uint64_t in_listener = 0;
    std::uint64_t in_pass = 0;
    std::uint64_t handed_over = 0;  ///< times the listener found a pass under way
  };
  [[nodiscard]] RequestCounts request_counts() const;
  /// request_counts() in a line for people.
  [[nodiscard]] std::string request_report() const;

 private:
  struct Local;
  struct Dedup;
  struct Inboxes;
  struct Program {
    std::uint64_t instance = 0;
    std::int64_t seen_ns = 0;  ///< steady clock, last heartbeat
  };
  struct Stream {
    cell::SeqLock<FrameState> frame;
    std::int64_t received_ns = 0;
    bool lost = false;
  };

  void claim();
  void release_claims() noexcept;
  void run() noexcept;
  void poll();
  void read_heartbeats(std::int64_t now);
  void read_states(std::int64_t now);
  void read_frames(std::int64_t now);
  /// Takes and answers the requests there are: how many.
  std::uint64_t read_requests(std::int64_t now);
  void handle(const rccx_net_MotionRequest& r, std::int64_t now);
  /// Writes an ack (its writer never waits: one it cannot take yet waits in acks_backlog_).
  void answer(const rccx_net_MotionAck& ack);
  void execute(Local& l, const rccx_net_MotionRequest& r, rccx_net_MotionAck& ack);
  void publish_events();
  /// A robot whose control an overrun ended (said and published already) starts again at rest.
  void restart_after_overruns();
  /// Fills the robots' states for send_states() (under serve_mutex_: it reads the arms).
  /// `heartbeat_pass`: this pass writes the heartbeat, and repeats the states with it.
  void publish_states(std::int64_t now, bool last = false, bool heartbeat_pass = false);
  /// Writes what publish_states() and poll() made ready: the states, the ROS 2 joint states, the
  /// heartbeat. Outside serve_mutex_ in a pass: the request listener, which never makes these
  /// writes, answers meanwhile instead of waiting for their system calls.
  void send_states();
  void check_lost(std::int64_t now);
  /// When the middleware thread must run again with nothing arriving (steady ns): the next
  /// heartbeat (states to repeat go with it), a peer's loss deadline.
  [[nodiscard]] std::int64_t next_wake() const noexcept;
  /// Cyclone's data-available listeners on the readers ring wake_ (from its receive thread);
  /// the request reader's answers requests itself (answer_in_receive_thread).
  void listen();
  /// In Cyclone's receive thread, when a request arrived: if the middleware thread is not in a
  /// pass (try_lock, never a wait), reads what arrived and answers the requests; else rings it.
  void answer_in_receive_thread() noexcept;
  /// In Cyclone's receive thread, when a heartbeat arrived: takes the heartbeats if the
  /// middleware thread is not in a pass (try_lock), else rings it.
  void take_heartbeats_in_receive_thread() noexcept;
  /// From a receive-thread listener that failed: records why and stops the serve.
  void stop_with(const std::exception& e) noexcept;
  /// Halts `l` smoothly; the events of its motions up to the last queued say `why`.
  void halt_with(Local& l, const std::string& why);
  /// `cell` is *cell_, passed in: ~Cell stops the tasks that call this, and unique_ptr::reset
  /// has made cell_ null by then.
  void on_cycle(const cell::Cell& cell) noexcept;
  [[nodiscard]] Local* local(std::string_view robot) noexcept;

  cell::CellModel full_model_;
  std::vector<std::string> robot_names_;
  ServeOptions options_;
  std::map<std::string, rccl::TransformFunction> functions_;

  std::string participant_name_;
  std::uint64_t instance_ = 0;
  /// Rung by the control task after a tick, by Cyclone's listeners when data arrives, by
  /// stop(); the middleware thread sleeps on it (a futex: the sample loop makes no DDS call,
  /// takes no lock). Before the entities: it outlives their listeners.
  rtc::detail::Doorbell wake_;
  /// Held by the middleware thread for each pass, tried by the request listener
  /// (answer_in_receive_thread): what they share has one user at a time. Before the entities:
  /// deleting a reader waits for its listener, which may hold it.
  mutable std::mutex serve_mutex_;
  std::unique_ptr<Inboxes> inboxes_;  ///< serve_mutex_
  /// The request listener answers only from the end of start() to stop().
  std::atomic<bool> answering_{false};
  std::uint64_t answered_in_listener_ = 0;  ///< serve_mutex_
  std::uint64_t answered_in_pass_ = 0;      ///< serve_mutex_
  /// Times the listener found the middleware thread in a pass and handed the request over.
  std::atomic<std::uint64_t> listener_handed_over_{0};
  std::unique_ptr<Participant> participant_;
  Entity hb_writer_, hb_reader_, claim_writer_, claim_reader_, state_writer_, state_reader_,
      request_reader_, ack_writer_, event_writer_, frame_reader_;
  std::vector<rccx_net_Claim> claims_;

  std::vector<std::unique_ptr<Local>> locals_;
  std::unique_ptr<StateBatch> states_out_;  ///< locals_' states, written a pass
  std::map<std::string, std::unique_ptr<RobotMirror>> mirrors_;  ///< the cell's other robots
  /// The other robots' newest joints for the collision check (cell::RemoteRobotSource).
  struct MirrorSource : cell::RemoteRobotSource {
    std::vector<const RobotMirror*> mirrors;  ///< by Cell::remote_names() index
    bool latest(std::size_t remote, kin::JointVector& q, kin::JointVector& qd,
                double& age_s) const noexcept override;
  };
  MirrorSource remote_source_;
  std::map<std::string, std::unique_ptr<Stream>> streams_;
  /// After what its cycle observer, remote source and streams read: it (its tasks) goes first.
  std::unique_ptr<cell::Cell> cell_;
  std::string clock_report_;  ///< kept by stop() for clock_report()
  std::map<std::string, Program> programs_;
  std::map<std::string, std::unique_ptr<Dedup>> dedup_;  ///< by "<program>|<robot>"

  std::thread thread_;
  std::atomic<bool> stop_{false};
  bool started_ = false;
  bool stopped_ = false;
  std::int64_t last_heartbeat_ns_ = 0;
  std::uint64_t heartbeat_seq_ = 0;
  bool heartbeat_due_ = false;  ///< poll() found a heartbeat due: send_states() writes it
  /// A request attached a program since the middleware thread's last pass (serve_mutex_).
  bool attached_since_pass_ = false;
  /// Samples of a reliable topic its writer could not take without waiting (a reader that
  /// acknowledges nothing filled its history), written in order before any newer one, each
  /// pass (serve_mutex_). Neither the receive thread nor the middleware thread ever waits.
  template <class Sample>
  struct Backlog {
    static constexpr std::size_t kBacklogLimit = 100'000;  ///< then the oldest go
    std::deque<Sample> waiting;
    std::size_t dropped = 0;
    bool said = false;  ///< the wait was said on stderr
    void write(dds_entity_t writer, const Sample& s, const char* what);
    void flush(dds_entity_t writer, const char* what);
  };
  Backlog<rccx_net_MotionAck> acks_backlog_;
  Backlog<rccx_net_MotionEvent> events_backlog_;
  std::int64_t next_loss_check_ns_ = INT64_MAX;  ///< steady: the earliest a peer may be lost
  mutable std::mutex failure_mutex_;
  std::string failure_;
};

}  // namespace rccx::net
