// An ideal servo for any robot file (no dynamics needed): each servo tick every joint moves
// toward its setpoint, reaching it when it can, but never faster than kOverspeedFactor x its
// max_velocity and never through its hard stops. There is no inertia, friction or gravity; in
// zero gravity a joint moves at a speed proportional to the external effort on it (admittance
// below) and stays where it is when released. Outside zero gravity external effort does nothing
// (the servo is infinitely stiff).
//
//   hw::IdealArm arm(kin::builtin_robot("puma560"));   // or make_simulated_arm, plant ideal
//   arm.command(0, {hw::ServoCommand::Kind::move, 30_deg, 10_deg});   // to 30 deg at 10 deg/s
//   arm.advance_to(0.5);                               // 0.5 s of 1 ms servo ticks
//   arm.true_position()[0];                            // 5 deg: exactly where the setpoint is
#pragma once

#include "rccx/hw/arm_base.hpp"

namespace rccx::hw {

/// Zero-gravity admittance of a revolute joint: speed per external torque, (rad/s) / (N m).
inline constexpr double kIdealAdmittance_rad_per_s_per_N_m = 0.01;
/// ... and of a prismatic joint: (m/s) / N.
inline constexpr double kIdealAdmittance_m_per_s_per_N = 0.001;

class IdealArm final : public ArmBase {
 public:
  /// Throws std::invalid_argument for an unusable model or initial pose.
  explicit IdealArm(kin::RobotModel model, const SimulatedArmOptions& options = {});

 private:
  void servo_tick(double dt) noexcept override;

  std::array<double, kin::kMaxJoints> admittance_{};
};

}  // namespace rccx::hw
