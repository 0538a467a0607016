#include "rccx/hw/simulated_puma.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rccx::hw {

bool SimulatedPuma::can_simulate(const kin::RobotModel& model) noexcept {
  if (model.joints.empty()) return false;
  return std::all_of(model.joints.begin(), model.joints.end(), [](const kin::Joint& j) {
    return j.dynamics.inertia > 0 && j.dynamics.max_effort > 0;
  });
}

namespace {

kin::RobotModel&& checked(kin::RobotModel&& model) {
  if (!SimulatedPuma::can_simulate(model)) {
    throw std::invalid_argument(
        fmt::format("{}: the simulated PUMA needs every joint's dynamics (inertia and max effort)",
                    model.name));
  }
  return std::move(model);
}

}  // namespace

SimulatedPuma::SimulatedPuma(kin::RobotModel model, const SimulatedArmOptions& options)
    : ArmBase(checked(std::move(model)), options), gravity_(this->model()) {
  for (std::size_t i = 0; i < n_; ++i) {
    const kin::JointDynamics& d = this->model().joints[i].dynamics;
    inertia_[i] = d.inertia;
    viscous_[i] = d.viscous_friction;
    coulomb_[i] = d.coulomb_friction;
    max_effort_[i] = d.max_effort;
    gains_[i] = servo_gains(d.inertia, kServoBandwidth_rad_per_s);
  }
}

kin::JointVector SimulatedPuma::motor_effort() const noexcept {
  kin::JointVector tau(n_);
  for (std::size_t i = 0; i < n_; ++i) tau[i] = tau_[i];
  return tau;
}

void SimulatedPuma::servo_tick(double dt) noexcept {
  const kin::JointVector hold = gravity_.load(true_position());
  for (std::size_t i = 0; i < n_; ++i) {
    tau_[i] = servo_effort(joints_[i], gains_[i], inertia_[i], viscous_[i], max_effort_[i], hold[i],
                           dt, integral_[i]);
  }

  const double h = dt / kPlantSubsteps;
  for (int step = 0; step < kPlantSubsteps; ++step) {
    const kin::JointVector load = step == 0 ? hold : gravity_.load(true_position());
    for (std::size_t i = 0; i < n_; ++i) {
      JointState& s = joints_[i];
      // Every effort on the joint but Coulomb friction.
      const double other = tau_[i] - viscous_[i] * s.qd - load[i] + s.external;
      const double fc = coulomb_[i];
      double qdd = 0.0;
      if (s.qd == 0.0) {
        if (std::abs(other) > fc) qdd = (other - std::copysign(fc, other)) / inertia_[i];
      } else {
        qdd = (other - std::copysign(fc, s.qd)) / inertia_[i];
      }
      double qd = s.qd + qdd * h;
      // Friction stops a joint; it does not reverse it. Crossing zero, the joint sticks unless
      // the other efforts can break it away.
      if (s.qd != 0.0 && qd * s.qd < 0.0 && std::abs(other) <= fc) qd = 0.0;
      s.qd = qd;
      s.q += qd * h;
      clamp_to_stops(s);
    }
  }
}

}  // namespace rccx::hw
