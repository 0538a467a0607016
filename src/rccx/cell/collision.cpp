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

// A distance that shrinks by less than this (m) since the last check is not an approach: two
// arms standing, their setpoints re-solved, change at rounding level.
constexpr double kApproach_m = 1e-12;
// Against a solid the distance comes from a search along the capsule's axis, exact to 1e-9 of
// its length: a standing arm's re-solved setpoint may move the result by that much.
constexpr double kApproachSolid_m = 1e-8;

Contact make_contact(std::size_t a, const Capsule& ca, std::size_t b, const Capsule& cb,
                     const CapsuleDistance& d) noexcept {
  return {a, ca.link, b, cb.link, d.distance_m, d.on_a_m, d.on_b_m};
}

}  // namespace

CollisionWorld::CollisionWorld(std::vector<RobotCapsules> robots, double margin_m,
                               std::vector<Solid> solids)
    : robots_(std::move(robots)),
      solids_(std::move(solids)),
      allowance_m_(robots_.size(), 0.0),
      touch_(robots_.size(), 0),
      margin_m_(margin_m) {
  if (!std::isfinite(margin_m) || margin_m < 0.0) {
    throw std::invalid_argument("collision margin " + std::to_string(margin_m) +
                                " m; it must be finite and not negative");
  }
  clearance_m_ = margin_m;
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

void CollisionWorld::set_allowance(std::size_t robot, double braking_m) noexcept {
  if (robot < allowance_m_.size()) {
    allowance_m_[robot] = std::isfinite(braking_m) && braking_m > 0.0 ? braking_m : 0.0;
  }
}

void CollisionWorld::set_touch(std::size_t robot, std::uint64_t solids) noexcept {
  if (robot < touch_.size()) touch_[robot] = solids;
}

bool CollisionWorld::exempt(std::size_t r, const Capsule& c, std::size_t s) const noexcept {
  if (c.mounting && robots_[r].mounted_on() == static_cast<int>(s)) return true;
  return c.tool && s < 64 && (touch_[r] >> s & 1U) != 0;
}

bool CollisionWorld::robot_threat(std::size_t a, std::size_t b, Threat& out) noexcept {
  const RobotCapsules& ra = robots_[a];
  const RobotCapsules& rb = robots_[b];
  // Neither moved since the last check: nothing approaches.
  if (!ra.moved() && !rb.moved()) return false;
  const double limit = clearance_m_ + allowance_m_[a] + allowance_m_[b];
  const std::span<const Capsule> ca_now = ra.capsules(), cb_now = rb.capsules();
  const std::span<const Capsule> ca_was = ra.before(), cb_was = rb.before();
  bool found = false;
  for (std::size_t i = 0; i < ca_now.size(); ++i) {
    const Capsule& ca = ca_now[i];
    if (!overlap(ca.bounds, rb.bounds(), limit)) continue;
    for (std::size_t k = 0; k < cb_now.size(); ++k) {
      const Capsule& cb = cb_now[k];
      if (!overlap(ca.bounds, cb.bounds, limit)) continue;
      ++stats_.capsule_pairs;
      const double d = capsule_distance(ca, cb).distance_m;
      if (!(d < limit) || (found && d >= out.distance_m)) continue;
      const double was = capsule_distance(ca_was[i], cb_was[k]).distance_m;
      if (!(d < was - kApproach_m)) continue;  // moving apart, or standing
      out = {a, i, false, b, k, d, was, limit};
      found = true;
    }
  }
  return found;
}

bool CollisionWorld::solid_threat(std::size_t r, std::size_t s, Threat& out) noexcept {
  const RobotCapsules& robot = robots_[r];
  const Solid& solid = solids_[s];
  const double limit = clearance_m_ + allowance_m_[r];
  if (!overlap(robot.bounds(), solid.bounds, limit)) return false;
  const std::span<const Capsule> now = robot.capsules(), was = robot.before();
  bool found = false;
  for (std::size_t i = 0; i < now.size(); ++i) {
    const Capsule& c = now[i];
    if (!overlap(c.bounds, solid.bounds, limit) || exempt(r, c, s)) continue;
    ++stats_.solid_pairs;
    const double d = capsule_solid_distance(c, solid).distance_m;
    if (!(d < limit) || (found && d >= out.distance_m)) continue;
    const double before = capsule_solid_distance(was[i], solid).distance_m;
    if (!(d < before - kApproachSolid_m)) continue;
    out = {r, i, true, s, 0, d, before, limit};
    found = true;
  }
  return found;
}

std::size_t CollisionWorld::threats(std::span<Threat> out) noexcept {
  // The broad phase passes every pair whose boxes come within the largest limit of this call.
  double widest = 0.0, second = 0.0;
  for (const double a : allowance_m_) {
    if (a > widest) {
      second = widest;
      widest = a;
    } else if (a > second) {
      second = a;
    }
  }
  std::size_t count = 0;
  Threat t;
  sweep(clearance_m_ + widest + second, [&](std::size_t a, std::size_t b) {
    if (!robot_threat(a, b, t)) return;
    if (count < out.size()) out[count] = t;
    ++count;
  });
  for (std::size_t r = 0; r < robots_.size(); ++r) {
    if (!robots_[r].moved()) continue;  // the solids stand: only a moving robot approaches
    for (std::size_t s = 0; s < solids_.size(); ++s) {
      if (!solid_threat(r, s, t)) continue;
      if (count < out.size()) out[count] = t;
      ++count;
    }
  }
  for (RobotCapsules& r : robots_) r.settle();
  return count;
}

SolidContact CollisionWorld::min_solid_distance(std::size_t robot, std::size_t solid,
                                                bool exemptions) const noexcept {
  SolidContact best;
  best.distance_m = std::numeric_limits<double>::infinity();
  if (robot >= robots_.size() || solid >= solids_.size()) return best;
  best.robot = robot;
  best.solid = solid;
  const std::span<const Capsule> caps = robots_[robot].capsules();
  for (std::size_t i = 0; i < caps.size(); ++i) {
    if (exemptions && exempt(robot, caps[i], solid)) continue;
    const SolidDistance d = capsule_solid_distance(caps[i], solids_[solid]);
    if (d.distance_m < best.distance_m) {
      best.capsule = i;
      best.distance_m = d.distance_m;
      best.point_m = d.on_axis_m;
    }
  }
  return best;
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
void CollisionWorld::sweep(double margin_m, OnPair&& on_pair) noexcept {
  sort_boxes();
  stats_ = {};
  const std::size_t n = order_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Entry& ei = order_[i];
    const double reach = along(ei.box.hi_m, axis_) + margin_m;
    // Sorted by the low end: the first box that starts beyond this one's reach ends the scan.
    for (std::size_t j = i + 1; j < n && order_[j].key <= reach; ++j) {
      const Entry& ej = order_[j];
      if (!overlap(ei.box, ej.box, margin_m)) continue;
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
  sweep(margin_m_, [&](std::size_t a, std::size_t b) {
    // Only a pair closer than the best so far can replace it.
    const double limit = best ? best->distance_m : margin_m_;
    if (closest_below(a, b, limit, c)) best = c;
  });
  return best;
}

std::size_t CollisionWorld::contacts(std::span<Contact> out) noexcept {
  std::size_t count = 0;
  Contact c;
  sweep(margin_m_, [&](std::size_t a, std::size_t b) {
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
