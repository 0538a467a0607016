// The MuJoCo plant (src/rccx/hw/mujoco_arm.hpp): one 1 ms servo tick of each shipped robot -
// the servo law, the gravity load from MuJoCo's Jacobians, mj_step1 and mj_step2 (one MuJoCo
// step) - holding its ready pose with a 1 kg tool above a table it does not touch
// (BM_MujocoStep/<robot>); the Microbo's tool pressed on the table, one contact in every step
// (BM_MujocoStepInContact/microbo); and the same tick of the two other plants for comparison
// (BM_PlantStep/<plant>_<robot>: the ideal servo, the simulated PUMA's ten Euler sub-steps).
#include <benchmark/benchmark.h>

#include <memory>

#include "rccx/hw/mjcf.hpp"
#include "rccx/hw/mujoco_arm.hpp"
#include "rccx/hw/simulated_arm.hpp"
#include "rccx/kinematics/kinematics.hpp"

namespace {

using namespace rccx;

/// A 1 kg, 0.1 m tool and a table 2 cm (or, pressed, 2 mm) below its tip at the ready pose.
std::shared_ptr<const hw::Scene> scene_for(const kin::RobotModel& model, double gap_m) {
  auto scene = std::make_shared<hw::Scene>();
  scene->tool_mass_kg = 1.0;
  scene->tool_com_m = {0.0, 0.0, 0.05};
  scene->tool_length_m = 0.1;
  const math::Transform t6 = kin::make_kinematics(model)->forward(model.ready());
  const math::Vec3 tip = t6 * math::Vec3{0.0, 0.0, 0.1};
  scene->boxes.push_back({"table",
                          math::Transform::translation(tip.x, tip.y, tip.z - gap_m - 0.02),
                          {0.1, 0.1, 0.02}});
  return scene;
}

void run_ticks(benchmark::State& state, hw::SimulatedArm& arm) {
  double t = arm.time_s();
  for (auto _ : state) {
    t += hw::kServoPeriod_s;
    arm.advance_to(t);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_MujocoStep(benchmark::State& state, const char* robot) {
  const kin::RobotModel model = kin::builtin_robot(robot);
  hw::SimulatedArmOptions o;
  o.plant = hw::Plant::mujoco;
  o.scene = scene_for(model, 0.02);
  const auto arm = hw::make_simulated_arm(model, o);
  arm->advance_to(0.5);  // settled
  run_ticks(state, *arm);
}
BENCHMARK_CAPTURE(BM_MujocoStep, microbo, "microbo");
BENCHMARK_CAPTURE(BM_MujocoStep, puma260, "puma260");
BENCHMARK_CAPTURE(BM_MujocoStep, puma560, "puma560");
BENCHMARK_CAPTURE(BM_MujocoStep, stanford, "stanford");

void BM_MujocoStepInContact(benchmark::State& state, const char* robot) {
  const kin::RobotModel model = kin::builtin_robot(robot);
  hw::SimulatedArmOptions o;
  o.plant = hw::Plant::mujoco;
  o.scene = scene_for(model, 0.002);
  const auto arm = hw::make_simulated_arm(model, o);
  // The Microbo's vertical slide 5 mm down: the tool stands on the table.
  (void)arm->command(1, {hw::ServoCommand::Kind::move, model.ready()[1] - 0.005, 0.02});
  arm->advance_to(1.0);
  const auto& mujoco = dynamic_cast<const hw::MujocoArm&>(*arm);
  if (mujoco.contact_count() == 0) state.SkipWithError("the tool does not touch the table");
  run_ticks(state, *arm);
  state.counters["contacts"] = mujoco.contact_count();
}
BENCHMARK_CAPTURE(BM_MujocoStepInContact, microbo, "microbo");

void BM_PlantStep(benchmark::State& state, hw::Plant plant, const char* robot) {
  const kin::RobotModel model = kin::builtin_robot(robot);
  hw::SimulatedArmOptions o;
  o.plant = plant;
  const auto arm = hw::make_simulated_arm(model, o);
  arm->advance_to(0.5);
  run_ticks(state, *arm);
}
BENCHMARK_CAPTURE(BM_PlantStep, ideal_puma560, hw::Plant::ideal, "puma560");
BENCHMARK_CAPTURE(BM_PlantStep, servo_puma560, hw::Plant::servo, "puma560");
BENCHMARK_CAPTURE(BM_PlantStep, mujoco_puma560, hw::Plant::mujoco, "puma560");

}  // namespace
