#include "rccx/cell/capsule.hpp"

#include <cmath>
#include <limits>

namespace rccx::cell {

namespace {

// Squared lengths below this (m^2) are points: 1e-12 m is far below any link's size.
constexpr double kPointLength2 = 1e-24;

double clamp01(double x) noexcept {
  return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x);
}

}  // namespace

SegmentClosest segment_distance(const math::Vec3& p0_m, const math::Vec3& p1_m,
                                const math::Vec3& q0_m, const math::Vec3& q1_m) noexcept {
  const math::Vec3 d1 = p1_m - p0_m;
  const math::Vec3 d2 = q1_m - q0_m;
  const math::Vec3 r = p0_m - q0_m;
  const double a = math::dot(d1, d1);
  const double e = math::dot(d2, d2);
  const double f = math::dot(d2, r);
  double s = 0.0;
  double t = 0.0;
  if (a <= kPointLength2 && e <= kPointLength2) {
    // Two points.
  } else if (a <= kPointLength2) {
    t = clamp01(f / e);
  } else {
    const double c = math::dot(d1, r);
    if (e <= kPointLength2) {
      s = clamp01(-c / a);
    } else {
      const double b = math::dot(d1, d2);
      const double denom = a * e - b * b;  // |d1 x d2|^2 >= 0
      if (denom <= 1e-14 * a * e) {
        // Parallel to rounding: the line-line solution is noise, but then a closest pair has
        // an end point of one segment (exactly for parallel ones, to second order in the
        // angle for nearly parallel ones): the best of the four end point projections.
        const double cand_s[4] = {0.0, 1.0, clamp01(-c / a), clamp01((b - c) / a)};
        const double cand_t[4] = {clamp01(f / e), clamp01((b + f) / e), 0.0, 1.0};
        double best = std::numeric_limits<double>::infinity();
        for (int k = 0; k < 4; ++k) {
          const math::Vec3 gap = r + d1 * cand_s[k] - d2 * cand_t[k];
          const double g2 = math::dot(gap, gap);
          if (g2 < best) {
            best = g2;
            s = cand_s[k];
            t = cand_t[k];
          }
        }
      } else {
        s = clamp01((b * f - c * e) / denom);
        t = (b * s + f) / e;
        // t outside the second segment: clamp it and take s again for that end point.
        if (t < 0.0) {
          t = 0.0;
          s = clamp01(-c / a);
        } else if (t > 1.0) {
          t = 1.0;
          s = clamp01((b - c) / a);
        }
      }
    }
  }
  SegmentClosest out;
  out.s = s;
  out.t = t;
  out.on_first_m = p0_m + d1 * s;
  out.on_second_m = q0_m + d2 * t;
  out.distance_m = (out.on_first_m - out.on_second_m).norm();
  return out;
}

CapsuleDistance capsule_distance(const Capsule& a, const Capsule& b) noexcept {
  const SegmentClosest c = segment_distance(a.p0_m, a.p1_m, b.p0_m, b.p1_m);
  CapsuleDistance out;
  out.distance_m = c.distance_m - a.radius_m - b.radius_m;
  if (c.distance_m > 0.0) {
    const math::Vec3 u = (c.on_second_m - c.on_first_m) / c.distance_m;
    out.on_a_m = c.on_first_m + u * a.radius_m;
    out.on_b_m = c.on_second_m - u * b.radius_m;
  } else {
    out.on_a_m = c.on_first_m;
    out.on_b_m = c.on_second_m;
  }
  return out;
}

}  // namespace rccx::cell
