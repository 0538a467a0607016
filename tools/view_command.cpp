#include "view_command.hpp"

#include "plot_command.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <thread>

#include "rccx/cell/cell.hpp"
#include "rccx/cell/cell_model.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/io/signals.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/simulated_robot.hpp"
#include "rccx/view/plot.hpp"
#include "rccx/view/run_log.hpp"
#include "rccx/view/server.hpp"

namespace rccx::tools {

namespace {

struct ViewArgs {
  RobotChoice robot{"microbo"};
  bool robot_given = false;  ///< --robot or --robot-file: with --log, it must be the log's own
  std::string cell;
  std::string log;
  std::string address = "127.0.0.1";
  int port = 8080;
  Duration seconds{"0s"};  ///< 0: until Ctrl-C
  double rate_hz = 50.0;
  bool fast = false;  ///< simulated time as fast as the machine goes (else paced to the clock)
};

using Clock = std::chrono::steady_clock;

/// Until Ctrl-C, or `seconds` of wall time when given.
struct Deadline {
  Clock::time_point end;
  bool bounded = false;
  explicit Deadline(double seconds)
      : end(Clock::now() +
            std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds))),
        bounded(seconds > 0.0) {}
  [[nodiscard]] bool over() const {
    return io::stop_count() > 0 || (bounded && Clock::now() >= end);
  }
};

/// Joint goals around the ready pose, within the limits: a demonstration the view can follow.
/// `from` > 0: only joints from there on move (the wrists of robots that share a cell, so that
/// their sweeps keep apart).
std::vector<kin::JointVector> sweep(const kin::RobotModel& m, std::size_t from = 0) {
  std::vector<kin::JointVector> goals;
  const kin::JointVector ready = m.ready();
  const double amplitude[] = {0.35, -0.35, 0.2, -0.2};
  for (double a : amplitude) {
    kin::JointVector q = ready;
    for (std::size_t i = from; i < m.dof(); ++i) {
      const kin::Joint& j = m.joints[i];
      const double span = j.upper - j.lower;
      const double step = j.type == kin::JointType::prismatic ? 0.15 * span : a;
      const double sign = (i % 2 == 0) ? 1.0 : -1.0;
      q[i] = ready[i] + sign * step;
      // A continuous joint has no limits to keep away from (its span is infinite).
      if (std::isfinite(span))
        q[i] = std::clamp(q[i], j.lower + 0.05 * span, j.upper - 0.05 * span);
    }
    goals.push_back(q);
  }
  goals.push_back(ready);
  return goals;
}

view::ServeOptions serve_options(const ViewArgs& a) {
  view::ServeOptions o;
  o.address = a.address;
  o.rate_hz = a.rate_hz;
  return o;
}

