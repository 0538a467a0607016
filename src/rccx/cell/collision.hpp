// Safety between arms: every robot of a cell as capsules around the whole arm (links, joints,
// hand, tool), and the cell's objects as solids, checked every sample.
//
//   std::vector<cell::RobotCapsules> robots;
//   robots.emplace_back(puma, puma_radii, puma_base);          // robot_capsules.hpp
//   robots.emplace_back(microbo, microbo_radii, microbo_base);
//   cell::CollisionWorld world(std::move(robots), 0.01, {table});   // 10 mm margin, solids
//   world.set_configuration(0, q);                  // every robot's next setpoint (rad / m)
//   std::array<cell::Threat, 8> out;
//   const std::size_t n = world.threats(out);       // pairs approaching within the margin
//
// The stop rule (threats()): a part of a robot within the margin plus the braking allowances
// (set_allowance) of a part of another robot, or of a solid, is a threat when the two
// approach: their distance now is less than at the last check (the capsules' before()). A
// setpoint that moves every such pair apart is no threat, so arms that stopped close together
// can be moved apart. A robot's mounting capsules may rest on the solid it stands on
// (RobotCapsules::set_mounted_on), and its tool capsules may touch the solids of its running
// motion's touch set (set_touch).
//
// The broad phase is sweep-and-prune over the robots' boxes along the axis where they spread
// most; the sorted order is kept between calls, so when robots move little between samples an
// insertion sort restores it in near-linear time. Only robot pairs whose boxes come within the
// margin go to the narrow phase (capsule against capsule, pruned by the capsules' own boxes).
//
// Real-time contract: the constructor may allocate and throw; after it, set_configuration,
// check, contacts, check_all_pairs and min_distance allocate nothing, take no lock and throw
// nothing (tests/collision_test.cpp counts operator new to prove it). A world is not shared
// between threads: one control thread owns it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "rccx/cell/capsule.hpp"
#include "rccx/cell/robot_capsules.hpp"
#include "rccx/kinematics/joint_vector.hpp"

namespace rccx::cell {

/// Two capsules of different robots, robot_a < robot_b.
struct Contact {
  std::size_t robot_a = 0;
  std::size_t link_a = 0;  ///< the joint that moves the capsule (0-based: DH link link_a + 1)
  std::size_t robot_b = 0;
  std::size_t link_b = 0;
  double distance_m = 0.0;  ///< between the surfaces; negative when they overlap
  math::Vec3 point_a_m;     ///< closest point on robot a's capsule, world frame
  math::Vec3 point_b_m;     ///< closest point on robot b's capsule, world frame
};

/// A robot's capsule and a solid.
struct SolidContact {
  std::size_t robot = 0;
  std::size_t capsule = 0;  ///< index in the robot's capsules()
  std::size_t solid = 0;
  double distance_m = 0.0;  ///< between the surfaces; negative when they overlap
  math::Vec3 point_m;       ///< the point of the capsule's axis nearest the solid, world frame
};

/// A pair about to come too close: what threats() reports, one per robot pair or robot and
/// solid (the closest of its approaching capsule pairs).
struct Threat {
  std::size_t robot_a = 0;
  std::size_t capsule_a = 0;  ///< index in robot_a's capsules()
  bool solid = false;         ///< b is a solid (capsule_b unused), else a robot > robot_a
  std::size_t b = 0;          ///< the other robot, or the solid
  std::size_t capsule_b = 0;
  double distance_m = 0.0;  ///< now
  double before_m = 0.0;    ///< at the last check
  double limit_m = 0.0;     ///< the margin plus the braking allowances
};

/// What the last check or contacts call did, for benchmarks and reports.
struct CheckStats {
  std::size_t robot_pairs = 0;    ///< pairs the broad phase passed to the narrow phase
  std::size_t capsule_pairs = 0;  ///< capsule distances computed
  std::size_t solid_pairs = 0;    ///< capsule-solid distances computed
};

class CollisionWorld {
 public:
  /// Robots (each with its base placement) and the margin in m: capsules of different robots
  /// closer than margin_m are a contact. Throws std::invalid_argument for a negative or
  /// non-finite margin. The robots start in the configuration their capsules hold.
  CollisionWorld(std::vector<RobotCapsules> robots, double margin_m,
                 std::vector<Solid> solids = {});

  /// Robot `robot`'s braking allowance, m (cell::Cell::braking_m): threats() stops a pair
  /// within the margin plus both allowances. Non-finite or negative values are taken as 0.
  void set_allowance(std::size_t robot, double braking_m) noexcept;
  /// The solids (bit i: solid i) robot `robot`'s tool capsules may touch for now: its running
  /// motion's touch set.
  void set_touch(std::size_t robot, std::uint64_t solids) noexcept;

