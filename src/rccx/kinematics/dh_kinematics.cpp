#include "rccx/kinematics/dh_kinematics.hpp"

#include <Eigen/Cholesky>
#include <array>
#include <cmath>

namespace rccx::kin {

DhKinematics::DhKinematics(RobotModel model, DhSolverSettings settings)
    : Kinematics(std::move(model)), settings_(settings) {}

math::Transform DhKinematics::forward(const JointVector& q) const noexcept {
  return chain_forward(q);
}

IkResult DhKinematics::inverse(const math::Transform& pose,
                               const IkOptions& options) const noexcept {
  IkResult result;
  const JointVector* const reference = checked_reference(pose, options);
  if (reference == nullptr) return result;  // bad_input
  const std::vector<Joint>& joints = model().joints;
  JointVector q = *reference;
  for (std::size_t i = 0; i < dof(); ++i) q[i] = std::clamp(q[i], joints[i].lower, joints[i].upper);
  const double lambda2 = settings_.damping * settings_.damping;
  result.status = IkStatus::no_convergence;

  for (int iteration = 0; iteration < settings_.max_iterations; ++iteration) {
    std::array<math::Transform, kMaxJoints> frames;
    const math::Transform T = chain_forward(q, frames.data());
    const math::Vec3 dp = pose.p - T.p;
    // Orientation error as a rotation vector, in the base frame: R_target R^T.
    math::Vec3 axis;
    double angle = 0.0;
    (pose.R * T.R.transposed()).to_axis_angle(axis, angle);
    if (dp.norm() <= settings_.position_tolerance_m &&
        angle <= settings_.orientation_tolerance_rad) {
      result.status = IkStatus::ok;
      break;
    }
    const math::Vec3 dw = axis * angle;
    Eigen::Matrix<double, 6, 1> e;
    e << dp.x, dp.y, dp.z, dw.x, dw.y, dw.z;
    const Jacobian J = jacobian_from_frames(frames.data());
    Eigen::Matrix<double, 6, 6> JJt = J * J.transpose();
    JJt.diagonal().array() += lambda2;
    const Eigen::Matrix<double, 6, 1> y = JJt.ldlt().solve(e);
    // All kMaxJoints entries written: GCC cannot see that a runtime-sized vector is, and warns
    // (-Wmaybe-uninitialized) on the vectorised maxCoeff.
    Eigen::Matrix<double, kMaxJoints, 1> dq_all = Eigen::Matrix<double, kMaxJoints, 1>::Zero();
    auto dq = dq_all.head(J.cols());
    dq.noalias() = J.transpose() * y;
    const double largest = dq.cwiseAbs().maxCoeff();
    if (largest > settings_.max_step_rad_or_m) dq *= settings_.max_step_rad_or_m / largest;
    bool moved = false;
    for (std::size_t i = 0; i < dof(); ++i) {
      const double next =
          std::clamp(q[i] + dq(static_cast<Eigen::Index>(i)), joints[i].lower, joints[i].upper);
      moved = moved || next != q[i];
      q[i] = next;
    }
    if (!moved) {  // every step is blocked by a limit or the Jacobian lost rank
      result.status = IkStatus::singular;
      break;
    }
  }
  if (result.status != IkStatus::ok) return result;
  // Whole turns back towards the reference, when a joint's range allows.
  if (!fit_to_limits(q, *reference)) {
    result.status = IkStatus::joint_limits;
    return result;
  }
  result.q = q;
  return result;
}

}  // namespace rccx::kin
