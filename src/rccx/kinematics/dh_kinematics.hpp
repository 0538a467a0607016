// Kinematics of any serial chain given by its standard DH table: forward by the product of A
// matrices, the geometric Jacobian, and a damped-least-squares inverse that keeps every joint
// within its limits. Slower than a closed form and it finds one solution (near the seed), but it
// serves every robot a data file can describe.
//
//   const kin::DhKinematics k(kin::builtin_robot("stanford"), {.max_iterations = 200});
//   const math::Transform T = k.forward(q);               // rad / m -> T6 in the base, m
//   const kin::IkResult r = k.inverse(T, {.near = seed});  // the solution the seed leads to
//   if (!r) kin::describe(r.status);                       // "no convergence: ..."
//
// make_kinematics() builds one for a model whose file says "solver": "dh".
#pragma once

#include "rccx/kinematics/kinematics.hpp"

namespace rccx::kin {

struct DhSolverSettings {
  int max_iterations = 100;
  double position_tolerance_m = 1e-12;
  double orientation_tolerance_rad = 1e-12;
  double damping = 1e-4;           ///< lambda of (J Jt + lambda^2 I)
  double max_step_rad_or_m = 0.5;  ///< largest joint change per iteration
  /// Seeds spread over the joint ranges tried after the first seed fails (each up to
  /// max_iterations): an unreachable pose costs (1 + restarts) solves before it is refused.
  int restarts = 16;
};

class DhKinematics final : public Kinematics {
 public:
  explicit DhKinematics(RobotModel model, DhSolverSettings settings = {});

  [[nodiscard]] math::Transform forward(const JointVector& q) const noexcept override;
  /// Iterates from options.near (or the ready pose), then from settings.restarts seeds spread
  /// over the joint ranges; options.configuration is not used.
  [[nodiscard]] IkResult inverse(const math::Transform& pose,
                                 const IkOptions& options = {}) const noexcept override;

 private:
  /// Damped least squares from q (updated in place) towards pose.
  IkStatus iterate(const math::Transform& pose, JointVector& q) const noexcept;
  DhSolverSettings settings_;
};

}  // namespace rccx::kin
