// The standard DH table of a general chain (a URDF's), with the fixed transforms before and
// after it: forward(q) of the chain = base * A1(q1) ... An(qn) * tool for every q. A closed-form
// solver written for a DH structure (the PUMA's spherical wrist, the UR family's three parallel
// axes) then serves a robot read from URDF: the structure is recognised on the table.
//
//   const kin::RobotModel ur5e = kin::load_urdf("robots/ur5e.urdf");
//   if (const auto dh = kin::dh_equivalent(ur5e)) {
//     dh->model.joints[1].dh.a_m;   // -0.425
//     dh->base, dh->tool;           // identity for a URDF written from the DH table
//   }
//
// How (Paul's rules, thesis 3.4, on the joint axes at q = 0): frame i-1's z is joint i's axis;
// x_i lies along the common normal from axis i to axis i+1 (through frame i-1's origin when the
// two are parallel, so that d_i = 0 there; along z(i-1) x z(i) when they meet); frame 0's
// origin is the point of axis 1 nearest the base's origin; the last frame keeps the previous x
// and its origin is the point of the last axis nearest the flange, the rest going into `tool`.
#pragma once

#include <optional>

#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::kin {

struct DhEquivalent {
  RobotModel model;      ///< the same joints (limits, dynamics ...), Geometry::dh
  math::Transform base;  ///< the chain's base frame -> DH frame 0
  math::Transform tool;  ///< DH frame n -> the chain's T6 (its flange)
};

/// The DH table of `chain` (any Geometry::dh model is returned as it is, with identities).
/// nullopt for a chain with a prismatic joint (not needed by the closed forms).
std::optional<DhEquivalent> dh_equivalent(const RobotModel& chain);

}  // namespace rccx::kin
