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
  const double w = kServoBandwidth_rad_per_s;
  for (std::size_t i = 0; i < n_; ++i) {
    const kin::JointDynamics& d = this->model().joints[i].dynamics;
    inertia_[i] = d.inertia;
    viscous_[i] = d.viscous_friction;
    coulomb_[i] = d.coulomb_friction;
    max_effort_[i] = d.max_effort;
    gains_[i] = {3.0 * d.inertia * w * w, d.inertia * w * w * w, 3.0 * d.inertia * w};
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
    const JointState& s = joints_[i];
    const double limit = max_effort_[i];
    double tau = 0.0;
    if (zero_gravity()) {
      integral_[i] = 0.0;
      tau = hold[i] - kZeroGravityDamping_per_s * inertia_[i] * s.qd;
    } else {
      const Gains& g = gains_[i];
      const double e = s.setpoint - s.q;
      const double pd = g.kp * e + g.kd * (s.setpoint_velocity - s.qd) +
                        viscous_[i] * s.setpoint_velocity + hold[i];
      double integral = integral_[i];
      if (std::abs(g.kp * e) < limit) {
        integral = std::clamp(integral + e * dt, -limit / g.ki, limit / g.ki);
      }
      tau = pd + g.ki * integral;
      if (std::abs(tau) < limit) integral_[i] = integral;  // no wind-up while saturated
    }
    // The motor: max_effort at rest, falling to zero at the no-load speed when driving along
    // the motion; braking against the motion keeps the full effort.
    double drive_limit = limit;
    if (tau * s.qd > 0.0) {
      drive_limit *= std::max(0.0, 1.0 - std::abs(s.qd) / (kOverspeedFactor * s.max_velocity));
    }
    tau_[i] = std::clamp(tau, -drive_limit, drive_limit);
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
