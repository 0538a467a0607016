// The wrench at the tool from the joint motors' efforts: the VAX/Puma RCCL way of thesis 4.4.2
// ("joint torques ... linearly proportional to the joint motor currents ... the inverse
// Jacobean matrix is used to map the forces from joint space to Cartesian space"). With the
// motors' efforts tau_motor (current times torque constant), the efforts that hold the arm
// against gravity and friction, and the effort contacts add at the joints, tau_ext = J^T F:
//
//   tau_ext = gravity_load(q) + friction(qd) - tau_motor,   F = J^-T tau_ext
//
// (quasi-static: inertia is left out, so the estimate is off while the arm accelerates). F is
// the wrench contacts put on the tool, the sign of force::external_wrench (and of a sensor
// reading); J^-T (tau_motor - gravity_load) - the form the thesis's words suggest - is the
// wrench the arm puts on its surroundings, the same with the other sign.
//
// What limits it (docs/FORCE.md, "Force from motor currents"): a joint standing still holds
// anything up to its Coulomb friction Fc without the motor's effort changing, so at rest each
// joint's effort is uncertain by +-Fc, and F by J^-T of that box; moving, the friction model's
// error. Noexcept and allocation-free: fixed-size Eigen, the kinematics' fixed-capacity Jacobian.
#pragma once

#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/wrench.hpp"

namespace rccx::force {

/// The robot file's friction model (JointDynamics): per joint, viscous x qd + Coulomb x
/// sign(qd), N m or N, for joint speeds `qd` (rad/s or m/s). A joint at rest gets 0: its static
/// friction, anywhere within +-Coulomb, cannot be known from the motor.
[[nodiscard]] kin::JointVector friction_effort(const kin::RobotModel& model,
                                               const kin::JointVector& qd) noexcept;

struct MotorWrenchOptions {
  /// The tool frame in T6 (RCCL's TOOL): the estimate is about its origin in its axes.
  math::Transform t6_from_tool = math::Transform::identity();
  /// Damped least squares: F = (J J^T + damping^2 I)^-1 J tau_ext (damping in the Jacobian's
  /// units, m for its translational rows). 0: the pseudo-inverse (exactly J^-T for a
  /// non-singular 6 x 6 Jacobian; the least-norm wrench for fewer joints, least squares for
  /// more).
  double damping = 0.0;
};

struct MotorWrenchEstimate {
  bool ok = false;  ///< false: the joint vectors' sizes do not match the robot's joints
  /// The wrench contacts put on the tool, about the tool frame's origin in the tool's axes (N,
  /// N m).
  math::Wrench wrench;
  /// tau_ext = gravity_load + friction - motor_effort, N m or N per joint.
  kin::JointVector external_effort;
  /// The Jacobian's smallest singular value (mixed units): near 0, near a singularity, the
  /// estimate blows up (or, damped, loses the directions the arm cannot push in).
  double min_singular_value = 0.0;
};

/// The VAX estimate at joint values `q` (rad, m) from `motor_effort` (N m, N; e.g.
/// hw::SimulatedPuma::motor_effort(), or currents times torque constants), the arm's
/// `gravity_load` at q (the effort that holds it against gravity, hw::GravityModel::load) and
/// the `friction` the motors overcome (friction_effort(), or empty for none).
[[nodiscard]] MotorWrenchEstimate wrench_from_motor_effort(
    const kin::Kinematics& kinematics, const kin::JointVector& q,
    const kin::JointVector& motor_effort, const kin::JointVector& gravity_load,
    const kin::JointVector& friction = {}, const MotorWrenchOptions& options = {}) noexcept;

}  // namespace rccx::force
