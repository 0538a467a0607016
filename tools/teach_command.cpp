#include "teach_command.hpp"

#include <cstdlib>
#include <iostream>

#include "rccx/math/units.hpp"
#include "rccx/rccl/teach.hpp"
#include "rccx/rtc/simulated_robot.hpp"

namespace rccx::tools {
namespace {

struct TeachArgs {
  RobotChoice robot{"microbo"};
  std::string db;
};

int run_teach(const TeachArgs& a) {
  const std::string file = database_file(a.db);
  try {
    rccl::PositionDb db(file);
    rtc::SimulatedRobot robot(a.robot.model());
    rccl::Manipulator arm(*robot.session);
    arm.start();
    const rccl::Taught t = rccl::teach_loop(
        arm, {std::cin, std::cout, &db, [&](std::size_t j, double e) { robot.push(j, e); }});
    fmt::print("\ntaught T6: p = ({:.3f}, {:.3f}, {:.3f}) mm\n", t.t6.p.x * 1e3, t.t6.p.y * 1e3,
               t.t6.p.z * 1e3);
    const rtc::Termination end = arm.stop_control();
    return end.ended() ? kFailure : kOk;
  } catch (const rccl::DatabaseError& e) {
    fmt::print(stderr, "rccx teach: {}\n", e.what());
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
      "s V q), xd / xr / xR examine, h / H hand, save NAME (to the database), e exit, ? menu.");
  add_robot_options(*cmd, args->robot);
  cmd->add_option("--db", args->db, "Position database (default $RCCX_DB, else ./rccx.db)");
  cmd->callback([args, &exit_code] { guarded(exit_code, [&] { return run_teach(*args); }); });
}

}  // namespace rccx::tools
