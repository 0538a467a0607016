#include "rccx/kinematics/collision_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rccx::kin {

namespace {

double segment_distance(const math::Vec3& p, const math::Vec3& a, const math::Vec3& b) noexcept {
  const math::Vec3 ab = b - a;
  const double len2 = math::dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(math::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + ab * t)).norm();
}

LinkCapsule along_z(const math::Transform& at, double half_length_m, double radius_m) {
  LinkCapsule c;
  c.from_m = at * math::Vec3{0, 0, -half_length_m};
  c.to_m = at * math::Vec3{0, 0, half_length_m};
  c.radius_m = radius_m;
  return c;
}

}  // namespace

LinkCapsule enclose_sphere(const math::Transform& at, double radius_m) {
  return along_z(at, 0.0, radius_m);
}

LinkCapsule enclose_cylinder(const math::Transform& at, double radius_m, double length_m) {
  return along_z(at, 0.5 * length_m, radius_m);
}

LinkCapsule enclose_box(const math::Transform& at, const math::Vec3& size_m) {
  // The longest edge becomes the axis: the capsule's radius is then the smallest possible
  // half diagonal of a cross-section.
  const double x = size_m.x, y = size_m.y, z = size_m.z;
  math::Transform axis = at;  // z along the longest edge
  double length = z, a = x, b = y;
  if (x >= y && x >= z) {
    axis.R = at.R * math::Rot3::rot_y(std::numbers::pi / 2);  // z' = x
    length = x;
    a = y;
    b = z;
  } else if (y >= z) {
    axis.R = at.R * math::Rot3::rot_x(-std::numbers::pi / 2);  // z' = y
    length = y;
    a = x;
    b = z;
  }
  return along_z(axis, 0.5 * length, 0.5 * std::hypot(a, b));
}

bool encloses(const LinkCapsule& outer, const LinkCapsule& inner) noexcept {
  if (outer.frame != inner.frame) return false;
  // A relative slack of 1e-12 so that a sphere written at a capsule's end, in the same
  // numbers, counts as inside it.
  const double slack = 1e-12 * std::max(1.0, outer.radius_m);
  for (const math::Vec3& p : {inner.from_m, inner.to_m}) {
    if (segment_distance(p, outer.from_m, outer.to_m) + inner.radius_m > outer.radius_m + slack) {
      return false;
    }
  }
  return true;
}

void drop_enclosed(std::vector<LinkCapsule>& capsules) {
  std::vector<LinkCapsule> kept;
  for (std::size_t i = 0; i < capsules.size(); ++i) {
    bool inside = false;
    for (std::size_t k = 0; k < capsules.size() && !inside; ++k) {
      if (k == i || !encloses(capsules[k], capsules[i])) continue;
      // Two that enclose each other are equal: the first of them stays.
      inside = !encloses(capsules[i], capsules[k]) || k < i;
    }
    if (!inside) kept.push_back(capsules[i]);
  }
  capsules = std::move(kept);
}

}  // namespace rccx::kin
