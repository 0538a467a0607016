// The Microbo Ecureuil's closed-form kinematics, thesis chapter 3 (sections 3.4-3.6), with the
// errata of the reading guide fixed: theta5 uses a_y S1 + a_x C1, and the theta4 branch is
// taken by the sign of S5 (atan2(a_z, a_y C1 - a_x S1) is theta4 only when S5 > 0).
//
//   const kin::MicroboKinematics k(kin::builtin_robot("microbo"));   // or make_kinematics()
//   const kin::IkResult r = k.inverse(T, {.configuration = k.find_configuration("n")});
//   r.q;                                  // theta1, d2, d3, theta4, theta5, theta6: rad and m
//   k.configuration_name(k.configuration_of(r.q));                     // "n"
//
// Joint variables: {theta1, d2, d3, theta4, theta5, theta6} in rad and m, as in the thesis.
// Configurations: "n" has S5 < 0 (theta5 in (-pi, 0), the side of the usual -pi/2 working pose);
// "f" has S5 > 0 (theta5 in (-2 pi, -pi) once brought within limits), the wrist flipped: theta4
// + pi, theta6 + pi. At theta5 = -pi (joints 4 and 6 aligned) theta4 is kept from `near`.
#pragma once

#include "rccx/kinematics/kinematics.hpp"

namespace rccx::kin {

class MicroboKinematics final : public AnalyticKinematics {
 public:
  /// Throws RobotFileError when the model's DH table is not the thesis's.
  explicit MicroboKinematics(RobotModel model);

  [[nodiscard]] math::Transform forward(const JointVector& q) const noexcept override;
  [[nodiscard]] std::span<const std::string_view> configuration_names() const noexcept override;
  [[nodiscard]] Configuration configuration_of(const JointVector& q) const noexcept override;

 protected:
  IkStatus solve(const math::Transform& pose, Configuration which, const JointVector& reference,
                 IkResult& out) const noexcept override;
};

}  // namespace rccx::kin
