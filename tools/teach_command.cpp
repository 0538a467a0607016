#include "teach_command.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>

#include "rccx/io/console.hpp"
#include "rccx/io/input.hpp"
#include "rccx/io/signals.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/teach.hpp"
#include "rccx/rtc/simulated_robot.hpp"
#include "rtc_robot.hpp"

namespace rccx::tools {
namespace {

struct TeachArgs {
  RobotChoice robot{"microbo"};
  std::string db;
};

int run_teach(const TeachArgs& a) {
  const std::string file = database_file(a.db);
  const io::ScopedStopHandlers handlers;
  // The robot first: a bad --robot or --robot-file must not create the database (exit 2 changes
  // nothing).
  kin::RobotModel model = a.robot.model();
  // A database path that names a directory or a device is bad input, as for `rccx db`.
  std::error_code ec;
  if (const auto type = std::filesystem::status(file, ec).type();
      !ec && type != std::filesystem::file_type::not_found &&
      type != std::filesystem::file_type::regular) {
    throw BadArgument{fmt::format(
        "position database {} is {}; name a database file with --db or RCCX_DB", io::quoted(file),
        type == std::filesystem::file_type::directory ? "a directory" : "not a regular file")};
  }
  try {
    // An existing file is opened now (a foreign or damaged one is said before the session); a
    // missing one is created at the first `save`, so a session that saves nothing leaves none.
    std::unique_ptr<rccl::PositionDb> db;
    if (std::filesystem::exists(file, ec)) {
      db = std::make_unique<rccl::PositionDb>(file, rccl::PositionDb::Open::existing);
    }
    const auto open_db = [&]() -> rccl::PositionDb& {
      if (!db) db = std::make_unique<rccl::PositionDb>(file, rccl::PositionDb::Open::create);
      return *db;
    };
    rtc::SimulatedRobot robot(std::move(model));
    rccl::Manipulator arm(*robot.session);
    arm.start();
    // Ctrl-C ends a wait for a line; also one during the start-up (main() installed the
    // handlers at start).
    io::StopAwareInput input(STDIN_FILENO, 0);
    std::istream in(&input);
    const rccl::Taught t = rccl::teach_loop(
        arm,
        {in, std::cout, db.get(), [&](std::size_t j, double e) { robot.push(j, e); }, open_db});
    fmt::print("\ntaught T6: p = ({:.3f}, {:.3f}, {:.3f}) mm\n", t.t6.p.x * 1e3, t.t6.p.y * 1e3,
               t.t6.p.z * 1e3);
    std::fflush(stdout);
    const rtc::Termination end = t.termination.ended() ? t.termination : arm.stop_control();
    if (t.stopped_by_signal || input.stopped()) {
      io::eprint("rccx teach: stopped by a signal; control released\n");
      return io::stop_exit_code();
    }
    if (end.ended()) {
      io::eprint("rccx teach: control ended: {}: {}\n", rtc::to_string(end.code),
                 rtc::describe(end.code));
      return kFailure;
    }
    if (input.error() != 0) {
      io::eprint("rccx teach: reading stdin failed: {}\n", std::strerror(input.error()));
      return kFailure;
    }
    if (t.failed_commands > 0) {
      io::eprint("rccx teach: {} command{} failed\n", t.failed_commands,
                 t.failed_commands == 1 ? "" : "s");
      return kFailure;
    }
    return finish_logs(robot, kOk);  // RCCX_LOG's log: a lost one makes the run a failure
  } catch (const rccl::DatabaseError& e) {
    io::eprint("rccx teach: {}\n", e.what());
    return kFailure;
  } catch (const std::invalid_argument& e) {
    throw BadArgument{e.what()};
  }
}

}  // namespace

void add_teach_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<TeachArgs>();
  CLI::App* cmd = app.add_subcommand(
      "teach",
      "Teach positions by hand on a simulated robot (thesis 4.5.4.4), one command a line on "
      "stdin: Z / z zero gravity, push J E S, m J V (deg or mm), p pendant mode (J+ J- x+ rx- "
      "s V q), xd / xr / xR examine, h / H hand, save NAME (to the database, created at the "
      "first save), e exit, ? menu.");
  add_robot_options(*cmd, args->robot);
  cmd->add_option("--db", args->db, "Position database (default $RCCX_DB, else ./rccx.db)")
      ->check(not_empty());
  cmd->callback([args, &exit_code] { guarded(exit_code, [&] { return run_teach(*args); }); });
}

}  // namespace rccx::tools
