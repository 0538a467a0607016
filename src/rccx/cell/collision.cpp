#include "rccx/cell/collision.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace rccx::cell {

namespace {

double along(const math::Vec3& v, int axis) noexcept {
  return axis == 0 ? v.x : (axis == 1 ? v.y : v.z);
}

// The sweep changes axis only when another spreads this much more: a switch costs a full sort,
// and robots hovering near equal spreads must not pay it every sample.
constexpr double kAxisHysteresis = 1.25;

Contact make_contact(std::size_t a, const Capsule& ca, std::size_t b, const Capsule& cb,
                     const CapsuleDistance& d) noexcept {
  return {a, ca.link, b, cb.link, d.distance_m, d.on_a_m, d.on_b_m};
}

}  // namespace

CollisionWorld::CollisionWorld(std::vector<RobotCapsules> robots, double margin_m)
    : robots_(std::move(robots)), margin_m_(margin_m) {
  if (!std::isfinite(margin_m) || margin_m < 0.0) {
    throw std::invalid_argument("collision margin " + std::to_string(margin_m) +
                                " m; it must be finite and not negative");
  }
  if (robots_.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument("too many robots for one collision world");
  }
  order_.resize(robots_.size());
  for (std::size_t i = 0; i < robots_.size(); ++i) order_[i].robot = static_cast<std::uint32_t>(i);
  // The first axis by spread; later calls keep it unless another spreads clearly more.
  double best = -1.0;
  for (int axis = 0; axis < 3; ++axis) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const RobotCapsules& r : robots_) {
      const double c = along(r.bounds().lo_m + r.bounds().hi_m, axis);
      lo = std::min(lo, c);
      hi = std::max(hi, c);
    }
    if (hi - lo > best) {
      best = hi - lo;
      axis_ = axis;
    }
  }
  sort_boxes();
}

bool CollisionWorld::set_configuration(std::size_t robot, const kin::JointVector& q) noexcept {
  return robot < robots_.size() && robots_[robot].update(q);
}

bool CollisionWorld::set_margin(double margin_m) noexcept {
  if (!std::isfinite(margin_m) || margin_m < 0.0) return false;
  margin_m_ = margin_m;
  return true;
}

void CollisionWorld::sort_boxes() noexcept {
  if (order_.empty()) return;
  // Boxes as they are now, and the spread of their centres (2x, which does not matter).
  math::Vec3 lo = robots_[order_[0].robot].bounds().lo_m, hi = lo;
  for (Entry& e : order_) {
    e.box = robots_[e.robot].bounds();
    const math::Vec3 c = e.box.lo_m + e.box.hi_m;
    lo = {std::min(lo.x, c.x), std::min(lo.y, c.y), std::min(lo.z, c.z)};
    hi = {std::max(hi.x, c.x), std::max(hi.y, c.y), std::max(hi.z, c.z)};
  }
  const math::Vec3 spread = hi - lo;
  int widest = 0;
  for (int axis = 1; axis < 3; ++axis) {
    if (along(spread, axis) > along(spread, widest)) widest = axis;
  }
  const bool switch_axis =
      widest != axis_ && along(spread, widest) > kAxisHysteresis * along(spread, axis_);
  if (switch_axis) axis_ = widest;
  for (Entry& e : order_) e.key = along(e.box.lo_m, axis_);
  if (switch_axis) {
    // The old order says nothing about the new axis; std::sort sorts in place.
    std::sort(order_.begin(), order_.end(),
              [](const Entry& x, const Entry& y) { return x.key < y.key; });
    return;
  }
  // Insertion sort: near-linear when the order changed little since the last sample.
  for (std::size_t i = 1; i < order_.size(); ++i) {
    if (order_[i - 1].key <= order_[i].key) continue;
    const Entry e = order_[i];
    std::size_t j = i;
    for (; j > 0 && order_[j - 1].key > e.key; --j) order_[j] = order_[j - 1];
    order_[j] = e;
  }
}

