// A robot from a URDF file (the Unified Robot Description Format of ROS), read with Debian's
// urdfdom, no ROS: the serial chain between a base link and a tip link, as a RobotModel of
// Geometry::chain that every solver, cell and plant of rccx takes like a DH model.
//
//   const kin::RobotModel ur5e = kin::load_urdf("robots/ur5e.urdf");   // root to the only leaf
//   const kin::RobotModel arm = kin::load_urdf("panda.urdf", {.tip_link = "panda_link8"});
//   const auto k = kin::make_kinematics(ur5e);                          // forward, inverse ...
//
// What is read, joint by joint from the base down to the tip:
//   - revolute and prismatic joints: a joint each (origin xyz / rpy, then the motion about or
//     along the unit axis), with their limits, velocity (max_velocity) and effort (max_effort);
//   - continuous joints: revolute with no limits (Joint::continuous);
//   - fixed joints: lumped, into the next joint's origin, or after the last joint into its
//     `after` (the flange), their links' masses into the moving link that carries them;
//   - each link's inertial: mass, centre of mass and inertia tensor (about the centre of
//     mass) in the link frame (JointDynamics), a fixed link's lumped into the moving link that
//     carries it (parallel axes; the last link's in the flange's frame).
// Refused with a RobotFileError naming the joint or link: floating and planar joints, mimic
// joints, a tree with no chain to the tip, a branching tree with no tip named (the message lists
// the leaves), non-finite or absurd numbers (a link over 100 m, a mass over 1e5 kg), more than
// kMaxJoints moving joints, a file over kMaxUrdfBytes. xacro files are not URDF: run
// `xacro robot.urdf.xacro > robot.urdf` first (the message says so).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include "rccx/kinematics/robot_model.hpp"

namespace rccx::kin {

struct UrdfOptions {
  /// The chain's first link: its frame is the robot's base frame. Empty: the tree's root.
  std::string base_link;
  /// The chain's last link: its frame is T6. Empty: the one leaf below the base (a tree that
  /// branches there needs it named).
  std::string tip_link;
};

/// Largest URDF read, bytes: a bigger file is refused before parsing (a robot's URDF without
/// meshes is tens of kB).
inline constexpr std::size_t kMaxUrdfBytes = 16u << 20;

/// The chain of a URDF text. `origin` names the text in messages. Throws RobotFileError.
RobotModel parse_urdf(std::string_view xml, std::string_view origin,
                      const UrdfOptions& options = {});
/// Reads and parses a URDF file. Throws RobotFileError (a missing or unreadable file too).
RobotModel load_urdf(const std::filesystem::path& path, const UrdfOptions& options = {});

/// True when `path` names a URDF by its extension (.urdf), so that callers taking robot files
/// can take both.
bool is_urdf_path(const std::filesystem::path& path);

}  // namespace rccx::kin
