// The effort each joint of a serial chain needs to hold a pose against gravity, from the link
// masses and centres of mass of the robot file (JointDynamics) through its DH table or, for a
// URDF's general chain (Geometry::chain), through each joint's origin, axis and `after`.
//
//   const hw::GravityModel gravity(kin::builtin_robot("puma560"));
//   const kin::JointVector hold = gravity.load(q);   // q rad / m -> N m (N) per joint
#pragma once

#include <array>
#include <cstddef>

#include "rccx/kinematics/dh_step.hpp"
#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/kinematics/robot_model.hpp"

namespace rccx::hw {

/// Standard gravity, m/s^2; it acts along -z of the robot's base frame.
inline constexpr double kGravity_m_per_s2 = 9.81;

class GravityModel {
 public:
  /// Caches the DH constants (or chain steps), masses and centres of mass of the model's joints.
  explicit GravityModel(const kin::RobotModel& model) noexcept;

  /// The gravity load at q: per joint, the torque (N m) or force (N) its motor must apply to
  /// hold q, i.e. dV/dq_j for the potential V(q) = sum_i m_i g z_ci(q). That is
  /// -(z_{j-1} x (p_ci - p_{j-1})) . (m_i g) summed over the links i >= j for a revolute joint,
  /// -z_{j-1} . (m_i g) for a prismatic one, with g = (0, 0, -9.81) m/s^2 (for a chain, z_{j-1}
  /// and p_{j-1} are joint j's axis and a point on it, the frame before it times its origin).
  /// q must hold dof() values.
  [[nodiscard]] kin::JointVector load(const kin::JointVector& q) const noexcept;

  [[nodiscard]] std::size_t dof() const noexcept { return n_; }

 private:
  struct Link {
    double a, ca, sa, d, theta;
    bool prismatic;
    double mass;
    std::array<double, 3> com;
  };
  std::array<Link, kin::kMaxJoints> links_{};
  std::array<kin::PreparedStep, kin::kMaxJoints> steps_{};  ///< a chain's, when general_
  bool general_ = false;
  std::size_t n_ = 0;
};

}  // namespace rccx::hw
