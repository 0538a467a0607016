// A URDF link's <collision> primitives enclosed by capsules, for the cell's collision check: a
// safety model is never smaller than the arm, so each capsule holds its primitive whole.
//
//   const math::Transform at = ...;                        // link frame <- the primitive's frame
//   kin::enclose_cylinder(at, 0.06, 0.3);                  // radius 0.06, segment +-0.15 along z
//   kin::enclose_box(at, {0.1, 0.2, 0.4});                 // along z (its longest edge)
//   kin::drop_enclosed(capsules);                          // Franka's cylinder + 2 spheres -> 1
//
// A sphere is its own capsule (a segment of no length). A cylinder of radius r and length L is
// the capsule of radius r along its axis from -L/2 to +L/2: the side is exact, the caps bulge
// r beyond the end faces. A box is the capsule along its longest edge, from face to face,
// whose radius is half the diagonal of the other two edges: every corner lies on it. Meshes
// are not enclosed (rccx reads no mesh files): the URDF reader lists their links
// (CollisionModel::mesh_links).
#pragma once

#include <vector>

#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::kin {

/// The capsule around a sphere of radius_m centred on `at`'s origin, in `at`'s parent frame.
LinkCapsule enclose_sphere(const math::Transform& at, double radius_m);
/// Around a cylinder of radius_m and length_m along `at`'s z, centred on its origin.
LinkCapsule enclose_cylinder(const math::Transform& at, double radius_m, double length_m);
/// Around a box of edges size_m (along `at`'s x, y, z), centred on its origin.
LinkCapsule enclose_box(const math::Transform& at, const math::Vec3& size_m);

/// True when capsule `inner` lies inside `outer` (same frame): both of inner's end spheres do,
/// and a capsule is convex, so the hull of the two does too.
bool encloses(const LinkCapsule& outer, const LinkCapsule& inner) noexcept;

/// Removes every capsule that lies inside another of the same frame (of two equal ones, keeps
/// the first): what a URDF writes as a capsule (a cylinder and a sphere at each end) becomes
/// one capsule again.
void drop_enclosed(std::vector<LinkCapsule>& capsules);

}  // namespace rccx::kin
