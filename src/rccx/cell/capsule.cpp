#include "rccx/cell/capsule.hpp"

#include <algorithm>
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

namespace {

math::Vec3 max0(const math::Vec3& v) noexcept {
  return {std::max(v.x, 0.0), std::max(v.y, 0.0), std::max(v.z, 0.0)};
}

Aabb world_box(const math::Transform& pose, const math::Vec3& half_m) noexcept {
  // The extent of an oriented box along each world axis: |R| h.
  const math::Rot3& R = pose.R;
  const math::Vec3 e{
      std::abs(R.n.x) * half_m.x + std::abs(R.o.x) * half_m.y + std::abs(R.a.x) * half_m.z,
      std::abs(R.n.y) * half_m.x + std::abs(R.o.y) * half_m.y + std::abs(R.a.y) * half_m.z,
      std::abs(R.n.z) * half_m.x + std::abs(R.o.z) * half_m.y + std::abs(R.a.z) * half_m.z};
  return {pose.p - e, pose.p + e};
}

}  // namespace

Solid make_box(const math::Vec3& size_m, const math::Transform& pose) noexcept {
  Solid s;
  s.kind = Solid::Kind::box;
  s.half_m = size_m * 0.5;
  s.pose = pose;
  s.inverse = pose.inverse();
  s.bounds = world_box(pose, s.half_m);
  return s;
}

Solid make_cylinder(double radius_m, double height_m, const math::Transform& pose) noexcept {
  Solid s;
  s.kind = Solid::Kind::cylinder;
  s.radius_m = radius_m;
  s.half_height_m = height_m / 2.0;
  s.half_m = {radius_m, radius_m, s.half_height_m};  // the box around it
  s.pose = pose;
  s.inverse = pose.inverse();
  s.bounds = world_box(pose, s.half_m);
  return s;
}

double signed_distance(const Solid& solid, const math::Vec3& p_m) noexcept {
  const math::Vec3 p = solid.inverse * p_m;
  if (solid.kind == Solid::Kind::box) {
    const math::Vec3 q{std::abs(p.x) - solid.half_m.x, std::abs(p.y) - solid.half_m.y,
                       std::abs(p.z) - solid.half_m.z};
    const double inside = std::min(std::max({q.x, q.y, q.z}), 0.0);
    return max0(q).norm() + inside;
  }
  const double radial = std::hypot(p.x, p.y) - solid.radius_m;
  const double axial = std::abs(p.z) - solid.half_height_m;
  const double inside = std::min(std::max(radial, axial), 0.0);
  return std::hypot(std::max(radial, 0.0), std::max(axial, 0.0)) + inside;
}

SolidDistance capsule_solid_distance(const Capsule& c, const Solid& s) noexcept {
  // Golden-section search of a convex function over [0, 1]: 44 steps shrink the interval by
  // 0.618^44 < 1e-9.
  const math::Vec3 d = c.p1_m - c.p0_m;
  const auto f = [&](double t) { return signed_distance(s, c.p0_m + d * t); };
  constexpr double kInvPhi = 0.6180339887498949;
  double lo = 0.0, hi = 1.0;
  double x1 = hi - kInvPhi * (hi - lo), x2 = lo + kInvPhi * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  if (d.x * d.x + d.y * d.y + d.z * d.z > kPointLength2) {
    for (int k = 0; k < 44; ++k) {
      if (f1 <= f2) {
        hi = x2;
        x2 = x1;
        f2 = f1;
        x1 = hi - kInvPhi * (hi - lo);
        f1 = f(x1);
      } else {
        lo = x1;
        x1 = x2;
        f1 = f2;
        x2 = lo + kInvPhi * (hi - lo);
        f2 = f(x2);
      }
    }
  }
  // The ends too: the minimum of a convex function on [0, 1] may sit at one.
  double best_t = f1 <= f2 ? x1 : x2;
  double best = std::min(f1, f2);
  for (const double t : {0.0, 1.0}) {
    const double v = f(t);
    if (v < best) {
      best = v;
      best_t = t;
    }
  }
  return {best - c.radius_m, c.p0_m + d * best_t};
}

}  // namespace rccx::cell
