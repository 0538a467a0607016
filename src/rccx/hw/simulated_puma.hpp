// A PUMA below the wire: per joint, a Unimation-style PID servo at 1 kHz driving a plant
//
//   I qdd = tau_motor - B qd - Fc sign(qd) - gravity_load(q) + external
//
// (I, B, Fc from the joint's dynamics; Coulomb friction also holds a joint at rest unless the
// other efforts on it exceed Fc; gravity through the DH chain from the link masses and centres
// of mass). The joints are coupled only through gravity: I is the effective inertia the robot
// file gives (motor reflected), not the configuration-dependent mass matrix.
//
// The servo, each tick: tau = Kp e + Ki int(e) + Kd (v_sp - qd) + B v_sp + gravity_load(q),
// with e = setpoint - q and v_sp the setpoint's velocity (velocity and gravity feedforward),
// saturated at max_effort and, in the direction of motion, on a motor's torque-speed line that
// reaches zero at kOverspeedFactor x max_velocity. The gains place the three closed-loop poles
// at -kServoBandwidth_rad_per_s: Kp = 3 I w^2, Kd = 3 I w, Ki = I w^3. The integrator runs only
// while the P term alone would not saturate (|e| < max_effort / Kp) and the output is not
// saturated, and is clamped to max_effort (anti-windup). The plant is integrated in
// kPlantSubsteps semi-implicit Euler sub-steps per tick, the torque held (zero-order hold).
//
// Zero gravity: tau = gravity_load(q) - kZeroGravityDamping_per_s x I qd (no position gain), so
// a pushed joint moves once the push exceeds its Coulomb friction, and friction stops it when
// released.
#pragma once

#include <array>

#include "rccx/hw/arm_base.hpp"
#include "rccx/hw/gravity.hpp"

namespace rccx::hw {

class SimulatedPuma final : public ArmBase {
 public:
  /// The closed-loop poles of every joint's servo, rad/s.
  static constexpr double kServoBandwidth_rad_per_s = 40.0;
  /// Plant integration sub-steps per servo tick.
  static constexpr int kPlantSubsteps = 10;

  using Gains = ServoGains;

  /// Needs every joint's dynamics (inertia and max_effort > 0); throws std::invalid_argument
  /// otherwise, or for an unusable initial pose.
  explicit SimulatedPuma(kin::RobotModel model, const SimulatedArmOptions& options = {});

  /// True when the model has what this simulator needs.
  [[nodiscard]] static bool can_simulate(const kin::RobotModel& model) noexcept;

  [[nodiscard]] const Gains& gains(std::size_t joint) const noexcept { return gains_[joint]; }
  /// The effort the motors hold q with against gravity (GravityModel::load).
  [[nodiscard]] kin::JointVector gravity_load(const kin::JointVector& q) const noexcept {
    return gravity_.load(q);
  }
  /// The motor efforts of the last servo tick, N m or N.
  [[nodiscard]] kin::JointVector motor_effort() const noexcept;

 private:
  void servo_tick(double dt) noexcept override;
  void on_servo_restart(std::size_t j) noexcept override { integral_[j] = 0.0; }

  GravityModel gravity_;
  std::array<Gains, kin::kMaxJoints> gains_{};
  std::array<double, kin::kMaxJoints> inertia_{}, viscous_{}, coulomb_{}, max_effort_{};
  std::array<double, kin::kMaxJoints> integral_{};  ///< int(e) dt, rad s or m s
  std::array<double, kin::kMaxJoints> tau_{};       ///< motor effort held this tick
};

}  // namespace rccx::hw
