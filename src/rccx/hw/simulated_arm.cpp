#include "rccx/hw/simulated_arm.hpp"

#include "rccx/hw/ideal_arm.hpp"
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
  if (SimulatedPuma::can_simulate(model)) return std::make_unique<SimulatedPuma>(model, options);
  return std::make_unique<IdealArm>(model, options);
}

}  // namespace rccx::hw
