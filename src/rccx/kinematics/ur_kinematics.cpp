#include "rccx/kinematics/ur_kinematics.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "rccx/kinematics/dh_step.hpp"
#include "rccx/math/batch_trig.hpp"
#include "rccx/math/units.hpp"

namespace rccx::kin {

namespace {

// Index = 4 shoulder + 2 elbow + wrist, with shoulder 0 = l, elbow 0 = u, wrist 0 = n.
constexpr std::array<std::string_view, 8> kConfigurationNames{"lun", "luf", "ldn", "ldf",
                                                              "run", "ruf", "rdn", "rdf"};
constexpr double kSingular = 1e-10;
constexpr std::array<double, 6> kAlphaDeg{90, 0, 0, 90, -90, 0};

/// angle in [-pi, pi], for the sums of a few atan2 the solver makes (within +-4 pi).
double wrap(double angle) {
  constexpr double kTurn = 2.0 * math::kPi;
  while (angle > math::kPi) angle -= kTurn;
  while (angle < -math::kPi) angle += kTurn;
  return angle;
}

}  // namespace

UrKinematics::UrKinematics(RobotModel model) : AnalyticKinematics(std::move(model)) {
  const RobotModel& m = this->model();
  auto fail = [&](const std::string& what) { throw detail::not_of_form(m, "UR", what); };
  detail::require_dh_form(m, "UR", kAlphaDeg, {false, true, true, false, false, false});
  d1_ = m.joints[0].dh.d_m;
  a2_ = m.joints[1].dh.a_m;
  a3_ = m.joints[2].dh.a_m;
  // z1, z2, z3 are parallel: offsets along them add up to the wrist's d4.
  d4_ = m.joints[1].dh.d_m + m.joints[2].dh.d_m + m.joints[3].dh.d_m;
  d5_ = m.joints[4].dh.d_m;
  d6_ = m.joints[5].dh.d_m;
  if (a2_ == 0.0 || a3_ == 0.0) fail("the upper arm (a2) and forearm (a3) need length");
  if (d6_ == 0.0) fail("d6 is 0 (the wrist angle theta5 would not follow from the position)");
}

math::Transform UrKinematics::forward(const JointVector& q) const noexcept {
  return chain_forward(q);
}

std::span<const std::string_view> UrKinematics::configuration_names() const noexcept {
  return kConfigurationNames;
}

Configuration UrKinematics::configuration_of(const JointVector& q) const noexcept {
  const math::Transform T = chain_forward(q);
  const math::Vec3 w = T.p - T.R.a * d6_;
  const double psi = std::atan2(w.y, w.x);
  const bool right = wrap(q[0] - psi - math::kPi / 2) < 0.0;
  const bool down = std::sin(q[2]) < 0.0;
  const bool flip = std::sin(q[4]) < 0.0;
  return {static_cast<std::uint8_t>((right ? 4 : 0) + (down ? 2 : 0) + (flip ? 1 : 0))};
}

IkStatus UrKinematics::solve(const math::Transform& pose, Configuration which,
                             const JointVector& reference, IkResult& out) const noexcept {
  const bool right = (which.index & 4) != 0;
  const bool down = (which.index & 2) != 0;
  const bool flip = (which.index & 1) != 0;
  out.q = JointVector(6);
  out.configuration = which;
  out.singularity = Singularity::none;
  const math::Vec3& n = pose.R.n;
  const math::Vec3& o = pose.R.o;
  const math::Vec3& a = pose.R.a;
  const math::Vec3& p = pose.p;
  // Every sine and cosine comes from the pose without an angle; the angles of the answer are
  // seven atan2 taken in one batch at the end.
  double y[8] = {}, x[8] = {};

  // Joint 1: the wrist point (frame 5's origin) lies d4 off the arm's plane, along z1:
  // theta1 = psi +- phi + pi/2, psi the direction of the wrist point, cos(phi) = d4 / r.
  const math::Vec3 w = p - a * d6_;
  const double r = std::sqrt(w.x * w.x + w.y * w.y);
  if (r < std::abs(d4_) - 1e-12 || r < kSingular) return IkStatus::out_of_reach;
  const double cpsi = w.x / r, spsi = w.y / r;
  const double cphi = std::clamp(d4_ / r, -1.0, 1.0);
  const double sphi = (right ? -1.0 : 1.0) * std::sqrt(1.0 - cphi * cphi);
  const double s1 = cpsi * cphi - spsi * sphi;     // cos(psi + phi)
  const double c1 = -(spsi * cphi + cpsi * sphi);  // -sin(psi + phi)
  y[0] = s1;
  x[0] = c1;

  // Joint 5: the flange's approach along z1 is cos(theta5).
  const double c5 = (p.x * s1 - p.y * c1 - d4_) / d6_;
  if (std::abs(c5) > 1.0 + 1e-12) return IkStatus::out_of_reach;
  const double cc5 = std::clamp(c5, -1.0, 1.0);
  const double s5 = (flip ? -1.0 : 1.0) * std::sqrt(1.0 - cc5 * cc5);
  y[4] = s5;
  x[4] = cc5;

  // Joint 6: z1 seen from the flange is (s5 c6, -s5 s6, c5).
  double s6, c6;
  if (std::abs(s5) < kSingular) {  // z5 along z1: theta6 and the arm's sum are one rotation
    ::sincos(reference[5], &s6, &c6);
    out.singularity = Singularity::wrist;
  } else {
    const double y6 = -(o.x * s1 - o.y * c1) / s5, x6 = (n.x * s1 - n.y * c1) / s5;
    const double h = std::sqrt(x6 * x6 + y6 * y6);
    s6 = y6 / h;
    c6 = x6 / h;
  }
  y[5] = s6;
  x[5] = c6;

  // Joints 2, 3, 4: a planar arm in frame 1, from frame 1 to frame 4:
  // T14 = A1^-1 pose A6^-1 A5^-1 (alpha1 = 90, alpha5 = -90, alpha6 = 0 deg).
  math::Transform A1, A5, A6;
  apply_dh_link(A1, c1, s1, 0.0, 1.0, 0.0, d1_);
  apply_dh_link(A5, cc5, s5, 0.0, -1.0, 0.0, d5_);
  apply_dh_link(A6, c6, s6, 1.0, 0.0, 0.0, d6_);
  const math::Transform T14 = A1.inverse_times(pose) * (A5 * A6).inverse();
  const double px = T14.p.x, py = T14.p.y;
  const double c3 = (px * px + py * py - a2_ * a2_ - a3_ * a3_) / (2.0 * a2_ * a3_);
  if (std::abs(c3) > 1.0 + 1e-12) return IkStatus::out_of_reach;
  const double cc3 = std::clamp(c3, -1.0, 1.0);
  const double s3 = (down ? -1.0 : 1.0) * std::sqrt(1.0 - cc3 * cc3);
  y[2] = s3;
  x[2] = cc3;
  y[1] = py;  // theta2 = atan2(py, px) - atan2(a3 s3, a2 + a3 c3)
  x[1] = px;
  y[6] = a3_ * s3;
  x[6] = a2_ + a3_ * cc3;
  y[3] = T14.R.n.y;  // theta2 + theta3 + theta4
  x[3] = T14.R.n.x;
  double angle[8];
  math::atan2_8(y, x, angle);
  const double t2 = angle[1] - angle[6];
  const double t[6] = {angle[0], t2,
                       angle[2], angle[3] - t2 - angle[2],
                       angle[4], out.singularity == Singularity::wrist ? reference[5] : angle[5]};
  for (std::size_t i = 0; i < 6; ++i) out.q[i] = wrap(t[i]);
  return IkStatus::ok;
}

PlacedKinematics::PlacedKinematics(RobotModel chain, std::unique_ptr<Kinematics> inner,
                                   const math::Transform& base, const math::Transform& tool)
    : Kinematics(std::move(chain)),
      inner_(std::move(inner)),
      base_(base),
      tool_(tool),
      tool_inverse_(tool.inverse()),
      placed_(base.rows() != math::Transform{}.rows() || tool.rows() != math::Transform{}.rows()) {}

math::Transform PlacedKinematics::forward(const JointVector& q) const noexcept {
  return placed_ ? base_ * inner_->forward(q) * tool_ : inner_->forward(q);
}

IkResult PlacedKinematics::inverse(const math::Transform& pose,
                                   const IkOptions& options) const noexcept {
  return inner_->inverse(to_inner(pose), options);
}

IkSolutions PlacedKinematics::inverse_all(const math::Transform& pose,
                                          const IkOptions& options) const noexcept {
  return inner_->inverse_all(to_inner(pose), options);
}

}  // namespace rccx::kin
