// One robot as capsules in the world, the whole arm: its links, its joints, its base, its hand
// and its tool, for the collision check between arms and against the cell's objects.
//
//   const std::vector<double> radii(model.dof(), 0.05);   // m, one per link (or one for all)
//   cell::RobotCapsules robot(model, radii, base, shapes);  // base: world <- frame 0
//   robot.update(q);                                     // rad / m; noexcept, no allocation
//   for (const cell::Capsule& c : robot.capsules()) ...  // c.p0_m .. c.p1_m, c.radius_m
//   robot.link_frame(model.dof() - 1);                   // world <- T6 at q
//
// Link i of a DH robot runs from the origin of frame i-1 to the origin of frame i: first d_i
// along z_(i-1), then a_i along x_i (standard DH). Each non-zero part is one capsule (a
// prismatic joint's d part is always one, since its length changes with q). A link with
// neither (a wrist joint: the PUMA's links 5 and 6, the Microbo's 1, 4, 5 and 6) is a sphere
// at its frame's origin, so that no joint is left out. Link i of a general chain (a URDF's,
// kin::Geometry::chain) runs from frame i-1's origin to joint i's (its origin's offset), and
// the last link on to the flange (its `after`); a prismatic joint's travel is a capsule of its
// own. Radii: one per link, from the cell file. A model with its own collision capsules
// (kin::RobotModel::collision, a URDF's <collision> geometry) adds those, in their frames,
// named by their URDF link in messages; its link radii may then be left out (none given).
// Named shapes (RobotShape) add what the chain does not say: a pedestal in the base frame, a
// flange, a hand and the tool in T6.
//
// What the pieces are is worked out once at construction (which may allocate and throw);
// update(q) then only computes the link frames and the world-space segments and boxes:
// noexcept, no allocation. The capsules before the last update are kept (before()), so that a
// check can tell two parts approaching from two parts moving apart.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/cell/capsule.hpp"
#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/kinematics/link_frames.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::cell {

class RobotCapsules {
 public:
  /// Two capsules per joint (the d part and the a part, or the joint's sphere; a chain's offset
  /// and its prismatic travel), the model's own collision capsules and the shapes.
  static constexpr std::size_t kMaxShapes = kMaxRobotShapes;
  static constexpr std::size_t kMaxCapsules =
      2 * kin::kMaxJoints + 1 + kin::kMaxCollisionCapsules + kMaxShapes;

  /// `link_radius_m` holds one radius (m) for every link or one per joint, or none when the
  /// model has collision capsules of its own; `base` places the robot's frame 0 in the world;
  /// `shapes` adds named capsules (at most kMaxShapes). Throws std::invalid_argument for a
  /// model of more than kin::kMaxJoints joints or none, a wrong number of radii, a radius that
  /// is negative or not finite, more than kin::kMaxCollisionCapsules model capsules, or a bad
  /// shape or model capsule (a frame past T6, a point or radius not finite). The capsules start
  /// at the model's ready pose.
  RobotCapsules(const kin::RobotModel& model, std::span<const double> link_radius_m,
                const math::Transform& base = math::Transform::identity(),
                std::span<const RobotShape> shapes = {});

  /// Moves the capsules to joint values q (rad / m). False, and nothing changed, when q has the
  /// wrong size or a value that is not finite. The capsules as they were go to before() unless
  /// an update since the last settle() put them there already.
  bool update(const kin::JointVector& q) noexcept;
  /// The check has compared before() with capsules(): from now on before() is capsules()
  /// until the next update.
  void settle() noexcept { moved_ = false; }
  /// True when update() has moved the capsules since the last settle().
  [[nodiscard]] bool moved() const noexcept { return moved_; }

  /// How a piece's far end follows its joint: fixed in its frame; a DH prismatic joint's d
  /// part (the far end along z by d + q); a chain's prismatic travel (from_m, the joint's
  /// origin, to from_m + to_m q, to_m the axis in that frame).
  enum class Motion : std::uint8_t { fixed, dh_prismatic, chain_prismatic };
  /// Where a capsule is: a segment in frame `frame` (0 base, i link i).
  struct Piece {
    std::uint8_t frame = 0;
    Motion motion = Motion::fixed;
    std::uint8_t joint = 0;  ///< the prismatic joint (0-based) of a moving piece
    math::Vec3 from_m;
    math::Vec3 to_m;
  };
  /// Where each capsule is, in its frame, in the order of capsules(): what the view draws
  /// the collision model from.
  [[nodiscard]] std::span<const Piece> pieces() const noexcept { return {pieces_.data(), count_}; }

  [[nodiscard]] std::span<const Capsule> capsules() const noexcept {
    return {capsules_.data(), count_};
  }
  /// The capsules at the last settle() (the same as capsules() when nothing moved since).
  [[nodiscard]] std::span<const Capsule> before() const noexcept {
    return moved_ ? std::span<const Capsule>{before_.data(), count_} : capsules();
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
  /// The name of a capsule's shape ("probe"), or "" for a link's piece.
  [[nodiscard]] std::string_view shape_name(const Capsule& c) const noexcept {
    return c.shape < 0 ? std::string_view{} : std::string_view{shape_names_[c.shape]};
  }
  /// The object index (of the cell's objects) the robot stands on, whose contact with the
  /// robot's mounting capsules is not a collision; -1: none.
  [[nodiscard]] int mounted_on() const noexcept { return mounted_on_; }
  void set_mounted_on(int object) noexcept { mounted_on_ = object; }

 private:
  void add_link_pieces_dh(std::span<const double> link_radius_m);
  void add_link_pieces_chain(const kin::RobotModel& model, std::span<const double> link_radius_m);
  /// Frames 0 .. this sit at the base origin in every configuration (every link before them
  /// a pure rotation): pieces from their origin rest on what the robot stands on.
  std::size_t origin_frames_ = 0;

  kin::DhChain chain_;
  math::Transform base_;
  std::array<Piece, kMaxCapsules> pieces_{};
  std::array<Capsule, kMaxCapsules> capsules_{};
  std::array<Capsule, kMaxCapsules> before_{};
  std::vector<std::string> shape_names_;
  /// update()'s link frames, kept here so that each call does not initialise new ones.
  std::array<math::Transform, kin::kMaxJoints> frames_{};
  std::size_t count_ = 0;
  Aabb bounds_;
  kin::JointVector q_;
  bool moved_ = false;
  int mounted_on_ = -1;
};

/// A capsule's name in messages: "link 4" (written into `buf`), or its shape's name. Allocates
/// nothing: the sample loop's stop messages use it.
std::string_view part_name(const RobotCapsules& robot, const Capsule& c,
                           std::array<char, 16>& buf) noexcept;

}  // namespace rccx::cell
