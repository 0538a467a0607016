// A pose typed on the command line, the same way for every command that takes one (`kin ik`,
// `db put`): either --T, the top three rows of the matrix (12 numbers, m), or --xyz and --rpy
// with units:
//
//   --T 1,0,0,0.325,0,-1,0,0.15,0,0,-1,0.25
//   --xyz 325mm,150mm,250mm --rpy 180deg,0,0      // the same pose
//
// --xyz: m or mm (a bare number is m). --rpy: URDF's roll-pitch-yaw, about the fixed axes:
// roll about x, then pitch about y, then yaw about z (math::Rot3::from_urdf_rpy), in deg or rad
// (a bare number is rad), each within one turn. --xyz and --rpy go together (--rpy 0,0,0 for
// the base frame's orientation) so that a forgotten orientation is not taken as the identity.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <string_view>

#include "rccx/math/transform.hpp"

namespace rccx::tools {

struct PoseArgs {
  std::string T;    ///< 12 comma-separated numbers (m), or empty
  std::string xyz;  ///< 3 lengths with units, or empty
  std::string rpy;  ///< 3 angles with units, or empty
};

/// Adds --T, --xyz and --rpy to `cmd`; `frame` says what the pose is ("T6 (wrist frame) in the
/// base frame").
void add_pose_options(CLI::App& cmd, PoseArgs& pose, std::string_view frame);

/// The pose given, each value within `max_position_m` on each axis and the rotation
/// orthonormal and right-handed (1e-6). Throws BadArgument or io::ParseError (exit 2).
math::Transform pose_from(const PoseArgs& pose, double max_position_m);

/// A length: a number and m or mm ("0.325m", "325mm", "0.325" = m), within +-max_m.
double parse_length(std::string_view text, std::string_view what, double max_m);

/// An angle: a number and deg or rad ("90deg", "1.5708rad", "1.5708" = rad), within one turn.
double parse_angle(std::string_view text, std::string_view what);

}  // namespace rccx::tools
