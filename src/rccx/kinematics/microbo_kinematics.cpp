#include "rccx/kinematics/microbo_kinematics.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>

#include "rccx/math/batch_trig.hpp"
#include "rccx/math/units.hpp"

namespace rccx::kin {

namespace {

constexpr std::array<std::string_view, 2> kConfigurationNames{"n", "f"};
constexpr double kSingular = 1e-10;  // |S5| (or d3 in m) below which a joint is taken from near

// The thesis's link table (section 3.4): alpha and theta offsets in degrees, all a = 0 and the
// fixed d = 0.
struct ExpectedLink {
  JointType type;
  double alpha_deg;
  double theta_deg;
};
constexpr std::array<ExpectedLink, 6> kTable{{{JointType::revolute, 0, 0},
                                              {JointType::prismatic, 90, 90},
                                              {JointType::prismatic, 0, 0},
                                              {JointType::revolute, 90, 0},
                                              {JointType::revolute, 90, 0},
                                              {JointType::revolute, 0, 0}}};

void check_structure(const RobotModel& model) {
  auto fail = [&](const std::string& what) {
    throw RobotFileError(fmt::format(
        "robot \"{}\" asks for the Microbo closed form, but {}; use \"solver\": \"dh\" for a "
        "different chain",
        model.name, what));
  };
  if (model.dof() != 6) fail(fmt::format("it has {} joints, not 6", model.dof()));
  for (std::size_t i = 0; i < 6; ++i) {
    const Joint& j = model.joints[i];
    const ExpectedLink& e = kTable[i];
    const bool fixed_d_zero = j.type == JointType::prismatic || std::abs(j.dh.d_m) < 1e-12;
    if (j.type != e.type || std::abs(j.dh.a_m) > 1e-12 || !fixed_d_zero ||
        std::abs(j.dh.alpha_rad - math::deg_to_rad(e.alpha_deg)) > 1e-12 ||
        std::abs(j.dh.theta_rad - math::deg_to_rad(e.theta_deg)) > 1e-12) {
      fail(fmt::format("joint {} differs from the thesis's link table", i + 1));
    }
    if (j.type == JointType::prismatic && std::abs(j.dh.d_m) > 1e-12) {
      fail(fmt::format("joint {} has a d offset", i + 1));
    }
  }
}

}  // namespace

MicroboKinematics::MicroboKinematics(RobotModel model) : AnalyticKinematics(std::move(model)) {
  check_structure(this->model());
}

std::span<const std::string_view> MicroboKinematics::configuration_names() const noexcept {
  return kConfigurationNames;
}

Configuration MicroboKinematics::configuration_of(const JointVector& q) const noexcept {
  return Configuration{static_cast<std::uint8_t>(std::sin(q[4]) < 0.0 ? 0 : 1)};
}

math::Transform MicroboKinematics::forward(const JointVector& q) const noexcept {
  // Section 3.5: o, a and p from the closed form, then n = o x a (30 mult, 13 add in the thesis).
  const double angles[4] = {q[0], q[3], q[4], q[5]};
  double s[4], c[4];
  math::sincos4(angles, s, c);
  const double S1 = s[0], C1 = c[0], S4 = s[1], C4 = c[1], S5 = s[2], C5 = c[2], S6 = s[3],
               C6 = c[3];
  const double d2 = q[1], d3 = q[2];
  const double u = C6 * S4 - C4 * C5 * S6;
  const double S5S6 = S5 * S6;
  const double C4S5 = C4 * S5;
  const math::Vec3 o{-S1 * u - C1 * S5S6, C1 * u - S1 * S5S6, -C5 * S4 * S6 - C4 * C6};
  const math::Vec3 a{-C4S5 * S1 - C1 * C5, C1 * C4S5 - C5 * S1, S4 * S5};
  return {{math::cross(o, a), o, a}, {C1 * d3, S1 * d3, d2}};
}

IkStatus MicroboKinematics::solve(const math::Transform& pose, Configuration which,
                                  const JointVector& reference, IkResult& out) const noexcept {
  const math::Vec3& o = pose.R.o;
  const math::Vec3& a = pose.R.a;
  const math::Vec3& p = pose.p;
  out.q = JointVector(6);
  out.configuration = which;
  out.singularity = Singularity::none;
  // Every angle follows from its sine and cosine, and those follow from the pose without any
  // angle: collect them and take the four atan2 at once.
  double y[4], x[4];

  // Joints 1-3 from p (eq. 3.14); d3 is the positive root by the robot's geometry.
  const double d3 = std::sqrt(p.x * p.x + p.y * p.y);
  out.q[1] = p.z;
  out.q[2] = d3;
  // Below, S1 and C1 enter scaled by d3 (they are p_y / d3 and p_x / d3) so that no division
  // stands between the pose and the atan2; every sine-cosine pair an angle comes from is then
  // scaled by a positive factor, which atan2 ignores.
  const bool shoulder_free = !(d3 > kSingular);  // wrist on joint 1's axis: any theta1 will do
  double S1 = p.y, C1 = p.x, scale = d3;
  if (shoulder_free) {
    ::sincos(reference[0], &S1, &C1);
    scale = 1.0;
  }
  y[0] = S1;
  x[0] = C1;

  // Joint 4 from the third column of U4: (C4 S5, S4 S5) = (a_y C1 - a_x S1, a_z).
  const double c4s5 = a.y * C1 - a.x * S1;
  const double s4s5 = a.z * scale;
  const double s5_squared = c4s5 * c4s5 + s4s5 * s4s5;
  const double sign = which.index == 0 ? -1.0 : 1.0;  // of S5
  const double S5 = sign * std::sqrt(s5_squared);
  const double C5 = -(a.y * S1 + a.x * C1);  // U5 (erratum: a_y S1 + a_x C1)
  const double oxy = o.y * S1 + C1 * o.x;
  const double oyx = C1 * o.y - o.x * S1;
  const double oz = o.z * scale;
  const bool wrist_free = !(s5_squared > kSingular * kSingular * scale * scale);
  if (wrist_free) {  // theta5 = -pi: joints 4 and 6 aligned, keep the reference theta4
    double S4, C4;
    ::sincos(reference[3], &S4, &C4);
    y[1] = S4;
    x[1] = C4;
    // Joint 6 from the second column of U6 (both sides scaled by scale^2).
    y[3] = -(oxy * S5 + C5 * (oz * S4 + C4 * oyx));
    x[3] = scale * (oyx * S4 - C4 * oz);
  } else {
    // The same with S4 and C4 scaled by |S5| as well (both sides by scale^3 |S5|).
    y[1] = sign * s4s5;
    x[1] = sign * c4s5;
    y[3] = -sign * (oxy * s5_squared + C5 * (oz * s4s5 + oyx * c4s5));
    x[3] = sign * scale * (oyx * s4s5 - oz * c4s5);
  }
  y[2] = S5;
  x[2] = C5;

  double angle[4];
  math::atan2_4(y, x, angle);
  out.q[0] = shoulder_free ? reference[0] : angle[0];
  out.q[3] = wrist_free ? reference[3] : angle[1];
  out.q[4] = angle[2];
  out.q[5] = angle[3];
  if (shoulder_free) out.singularity = Singularity::shoulder;
  if (wrist_free) out.singularity = Singularity::wrist;
  return IkStatus::ok;
}

}  // namespace rccx::kin