template <class OnPair>
void CollisionWorld::sweep(OnPair&& on_pair) noexcept {
  sort_boxes();
  stats_ = {};
  const std::size_t n = order_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Entry& ei = order_[i];
    const double reach = along(ei.box.hi_m, axis_) + margin_m_;
    // Sorted by the low end: the first box that starts beyond this one's reach ends the scan.
    for (std::size_t j = i + 1; j < n && order_[j].key <= reach; ++j) {
      const Entry& ej = order_[j];
      if (!overlap(ei.box, ej.box, margin_m_)) continue;
      ++stats_.robot_pairs;
      on_pair(std::min(ei.robot, ej.robot), std::max(ei.robot, ej.robot));
    }
  }
}

bool CollisionWorld::closest_below(std::size_t a, std::size_t b, double limit_m,
                                   Contact& out) noexcept {
  const RobotCapsules& ra = robots_[a];
  const RobotCapsules& rb = robots_[b];
  bool found = false;
  for (const Capsule& ca : ra.capsules()) {
    // A capsule's box within limit_m of another box is necessary for the capsules to be
    // within limit_m (also for a negative limit: an overlap of depth h overlaps the boxes by h).
    if (!overlap(ca.bounds, rb.bounds(), limit_m)) continue;
    for (const Capsule& cb : rb.capsules()) {
      if (!overlap(ca.bounds, cb.bounds, limit_m)) continue;
      ++stats_.capsule_pairs;
      const CapsuleDistance d = capsule_distance(ca, cb);
      if (d.distance_m < limit_m) {
        limit_m = d.distance_m;
        out = make_contact(a, ca, b, cb, d);
        found = true;
      }
    }
  }
  return found;
}

std::optional<Contact> CollisionWorld::check() noexcept {
  std::optional<Contact> best;
  Contact c;
  sweep([&](std::size_t a, std::size_t b) {
    // Only a pair closer than the best so far can replace it.
    const double limit = best ? best->distance_m : margin_m_;
    if (closest_below(a, b, limit, c)) best = c;
  });
  return best;
}

std::size_t CollisionWorld::contacts(std::span<Contact> out) noexcept {
  std::size_t count = 0;
  Contact c;
  sweep([&](std::size_t a, std::size_t b) {
    if (!closest_below(a, b, margin_m_, c)) return;
    if (count < out.size()) out[count] = c;
    ++count;
  });
  return count;
}

std::optional<Contact> CollisionWorld::check_all_pairs() const noexcept {
  std::optional<Contact> best;
  for (std::size_t a = 0; a < robots_.size(); ++a) {
    for (std::size_t b = a + 1; b < robots_.size(); ++b) {
      for (const Capsule& ca : robots_[a].capsules()) {
        for (const Capsule& cb : robots_[b].capsules()) {
          const CapsuleDistance d = capsule_distance(ca, cb);
          if (d.distance_m < (best ? best->distance_m : margin_m_)) {
            best = make_contact(a, ca, b, cb, d);
          }
        }
      }
    }
  }
  return best;
}

Contact CollisionWorld::min_distance(std::size_t a, std::size_t b) const noexcept {
  Contact best;
  best.distance_m = std::numeric_limits<double>::infinity();
  if (a >= robots_.size() || b >= robots_.size() || a == b) return best;
  const bool swap = b < a;
  const std::size_t lo = swap ? b : a, hi = swap ? a : b;
  best.robot_a = lo;
  best.robot_b = hi;
  for (const Capsule& ca : robots_[lo].capsules()) {
    for (const Capsule& cb : robots_[hi].capsules()) {
      const CapsuleDistance d = capsule_distance(ca, cb);
      if (d.distance_m < best.distance_m) best = make_contact(lo, ca, hi, cb, d);
    }
  }
  return best;
}

}  // namespace rccx::cell
