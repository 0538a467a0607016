// A wrench (force and torque) and the force transform of thesis 4.4.2 in general form: the
// same load expressed at another frame's origin and in its axes. A wrist sensor reports the
// wrench in its own frame; the tool tip, the world or any frame of a position equation is one
// call away.
//
//   const math::Wrench at_t6{{0, 0, -10}, {0, 0, 0}};    // N, N m, about T6 in T6's axes
//   const math::Wrench at_tool = math::transform_wrench(t6_from_tool.inverse(), at_t6);
//   const math::Wrench tool_weight = math::weight_wrench(world_from_t6.R, 0.4, {0, 0, 0.05});
//   at_t6 - tool_weight;                                  // what is left: contacts (0.4 kg, m)
#pragma once

#include <array>

#include "rccx/math/transform.hpp"

namespace rccx::math {

/// A force (N) and a torque (N m) about a frame's origin, both in that frame's axes.
struct Wrench {
  Vec3 force_N;
  Vec3 torque_N_m;

  constexpr Wrench operator+(const Wrench& b) const noexcept {
    return {force_N + b.force_N, torque_N_m + b.torque_N_m};
  }
  constexpr Wrench operator-(const Wrench& b) const noexcept {
    return {force_N - b.force_N, torque_N_m - b.torque_N_m};
  }
  constexpr Wrench operator*(double s) const noexcept { return {force_N * s, torque_N_m * s}; }
  constexpr bool operator==(const Wrench&) const noexcept = default;
  /// fx fy fz (N), tx ty tz (N m).
  [[nodiscard]] constexpr std::array<double, 6> to_array() const noexcept {
    return {force_N.x, force_N.y, force_N.z, torque_N_m.x, torque_N_m.y, torque_N_m.z};
  }
  [[nodiscard]] static constexpr Wrench from_array(const std::array<double, 6>& w) noexcept {
    return {{w[0], w[1], w[2]}, {w[3], w[4], w[5]}};
  }
};

/// The force transform: `in_b`, a wrench about frame b's origin in b's axes, expressed about
/// frame a's origin in a's axes, where `a_from_b` is frame b described in frame a (b's pose in
/// a). f_a = R f_b; t_a = R t_b + p x (R f_b).
[[nodiscard]] constexpr Wrench transform_wrench(const Transform& a_from_b,
                                                const Wrench& in_b) noexcept {
  const Vec3 f = a_from_b.R * in_b.force_N;
  return {f, a_from_b.R * in_b.torque_N_m + cross(a_from_b.p, f)};
}

/// The weight of a body of `mass_kg` whose centre of mass sits at `com_m` in frame s, as a
/// wrench about s's origin in s's axes, when s's orientation in the world is `world_from_s_R`
/// and gravity points along world -z at `g_m_per_s2`.
[[nodiscard]] constexpr Wrench weight_wrench(const Rot3& world_from_s_R, double mass_kg,
                                             const Vec3& com_m, double g_m_per_s2 = 9.81) noexcept {
  const Vec3 f = world_from_s_R.transpose_times(Vec3{0.0, 0.0, -mass_kg * g_m_per_s2});
  return {f, cross(com_m, f)};
}

}  // namespace rccx::math
