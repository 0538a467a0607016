// One link of a DH chain applied to a frame, T <- T A_i, multiplied out (thesis eq. 3.3): A_i's
// n is (ct, st, 0); its o and a mix v = T.o ct - T.n st with T.a through alpha. Shared by the
// solvers' forward kinematics and the link frames of the collision capsules:
//
//   kin::apply_dh_link(T, ct, st, ca, sa, a_m, d_m);   // each link in turn, from T = base
#pragma once

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

}  // namespace rccx::kin
