// `rccx view`: a read-only web page of robots at work, served from the program that drives them.
//
//   auto view = rccx::view::serve(arm, 8080);   // an rccl::Manipulator; prints
//   http://127.0.0.1:8080/
//
// Served from a Manipulator (or a cell, whose robots are), the page also draws the goal of every
// position the program moves to, named, as move() queues it, and marks the one the running
// motion goes to (the motion id travels in the tapped sample as its segment).
// The sample loop is tapped the way the CSV log is (rtc::Session::set_tap): the communication
// task copies a fixed-size sample into a lock-free single-producer queue every 1/rate s of
// sample time (decimated in the loop, so the copy costs nothing the other samples) and returns;
// it never waits, locks or allocates, and a full queue drops the sample (counted). The server's
// own thread (Boost.Beast over Boost.Asio, one io_context) drains the queues at the same rate,
// computes the tool frame, keeps a history for pages that open late, and sends each page the new
// samples over a WebSocket; a page that cannot keep up loses samples, never slows anyone else.
// In simulated time, which runs many times faster than the wall clock, at most 3 samples a
// robot go on per tick (evenly spaced, the newest among them): the server's work stays that of
// real time, and so does what it takes from the processors the loop runs on.
//
// HTTP, GET only (anything else: 405, the view is read-only):
//   /                  the page, every robot           /robot/NAME   the page, one robot
//   /assets/FILE       the bundled front end (web/, built by the project's build)
//   /api/scene         robots (DH chains, bases, tools, capsules), objects, frames (?robot=NAME)
//   /api/state         the last sample of every robot (its "goal": the frame the running
//                      motion goes to, when known); ?robot=NAME&t=T: that robot's at time T
//   /api/log           replay only: the whole recorded run (of robot 0: a replay is one robot's)
//   /ws                the live samples (?robot=NAME), as JSON text messages
// An unknown robot is a 404 with a message naming the robots there; the server goes on.
// Inside (namespace detail): sample_feed.hpp the taps and what the server's thread makes of
// them, page_socket.hpp a page's WebSocket, routes.hpp which URL gives what, goals.hpp the
// frames the program adds, site.hpp what they all read.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "rccx/rccl/position.hpp"
#include "rccx/view/run_log.hpp"
#include "rccx/view/scene.hpp"

namespace rccx::rtc {
class Session;
}
namespace rccx::cell {
class Cell;
}
namespace rccx::rccl {
class Manipulator;
}

namespace rccx::view {

/// The view cannot start (a port in use, an address that cannot be bound, no front end).
class ViewError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ServeOptions {
  /// The address to listen on: 127.0.0.1 unless asked (0.0.0.0 serves the network, read-only).
  std::string address = "127.0.0.1";
  /// Samples a second sent to the pages (the tap decimates to it), 1 .. 200.
  double rate_hz = 50.0;
  /// The bundled front end; empty: found beside the executable (see find_assets).
  std::filesystem::path assets;
  /// Samples kept for pages that open late (and /api/state?t=).
  std::size_t history = 6000;
  /// Say the address to open on stderr.
  bool announce = true;
};

/// Where the front end the build made is: $RCCX_VIEW_ASSETS, else <exe>/../web/dist (the build
/// tree: build/<type>/web/dist), <exe>/../share/rccx/web (an install), else the build tree
/// configured in. Empty when none holds index.html.
std::filesystem::path find_assets();

struct ServerStats {
  std::uint64_t samples_sent = 0;      ///< samples drained from the taps and broadcast
  std::uint64_t samples_dropped = 0;   ///< by the taps (queue full)
  std::uint64_t messages_dropped = 0;  ///< to pages that did not keep up
  std::size_t pages = 0;               ///< WebSocket connections open now
  std::uint64_t requests = 0;          ///< HTTP requests served
};

class Server {
 public:
  /// Listens on options.address:port (0: any free port) and starts the server's thread. Throws
  /// ViewError for a port in use or an address that cannot be bound, saying what to do.
  Server(Scene scene, std::uint16_t port, ServeOptions options = {});
  /// Detaches every tap, then stops the server. Destroy it before the sessions it taps (the
  /// manipulators it is attached to may outlive it: their observers then do nothing).
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Taps `session` for scene robot `robot` (0-based). Planning level, any time.
  void attach(std::size_t robot, rtc::Session& session);
  /// As attach(robot, arm.session()) (unless that session is tapped already), and from now on
  /// shows the goal of every position `arm` moves to, as show() would, when move() queues it
  /// (arm's move observer, on the planning thread: nothing is added to the sample loop); the
  /// samples of that motion name it as their "goal". Replaces any move observer `arm` had.
  void attach(std::size_t robot, rccl::Manipulator& arm);
  /// Replay: the page gets `log` (robot 0) with a time slider instead of live samples.
  void set_replay(RunLog log);
  /// Draws a position equation's goal (the tool frame where the equation puts it, in the world)
  /// with its name, for scene robot `robot`; the same name again for the same robot moves that
  /// frame (a goal whose transforms changed). Planning level. An attached Manipulator's moves
  /// do this by themselves.
  void show(const rccl::PositionPtr& position, std::size_t robot = 0);
  /// Adds a named frame (world <- frame). Planning level.
  void add_frame(SceneFrame frame);

  /// Prints "rccx view: open URL (Ctrl-C to stop)" on stderr: the constructor does when
  /// options.announce is set; a caller that still has to set the server up (serve_replay's
  /// log) constructs it without and announces when a page opened at once sees all.
  void announce() const;

  [[nodiscard]] std::uint16_t port() const noexcept;
  /// http://ADDRESS:PORT/
  [[nodiscard]] std::string url() const;
  [[nodiscard]] ServerStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The view of one robot's session (rtc::SimulatedRobot::session, a Manipulator's session).
std::unique_ptr<Server> serve(rtc::Session& session, std::uint16_t port = 8080,
                              ServeOptions options = {});
/// The view of one arm: its session, and the goals of the positions it moves to (attach).
std::unique_ptr<Server> serve(rccl::Manipulator& arm, std::uint16_t port = 8080,
                              ServeOptions options = {});
/// The view of every robot of a cell, with its objects, frames and collision capsules, and the
/// goals of the positions each robot moves to (attach).
std::unique_ptr<Server> serve(cell::Cell& cell, std::uint16_t port = 8080,
                              ServeOptions options = {});
/// A recorded run of `model`, replayed in the page. RunLogError when the log's joints do not
/// match the robot's.
std::unique_ptr<Server> serve_replay(const kin::RobotModel& model, RunLog log,
                                     std::uint16_t port = 8080, ServeOptions options = {});

}  // namespace rccx::view