int run_replay(const ViewArgs& a) {
  view::RunLog log;
  try {
    log = view::load_run_log(a.log);
  } catch (const view::RunLogError& e) {
    throw BadArgument{fmt::format("--log: {}", e.what())};
  }
  const kin::RobotModel model = robot_of_log(log, a.robot, a.robot_given);
  std::unique_ptr<view::Server> server;
  try {
    server = view::serve_replay(model, std::move(log), static_cast<std::uint16_t>(a.port),
                                serve_options(a));
  } catch (const view::RunLogError& e) {
    throw BadArgument{fmt::format("--log {}: {}", a.log, e.what())};
  }
  const Deadline deadline(a.seconds.seconds());
  while (!deadline.over()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  return kOk;
}

int run_robot(const ViewArgs& a) {
  const kin::RobotModel model = a.robot.model();
  // Simulated time (deterministic, and no overrun on a busy machine), paced to the wall clock.
  rtc::SimulatedRobot robot(model);
  rccl::Manipulator arm(*robot.session);
  // The arm's, so that the page draws the goal of each move (and marks the running one).
  const auto server = view::serve(arm, static_cast<std::uint16_t>(a.port), serve_options(a));
  arm.start();
  arm.set_velocity(0.1, 0.6);
  const auto goals = sweep(model);
  std::vector<rccl::PositionPtr> positions;
  for (std::size_t i = 0; i < goals.size(); ++i) {
    positions.push_back(rccl::Position::joints(fmt::format("P{}", i + 1), goals[i]));
  }
  const Deadline deadline(a.seconds.seconds());
  int code = kOk;
  for (std::size_t i = 0; !deadline.over(); i = (i + 1) % positions.size()) {
    const rccl::Motion m = arm.move(positions[i]);
    rccl::WaitResult w = rccl::WaitResult::timeout;
    const auto period = robot.session->period();
    for (int k = 0; k < 100000 && w == rccl::WaitResult::timeout && !deadline.over(); ++k) {
      w = arm.waitfor(m.end(),
                      a.fast ? std::chrono::nanoseconds(std::chrono::seconds(60)) : period);
      if (w == rccl::WaitResult::timeout && !a.fast) std::this_thread::sleep_for(period);
    }
    if (w == rccl::WaitResult::timeout) break;
    if (w == rccl::WaitResult::session_ended || w == rccl::WaitResult::failed) {
      if (io::stop_count() == 0) {
        io::eprint("rccx view: the robot stopped: {}\n", rccl::to_string(w));
        code = kFailure;
      }
      break;
    }
  }
  (void)arm.stop_control();
  return robot.finish_logs("rccx view") ? code : kFailure;  // RCCX_LOG's log, whole or said
}

int run_cell(const ViewArgs& a) {
  cell::CellModel model;
  try {
    model = cell::load_cell_file(a.cell);
  } catch (const cell::CellFileError& e) {
    throw BadArgument{e.what()};
  }
  cell::Cell c(model);  // simulated time, paced to the wall clock as run_robot's
  c.start();
  const auto server = view::serve(c, static_cast<std::uint16_t>(a.port), serve_options(a));
  std::vector<std::vector<rccl::PositionPtr>> positions;
  for (const cell::CellRobot& r : model.robots) {
    c.robot(r.name).set_velocity(0.05, 0.3);
    std::vector<rccl::PositionPtr> p;
    for (const kin::JointVector& q : sweep(r.model, 3)) {
      p.push_back(rccl::Position::joints(fmt::format("{}_P{}", r.name, p.size() + 1), q));
    }
    positions.push_back(std::move(p));
  }
  const Deadline deadline(a.seconds.seconds());
  for (std::size_t i = 0; !deadline.over(); ++i) {
    std::vector<rccl::EventGate> gates;
    for (std::size_t r = 0; r < model.robots.size(); ++r) {
      const auto& p = positions[r];
      const rccl::Motion m = c.robot(model.robots[r].name).move(p[i % p.size()]);
      gates.push_back(c.event(model.robots[r].name, m.end()));
    }
    rccl::WaitResult w = rccl::WaitResult::timeout;
    const auto tick = c.group().period();
    for (int k = 0; k < 100000 && w == rccl::WaitResult::timeout && !deadline.over(); ++k) {
      w = c.waitfor(gates, a.fast ? std::chrono::nanoseconds(std::chrono::seconds(60)) : tick);
      if (w == rccl::WaitResult::timeout && !a.fast) std::this_thread::sleep_for(tick);
    }
    if (w == rccl::WaitResult::timeout) break;
    if (w == rccl::WaitResult::reached) continue;
    if (io::stop_count() > 0) break;
    io::eprint("rccx view: the cell: {}\n", rccl::to_string(w));
    bool ended = false;
    for (const cell::CellRobot& r : model.robots) {
      const rtc::Termination t = c.session(r.name).termination();
      if (t.ended()) io::eprint("  {}: {}\n", r.name, rtc::describe(t.code));
      ended = ended || t.ended();
      for (const rccl::MotionEvent& f : c.robot(r.name).failures()) {
        io::eprint("  {}: motion {}: {}\n", r.name, f.id, f.message());
      }
    }
    // A collision stop is the cell's check at work: the sweep goes on. Control that ended does not.
    if (ended || w == rccl::WaitResult::session_ended) return kFailure;
  }
  return c.finish_logs("rccx view") ? kOk : kFailure;  // RCCX_LOG's logs, whole or said
}

int run_view(const ViewArgs& a) {
  try {
    if (!a.log.empty()) return run_replay(a);
    if (!a.cell.empty()) return run_cell(a);
    return run_robot(a);
  } catch (const view::ViewError& e) {
    throw BadArgument{e.what()};
  }
}

}  // namespace

void add_view_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* cmd = app.add_subcommand(
      "view",
      "Serve a read-only web page of a simulated robot (or a cell's robots) at work: the arm in "
      "3D from its chain (DH or URDF), the tool path, named frames, live joint, Cartesian and "
      "speed plots. "
      "With --log, replays a recorded run (--log of the control programs, RCCX_LOG) with a time "
      "slider. Listens on 127.0.0.1 only unless --address says otherwise; open the address it "
      "prints. Runs until Ctrl-C (or --seconds).");
  add_robot_options(*cmd, args->robot);
  auto* cell =
      cmd->add_option("--cell", args->cell, "A cell file (cells/*.json): every robot of it")
          ->check(CLI::ExistingFile);
  auto* log = cmd->add_option("--log", args->log,
                              "Replay this run (a CSV written by --log / RCCX_LOG) as the robot "
                              "its header names (--robot only for a log without a header)")
                  ->check(CLI::ExistingFile);
  cell->excludes(log);
  cmd->add_option("--port", args->port, "TCP port (0: any free port)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  cmd->add_option("--address", args->address,
                  "Address to listen on; 0.0.0.0 serves every network (the page stays read-only)")
      ->check(not_empty())
      ->capture_default_str();
  cmd->add_option("--rate", args->rate_hz, "Samples a second sent to the page, 1 .. 200")
      ->check(CLI::Range(1.0, 200.0))
      ->capture_default_str();
  add_duration_option(*cmd, "--seconds", args->seconds, std::chrono::nanoseconds(0),
                      std::chrono::seconds(1'000'000), "Stop after this long (0: at Ctrl-C)");
  cmd->add_flag("--fast", args->fast,
                "Run simulated time as fast as the machine goes (default: at the clock's pace); "
                "with RCCX_LOG=FILE, a quick way to record a run");
  cmd->callback([args, cmd, &exit_code] {
    args->robot_given = robot_given(*cmd);
    guarded(exit_code, [&] { return run_view(*args); });
  });
}

}  // namespace rccx::tools
