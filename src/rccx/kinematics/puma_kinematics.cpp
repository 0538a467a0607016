#include "rccx/kinematics/puma_kinematics.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>

#include "rccx/math/batch_trig.hpp"
#include "rccx/math/units.hpp"

namespace rccx::kin {

namespace {

// Index = 4 arm + 2 elbow + wrist, with arm 0 = left, elbow 0 = up, wrist 0 = no flip.
constexpr std::array<std::string_view, 8> kConfigurationNames{"lun", "luf", "ldn", "ldf",
                                                              "run", "ruf", "rdn", "rdf"};
constexpr double kSingular = 1e-10;
constexpr std::array<double, 6> kAlphaDeg{90, 0, -90, 90, -90, 0};

}  // namespace

PumaKinematics::PumaKinematics(RobotModel model) : AnalyticKinematics(std::move(model)) {
  const RobotModel& m = this->model();
  auto fail = [&](const std::string& what) { throw detail::not_of_form(m, "PUMA", what); };
  detail::require_dh_form(m, "PUMA", kAlphaDeg, {false, true, true, false, false, false});
  if (std::abs(m.joints[4].dh.d_m) > 1e-12) fail("joint 5 has d != 0");
  d1_ = m.joints[0].dh.d_m;
  a2_ = m.joints[1].dh.a_m;
  d3_ = m.joints[1].dh.d_m + m.joints[2].dh.d_m;  // z1 and z2 are parallel: the offsets add
  a3_ = m.joints[2].dh.a_m;
  d4_ = m.joints[3].dh.d_m;
  d6_ = m.joints[5].dh.d_m;
  L_ = std::hypot(a3_, d4_);
  if (!(a2_ > 0.0) || !(L_ > 0.0)) fail("the upper arm (a2) and forearm (a3, d4) need length");
  cphi_ = a3_ / L_;
  sphi_ = d4_ / L_;
}

std::span<const std::string_view> PumaKinematics::configuration_names() const noexcept {
  return kConfigurationNames;
}

Configuration PumaKinematics::configuration_of(const JointVector& q) const noexcept {
  const double S2 = std::sin(q[1]), C2 = std::cos(q[1]);
  const double S3 = std::sin(q[2]), C3 = std::cos(q[2]);
  const double S23 = S2 * C3 + C2 * S3, C23 = C2 * C3 - S2 * S3;
  const double reach = a2_ * C2 + a3_ * C23 - d4_ * S23;  // wrist centre along x1
  const bool right = reach >= 0.0;
  const double s = S3 * cphi_ + C3 * sphi_;  // sin(theta3 + phi)
  const bool up = right ? s < 0.0 : s > 0.0;
  const bool flip = std::sin(q[4]) < 0.0;
  return Configuration{static_cast<std::uint8_t>((right ? 4 : 0) + (up ? 0 : 2) + (flip ? 1 : 0))};
}

math::Transform PumaKinematics::forward(const JointVector& q) const noexcept {
  const double angles[8] = {q[0], q[1], q[3], q[4], q[5], q[1] + q[2], 0.0, 0.0};
  double s[8], c[8];
  math::sincos8(angles, s, c);
  const double S1 = s[0], C1 = c[0], S2 = s[1], C2 = c[1], S4 = s[2], C4 = c[2], S5 = s[3],
               C5 = c[3], S6 = s[4], C6 = c[4], S23 = s[5], C23 = c[5];
  // R03 by columns, and R36 = R4 R5 R6 by columns.
  const math::Vec3 c0{C1 * C23, S1 * C23, S23};
  const math::Vec3 c1{-S1, C1, 0.0};
  const math::Vec3 c2{-C1 * S23, -S1 * S23, C23};
  const double C4C5 = C4 * C5, S4C5 = S4 * C5;
  const math::Vec3 n36{C4C5 * C6 - S4 * S6, S4C5 * C6 + C4 * S6, S5 * C6};
  const math::Vec3 o36{-C4C5 * S6 - S4 * C6, -S4C5 * S6 + C4 * C6, -S5 * S6};
  const math::Vec3 a36{-C4 * S5, -S4 * S5, C5};
  auto times_r03 = [&](const math::Vec3& v) {
    return math::Vec3{c0.x * v.x + c1.x * v.y + c2.x * v.z, c0.y * v.x + c1.y * v.y + c2.y * v.z,
                      c0.z * v.x + c2.z * v.z};
  };
  const math::Vec3 a = times_r03(a36);
  // Wrist centre: in frame 1, (reach, height, d3); then into the base frame.
  const double reach = a2_ * C2 + a3_ * C23 - d4_ * S23;
  const double height = a2_ * S2 + a3_ * S23 + d4_ * C23;
  const math::Vec3 wrist{C1 * reach + S1 * d3_, S1 * reach - C1 * d3_, height + d1_};
  return {{times_r03(n36), times_r03(o36), a}, wrist + a * d6_};
}

IkStatus PumaKinematics::solve(const math::Transform& pose, Configuration which,
                               const JointVector& reference, IkResult& out) const noexcept {
  const bool right = (which.index & 4) != 0;
  const bool down = (which.index & 2) != 0;
  const bool flip = (which.index & 1) != 0;
  out.q = JointVector(6);
  out.configuration = which;
  out.singularity = Singularity::none;
  // Sines and cosines come from the pose without any angle; the six atan2 are taken in two
  // batches at the end: y/x[0..3] for theta1, theta2, theta3, theta5; [4..5] theta4, theta6.
  double y[8] = {}, x[8] = {};

  const math::Vec3 w = pose.p - pose.R.a * d6_;  // wrist centre
  const double z = w.z - d1_;

  // Joint 1: the wrist centre sits at lateral offset d3 from the arm's plane, at reach rho.
  const double r2 = w.x * w.x + w.y * w.y;
  const double rho2 = r2 - d3_ * d3_;
  if (rho2 < -1e-12) return IkStatus::out_of_reach;  // inside the cylinder of radius |d3|
  const double arm = right ? 1.0 : -1.0;
  const double rho = arm * std::sqrt(std::max(rho2, 0.0));
  const bool shoulder_free = !(r2 > kSingular * kSingular);  // wrist on joint 1's axis (d3 = 0)
  double S1, C1;
  if (shoulder_free) {
    ::sincos(reference[0], &S1, &C1);
    out.singularity = Singularity::shoulder;
  } else {
    const double inv_r2 = 1.0 / r2;
    C1 = (rho * w.x - d3_ * w.y) * inv_r2;
    S1 = (d3_ * w.x + rho * w.y) * inv_r2;
  }
  y[0] = S1;
  x[0] = C1;

  // Joints 2 and 3: a planar two-link problem in the arm's plane, wrist at (rho, z).
  const double D = rho * rho + z * z;
  const double c = (D - a2_ * a2_ - L_ * L_) / (2.0 * a2_ * L_);  // cos(theta3 + phi)
  if (c > 1.0 + 1e-12 || c < -1.0 - 1e-12) return IkStatus::out_of_reach;
  const double cc = std::clamp(c, -1.0, 1.0);
  const double elbow = (down ? 1.0 : -1.0) * arm;  // sign of sin(theta3 + phi)
  const double s = elbow * std::sqrt(1.0 - cc * cc);
  const double C3 = cc * cphi_ + s * sphi_;
  const double S3 = s * cphi_ - cc * sphi_;
  y[2] = S3;
  x[2] = C3;
  const double X = a2_ + L_ * cc, Y = L_ * s;            // wrist in frame 2
  const bool elbow_free = !(D > kSingular * kSingular);  // wrist on the shoulder (a2 = L only)
  double S2, C2;
  if (elbow_free) {
    ::sincos(reference[1], &S2, &C2);
    out.singularity = Singularity::elbow;
  } else {
    const double inv_d = 1.0 / D;
    C2 = (rho * X + z * Y) * inv_d;
    S2 = (z * X - rho * Y) * inv_d;
  }
  y[1] = S2;
  x[1] = C2;

  // Joints 4-6 from R36 = R03^T R: a36 = (-C4 S5, -S4 S5, C5), n36_z = S5 C6, o36_z = -S5 S6.
  const double S23 = S2 * C3 + C2 * S3, C23 = C2 * C3 - S2 * S3;
  const math::Vec3 c0{C1 * C23, S1 * C23, S23};
  const math::Vec3 c1{-S1, C1, 0.0};
  const math::Vec3 c2{-C1 * S23, -S1 * S23, C23};
  const math::Vec3& n = pose.R.n;
  const math::Vec3& o = pose.R.o;
  const math::Vec3& a = pose.R.a;
  const double r02 = math::dot(c0, a), r12 = math::dot(c1, a), r22 = math::dot(c2, a);
  const double wrist = flip ? -1.0 : 1.0;  // sign of S5
  const double abs_s5 = std::sqrt(r02 * r02 + r12 * r12);
  y[3] = wrist * abs_s5;
  x[3] = r22;
  const bool wrist_free = !(abs_s5 > kSingular);  // theta5 = 0 or pi: joints 4 and 6 aligned
  if (wrist_free) {
    // Only theta4 +- theta6 is determined: keep the reference theta4.
    const double r00 = math::dot(c0, n), r10 = math::dot(c1, n);
    y[5] = r10;
    x[5] = r22 > 0.0 ? r00 : -r00;
    out.singularity = Singularity::wrist;
  } else {
    y[4] = -wrist * r12;
    x[4] = -wrist * r02;
    y[5] = -wrist * math::dot(c2, o);
    x[5] = wrist * math::dot(c2, n);
  }

  double angle[8];
  math::atan2_8(y, x, angle);
  out.q[0] = shoulder_free ? reference[0] : angle[0];
  out.q[1] = elbow_free ? reference[1] : angle[1];
  out.q[2] = angle[2];
  out.q[4] = angle[3];
  if (wrist_free) {
    out.q[3] = reference[3];
    out.q[5] =
        std::remainder(r22 > 0.0 ? angle[5] - out.q[3] : angle[5] + out.q[3], 2.0 * math::kPi);
  } else {
    out.q[3] = angle[4];
    out.q[5] = angle[5];
  }
  return IkStatus::ok;
}

}  // namespace rccx::kin
