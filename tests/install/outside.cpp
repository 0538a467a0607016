// A program of another project: one motion of a simulated PUMA 560 through the installed rccx.
#include <cmath>
#include <cstdio>

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
  return error_rad < 1e-3 ? 0 : 1;
}
