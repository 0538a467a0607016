// A program of another project (README.md's app.cpp, built by tests/install_test.sh with no
// CMAKE_CXX_STANDARD): one motion of a simulated PUMA 560 through the installed rccx, the
// tool-load compensation, and where the installed package's data is.
#include <cmath>
#include <cstdio>

#include "rccx/force/tool_load.hpp"
#include "rccx/io/data_files.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/simulated_robot.hpp"

int main() {
  using namespace rccx;
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  kin::JointVector goal = arm.kinematics().model().ready();
  goal[0] += 0.2;  // rad
  const rccl::Motion m = arm.move(rccl::Position::joints("GOAL", goal));
  if (arm.waitfor(m.end()) != rccl::WaitResult::reached) return 1;
  robot.session->wait_for(std::chrono::milliseconds(500));
  const double error_rad = std::abs(robot.session->how().q()[0] - goal[0]);
  std::printf("outside: joint 1 within %.2g rad of its goal\n", error_rad);
  // rccx::force: a 2 kg tool hanging from T6 reads its weight, which compensation removes.
  const math::Rot3 down = math::Rot3::rot_x(3.141592653589793);
  const force::ToolLoad tool{{}, 2.0, {0.0, 0.0, 0.1}};
  const math::Wrench weight{{0.0, 0.0, 2.0 * 9.81}, {0.0, 0.0, 0.0}};
  const double left_N = force::external_wrench(tool, down, weight).force_N.norm();
  std::printf("outside: a hanging tool compensated to %.2g N\n", left_N);
  // The installed cell, found from the headers' install (not the source tree's).
  std::printf("outside: the cell is %s\n", io::find_data_file("cells/cvarl.json").c_str());
  return error_rad < 1e-3 && left_N < 1e-9 ? 0 : 1;
}
