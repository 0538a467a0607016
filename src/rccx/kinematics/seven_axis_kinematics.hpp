// Closed-form kinematics of a 7-axis arm given its seventh joint, for the structure of the
// Franka Panda and the KUKA iiwa: the axes of joints 1, 2, 3 meet at one point (the shoulder S)
// and those of joints 5 and 6 at another (the wrist W). With q7 held, the pose gives link 6's
// frame and so W; |SW| depends on q4 alone (two roots: the elbow); two rotations about axes 5
// and 6 turn the shoulder-to-wrist vector from link 6's frame into link 4's (two solutions: the
// wrist); link 3's orientation follows, and the shoulder's three angles from it (two solutions:
// the shoulder). Up to 8 solutions for each q7; derivation in docs/KINEMATICS.md ("Seven axes:
// the Panda").
//
// The redundancy: IkOptions::redundant holds q7 where a caller asks; otherwise the solver keeps
// the q7 of `near` and moves it only as far as it must to find a solution within limits (outward
// in kRedundantStep_rad steps, then by bisection to the nearest q7 that solves), so that along a
// Cartesian line, where the generator passes the last sample as `near`, q7 stays put and, when
// it must move, moves continuously.
//
// Configurations, three letters as RCCL names the PUMA's (index 4 shoulder + 2 elbow + wrist):
//   shoulder l / r: the shoulder's subproblem takes its + / - root (on the Panda: q2 <= 0 / > 0),
//   elbow    u / d: q4 = phi + beta / phi - beta, phi and beta of the |SW| equation,
//   wrist    n / f: the wrist's subproblem takes its + / - root (on the Panda: q6 in [0, pi] or
//                   not, up to the sign conventions of the file's axes).
// make_kinematics serves a URDF chain of this structure by it, after checking it against the
// chain.
#pragma once

#include "rccx/kinematics/kinematics.hpp"

namespace rccx::kin {

class SevenAxisKinematics final : public Kinematics {
 public:
  /// First step (rad) of the search over q7 when the q7 asked for gives no solution.
  static constexpr double kRedundantStep_rad = 0.05;

  /// Throws RobotFileError when the model is not a general chain of 7 revolute joints whose
  /// axes 1-3 meet at one point and 5-6 at another.
  explicit SevenAxisKinematics(RobotModel model);

  [[nodiscard]] math::Transform forward(const JointVector& q) const noexcept override;
  /// The solution closest to `near` (or of the configuration asked), with q7 as IkOptions
  /// says; IkResult::q[6] tells which q7 was taken.
  [[nodiscard]] IkResult inverse(const math::Transform& pose,
                                 const IkOptions& options = {}) const noexcept override;
  /// Every configuration's solution within limits at the q7 inverse() takes.
  [[nodiscard]] IkSolutions inverse_all(const math::Transform& pose,
                                        const IkOptions& options = {}) const noexcept override;
  [[nodiscard]] std::span<const std::string_view> configuration_names() const noexcept override;
  [[nodiscard]] Configuration configuration_of(const JointVector& q) const noexcept override;

  /// The shoulder and wrist points, in the base frame and in the link frames they are fixed in
  /// (for tests and docs).
  [[nodiscard]] const math::Vec3& shoulder() const noexcept { return shoulder_; }

 private:
  /// The raw solutions (angles in (-pi, pi]) with joint 7 at q7, of every configuration or of
  /// `only`; each with its configuration and singularity. Returns how many; `why` says
  /// out_of_reach when there is none.
  std::size_t solve_at(const math::Transform& pose, double q7, std::optional<Configuration> only,
                       const JointVector& reference,
                       std::array<IkResult, kMaxIkSolutions>& out) const noexcept;
  /// The solution within limits closest to `reference` with joint 7 at q7; status
  /// out_of_reach or joint_limits when there is none.
  IkResult best_at(const math::Transform& pose, double q7, std::optional<Configuration> only,
                   const JointVector& reference) const noexcept;

  // Constants of the chain at q = 0 (see the .cpp for their use).
  math::Vec3 shoulder_;     ///< S in the base frame, m
  math::Vec3 wrist_in_6_;   ///< W in link 6's frame, m
  math::Vec3 wrist_in_4_;   ///< W in link 4's frame, m
  math::Vec3 elbow_e_;      ///< origin4⁻¹ S expressed in origin4's rotated frame, negated, m
  double elbow_a_ = 0.0;    ///< |SW|^2 = a + r cos(q4 - phi), m^2
  double elbow_r_ = 0.0;    ///< m^2
  double elbow_phi_ = 0.0;  ///< rad
  double elbow_cos_phi_ = 1.0, elbow_sin_phi_ = 0.0;
  math::Vec3 k1_, k2_, k3_;  ///< shoulder axes, all in link 0's frame after origin1 (see .cpp)
  math::Rot3 origin1_R_;     ///< origin1's rotation
  math::Rot3 shoulder_C_;    ///< origin2 origin3 rotations
  math::Vec3 k3_perp_;       ///< a unit vector normal to k3_
  math::Vec3 k4_;            ///< axis 4 in its own frame
  math::Rot3 origin5_R_;     ///< origin5's rotation
  math::Rot3 origin6_R_;     ///< origin6's rotation
  math::Vec3 k5_, k6_;       ///< axis 5 in origin5's frame, axis 6 in link 5's frame
};

}  // namespace rccx::kin
