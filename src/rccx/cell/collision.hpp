// Safety between arms: every robot of a cell as capsules around its links, checked every
// sample for pairs of capsules of different robots closer than a margin.
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

/// What the last check or contacts call did, for benchmarks and reports.
struct CheckStats {
  std::size_t robot_pairs = 0;    ///< pairs the broad phase passed to the narrow phase
  std::size_t capsule_pairs = 0;  ///< capsule distances computed
};

class CollisionWorld {
 public:
  /// Robots (each with its base placement) and the margin in m: capsules of different robots
  /// closer than margin_m are a contact. Throws std::invalid_argument for a negative or
  /// non-finite margin. The robots start in the configuration their capsules hold.
  CollisionWorld(std::vector<RobotCapsules> robots, double margin_m);

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

  [[nodiscard]] std::size_t size() const noexcept { return robots_.size(); }
  [[nodiscard]] double margin_m() const noexcept { return margin_m_; }
  /// Changes the margin (m) for the next calls: a cell narrows it to what its robots' speeds
  /// need at this tick, so that the broad phase passes fewer pairs. False, and nothing changed,
  /// for a negative or non-finite margin.
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
  /// Calls on_pair(a, b) for each robot pair whose boxes come within the margin.
  template <class OnPair>
  void sweep(OnPair&& on_pair) noexcept;
  /// The closest capsule pair of robots a and b closer than limit_m, into out; false if none.
  bool closest_below(std::size_t a, std::size_t b, double limit_m, Contact& out) noexcept;

  std::vector<RobotCapsules> robots_;
  std::vector<Entry> order_;
  int axis_ = 0;
  double margin_m_ = 0.0;
  CheckStats stats_;
};

}  // namespace rccx::cell
