#include "rccx/cell/robot_capsules.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "rccx/io/fixed_text.hpp"

namespace rccx::cell {

namespace {

// DH lengths below this (m) have no capsule: a link with only an a part, or only a d part,
// gets one capsule, not a second of zero length.
constexpr double kZeroLength_m = 1e-9;

bool finite(const math::Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

RobotCapsules::RobotCapsules(const kin::RobotModel& model, std::span<const double> link_radius_m,
                             const math::Transform& base, std::span<const RobotShape> shapes)
    : base_(base) {
  const std::size_t dof = model.dof();
  if (dof == 0 || dof > kin::kMaxJoints) {
    throw std::invalid_argument("robot " + model.name + ": " + std::to_string(dof) +
                                " joints; collision capsules need 1 to " +
                                std::to_string(kin::kMaxJoints));
  }
  const std::vector<kin::LinkCapsule>& own = model.collision.capsules;
  const bool none_ok = !own.empty();  // the model's own capsules stand for its links
  if (link_radius_m.size() != 1 && link_radius_m.size() != dof &&
      !(none_ok && link_radius_m.empty())) {
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
  if (shapes.size() > kMaxShapes) {
    throw std::invalid_argument(
        fmt::format("robot {}: {} shapes; at most {}", model.name, shapes.size(), kMaxShapes));
  }
  if (own.size() > kin::kMaxCollisionCapsules) {
    throw std::invalid_argument(
        fmt::format("robot {}: {} collision capsules of its own; at most {}", model.name,
                    own.size(), kin::kMaxCollisionCapsules));
  }
  chain_ = kin::DhChain(model);
  q_ = kin::JointVector(dof);
  if (!link_radius_m.empty()) {
    if (model.geometry == kin::Geometry::chain) {
      add_link_pieces_chain(model, link_radius_m);
    } else {
      add_link_pieces_dh(link_radius_m);
    }
  } else if (model.geometry == kin::Geometry::dh) {
    add_link_pieces_dh(std::array<double, 1>{0.0});  // only for origin_frames_: dropped below
    count_ = 0;
  } else {
    add_link_pieces_chain(model, std::array<double, 1>{0.0});
    count_ = 0;
  }
  // Named capsules: the model's own (named by their link), then the cell's shapes.
  const auto add_named = [&](std::size_t frame, const math::Vec3& from, const math::Vec3& to,
                             double radius, const std::string& name, bool shape) {
    if (frame > dof) {
      throw std::invalid_argument(
          fmt::format("robot {}: {} \"{}\" is in frame {}; 0 (the base) to {} (T6)", model.name,
                      shape ? "shape" : "collision capsule of link", name, frame, dof));
    }
    if (!finite(from) || !finite(to) || !std::isfinite(radius) || radius < 0.0) {
      throw std::invalid_argument(fmt::format(
          "robot {}: {} \"{}\": its points and radius must be finite, the radius not negative",
          model.name, shape ? "shape" : "collision capsule of link", name));
    }
    Capsule& c = capsules_[count_];
    c.link = static_cast<std::uint8_t>(frame == 0 ? 0 : frame - 1);
    c.radius_m = radius;
    c.shape = static_cast<std::int8_t>(shape_names_.size());
    c.tool = shape && frame == dof;
    // A base shape never moves: it rests on what the robot stands on.
    c.mounting = frame == 0 || (frame <= origin_frames_ &&
                                (from.norm() <= kZeroLength_m || to.norm() <= kZeroLength_m));
    pieces_[count_++] = {static_cast<std::uint8_t>(frame), Motion::fixed, 0, from, to};
    shape_names_.push_back(name);
  };
  for (const kin::LinkCapsule& k : own) {
    add_named(k.frame, k.from_m, k.to_m, k.radius_m, k.link, false);
  }
  for (const RobotShape& s : shapes) add_named(s.frame, s.from_m, s.to_m, s.radius_m, s.name, true);
  const kin::JointVector ready = model.ready();
  if (!update(ready)) {
    throw std::invalid_argument("robot " + model.name + ": the ready pose is not finite");
  }
  settle();
}

void RobotCapsules::add_link_pieces_dh(std::span<const double> link_radius_m) {
  const std::size_t dof = chain_.dof;
  const auto radius = [&](std::size_t i) {
    return link_radius_m.size() == 1 ? link_radius_m[0] : link_radius_m[i];
  };
  // Frames 0 .. k have their origins at the base's in every configuration while every link
  // before them is a pure rotation: pieces that start there reach the base origin always.
  for (std::size_t i = 0; i < dof; ++i) {
    const kin::DhChain::Link& l = chain_.links[i];
    const auto add = [&](std::size_t frame, bool prismatic, const math::Vec3& from,
                         const math::Vec3& to) {
      Capsule& c = capsules_[count_];
      c.link = static_cast<std::uint8_t>(i);
      c.radius_m = radius(i);
      c.mounting = frame <= origin_frames_ && from.norm() <= kZeroLength_m;
      pieces_[count_++] = {static_cast<std::uint8_t>(frame),
                           prismatic ? Motion::dh_prismatic : Motion::fixed,
                           static_cast<std::uint8_t>(i), from, to};
    };
    const bool d_part = l.prismatic || std::abs(l.d_m) > kZeroLength_m;
    const bool a_part = std::abs(l.a_m) > kZeroLength_m;
    if (!d_part && !a_part && origin_frames_ == i) origin_frames_ = i + 1;
    // The d part, in frame i-1: from its origin along its z.
    if (d_part) add(i, l.prismatic, {0, 0, 0}, {0, 0, l.d_m});
    // The a part, in frame i: from -a along its x to its origin.
    if (a_part) add(i + 1, false, {-l.a_m, 0, 0}, {0, 0, 0});
    // Neither: the joint as a sphere at frame i's origin (where frame i-1's is too).
    if (!d_part && !a_part) add(i + 1, false, {0, 0, 0}, {0, 0, 0});
  }
}

void RobotCapsules::add_link_pieces_chain(const kin::RobotModel& model,
                                          std::span<const double> link_radius_m) {
  const std::size_t dof = chain_.dof;
  const auto radius = [&](std::size_t i) {
    return link_radius_m.size() == 1 ? link_radius_m[0] : link_radius_m[i];
  };
  for (std::size_t i = 0; i < dof; ++i) {
    const kin::ChainStep& step = model.joints[i].chain;
    const bool prismatic = model.joints[i].type == kin::JointType::prismatic;
    const auto add = [&](std::size_t frame, Motion motion, const math::Vec3& from,
                         const math::Vec3& to) {
      Capsule& c = capsules_[count_];
      c.link = static_cast<std::uint8_t>(i);
      c.radius_m = radius(i);
      c.mounting = frame <= origin_frames_ && from.norm() <= kZeroLength_m;
      pieces_[count_++] = {static_cast<std::uint8_t>(frame), motion, static_cast<std::uint8_t>(i),
                           from, to};
    };
    const bool offset = step.origin.p.norm() > kZeroLength_m;
    const bool flange = step.after.p.norm() > kZeroLength_m;  // the last joint's only
    // A link reached by rotations alone keeps its origin at the base's.
    if (!offset && !prismatic && origin_frames_ == i) origin_frames_ = i + 1;
    // From frame i-1's origin to joint i's, in frame i-1.
    if (offset) add(i, Motion::fixed, {0, 0, 0}, step.origin.p);
    // A prismatic joint's travel, from its origin along its axis (in frame i-1).
    if (prismatic) add(i, Motion::chain_prismatic, step.origin.p, step.origin.R * step.axis);
    // On to the flange, in T6: from the last link's origin (before `after`) to T6's.
    if (flange) add(i + 1, Motion::fixed, step.after.inverse().p, {0, 0, 0});
    // Neither: the joint as a sphere at frame i's origin.
    if (!offset && !prismatic && !flange) add(i + 1, Motion::fixed, {0, 0, 0}, {0, 0, 0});
  }
}

bool RobotCapsules::update(const kin::JointVector& q) noexcept {
  if (q.size() != chain_.dof) return false;
  for (const double v : q) {
    if (!std::isfinite(v)) return false;
  }
  if (!moved_) {
    std::copy_n(capsules_.begin(), count_, before_.begin());
    moved_ = true;
  }
  auto& frames = frames_;
  kin::link_frames(chain_, q, frames, base_);
  bool first = true;
  for (std::size_t k = 0; k < count_; ++k) {
    const Piece& piece = pieces_[k];
    Capsule& c = capsules_[k];
    const math::Transform& frame = piece.frame == 0 ? base_ : frames[piece.frame - 1];
    c.p0_m = frame * piece.from_m;
    const std::size_t j = piece.joint;
    switch (piece.motion) {
      case Motion::dh_prismatic:  // joint j's d part, its length d + q
        c.p1_m = frame.p + frame.R.a * (chain_.links[j].d_m + q[j]);
        break;
      case Motion::chain_prismatic:  // joint j's travel along its axis
        c.p1_m = c.p0_m + frame.R * piece.to_m * q[j];
        break;
      case Motion::fixed:
        c.p1_m = frame * piece.to_m;
        break;
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
  // Every robot has a capsule per joint now; kept for a robot of no joints' worth.
  if (first) bounds_ = {base_.p, base_.p};
  // Element by element: a JointVector assignment compiles to a slow block copy here.
  std::copy(q.begin(), q.end(), q_.begin());
  return true;
}

std::string_view part_name(const RobotCapsules& robot, const Capsule& c,
                           std::array<char, 16>& buf) noexcept {
  if (c.shape >= 0) return robot.shape_name(c);
  return io::format_fixed(buf, "link {}", c.link + 1);
}

}  // namespace rccx::cell
