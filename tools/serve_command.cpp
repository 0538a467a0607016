#include "serve_command.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "rccx/cell/cell_model.hpp"
#include "rccx/io/signals.hpp"
#include "rccx/net/robot_server.hpp"

namespace rccx::tools {

namespace {

struct ServeArgs {
  std::string cell;
  std::vector<std::string> robots;
  long domain = -1;
  std::string interface;
  Duration detection{"20ms"};
  Duration seconds;
  Duration claim_wait{"300ms"};
  std::string secure;
  std::string identity;
  bool no_ros2 = false;
};

int run_serve(const ServeArgs& args) {
  cell::CellModel model;
  try {
    model = cell::load_cell_file(args.cell);
  } catch (const cell::CellFileError& e) {
    throw BadArgument{e.what()};
  }
  std::vector<std::string> known;
  for (const auto& r : model.robots) known.push_back(r.name);
  for (const std::string& name : args.robots) {
    if (model.find_robot(name) != nullptr) continue;
    const std::string near = nearest(name, known);
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    throw BadArgument{
        fmt::format("--robots: cell {} has no robot \"{}\"{}; its robots are: {}", model.name, name,
                    near.empty() ? "" : fmt::format(" (did you mean {}?)", near), list)};
  }
  if (args.secure.empty() != args.identity.empty()) {
    throw BadArgument{"--secure DIR and --identity NAME go together (rccx certs init DIR)"};
  }
  net::ServeOptions o;
  if (args.domain >= 0) o.net.domain = static_cast<std::uint32_t>(args.domain);
  o.net.interface = args.interface;
  o.net.detection = args.detection.value;
  o.net.heartbeat = std::max(args.detection.value / 4, std::chrono::nanoseconds(1'000'000));
  o.net.secure_dir = args.secure;
  o.net.secure_identity = args.identity;
  o.claim_wait = args.claim_wait.value;
  o.ros2_joint_states = !args.no_ros2;
  std::unique_ptr<net::RobotServer> server;
  try {
    server = std::make_unique<net::RobotServer>(model, args.robots, o);
    fmt::print("{}\n", server->banner());
    std::fflush(stdout);
    server->start();
  } catch (const net::ClaimRefused& e) {
    throw BadArgument{e.what()};
  } catch (const std::invalid_argument& e) {
    throw BadArgument{e.what()};
  } catch (const net::NetError& e) {
    io::eprint("error: {}\n", e.what());
    return kFailure;
  }
  fmt::print("rccx serve: serving (stop with Ctrl-C or SIGTERM)\n");
  std::fflush(stdout);
  const auto until = args.seconds.given() ? std::chrono::steady_clock::now() + args.seconds.value
                                          : std::chrono::steady_clock::time_point::max();
  while (io::stop_count() == 0 && std::chrono::steady_clock::now() < until &&
         server->failure().empty()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  server->stop();
  fmt::print("rccx serve: the control clock, {}\n", server->clock_report());
  fmt::print("rccx serve: {}\n", server->request_report());
  if (const std::string why = server->failure(); !why.empty()) {
    io::eprint("rccx serve: stopped on an error: {}\n", why);
    return kFailure;
  }
  fmt::print("rccx serve: stopped; robots halted, claims given back\n");
  return kOk;
}

}  // namespace

void add_serve_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<ServeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "serve",
      "Serves some robots of a cell to programs in other processes over Cyclone DDS "
      "(docs/NETWORK.md): their control runs here in real time; a robot is served by one "
      "process only. Plain DDS unless --secure. Exit code 2 for bad arguments or a robot "
      "another process serves");
  cmd->add_option("--cell", args->cell, "Cell file (JSON, see cells/README.md)")
      ->required()
      ->check(not_empty());
  cmd->add_option("--robots", args->robots, "The robots to serve, by their names in the cell")
      ->required()
      ->delimiter(',');
  cmd->add_option("--domain", args->domain, "DDS domain, 0 .. 232 (default: $RCCX_DOMAIN, else 0)")
      ->check(CLI::Range(0, 232));
  cmd->add_option("--interface", args->interface,
                  "Network interface for DDS (lo, eth0, an address; default: "
                  "$RCCX_DDS_INTERFACE, else Cyclone's choice)")
      ->check(not_empty());
  add_duration_option(*cmd, "--detection", args->detection, std::chrono::milliseconds(2),
                      std::chrono::seconds(10),
                      "A program silent this long is lost: its robots stop smoothly");
  add_duration_option(*cmd, "--seconds", args->seconds, std::chrono::milliseconds(1),
                      std::chrono::hours(24 * 365),
                      "Serve this long, then stop (default: until SIGINT or SIGTERM)");
  add_duration_option(*cmd, "--claim-wait", args->claim_wait, std::chrono::milliseconds(10),
                      std::chrono::seconds(10),
                      "How long to listen for other processes' claims before and after claiming");
  cmd->add_option("--secure", args->secure, "DDS Security: the directory `rccx certs init` made")
      ->check(not_empty());
  cmd->add_option("--identity", args->identity,
                  "This process's participant name in --secure's directory")
      ->check(not_empty());
  cmd->add_flag("--no-ros2", args->no_ros2,
                "Do not publish each robot's joint state for ROS 2 (rt/<robot>/joint_states, "
                "sensor_msgs/JointState); published by default");
  cmd->callback([args, &exit_code] { guarded(exit_code, [&] { return run_serve(*args); }); });
}

}  // namespace rccx::tools
