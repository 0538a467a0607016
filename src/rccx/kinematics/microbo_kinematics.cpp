#include "rccx/kinematics/microbo_kinematics.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>

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
  double S1, C1, S4, C4, S5, C5, S6, C6;
  ::sincos(q[0], &S1, &C1);
  ::sincos(q[3], &S4, &C4);
  ::sincos(q[4], &S5, &C5);
  ::sincos(q[5], &S6, &C6);
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

  // Joints 1-3 from p (eq. 3.14); d3 is the positive root by the robot's geometry.
  const double d3 = std::hypot(p.x, p.y);
  double S1, C1;
  if (d3 > kSingular) {
    S1 = p.y / d3;
    C1 = p.x / d3;
    out.q[0] = std::atan2(p.y, p.x);
  } else {  // wrist on joint 1's axis: any theta1 will do, keep the reference one
    out.q[0] = reference[0];
    ::sincos(out.q[0], &S1, &C1);
    out.singularity = Singularity::shoulder;
  }
  out.q[1] = p.z;
  out.q[2] = d3;

  // Joint 4 from the third column of U4: (C4 S5, S4 S5) = (a_y C1 - a_x S1, a_z).
  const double c4s5 = a.y * C1 - a.x * S1;
  const double s4s5 = a.z;
  const double abs_s5 = std::hypot(c4s5, s4s5);
  const double sign = which.index == 0 ? -1.0 : 1.0;  // sign of S5
  double S4, C4;
  const double S5 = sign * abs_s5;
  if (abs_s5 > kSingular) {
    S4 = s4s5 / S5;
    C4 = c4s5 / S5;
    out.q[3] = std::atan2(S4, C4);
  } else {  // theta5 = -pi: joints 4 and 6 aligned, keep the reference theta4
    out.q[3] = reference[3];
    ::sincos(out.q[3], &S4, &C4);
    out.singularity = Singularity::wrist;
  }
  // Joint 5 from U5 (erratum: a_y S1 + a_x C1).
  const double C5 = -(a.y * S1 + a.x * C1);
  out.q[4] = std::atan2(S5, C5);
  // Joint 6 from the second column of U6.
  const double oxy = o.y * S1 + C1 * o.x;
  const double oyx = C1 * o.y - o.x * S1;
  const double S6 = -(oxy * S5 + C5 * (o.z * S4 + C4 * oyx));
  const double C6 = oyx * S4 - C4 * o.z;
  out.q[5] = std::atan2(S6, C6);
  return IkStatus::ok;
}

}  // namespace rccx::kin
