// Unit literals. Everything inside rccx is SI (m, rad, s); these literals let code written the
// 1986 way (millimetres, degrees) say so where the number is written.
//
//   using namespace rccx::math::literals;
//   const double reach = 325_mm;     // 0.325 (m)
//   const double turn = 90_deg;      // 1.5708 (rad)
//   const double period = 28_ms;     // 0.028 (s); _s takes a decimal point: 2.0_s
//   math::rad_to_deg(turn);          // 90
#pragma once

#include <numbers>

namespace rccx::math {

inline constexpr double kPi = std::numbers::pi;

constexpr double deg_to_rad(double deg) noexcept {
  return deg * (kPi / 180.0);
}
constexpr double rad_to_deg(double rad) noexcept {
  return rad * (180.0 / kPi);
}

namespace literals {
// clang-format off
constexpr double operator""_m(long double v) noexcept { return static_cast<double>(v); }
constexpr double operator""_m(unsigned long long v) noexcept { return static_cast<double>(v); }
constexpr double operator""_mm(long double v) noexcept { return static_cast<double>(v) * 1e-3; }
constexpr double operator""_mm(unsigned long long v) noexcept { return static_cast<double>(v) * 1e-3; }
constexpr double operator""_rad(long double v) noexcept { return static_cast<double>(v); }
constexpr double operator""_rad(unsigned long long v) noexcept { return static_cast<double>(v); }
constexpr double operator""_deg(long double v) noexcept { return deg_to_rad(static_cast<double>(v)); }
constexpr double operator""_deg(unsigned long long v) noexcept { return deg_to_rad(static_cast<double>(v)); }
constexpr double operator""_s(long double v) noexcept { return static_cast<double>(v); }
constexpr double operator""_ms(long double v) noexcept { return static_cast<double>(v) * 1e-3; }
constexpr double operator""_ms(unsigned long long v) noexcept { return static_cast<double>(v) * 1e-3; }
// clang-format on
}  // namespace literals

}  // namespace rccx::math
