// One robot's links as capsules in the world, for the collision check between arms.
//
// Link i of a DH robot runs from the origin of frame i-1 to the origin of frame i: first d_i
// along z_(i-1), then a_i along x_i (standard DH). Each non-zero part is one capsule (a
// prismatic joint's d part is always one, since its length changes with q). What the pieces
// are is worked out once at construction (which may allocate and throw); update(q) then only
// computes the link frames and the world-space segments and boxes: noexcept, no allocation.
#pragma once

#include <array>
#include <cstddef>
#include <span>

#include "rccx/cell/capsule.hpp"
#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/kinematics/link_frames.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::cell {

class RobotCapsules {
 public:
  /// At most two capsules per joint (the d part and the a part).
  static constexpr std::size_t kMaxCapsules = 2 * kin::kMaxJoints;

  /// `link_radius_m` holds one radius (m) for every link or one per joint; `base` places the
  /// robot's frame 0 in the world. Throws std::invalid_argument for a model of more than
  /// kin::kMaxJoints joints or none, a wrong number of radii, or a radius that is negative or
  /// not finite. The capsules start at the model's ready pose.
  RobotCapsules(const kin::RobotModel& model, std::span<const double> link_radius_m,
                const math::Transform& base = math::Transform::identity());

  /// Moves the capsules to joint values q (rad / m). False, and nothing changed, when q has the
  /// wrong size or a value that is not finite.
  bool update(const kin::JointVector& q) noexcept;

  [[nodiscard]] std::span<const Capsule> capsules() const noexcept {
    return {capsules_.data(), count_};
  }
  /// The box around every capsule, m.
  [[nodiscard]] const Aabb& bounds() const noexcept { return bounds_; }
  [[nodiscard]] const math::Transform& base() const noexcept { return base_; }
  [[nodiscard]] std::size_t dof() const noexcept { return chain_.dof; }
  /// The joint values of the last successful update.
  [[nodiscard]] const kin::JointVector& configuration() const noexcept { return q_; }
  /// World <- frame i+1 of the chain at the last successful update (frame dof() - 1 is the
  /// world's T6): what the cell's tool frame is taken from, so that a robot's forward
  /// kinematics run once a tick.
  [[nodiscard]] const math::Transform& link_frame(std::size_t i) const noexcept {
    return frames_[i];
  }

 private:
  /// Which part of which link a capsule covers.
  struct Piece {
    std::uint8_t link = 0;
    bool along_z = false;  ///< the d part (along z_(i-1)); else the a part (along x_i)
  };

  kin::DhChain chain_;
  math::Transform base_;
  std::array<double, kin::kMaxJoints> radius_m_{};
  std::array<Piece, kMaxCapsules> pieces_{};
  std::array<Capsule, kMaxCapsules> capsules_{};
  /// update()'s link frames, kept here so that each call does not initialise new ones.
  std::array<math::Transform, kin::kMaxJoints> frames_{};
  std::size_t count_ = 0;
  Aabb bounds_;
  kin::JointVector q_;
};

}  // namespace rccx::cell
