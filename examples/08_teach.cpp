// Example 08: teach three positions by hand and save them in the position database.
//
// The teach loop takes the terminal: here a script types what an operator would (move joint 1,
// jog the tool in pendant mode, save), so that the example runs as it is; `--interactive`
// hands the loop your keyboard instead (`?` lists the commands). The positions go to
// taught.db (or the file named as the first argument); example 09 moves through them.
// Run: ./build/release/examples/08_teach [FILE] [--interactive]
#include <fmt/format.h>

#include <iostream>
#include <sstream>
#include <string>

#include "rccx/rccl/teach.hpp"
#include "rccx/rtc/simulated_robot.hpp"

using namespace rccx;

int main(int argc, char** argv) {
  std::string file = "taught.db";
  bool interactive = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--interactive") {
      interactive = true;
    } else if (a == "--help" || a == "-h") {
      fmt::print("usage: 08_teach [FILE] [--interactive]   (FILE defaults to taught.db)\n");
      return 0;
    } else {
      file = a;
    }
  }
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  rccl::PositionDb db(file);
  arm.start();

  // What an operator types: three positions, each reached a different way, each saved.
  std::istringstream script(
      "m 1 20\n"  // joint 1 to 20 deg
      "save A\n"
      "p\ns 30\nz-\nx+\nq\n"  // pendant: 30 mm down, 30 mm along x
      "save B\n"
      "p\ns 15\nrz+\n1-\nq\n"  // pendant: turn the tool 15 deg about z, joint 1 back 15 deg
      "xd\n"
      "save C\n"
      "e\n");
  std::istream& in = interactive ? std::cin : script;
  const rccl::Taught t = rccl::teach_loop(
      arm, {in, std::cout, &db, [&](std::size_t j, double e) { robot.push(j, e); }});
  fmt::print("\n\nin {}:\n", file);
  for (const rccl::StoredTransform& s : db.list("puma560")) {
    fmt::print("  {:<4} ({:8.2f}, {:8.2f}, {:8.2f}) mm\n", s.name, s.value.p.x * 1e3,
               s.value.p.y * 1e3, s.value.p.z * 1e3);
  }
  const bool ok = t.ended_by_exit && !arm.stop_control().ended();
  return robot.finish_logs("08_teach") && ok ? 0 : 1;  // RCCX_LOG's log whole
}
