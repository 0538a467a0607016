// One link of a chain applied to a frame, T <- T A_i, multiplied out (thesis eq. 3.3): A_i's
// n is (ct, st, 0); its o and a mix v = T.o ct - T.n st with T.a through alpha. Shared by the
// solvers' forward kinematics and the link frames of the collision capsules:
//
//   kin::apply_dh_link(T, ct, st, ca, sa, a_m, d_m);   // each link in turn, from T = base
//   kin::rotate_about(T.R, axis, principal_axis(axis), c, s);   // a general chain's joint
#pragma once

#include <cmath>

#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::kin {

/// ct, st: cos and sin of the joint angle; ca, sa: of alpha; a_m, d_m: the link's a and d, m.
inline void apply_dh_link(math::Transform& T, double ct, double st, double ca, double sa,
                          double a_m, double d_m) noexcept {
  const math::Vec3 n = T.R.n * ct + T.R.o * st;
  const math::Vec3 v = T.R.o * ct - T.R.n * st;
  const math::Vec3 o = v * ca + T.R.a * sa;
  const math::Vec3 a = T.R.a * ca - v * sa;
  T.p += T.R.a * d_m + n * a_m;
  T.R = {n, o, a};
}

/// Which coordinate axis a unit vector is: 1, 2, 3 for +x, +y, +z, -1, -2, -3 for the negative
/// ones, 0 for any other direction (rotate_about's cheaper cases).
inline int principal_axis(const math::Vec3& unit_axis) noexcept {
  const double c[3] = {unit_axis.x, unit_axis.y, unit_axis.z};
  for (int k = 0; k < 3; ++k) {
    if (std::abs(c[k]) == 1.0) return c[k] > 0.0 ? k + 1 : -(k + 1);
  }
  return 0;
}

/// R <- R Rot(axis, angle) for a unit axis, given cos and sin of the angle. `principal`
/// (principal_axis) picks the two-column update of a rotation about a coordinate axis.
inline void rotate_about(math::Rot3& R, const math::Vec3& axis, int principal, double c,
                         double s) noexcept {
  if (principal < 0) {
    s = -s;
    principal = -principal;
  }
  switch (principal) {
    case 1: {  // Rot(x): o' = o c + a s, a' = a c - o s
      const math::Vec3 o = R.o * c + R.a * s;
      R.a = R.a * c - R.o * s;
      R.o = o;
      return;
    }
    case 2: {  // Rot(y): n' = n c - a s, a' = n s + a c
      const math::Vec3 n = R.n * c - R.a * s;
      R.a = R.n * s + R.a * c;
      R.n = n;
      return;
    }
    case 3: {  // Rot(z): n' = n c + o s, o' = o c - n s
      const math::Vec3 n = R.n * c + R.o * s;
      R.o = R.o * c - R.n * s;
      R.n = n;
      return;
    }
    default: {  // Rodrigues: c I + s [k]x + (1 - c) k k^T, column by column
      const math::Vec3& k = axis;
      const double v = 1.0 - c;
      const math::Rot3 M{{c + v * k.x * k.x, v * k.x * k.y + s * k.z, v * k.x * k.z - s * k.y},
                         {v * k.x * k.y - s * k.z, c + v * k.y * k.y, v * k.y * k.z + s * k.x},
                         {v * k.x * k.z + s * k.y, v * k.y * k.z - s * k.x, c + v * k.z * k.z}};
      R = R * M;
      return;
    }
  }
}

/// One joint of a general chain (RobotModel's ChainStep) made ready for every sample: its unit
/// axis, which coordinate axis that is, whether `after` is the identity.
struct PreparedStep {
  math::Transform origin;
  math::Vec3 axis{0, 0, 1};
  math::Transform after;
  int principal = 3;  ///< principal_axis(axis)
  bool after_identity = true;
  bool prismatic = false;

  PreparedStep() = default;
  PreparedStep(const ChainStep& step, bool is_prismatic) noexcept
      : origin(step.origin),
        axis(step.axis.normalized()),
        after(step.after),
        principal(principal_axis(axis)),
        after_identity(step.after.rows() == math::Transform{}.rows()),
        prismatic(is_prismatic) {}
};

/// T <- T origin Motion(axis, q) after: one joint of a general chain, c and s the cosine and
/// sine of q (unused for a prismatic joint).
inline void apply_chain_step(math::Transform& T, const PreparedStep& step, double q, double c,
                             double s) noexcept {
  T = T * step.origin;
  if (step.prismatic) {
    T.p += T.R * (step.axis * q);
  } else {
    rotate_about(T.R, step.axis, step.principal, c, s);
  }
  if (!step.after_identity) T = T * step.after;
}

}  // namespace rccx::kin
