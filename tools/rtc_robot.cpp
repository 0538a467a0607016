#include "rtc_robot.hpp"

#include <fmt/format.h>

#include <string>
#include <string_view>
#include <utility>

namespace rccx::tools {

void add_rtc_options(CLI::App& cmd, RtcArgs& a) {
  add_robot_options(cmd, a.robot);
  add_period_option(cmd, a.period,
                    "Sample period, 0.25ms to 56ms (e.g. 1ms, 28ms); default 28ms for the Microbo "
                    "(its bus needs about 10 ms a sample), 10ms for the others");
  cmd.add_flag("--realtime", a.realtime,
               "Run in real time (SCHED_FIFO when allowed) instead of simulated time, which is "
               "deterministic and runs as fast as the machine allows");
  cmd.add_flag("--uncalibrated", a.uncalibrated,
               "Start the simulated robot uncalibrated (encoders relative to power-up)");
  cmd.add_option("--log", a.log,
                 "Write every controlled sample to this CSV file: t,seg,q1..,qm1..,x,y,z,ax,ay,az "
                 "(s, rad or m; the environment's RCCX_LOG does the same for any program)")
      ->check(not_empty());
}

rtc::SimulatedRobot SimulatedRobot::make(const RtcArgs& a) {
  kin::RobotModel model = a.robot.model();
  rtc::SimulatedRobotOptions o;
  o.calibrated = !a.uncalibrated;
  o.clock = a.realtime ? rtc::ClockKind::real_time : rtc::ClockKind::simulated;
  if (a.period.given()) o.period = a.period.value;
  o.log = a.log;
  const std::string name = model.name;
  const bool log_given = !a.log.empty();
  try {
    return rtc::SimulatedRobot(std::move(model), o);
  } catch (const rtc::SessionError& e) {
    // Name what the user gave: the period, else the robot (file) whose bus needs more.
    const std::string given = a.period.given()        ? std::string("--period")
                              : !a.robot.file.empty() ? "--robot-file " + a.robot.file
                                                      : "--robot " + a.robot.name;
    throw BadArgument{fmt::format("{}: {}", given, e.what())};
  } catch (const rtc::LogError& e) {
    // RCCX_LOG's errors name it; --log's are named here.
    const bool environment = std::string_view(e.what()).starts_with("RCCX_LOG");
    throw BadArgument{environment || !log_given ? std::string(e.what())
                                                : fmt::format("--log {}: {}", a.log, e.what())};
  } catch (const std::invalid_argument& e) {
    throw BadArgument{fmt::format("robot {} cannot be simulated: {}", name, e.what())};
  }
}

int finish_logs(rtc::SimulatedRobot& robot, int code) {
  if (robot.finish_logs("error")) return code;
  return code == kOk ? kFailure : code;
}

void print_positions(const kin::RobotModel& m, const rtc::How& h) {
  fmt::print("t {:8.3f} s ", h.time_s);
  for (std::size_t i = 0; i < h.dof; ++i) {
    const kin::Joint& j = m.joints[i];
    fmt::print(" {} {:.3f} {}", j.name, shown(j, h.joint[i].q), unit(j));
  }
  if (!h.all_calibrated) fmt::print("  (not calibrated)");
  if (!h.power) fmt::print("  (power off)");
  fmt::print("\n");
}

void print_positions_detailed(const kin::RobotModel& m, const rtc::How& h) {
  fmt::print("t = {:.3f} s, sample {}, power {}, hand {}, outputs 0x{:04x}\n", h.time_s, h.sample,
             h.power ? "on" : "off", h.hand_closed ? "closed" : "open", h.outputs);
  for (std::size_t i = 0; i < h.dof; ++i) {
    const kin::Joint& j = m.joints[i];
    const rtc::JointHow& jh = h.joint[i];
    fmt::print("  {} {:<7} {:10.3f} {:<3}  range {:10.3f} {:<3}  speed {:9.3f} {}/s{}{}\n", i + 1,
               j.name, shown(j, jh.q), unit(j), shown(j, jh.range), unit(j), shown(j, jh.velocity),
               unit(j), jh.has(rtc::kCalibrated) ? "" : "  not calibrated",
               jh.has(rtc::kCalibrating) ? "  calibrating" : "");
  }
}

}  // namespace rccx::tools
