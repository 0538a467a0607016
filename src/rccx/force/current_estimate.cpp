#include "rccx/force/current_estimate.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "rccx/force/tool_load.hpp"

namespace rccx::force {

kin::JointVector friction_effort(const kin::RobotModel& model,
                                 const kin::JointVector& qd) noexcept {
  const std::size_t n = std::min(model.dof(), qd.size());
  kin::JointVector tau(n);
  for (std::size_t j = 0; j < n; ++j) {
    const kin::JointDynamics& d = model.joints[j].dynamics;
    const double v = qd[j];
    const double sign = v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0);
    tau[j] = d.viscous_friction * v + d.coulomb_friction * sign;
  }
  return tau;
}

MotorWrenchEstimate wrench_from_motor_effort(const kin::Kinematics& kinematics,
                                             const kin::JointVector& q,
                                             const kin::JointVector& motor_effort,
                                             const kin::JointVector& gravity_load,
                                             const kin::JointVector& friction,
                                             const MotorWrenchOptions& options) noexcept {
  MotorWrenchEstimate out;
  const std::size_t n = kinematics.dof();
  if (q.size() != n || motor_effort.size() != n || gravity_load.size() != n ||
      (!friction.empty() && friction.size() != n)) {
    return out;
  }
  const auto cols = static_cast<Eigen::Index>(n);
  using JointEffort = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kin::kMaxJoints, 1>;
  JointEffort tau(cols);
  out.external_effort = kin::JointVector(n);
  for (std::size_t j = 0; j < n; ++j) {
    const double f = friction.empty() ? 0.0 : friction[j];
    out.external_effort[j] = gravity_load[j] + f - motor_effort[j];
    tau(static_cast<Eigen::Index>(j)) = out.external_effort[j];
  }

  // J^T W = tau_ext, W = (force on T6's origin, torque about it) in base axes. With
  // J^T = U S V^T: W = V S^+ U^T tau (damped: s / (s^2 + damping^2)).
  using JacobianT = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor, kin::kMaxJoints, 6>;
  const JacobianT Jt = kinematics.jacobian(q).transpose();
  const Eigen::JacobiSVD<JacobianT> svd(Jt, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const auto& s = svd.singularValues();  // min(n, 6) values, largest first
  const Eigen::Index k = s.size();
  out.min_singular_value = k == 6 ? s(k - 1) : 0.0;
  const JointEffort utau = svd.matrixU().transpose() * tau;
  Eigen::Matrix<double, 6, 1> z = Eigen::Matrix<double, 6, 1>::Zero();
  const double cutoff = s(0) * 1e-12;
  const double d2 = options.damping * options.damping;
  for (Eigen::Index i = 0; i < k; ++i) {
    if (d2 > 0.0) {
      z(i) = s(i) / (s(i) * s(i) + d2) * utau(i);
    } else if (s(i) > cutoff) {
      z(i) = utau(i) / s(i);
    }
  }
  const Eigen::Matrix<double, 6, 1> w = svd.matrixV() * z;

  const math::Rot3 R = kinematics.forward(q).R;
  const math::Wrench at_t6{R.transpose_times({w(0), w(1), w(2)}),
                           R.transpose_times({w(3), w(4), w(5)})};
  out.wrench = at_tool(options.t6_from_tool, at_t6);
  out.ok = true;
  return out;
}

}  // namespace rccx::force
