// Compiled with -mavx2 -mfma (src/CMakeLists.txt); called only when the processor has both.
#include <immintrin.h>
#include <sleef.h>

#include "rccx/math/batch_trig.hpp"

namespace rccx::math::detail {

namespace {
// The callers have just written the inputs one by one: gathering them with scalar loads avoids
// the store-forwarding stall a 256-bit load of four fresh 64-bit stores would take.
inline __m256d gather(const double v[4]) noexcept {
  return _mm256_set_pd(v[3], v[2], v[1], v[0]);
}
}  // namespace

void sincos4_avx2(const double angle_rad[4], double s[4], double c[4]) noexcept {
  const Sleef___m256d_2 r = Sleef_sincosd4_u35avx2(gather(angle_rad));
  _mm256_storeu_pd(s, r.x);
  _mm256_storeu_pd(c, r.y);
}

void atan2_4_avx2(const double y[4], const double x[4], double out_rad[4]) noexcept {
  _mm256_storeu_pd(out_rad, Sleef_atan2d4_u35avx2(gather(y), gather(x)));
}

void sincos8_avx2(const double angle_rad[8], double s[8], double c[8]) noexcept {
  const Sleef___m256d_2 low = Sleef_sincosd4_u35avx2(gather(angle_rad));
  const Sleef___m256d_2 high = Sleef_sincosd4_u35avx2(gather(angle_rad + 4));
  _mm256_storeu_pd(s, low.x);
  _mm256_storeu_pd(c, low.y);
  _mm256_storeu_pd(s + 4, high.x);
  _mm256_storeu_pd(c + 4, high.y);
}

void atan2_8_avx2(const double y[8], const double x[8], double out_rad[8]) noexcept {
  const __m256d low = Sleef_atan2d4_u35avx2(gather(y), gather(x));
  const __m256d high = Sleef_atan2d4_u35avx2(gather(y + 4), gather(x + 4));
  _mm256_storeu_pd(out_rad, low);
  _mm256_storeu_pd(out_rad + 4, high);
}

}  // namespace rccx::math::detail