  /// Every pair that approaches within its limit (the margin plus the allowances), against the
  /// last call: writes up to out.size() of them and returns how many there are. Then settles
  /// every robot (the next call compares with the capsules of now). At most one per robot pair
  /// and per robot and solid.
  std::size_t threats(std::span<Threat> out) noexcept;
  /// The most threats() can report: every robot pair, every robot with every solid.
  [[nodiscard]] std::size_t max_threats() const noexcept {
    return robots_.size() * (robots_.size() - 1) / 2 + robots_.size() * solids_.size();
  }

  /// Moves robot `robot` to joint values q (rad / m). False, and nothing changed, for an index
  /// out of range, q of the wrong size or a value that is not finite.
  bool set_configuration(std::size_t robot, const kin::JointVector& q) noexcept;

  /// The closest pair of capsules of different robots closer than the margin, if any.
  [[nodiscard]] std::optional<Contact> check() noexcept;

  /// For every robot pair closer than the margin, its closest capsule pair: writes up to
  /// out.size() of them (in no particular order) and returns how many there are.
  std::size_t contacts(std::span<Contact> out) noexcept;

  /// check() without the broad phase or any pruning: every capsule of every robot against every
  /// capsule of every other. The oracle of the tests and the peer of the benchmark.
  [[nodiscard]] std::optional<Contact> check_all_pairs() const noexcept;

  /// The closest capsule pair of robots a and b, whatever the margin (distance_m is +infinity
  /// when either has no capsule, an index is out of range or a == b).
  [[nodiscard]] Contact min_distance(std::size_t a, std::size_t b) const noexcept;

  /// The closest capsule of robot `robot` to solid `solid`, whatever the margin; with
  /// `exemptions`, leaving out the capsules that may be there (mounting, touch set).
  /// distance_m is +infinity for an index out of range or no capsule left.
  [[nodiscard]] SolidContact min_solid_distance(std::size_t robot, std::size_t solid,
                                                bool exemptions = true) const noexcept;

  [[nodiscard]] std::size_t size() const noexcept { return robots_.size(); }
  [[nodiscard]] const std::vector<Solid>& solids() const noexcept { return solids_; }
  [[nodiscard]] double margin_m() const noexcept { return margin_m_; }
  /// Changes the margin (m) of check(), contacts() and check_all_pairs() for the next calls.
  /// threats() keeps the margin the world was made with. False, and nothing changed, for a
  /// negative or non-finite margin.
  bool set_margin(double margin_m) noexcept;
  [[nodiscard]] const RobotCapsules& robot(std::size_t i) const noexcept { return robots_[i]; }
  [[nodiscard]] const CheckStats& last_stats() const noexcept { return stats_; }
  /// The axis the broad phase sweeps along (0 x, 1 y, 2 z).
  [[nodiscard]] int sweep_axis() const noexcept { return axis_; }

 private:
  /// A robot's box in the sweep order; key is lo_m along the sweep axis.
  struct Entry {
    double key = 0.0;
    Aabb box;
    std::uint32_t robot = 0;
  };

  /// Refreshes the boxes, picks the axis and restores the order.
  void sort_boxes() noexcept;
  /// Calls on_pair(a, b) for each robot pair whose boxes come within margin_m.
  template <class OnPair>
  void sweep(double margin_m, OnPair&& on_pair) noexcept;
  /// The closest capsule pair of robots a and b closer than limit_m, into out; false if none.
  bool closest_below(std::size_t a, std::size_t b, double limit_m, Contact& out) noexcept;

  /// Whether robot r's capsule c is exempt from solid s (mounting on it, or a tool touching it).
  [[nodiscard]] bool exempt(std::size_t r, const Capsule& c, std::size_t s) const noexcept;
  /// threats() for one robot pair and for one robot against the solids.
  bool robot_threat(std::size_t a, std::size_t b, Threat& out) noexcept;
  bool solid_threat(std::size_t r, std::size_t s, Threat& out) noexcept;

  std::vector<RobotCapsules> robots_;
  std::vector<Solid> solids_;
  std::vector<double> allowance_m_;
  std::vector<std::uint64_t> touch_;
  std::vector<Entry> order_;
  int axis_ = 0;
  double margin_m_ = 0.0;     ///< the broad phase's (set_margin)
  double clearance_m_ = 0.0;  ///< the clearance threats() keeps, as constructed
  CheckStats stats_;
};

}  // namespace rccx::cell
