// Position equations (thesis 2.4.1, RCCL's makeposition): a left side holding T6 and a right
// side, both products of transforms, with one transform of the left side named the tool:
//
//     A1 .. Ak  T6  B1 .. Bj(tool)  Bj+1 .. Bm  =  C1 .. Cn
//
// The frame the trajectory generator moves on straight lines in Cartesian mode is the tool
// frame F = T6 B1 .. Bj; its goal is
//
//     F = Ak⁻¹ .. A1⁻¹  C1 .. Cn  Bm⁻¹ .. Bj+1⁻¹        and then   T6 = F (B1 .. Bj)⁻¹.
//
// Runs of adjacent constant factors of both products are multiplied once, here. A position can
// also be a joint vector (RCCL's `park`): its goal is given in joints, not by an equation.
#pragma once

#include <array>
#include <atomic>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/rccl/transforms.hpp"

namespace rccx::rccl {

/// A malformed equation; the message says what is wrong and how to write it.
class EquationError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// At most this many hold transforms in one equation (their latched values travel with each
/// motion, by value).
inline constexpr std::size_t kMaxHolds = 8;

/// The values of an equation's hold transforms, latched when a motion starts.
struct LatchedHolds {
  std::array<math::Transform, kMaxHolds> values{};
};

class Position;
using PositionPtr = std::shared_ptr<Position>;

class Position {
 public:
  /// The equation `lhs = rhs` with `tool` one of the left side's transforms at or after T6
  /// (T6 itself: no tool). Throws EquationError when T6 is missing, on the right side or there
  /// twice, when the tool is not on the left side at or after T6, when a transform appears
  /// twice, a pointer is null, the right side is empty, or there are more than kMaxHolds hold
  /// transforms.
  static PositionPtr make(std::string name, const std::vector<TransformPtr>& lhs,
                          const std::vector<TransformPtr>& rhs, const TransformPtr& tool);
  /// The same with the tool the left side's last transform, as most equations have it (T6
  /// itself when nothing follows it), so that it is named once:
  /// `make("GET", {t6, tool}, {obj, grasp})` is `T6 TOOL = OBJ GRASP (tool TOOL)`.
  static PositionPtr make(std::string name, const std::vector<TransformPtr>& lhs,
                          const std::vector<TransformPtr>& rhs);
  /// A position given in joint values (rad / m), like RCCL's park.
  static PositionPtr joints(std::string name, const kin::JointVector& q);

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  /// True for a position given in joints.
  [[nodiscard]] bool in_joints() const noexcept { return in_joints_; }
  [[nodiscard]] const kin::JointVector& joint_values() const noexcept { return joints_; }
  /// True when a functional transform takes part: the goal moves while the arm moves.
  [[nodiscard]] bool moves() const noexcept { return moves_; }
  /// True when every factor is constant (a hold counts as constant here: its value is the one
  /// the planning level last set).
  [[nodiscard]] bool fixed() const noexcept { return !moves_; }
  /// The equation as written, e.g. "T6 TOOL = CONV OBJ GRASP (tool TOOL)".
  [[nodiscard]] std::string describe() const;
  /// How many factors the goal and tool products have after constants were multiplied.
  [[nodiscard]] std::size_t goal_factor_count() const noexcept { return goal_.size(); }
  [[nodiscard]] std::size_t tool_factor_count() const noexcept { return tool_.size(); }
  /// The equation's sides as written and its tool (T6 itself: none); empty for joints. What a
  /// position is sent across processes as (net::encode_position).
  [[nodiscard]] const std::vector<TransformPtr>& lhs() const noexcept { return lhs_; }
  [[nodiscard]] const std::vector<TransformPtr>& rhs() const noexcept { return rhs_; }
  [[nodiscard]] const TransformPtr& tool_transform() const noexcept { return tool_transform_; }

  /// Planning level: T6 for the present values (hold transforms as last set). Only for
  /// positions without functional transforms (otherwise std::logic_error).
  [[nodiscard]] math::Transform t6_now() const;
  /// Planning level: T6 for the values at `ctx` - functional transforms called afresh with it
  /// (from the planning thread: their functions must allow that), holds as last set.
  [[nodiscard]] math::Transform t6_at(const SampleContext& ctx) const;
  /// Planning level: the tool product B1 .. Bj (identity for a position in joints).
  [[nodiscard]] math::Transform tool_now() const;

  /// RCCL's update (thesis 4.5.4.4): the value transform `x` must have for the equation to hold
  /// with T6 = `t6` (m, rad), the other transforms at their present values (functional ones
  /// called with `ctx`). `x` may stand on either side, but is not T6. Throws EquationError
  /// when `x` is not in the equation or is T6. Teach stores the result (a hold: set()).
  [[nodiscard]] math::Transform solve_for(const Transform& x, const math::Transform& t6,
                                          const SampleContext& ctx = {}) const;

  // --- Sample loop -------------------------------------------------------------------------
  /// Latches the hold transforms' present values.
  void latch(LatchedHolds& holds) const noexcept;
  /// The tool frame's goal F and the tool product (B1 .. Bj) at this sample.
  void evaluate(const SampleContext& ctx, const LatchedHolds& holds, math::Transform& goal,
                math::Transform& tool) const;

  /// Motions to this position queued and not yet ended (RCCL's `p->end`: waitfor it to reach
  /// zero). Incremented by move(), decremented by the trajectory generator.
  mutable std::atomic<int> pending_ends{0};

 private:
  struct Factor {
    TransformKind kind = TransformKind::constant;
    const Transform* source = nullptr;  ///< functional and hold factors
    bool inverted = false;
    std::uint8_t hold_slot = 0;
    math::Transform value;  ///< constant factors: the multiplied run
  };
  using Factors = std::vector<Factor>;
  static void append(Factors& to, const TransformPtr& t, bool inverted, std::uint8_t& holds);
  static math::Transform product(const Factors& f, const SampleContext& ctx,
                                 const LatchedHolds& holds);

  Position() = default;
  std::string name_;
  bool in_joints_ = false;
  bool moves_ = false;
  kin::JointVector joints_;
  std::vector<TransformPtr> lhs_, rhs_;  ///< as written: keeps the transforms alive
  TransformPtr tool_transform_;
  Factors goal_, tool_;
  std::array<const Transform*, kMaxHolds> holds_{};
  std::uint8_t hold_count_ = 0;
};

}  // namespace rccx::rccl
