// Every link frame of a chain (DH or general), not only T6: what collision capsules and other
// per-link geometry need each sample. Noexcept and allocation-free, like forward().
//
//   const kin::DhChain chain(model);                 // once: the chain's constants
//   std::array<math::Transform, kin::kMaxJoints> frames;
//   kin::link_frames(chain, q, frames, base);        // each sample; q rad / m
//   frames[0];                                       // world <- frame 1 (base A1), m
//   frames[model.dof() - 1];                         // world <- T6
#pragma once

#include <array>
#include <cstddef>
#include <span>

#include "rccx/kinematics/dh_step.hpp"
#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::kin {

/// The constants of a model's DH chain (cos and sin of alpha taken once), for callers that
/// compute link frames every sample.
struct DhChain {
  struct Link {
    double a_m = 0.0;
    double cos_alpha = 1.0;
    double sin_alpha = 0.0;
    double d_m = 0.0;
    double theta_rad = 0.0;
    bool prismatic = false;
  };
  std::array<Link, kMaxJoints> links{};
  std::size_t dof = 0;  ///< at most kMaxJoints: joints past it are ignored
  /// A general chain's steps (Geometry::chain, a URDF's): used instead of `links` when set.
  std::array<PreparedStep, kMaxJoints> steps{};
  bool general = false;

  DhChain() = default;
  explicit DhChain(const RobotModel& model) noexcept;
};

/// Frames 1 .. dof of the chain for joint values q (rad / m): out[i] = base A1 ... A(i+1), the
/// frame of link i+1 (thesis eq. 3.11), so out[dof - 1] is base T6. Writes min(dof, out.size())
/// frames; q must have dof values.
void link_frames(const DhChain& chain, const JointVector& q, std::span<math::Transform> out,
                 const math::Transform& base = math::Transform::identity()) noexcept;

/// The same, from the model (computes the chain's constants on each call).
void link_frames(const RobotModel& model, const JointVector& q,
                 std::span<math::Transform> out) noexcept;

}  // namespace rccx::kin
