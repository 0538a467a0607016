#include "rccx/rtc/simulated_robot.hpp"

#include "rccx/hw/rcu.hpp"
#include "rccx/io/console.hpp"
#include "rccx/rtc/microbo_driver.hpp"
#include "rccx/rtc/servo_driver.hpp"

namespace rccx::rtc {

namespace {

/// The RCU serves a robot whose file describes one, unless a plant is named.
bool behind_rcu(const kin::RobotModel& model, hw::Plant plant) {
  return hw::has_rcu(model) && plant == hw::Plant::automatic && model.plant == hw::Plant::automatic;
}

}  // namespace

std::chrono::nanoseconds SimulatedRobot::usual_period(const kin::RobotModel& model,
                                                      hw::Plant plant) {
  using std::chrono::milliseconds;
  return behind_rcu(model, plant) ? milliseconds(28) : milliseconds(10);
}

SimulatedHardware make_simulated_hardware(const kin::RobotModel& model, bool calibrated,
                                          bool ideal_servo) {
  hw::SimulatedArmOptions arm_options;
  arm_options.calibrated = calibrated;
  if (ideal_servo) arm_options.plant = hw::Plant::ideal;
  return make_simulated_hardware(model, arm_options);
}

SimulatedHardware make_simulated_hardware(const kin::RobotModel& model,
                                          const hw::SimulatedArmOptions& arm_options) {
  SimulatedHardware h;
  if (behind_rcu(model, arm_options.plant)) {
    h.rcu = std::make_unique<hw::Rcu>(model, arm_options);
    h.bus = std::make_unique<hw::RcuBus>(*h.rcu);
    MicroboDriverOptions o;
    for (std::size_t j = 0; j < model.dof(); ++j) o.work_areas[j] = h.rcu->work_area(j);
    h.driver = std::make_unique<MicroboDriver>(model, *h.bus, *h.rcu, o);
  } else {
    h.arm = hw::make_simulated_arm(model, arm_options);
    h.driver = std::make_unique<ServoDriver>(*h.arm);
  }
  return h;
}

SimulatedRobot::SimulatedRobot(kin::RobotModel m, const SimulatedRobotOptions& options)
    : model(std::move(m)) {
  hw::SimulatedArmOptions arm_options;
  arm_options.calibrated = options.calibrated;
  arm_options.plant = options.plant;
  arm_options.scene = options.scene;
  SimulatedHardware h = make_simulated_hardware(model, arm_options);
  arm = std::move(h.arm);
  rcu = std::move(h.rcu);
  bus = std::move(h.bus);
  driver = std::move(h.driver);
  SessionOptions so;
  so.period = options.period.count() > 0 ? options.period : usual_period(model, options.plant);
  so.clock = options.clock;
  session = std::make_unique<Session>(*driver, so);
  if (!options.log.empty()) {
    log = std::make_unique<SampleLog>(
        options.log, model,
        LogHeader::of(model, {}, session->period(), options.clock == ClockKind::simulated));
    session->set_log(log.get());
  }
}

double SimulatedRobot::period_s() const {
  return std::chrono::duration<double>(session->period()).count();
}

std::string SimulatedRobot::finish() {
  session->close();
  std::string problem = session->log_problem();
  if (log) {
    if (std::string p = log->close(); !p.empty()) problem += (problem.empty() ? "" : "; ") + p;
  }
  return problem;
}

bool SimulatedRobot::finish_logs(std::string_view program) {
  const std::string lost = finish();
  if (lost.empty()) return true;
  io::eprint("{}: the sample log is lost: {}\n", program, lost);
  return false;
}

void SimulatedRobot::push(std::size_t joint, double effort) {
  if (rcu) {
    rcu->set_external_effort(joint, effort);
  } else {
    arm->set_external_effort(joint, effort);
  }
}

}  // namespace rccx::rtc
