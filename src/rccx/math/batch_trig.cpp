#include "rccx/math/batch_trig.hpp"

#include <cmath>

namespace rccx::math {

namespace detail {

void sincos4_scalar(const double angle_rad[4], double s[4], double c[4]) noexcept {
  for (int i = 0; i < 4; ++i) ::sincos(angle_rad[i], &s[i], &c[i]);
}

void atan2_4_scalar(const double y[4], const double x[4], double out_rad[4]) noexcept {
  for (int i = 0; i < 4; ++i) out_rad[i] = std::atan2(y[i], x[i]);
}

}  // namespace detail

namespace {
// Checked once; a predictable branch per call afterwards.
const bool kUseAvx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}  // namespace

bool batch_trig_uses_avx2() noexcept {
  return kUseAvx2;
}

void sincos4(const double angle_rad[4], double s[4], double c[4]) noexcept {
  if (kUseAvx2) {
    detail::sincos4_avx2(angle_rad, s, c);
  } else {
    detail::sincos4_scalar(angle_rad, s, c);
  }
}

void atan2_4(const double y[4], const double x[4], double out_rad[4]) noexcept {
  if (kUseAvx2) {
    detail::atan2_4_avx2(y, x, out_rad);
  } else {
    detail::atan2_4_scalar(y, x, out_rad);
  }
}

void sincos8(const double angle_rad[8], double s[8], double c[8]) noexcept {
  if (kUseAvx2) {
    detail::sincos8_avx2(angle_rad, s, c);
  } else {
    detail::sincos4_scalar(angle_rad, s, c);
    detail::sincos4_scalar(angle_rad + 4, s + 4, c + 4);
  }
}

void atan2_8(const double y[8], const double x[8], double out_rad[8]) noexcept {
  if (kUseAvx2) {
    detail::atan2_8_avx2(y, x, out_rad);
  } else {
    detail::atan2_4_scalar(y, x, out_rad);
    detail::atan2_4_scalar(y + 4, x + 4, out_rad + 4);
  }
}

}  // namespace rccx::math
