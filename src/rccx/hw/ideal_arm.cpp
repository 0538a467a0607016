#include "rccx/hw/ideal_arm.hpp"

#include <algorithm>
#include <cmath>

namespace rccx::hw {

IdealArm::IdealArm(kin::RobotModel model, const SimulatedArmOptions& options)
    : ArmBase(std::move(model), options) {
  for (std::size_t i = 0; i < n_; ++i) {
    admittance_[i] = this->model().joints[i].type == kin::JointType::revolute
                         ? kIdealAdmittance_rad_per_s_per_N_m
                         : kIdealAdmittance_m_per_s_per_N;
  }
}

void IdealArm::servo_tick(double dt) noexcept {
  for (std::size_t i = 0; i < n_; ++i) {
    JointState& s = joints_[i];
    const double cap = kOverspeedFactor * s.max_velocity;
    const double before = s.q;
    if (zero_gravity()) {
      s.q += std::clamp(admittance_[i] * s.external, -cap, cap) * dt;
    } else {
      const double left = s.setpoint - s.q;
      s.q = std::abs(left) <= cap * dt ? s.setpoint : s.q + std::copysign(cap * dt, left);
    }
    clamp_to_stops(s);
    s.qd = (s.q - before) / dt;
  }
}

}  // namespace rccx::hw
