// The narrow phase of the collision check: the distance between two segments, between two
// capsules (a segment swept by a sphere), and between a capsule and a solid (a box or a
// cylinder). Pure functions, noexcept, no allocation.
//
//   const cell::Capsule a{.p0_m = {0, 0, 0}, .p1_m = {0, 0, 0.3}, .radius_m = 0.05};
//   const cell::Capsule b{.p0_m = {0.2, -0.1, 0.1}, .p1_m = {0.2, 0.1, 0.1}, .radius_m = 0.03};
//   cell::capsule_distance(a, b).distance_m;             // 0.12 (m) between the surfaces
//   const cell::Solid table =                            // 1 m x 1 m x 40 mm, top at z = 0
//       cell::make_box({1, 1, 0.04}, math::Transform::translation(0, 0, -0.02));
//   cell::capsule_solid_distance(a, table).distance_m;   // -0.05: a's end sphere is in it
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>

#include "rccx/math/transform.hpp"

namespace rccx::cell {

/// An axis-aligned box, corners in m.
struct Aabb {
  math::Vec3 lo_m;
  math::Vec3 hi_m;
};

/// True when the boxes are closer than margin_m along every axis (the boxes touch when each is
/// grown by margin_m / 2).
[[nodiscard]] inline bool overlap(const Aabb& a, const Aabb& b, double margin_m) noexcept {
  return a.lo_m.x <= b.hi_m.x + margin_m && b.lo_m.x <= a.hi_m.x + margin_m &&
         a.lo_m.y <= b.hi_m.y + margin_m && b.lo_m.y <= a.hi_m.y + margin_m &&
         a.lo_m.z <= b.hi_m.z + margin_m && b.lo_m.z <= a.hi_m.z + margin_m;
}

/// A named capsule fixed in one of a robot's frames, for the collision check: what the DH chain
/// does not say (a pedestal, a flange, a hand, the tool). Points in that frame, m. Read from a
/// cell file (CellRobot::shapes), placed in the world by RobotCapsules.
struct RobotShape {
  std::string name;       ///< "pedestal", "flange", "probe": what a stop message calls it
  std::size_t frame = 0;  ///< 0: the base frame; i: link i's frame; dof: T6
  math::Vec3 from_m;
  math::Vec3 to_m;
  double radius_m = 0.0;
  std::string note;
};

/// Shapes a robot may carry.
inline constexpr std::size_t kMaxRobotShapes = 16;

/// A capsule in world coordinates: the points within radius_m of the segment p0_m .. p1_m.
struct Capsule {
  math::Vec3 p0_m;
  math::Vec3 p1_m;
  double radius_m = 0.0;
  Aabb bounds;            ///< the capsule's box, radius included
  std::uint8_t link = 0;  ///< the joint that moves it (0-based: DH link link + 1)
  /// -1: a piece of a DH link (or the sphere at its joint); else the index of the robot's
  /// named shape (RobotCapsules::shape_name): a pedestal, a flange, a hand, a tool.
  std::int8_t shape = -1;
  /// Fixed to the flange (T6): the hand and the tool, what a motion that may touch an object
  /// touches it with.
  bool tool = false;
  /// Reaches the robot's base origin in every configuration (a base shape, the first links'
  /// pieces from the origin): what may rest on the object the robot stands on.
  bool mounting = false;
};

/// A solid obstacle of the cell: a box of half extents half_m, or a cylinder of radius_m and
/// half height half_height_m along its z, centred on `pose` (world <- the solid's centre).
struct Solid {
  enum class Kind : std::uint8_t { box, cylinder };
  Kind kind = Kind::box;
  math::Vec3 half_m;
  double radius_m = 0.0;
  double half_height_m = 0.0;
  math::Transform pose;
  math::Transform inverse;  ///< pose^-1, kept so that each distance does not invert it
  Aabb bounds;              ///< in the world
};

/// A solid from its shape and pose (computes the inverse and the world box).
[[nodiscard]] Solid make_box(const math::Vec3& size_m, const math::Transform& pose) noexcept;
[[nodiscard]] Solid make_cylinder(double radius_m, double height_m,
                                  const math::Transform& pose) noexcept;

/// Signed distance from a point (world) to a solid's surface, m: negative inside, by the
/// depth to the nearest face.
[[nodiscard]] double signed_distance(const Solid& solid, const math::Vec3& p_m) noexcept;

/// The distance between a capsule and a solid.
struct SolidDistance {
  double distance_m = 0.0;  ///< between the surfaces; negative when they overlap
  math::Vec3 on_axis_m;     ///< the point of the capsule's axis nearest the solid
};

/// Capsule against solid: the signed distance of the solid is convex along the capsule's axis,
/// so a golden-section search over the axis finds its minimum (to 1e-9 of the axis' length);
/// the capsule's radius is then taken off.
[[nodiscard]] SolidDistance capsule_solid_distance(const Capsule& c, const Solid& s) noexcept;

/// The box around a capsule.
[[nodiscard]] inline Aabb bounds_of(const math::Vec3& p0_m, const math::Vec3& p1_m,
                                    double radius_m) noexcept {
  const math::Vec3 r{radius_m, radius_m, radius_m};
  const math::Vec3 lo{std::min(p0_m.x, p1_m.x), std::min(p0_m.y, p1_m.y), std::min(p0_m.z, p1_m.z)};
  const math::Vec3 hi{std::max(p0_m.x, p1_m.x), std::max(p0_m.y, p1_m.y), std::max(p0_m.z, p1_m.z)};
  return {lo - r, hi + r};
}

/// The closest points of two segments.
struct SegmentClosest {
  double distance_m = 0.0;
  double s = 0.0;          ///< fraction along the first segment, 0..1
  double t = 0.0;          ///< fraction along the second segment, 0..1
  math::Vec3 on_first_m;   ///< p0 + s (p1 - p0)
  math::Vec3 on_second_m;  ///< q0 + t (q1 - q0)
};

/// The closest points of the segments p0..p1 and q0..q1 (Ericson, Real-Time Collision
/// Detection, 5.1.9). Either segment may be a point, and parallel segments give one of their
/// closest pairs.
[[nodiscard]] SegmentClosest segment_distance(const math::Vec3& p0_m, const math::Vec3& p1_m,
                                              const math::Vec3& q0_m,
                                              const math::Vec3& q1_m) noexcept;

/// The distance between two capsules and where it is taken.
struct CapsuleDistance {
  /// Distance between the surfaces, m; negative when they overlap (by that depth along the
  /// line of the axes' closest points).
  double distance_m = 0.0;
  /// Closest points on each surface, along the line joining the axes' closest points; when the
  /// axes meet, both are that meeting point.
  math::Vec3 on_a_m;
  math::Vec3 on_b_m;
};

[[nodiscard]] CapsuleDistance capsule_distance(const Capsule& a, const Capsule& b) noexcept;

}  // namespace rccx::cell
