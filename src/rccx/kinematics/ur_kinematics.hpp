// Closed-form kinematics of the Universal Robots family (UR3e, UR5e, UR10e ...): three parallel
// axes (joints 2, 3, 4), in the standard DH convention UR publishes (alpha = 90, 0, 0, 90, -90,
// 0 deg; shoulder height d1, upper arm a2, forearm a3, wrist offsets d4, d5, d6). Every pose in
// reach has up to 8 solutions; the derivation is in docs/KINEMATICS.md ("The UR family").
//
// Configurations, three letters as RCCL names the PUMA's:
//   shoulder l / r: theta1 = psi + pi/2 + acos(d4 / r) / - acos(d4 / r), with psi and r the
//                   direction and distance of the wrist point (frame 5's origin) from joint 1's
//                   axis,
//   elbow    u / d: sin(theta3) >= 0 / < 0,
//   wrist    n / f: sin(theta5) >= 0 / < 0.
// Served for a URDF arm of this structure too (make_kinematics recognises it on its DH table,
// kin::dh_equivalent).
#pragma once

#include "rccx/kinematics/kinematics.hpp"

namespace rccx::kin {

class UrKinematics final : public AnalyticKinematics {
 public:
  /// Throws RobotFileError when the model's DH table is not of the UR form.
  explicit UrKinematics(RobotModel model);

  [[nodiscard]] math::Transform forward(const JointVector& q) const noexcept override;
  [[nodiscard]] std::span<const std::string_view> configuration_names() const noexcept override;
  [[nodiscard]] Configuration configuration_of(const JointVector& q) const noexcept override;

 protected:
  IkStatus solve(const math::Transform& pose, Configuration which, const JointVector& reference,
                 IkResult& out) const noexcept override;

 private:
  double d1_, a2_, a3_, d4_, d5_, d6_;
};

/// A closed form written for a DH table, serving a general chain (a URDF's) whose DH
/// equivalent has that table: forward(q) = base * inner.forward(q) * tool, and the inverse of
/// base^-1 * pose * tool^-1. Limits, names and the Jacobian are the chain model's.
class PlacedKinematics final : public Kinematics {
 public:
  PlacedKinematics(RobotModel chain, std::unique_ptr<Kinematics> inner, const math::Transform& base,
                   const math::Transform& tool);

  [[nodiscard]] math::Transform forward(const JointVector& q) const noexcept override;
  [[nodiscard]] IkResult inverse(const math::Transform& pose,
                                 const IkOptions& options = {}) const noexcept override;
  [[nodiscard]] IkSolutions inverse_all(const math::Transform& pose,
                                        const IkOptions& options = {}) const noexcept override;
  [[nodiscard]] std::span<const std::string_view> configuration_names() const noexcept override {
    return inner_->configuration_names();
  }
  [[nodiscard]] Configuration configuration_of(const JointVector& q) const noexcept override {
    return inner_->configuration_of(q);
  }
  /// The closed form it wraps.
  [[nodiscard]] const Kinematics& inner() const noexcept { return *inner_; }

 private:
  [[nodiscard]] math::Transform to_inner(const math::Transform& pose) const noexcept {
    return placed_ ? base_.inverse_times(pose) * tool_inverse_ : pose;
  }
  std::unique_ptr<Kinematics> inner_;
  math::Transform base_, tool_, tool_inverse_;
  bool placed_;  ///< base or tool is not the identity
};

}  // namespace rccx::kin
