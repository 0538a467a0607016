// Closed-form kinematics of the PUMA 560/260 family in the standard DH convention of Corke's
// model (alpha = 90, 0, -90, 90, -90, 0 deg): shoulder height d1, upper arm a2, lateral offset
// d2 + d3, forearm offset a3 and length d4, flange d6. The derivation is in docs/KINEMATICS.md.
//
// Configurations, named as RCCL did by three letters:
//   arm    l / r: the wrist centre lies behind / in front of joint 1's axis along the arm's
//                 reach direction (x of frame 1),
//   elbow  u / d: the elbow lies above / below the line from the shoulder to the wrist centre,
//   wrist  n / f: sin(theta5) >= 0 / < 0 (flip: theta4 + pi, -theta5, theta6 + pi).
// The zero pose is "rdn" (forearm up, elbow below the shoulder-wrist line); Corke's nominal
// pose {0, 45, 180, 0, 45, 0} deg is "run".
#pragma once

#include "rccx/kinematics/kinematics.hpp"

namespace rccx::kin {

class PumaKinematics final : public AnalyticKinematics {
 public:
  /// Throws RobotFileError when the model's DH table is not of the PUMA's form.
  explicit PumaKinematics(RobotModel model);

  [[nodiscard]] math::Transform forward(const JointVector& q) const noexcept override;
  [[nodiscard]] std::span<const std::string_view> configuration_names() const noexcept override;
  [[nodiscard]] Configuration configuration_of(const JointVector& q) const noexcept override;

 protected:
  IkStatus solve(const math::Transform& pose, Configuration which, const JointVector& reference,
                 IkResult& out) const noexcept override;

 private:
  double d1_, a2_, d3_, a3_, d4_, d6_;
  double L_, cphi_, sphi_;  // forearm length sqrt(a3^2 + d4^2) and its angle phi = atan2(d4, a3)
};

}  // namespace rccx::kin
