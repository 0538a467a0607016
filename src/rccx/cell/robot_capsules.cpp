#include "rccx/cell/robot_capsules.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rccx::cell {

namespace {

// DH lengths below this (m) have no capsule: a link with only an a part, or only a d part,
// gets one capsule, not a second of zero length.
constexpr double kZeroLength_m = 1e-9;

}  // namespace

RobotCapsules::RobotCapsules(const kin::RobotModel& model, std::span<const double> link_radius_m,
                             const math::Transform& base)
    : base_(base) {
  const std::size_t dof = model.dof();
  if (dof == 0 || dof > kin::kMaxJoints) {
    throw std::invalid_argument("robot " + model.name + ": " + std::to_string(dof) +
                                " joints; collision capsules need 1 to " +
                                std::to_string(kin::kMaxJoints));
  }
  if (link_radius_m.size() != 1 && link_radius_m.size() != dof) {
    throw std::invalid_argument(
        "robot " + model.name + ": " + std::to_string(link_radius_m.size()) +
        " link radii; give one, or one per joint (" + std::to_string(dof) + ")");
  }
  for (const double r : link_radius_m) {
    if (!std::isfinite(r) || r < 0.0) {
      throw std::invalid_argument("robot " + model.name + ": link radius " + std::to_string(r) +
                                  " m; radii must be finite and not negative");
    }
  }
  chain_ = kin::DhChain(model);
  q_ = kin::JointVector(dof);
  for (std::size_t i = 0; i < dof; ++i) {
    radius_m_[i] = link_radius_m.size() == 1 ? link_radius_m[0] : link_radius_m[i];
    const kin::DhChain::Link& l = chain_.links[i];
    const auto link = static_cast<std::uint8_t>(i);
    if (l.prismatic || std::abs(l.d_m) > kZeroLength_m) pieces_[count_++] = {link, true};
    if (std::abs(l.a_m) > kZeroLength_m) pieces_[count_++] = {link, false};
  }
  for (std::size_t k = 0; k < count_; ++k) {
    capsules_[k].link = pieces_[k].link;
    capsules_[k].radius_m = radius_m_[pieces_[k].link];
  }
  const kin::JointVector ready = model.ready();
  if (!update(ready)) {
    throw std::invalid_argument("robot " + model.name + ": the ready pose is not finite");
  }
}

bool RobotCapsules::update(const kin::JointVector& q) noexcept {
  if (q.size() != chain_.dof) return false;
  for (const double v : q) {
    if (!std::isfinite(v)) return false;
  }
  auto& frames = frames_;
  kin::link_frames(chain_, q, frames, base_);
  bool first = true;
  for (std::size_t k = 0; k < count_; ++k) {
    const std::size_t i = pieces_[k].link;
    Capsule& c = capsules_[k];
    const math::Transform& end = frames[i];
    if (pieces_[k].along_z) {
      // From frame i-1's origin, d_i along its z.
      const math::Transform& start = i == 0 ? base_ : frames[i - 1];
      const double d = chain_.links[i].d_m + (chain_.links[i].prismatic ? q[i] : 0.0);
      c.p0_m = start.p;
      c.p1_m = start.p + start.R.a * d;
    } else {
      // To frame i's origin, a_i along its x.
      c.p1_m = end.p;
      c.p0_m = end.p - end.R.n * chain_.links[i].a_m;
    }
    c.bounds = bounds_of(c.p0_m, c.p1_m, c.radius_m);
    if (first) {
      bounds_ = c.bounds;
      first = false;
    } else {
      bounds_.lo_m = {std::min(bounds_.lo_m.x, c.bounds.lo_m.x),
                      std::min(bounds_.lo_m.y, c.bounds.lo_m.y),
                      std::min(bounds_.lo_m.z, c.bounds.lo_m.z)};
      bounds_.hi_m = {std::max(bounds_.hi_m.x, c.bounds.hi_m.x),
                      std::max(bounds_.hi_m.y, c.bounds.hi_m.y),
                      std::max(bounds_.hi_m.z, c.bounds.hi_m.z)};
    }
  }
  // A robot without capsules (every DH length zero) is a point at its base.
  if (first) bounds_ = {base_.p, base_.p};
  // Element by element: a JointVector assignment compiles to a slow block copy here.
  std::copy(q.begin(), q.end(), q_.begin());
  return true;
}

}  // namespace rccx::cell
