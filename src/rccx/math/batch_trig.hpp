// Four or eight sines and cosines, or atan2, in one call. The closed-form kinematics need several
// of each per solution with no dependency between them, so they are computed side by side:
// with SLEEF's AVX2 kernels (3.5 ulp at most) when the processor has AVX2 and FMA, with glibc
// otherwise. The choice is made once, at run time, so one binary runs on any x86-64.
//
//   const double theta_rad[4] = {q[0], q[3], q[4], q[5]};
//   double s[4], c[4];
//   math::sincos4(theta_rad, s, c);     // s[i] = sin(theta_rad[i]), c[i] = cos(theta_rad[i])
//   math::atan2_4(y, x, angle_rad);     // four atan2(y[i], x[i]), in [-pi, pi]
#pragma once

namespace rccx::math {

/// s[i] = sin(angle_rad[i]), c[i] = cos(angle_rad[i]) for i = 0..3.
void sincos4(const double angle_rad[4], double s[4], double c[4]) noexcept;
/// out_rad[i] = atan2(y[i], x[i]) for i = 0..3, in [-pi, pi].
void atan2_4(const double y[4], const double x[4], double out_rad[4]) noexcept;

/// The same for eight: two batches of four issued back to back (unused lanes may hold anything
/// finite).
void sincos8(const double angle_rad[8], double s[8], double c[8]) noexcept;
void atan2_8(const double y[8], const double x[8], double out_rad[8]) noexcept;

/// Whether the AVX2 kernels are in use on this processor.
bool batch_trig_uses_avx2() noexcept;

namespace detail {
// The two implementations, exposed for the tests that compare them.
void sincos4_scalar(const double angle_rad[4], double s[4], double c[4]) noexcept;
void atan2_4_scalar(const double y[4], const double x[4], double out_rad[4]) noexcept;
void sincos4_avx2(const double angle_rad[4], double s[4], double c[4]) noexcept;
void atan2_4_avx2(const double y[4], const double x[4], double out_rad[4]) noexcept;
void sincos8_avx2(const double angle_rad[8], double s[8], double c[8]) noexcept;
void atan2_8_avx2(const double y[8], const double x[8], double out_rad[8]) noexcept;
}  // namespace detail

}  // namespace rccx::math
