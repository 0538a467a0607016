// What the RTC control programs (rtc_commands.cpp: calib, limp, marsh, report; jointtest.cpp)
// share: their options, the simulated robot they run on, and how they print joints (deg, mm).
//
//   RtcArgs args;                      // filled by CLI11 through add_rtc_options(cmd, args)
//   SimulatedRobot r(args);            // BadArgument for a bad period or log
//   r.session->control(f1, f2);
//   print_positions(r.model, r.session->how());
#pragma once

#include <string>

#include "cli_common.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rtc/simulated_robot.hpp"

namespace rccx::tools {

/// What every control program takes.
struct RtcArgs {
  RobotChoice robot{"microbo"};
  Duration period;  ///< not given: the robot's usual period
  bool realtime = false;
  bool uncalibrated = false;
  std::string log;  ///< CSV of every controlled sample
};

void add_rtc_options(CLI::App& cmd, RtcArgs& a);

/// The simulated robot the options ask for, its errors turned into bad arguments.
struct SimulatedRobot : rtc::SimulatedRobot {
  explicit SimulatedRobot(const RtcArgs& a) : rtc::SimulatedRobot(make(a)) {}

 private:
  static rtc::SimulatedRobot make(const RtcArgs& a);
};

inline bool revolute(const kin::Joint& j) {
  return j.type == kin::JointType::revolute;
}
/// SI to what people read: degrees, millimetres.
inline double shown(const kin::Joint& j, double si) {
  return revolute(j) ? math::rad_to_deg(si) : si * 1e3;
}
inline double from_shown(const kin::Joint& j, double value) {
  return revolute(j) ? math::deg_to_rad(value) : value * 1e-3;
}
inline const char* unit(const kin::Joint& j) {
  return revolute(j) ? "deg" : "mm";
}

/// Closes `robot`'s session and puts its logs (--log's, RCCX_LOG's) in place. A log that is lost
/// (a write that failed: a full disk, an I/O error; rows dropped) is said on stderr and turns
/// `code` kOk into kFailure: the run did not leave what was asked of it. Returns the code.
int finish_logs(rtc::SimulatedRobot& robot, int code);

/// One line: the time and every joint's position.
void print_positions(const kin::RobotModel& m, const rtc::How& h);
/// A table: power, hand, outputs, and every joint's position, range, speed and calibration.
void print_positions_detailed(const kin::RobotModel& m, const rtc::How& h);

}  // namespace rccx::tools
