// Shared by the URDF tests: random joint values within limits, and the KDL oracle for URDF robots:
// a KDL chain built from a URDF file through urdfdom as kdl_parser builds it (each joint about its
// axis in the joint frame, each segment's frame the joint origin, each link's inertial as a
// RigidBodyInertia), independently of rccx's reader.
#pragma once

#include <urdf_parser/urdf_parser.h>

#include <cmath>
#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/rotationalinertia.hpp>
#include <random>
#include <string>
#include <vector>

#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/units.hpp"

namespace rccx::test {

inline KDL::Frame kdl_frame(const urdf::Pose& p) {
  return {KDL::Rotation::Quaternion(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w),
          KDL::Vector(p.position.x, p.position.y, p.position.z)};
}

/// A link's inertial as kdl_parser turns it into a RigidBodyInertia about the link frame's
/// origin: the tensor turned by the inertial origin's rotation, the mass at its position.
inline KDL::RigidBodyInertia kdl_inertia(const urdf::Link& link) {
  if (link.inertial == nullptr) return KDL::RigidBodyInertia::Zero();
  const urdf::Inertial& i = *link.inertial;
  const KDL::Frame origin = kdl_frame(i.origin);
  const KDL::RigidBodyInertia turned =
      origin.M *
      KDL::RigidBodyInertia(0, KDL::Vector::Zero(),
                            KDL::RotationalInertia(i.ixx, i.iyy, i.izz, i.ixy, i.ixz, i.iyz));
  return KDL::RigidBodyInertia(i.mass, origin.p, turned.getRotationalInertia());
}

/// The KDL chain from `base` to `tip` with each link's inertia (fixed joints stay segments of
/// their own; KDL's kinematics and dynamics carry them).
inline KDL::Chain kdl_chain_from_urdf(const urdf::ModelInterface& model, const std::string& base,
                                      const std::string& tip) {
  std::vector<urdf::LinkConstSharedPtr> links{model.getLink(tip)};
  while (links.back()->name != base) links.push_back(links.back()->getParent());
  KDL::Chain chain;
  for (auto it = links.rbegin() + 1; it != links.rend(); ++it) {
    const urdf::Joint& j = *(*it)->parent_joint;
    const KDL::Frame origin = kdl_frame(j.parent_to_joint_origin_transform);
    const KDL::Vector axis(j.axis.x, j.axis.y, j.axis.z);
    KDL::Joint joint(j.name, KDL::Joint::Fixed);
    if (j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS) {
      joint = KDL::Joint(j.name, origin.p, origin.M * axis, KDL::Joint::RotAxis);
    } else if (j.type == urdf::Joint::PRISMATIC) {
      joint = KDL::Joint(j.name, origin.p, origin.M * axis, KDL::Joint::TransAxis);
    }
    chain.addSegment(KDL::Segment((*it)->name, joint, origin, kdl_inertia(**it)));
  }
  return chain;
}

/// Joint values drawn uniformly within each joint's limits (a continuous joint within a turn).
inline kin::JointVector random_within_limits(const kin::RobotModel& m, std::mt19937_64& rng) {
  kin::JointVector q(m.dof());
  for (std::size_t i = 0; i < m.dof(); ++i) {
    const double lo = std::isfinite(m.joints[i].lower) ? m.joints[i].lower : -math::kPi;
    const double hi = std::isfinite(m.joints[i].upper) ? m.joints[i].upper : math::kPi;
    q[i] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

}  // namespace rccx::test
