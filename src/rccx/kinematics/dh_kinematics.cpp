#include "rccx/kinematics/dh_kinematics.hpp"

#include <Eigen/Cholesky>
#include <array>
#include <cmath>
#include <cstdint>

#include "rccx/math/units.hpp"

namespace rccx::kin {

DhKinematics::DhKinematics(RobotModel model, DhSolverSettings settings)
    : Kinematics(std::move(model)), settings_(settings) {}

math::Transform DhKinematics::forward(const JointVector& q) const noexcept {
  return chain_forward(q);
}

IkStatus DhKinematics::iterate(const math::Transform& pose, JointVector& q) const noexcept {
  const std::vector<Joint>& joints = model().joints;
  const double lambda2 = settings_.damping * settings_.damping;
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
      return IkStatus::ok;
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
    if (!moved) return IkStatus::singular;  // every step blocked by a limit, or J lost rank
  }
  return IkStatus::no_convergence;
}

IkResult DhKinematics::inverse(const math::Transform& pose,
                               const IkOptions& options) const noexcept {
  IkResult result;
  const JointVector* const reference = checked_reference(pose, options);
  if (reference == nullptr) return result;  // bad_input
  const std::vector<Joint>& joints = model().joints;
  JointVector q = *reference;
  for (std::size_t i = 0; i < dof(); ++i) q[i] = std::clamp(q[i], joints[i].lower, joints[i].upper);
  result.status = iterate(pose, q);
  // A seed in the wrong basin (a limit in the way, a singular start) is the usual failure:
  // start again from seeds spread over the joint ranges, the same ones every call.
  std::uint64_t state = 0x9e3779b97f4a7c15ULL;
  for (int restart = 0; restart < settings_.restarts && result.status != IkStatus::ok; ++restart) {
    for (std::size_t i = 0; i < dof(); ++i) {
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;  // Knuth's MMIX LCG
      const double u = static_cast<double>(state >> 11) * 0x1.0p-53;
      const double lo = std::isfinite(joints[i].lower) ? joints[i].lower : -math::kPi;
      const double hi = std::isfinite(joints[i].upper) ? joints[i].upper : math::kPi;
      q[i] = lo + u * (hi - lo);
    }
    const IkStatus again = iterate(pose, q);
    // Keep the first attempt's reason unless a restart gets further.
    if (again == IkStatus::ok) result.status = again;
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
