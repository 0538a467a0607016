// A simulated robot below the wire with an RTC session on it, assembled in one call: the
// Microbo's emulated RCU behind its bus and register-level driver when the robot file describes
// an RCU (and names no other plant), else a servo arm (MuJoCo when the file or the options say
// "mujoco", the PUMA's PID servos, or the ideal servo for any robot file). What the control
// programs, the examples and the compat layer all start from.
//
//   rtc::SimulatedRobot robot(kin::builtin_robot("puma560"), {.log = "run.csv"});  // 10 ms
//   rccl::Manipulator arm(*robot.session);           // or robot.session->control(f1, f2)
//   arm.start();
//   arm.waitfor(arm.move(arm.park()).end());         // simulated time runs while waiting
//   robot.push(1, 20.0);                             // a hand pushes joint 2, N m
//   const std::string problem = robot.finish();      // closes; run.csv in place, "" if whole
//   return robot.finish_logs("demo") ? 0 : 1;         // or: a lost log said, the exit code 1
#pragma once

#include <chrono>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

#include "rccx/hw/rcu.hpp"
#include "rccx/hw/simulated_arm.hpp"
#include "rccx/rtc/driver.hpp"
#include "rccx/rtc/sample_log.hpp"
#include "rccx/rtc/session.hpp"

namespace rccx::rtc {

struct SimulatedRobotOptions {
  /// Sample period; zero: the robot's usual one (28 ms for the Microbo, whose bus needs about
  /// 10 ms a sample, 10 ms for the others).
  std::chrono::nanoseconds period{0};
  ClockKind clock = ClockKind::simulated;
  bool calibrated = true;     ///< false: encoders relative to power-up
  std::filesystem::path log;  ///< a CSV of every controlled sample; empty: none (or RCCX_LOG)
  /// The plant below the wire; automatic: the robot file's choice (robots/README.md).
  hw::Plant plant = hw::Plant::automatic;
  /// What surrounds a MuJoCo arm (hw/mjcf.hpp); null: nothing.
  std::shared_ptr<const hw::Scene> scene;
};

/// The part below the session: the simulated arm (or the Microbo's RCU and its bus) and the
/// driver over it. What a SimulatedRobot and each robot of a cell are built on.
struct SimulatedHardware {
  std::unique_ptr<hw::SimulatedArm> arm;  ///< servo arms
  std::unique_ptr<hw::Rcu> rcu;           ///< the Microbo
  std::unique_ptr<hw::RcuBus> bus;
  std::unique_ptr<Driver> driver;
};

/// Builds the hardware and driver of `model`: the Microbo's RCU when the robot file describes
/// one and neither the file nor arm_options.plant names a plant, else a servo arm
/// (hw::make_simulated_arm) behind a ServoDriver. Throws std::invalid_argument when the robot
/// cannot be simulated.
SimulatedHardware make_simulated_hardware(const kin::RobotModel& model,
                                          const hw::SimulatedArmOptions& arm_options);
/// The same with the default options but `calibrated`; `ideal_servo` asks for the ideal servo.
SimulatedHardware make_simulated_hardware(const kin::RobotModel& model, bool calibrated = true,
                                          bool ideal_servo = false);

struct SimulatedRobot {
  /// Throws std::invalid_argument when the robot cannot be simulated, SessionError for a bad
  /// period, LogError for a log file that cannot be written.
  SimulatedRobot(kin::RobotModel model, const SimulatedRobotOptions& options = {});

  kin::RobotModel model;
  std::unique_ptr<hw::SimulatedArm> arm;  ///< servo arms
  std::unique_ptr<hw::Rcu> rcu;           ///< the Microbo
  std::unique_ptr<hw::RcuBus> bus;
  std::unique_ptr<Driver> driver;
  std::unique_ptr<SampleLog> log;
  std::unique_ptr<Session> session;

  /// The usual sample period of a robot (28 ms behind the Microbo's RCU, else 10 ms); `plant`
  /// overrides the file's choice, as SimulatedRobotOptions::plant does.
  static std::chrono::nanoseconds usual_period(const kin::RobotModel& model,
                                               hw::Plant plant = hw::Plant::automatic);
  [[nodiscard]] bool simulated() const { return session->clock() == ClockKind::simulated; }
  [[nodiscard]] double period_s() const;
  /// A simulated hand pushes a joint (N m or N); only between samples of simulated time.
  void push(std::size_t joint, double effort);
  /// Closes the session and puts the logs (--log's and RCCX_LOG's) in place: empty when they
  /// are complete, else what went wrong (already said on stderr).
  std::string finish();
  /// finish(), a lost log said on stderr as "<program>: the sample log is lost: <why>" (a full
  /// disk, an I/O error, rows dropped). True when every log is whole (or there is none): what a
  /// program's exit code checks, `return robot.finish_logs("washer") && ok ? 0 : 1;`.
  bool finish_logs(std::string_view program);
};

}  // namespace rccx::rtc
