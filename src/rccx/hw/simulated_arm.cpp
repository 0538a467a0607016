#include "rccx/hw/simulated_arm.hpp"

#include "rccx/hw/ideal_arm.hpp"
#include "rccx/hw/mujoco_arm.hpp"
#include "rccx/hw/simulated_puma.hpp"

namespace rccx::hw {

std::string_view to_string(Fault f) noexcept {
  switch (f) {
    case Fault::joint_not_answering:
      return "joint_not_answering";
    case Fault::encoder_error:
      return "encoder_error";
    case Fault::power_loss:
      return "power_loss";
  }
  return "?";
}

std::unique_ptr<SimulatedArm> make_simulated_arm(const kin::RobotModel& model,
                                                 const SimulatedArmOptions& options) {
  const Plant plant = options.plant != Plant::automatic ? options.plant : model.plant;
  switch (plant) {
    case Plant::ideal:
      return std::make_unique<IdealArm>(model, options);
    case Plant::servo:
      return std::make_unique<SimulatedPuma>(model, options);
    case Plant::mujoco:
      return std::make_unique<MujocoArm>(model, options);
    case Plant::automatic:
      break;
  }
  if (SimulatedPuma::can_simulate(model)) return std::make_unique<SimulatedPuma>(model, options);
  return std::make_unique<IdealArm>(model, options);
}

}  // namespace rccx::hw
