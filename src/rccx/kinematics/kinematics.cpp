#include "rccx/kinematics/kinematics.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "rccx/kinematics/dh_equivalent.hpp"
#include "rccx/kinematics/dh_kinematics.hpp"
#include "rccx/kinematics/dh_step.hpp"
#include "rccx/kinematics/microbo_kinematics.hpp"
#include "rccx/kinematics/puma_kinematics.hpp"
#include "rccx/kinematics/seven_axis_kinematics.hpp"
#include "rccx/kinematics/ur_kinematics.hpp"
#include "rccx/math/batch_trig.hpp"
#include "rccx/math/units.hpp"

namespace rccx::kin {

std::string_view to_string(IkStatus status) noexcept {
  switch (status) {
    case IkStatus::ok:
      return "ok";
    case IkStatus::out_of_reach:
      return "out_of_reach";
    case IkStatus::joint_limits:
      return "joint_limits";
    case IkStatus::singular:
      return "singular";
    case IkStatus::no_convergence:
      return "no_convergence";
    case IkStatus::bad_configuration:
      return "bad_configuration";
    case IkStatus::bad_input:
      return "bad_input";
  }
  return "?";
}

std::string_view describe(IkStatus status) noexcept {
  switch (status) {
    case IkStatus::ok:
      return "solved";
    case IkStatus::out_of_reach:
      return "out of reach: no joint values put T6 at this pose";
    case IkStatus::joint_limits:
      return "out of joint limits: the pose is reachable only with a joint outside its limits";
    case IkStatus::singular:
      return "stuck: a joint limit or a singularity blocks every step of the numeric solver (try "
             "another --near)";
    case IkStatus::no_convergence:
      return "no convergence: the numeric solver did not reach the pose (unreachable, or try "
             "another --near)";
    case IkStatus::bad_configuration:
      return "unknown configuration for this robot";
    case IkStatus::bad_input:
      return "bad input: the pose must be finite and --near must have one value per joint";
  }
  return "?";
}

std::string_view to_string(Singularity s) noexcept {
  switch (s) {
    case Singularity::none:
      return "none";
    case Singularity::shoulder:
      return "shoulder";
    case Singularity::elbow:
      return "elbow";
    case Singularity::wrist:
      return "wrist";
  }
  return "?";
}

Kinematics::Kinematics(RobotModel model) : model_(std::move(model)) {
  for (std::size_t i = 0; i < model_.dof(); ++i) {
    const Joint& j = model_.joints[i];
    links_[i] = {j.dh.a_m, std::cos(j.dh.alpha_rad), std::sin(j.dh.alpha_rad),
                 j.dh.d_m, j.dh.theta_rad,           j.type == JointType::prismatic};
    // cos(pi/2) is 6e-17, not 0; snap so that the DH chain is exact for the usual right angles.
    if (std::abs(links_[i].ca) < 1e-15) links_[i].ca = 0.0;
    if (std::abs(links_[i].sa) < 1e-15) links_[i].sa = 0.0;
    const double lo = j.lower - kLimitTolerance;
    const double hi = j.upper + kLimitTolerance;
    const bool revolute = j.type == JointType::revolute;
    // The widened range, so that a value within it never has a second turn within it too.
    limits_[i] = {j.lower, j.upper, lo, hi, revolute, revolute && hi - lo >= 2.0 * math::kPi};
  }
  general_ = model_.geometry == Geometry::chain;
  for (std::size_t i = 0; general_ && i < model_.dof(); ++i) {
    steps_[i] = PreparedStep(model_.joints[i].chain, model_.joints[i].type == JointType::prismatic);
  }
  ready_ = model_.ready();
}

std::optional<Configuration> Kinematics::find_configuration(std::string_view name) const noexcept {
  const auto names = configuration_names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return Configuration{static_cast<std::uint8_t>(i)};
  }
  return std::nullopt;
}

std::string_view Kinematics::configuration_name(Configuration c) const noexcept {
  const auto names = configuration_names();
  return c.index < names.size() ? names[c.index] : std::string_view{};
}

const JointVector* Kinematics::checked_reference(const math::Transform& pose,
                                                 const IkOptions& options) const noexcept {
  for (double v : pose.rows()) {
    if (!std::isfinite(v)) return nullptr;
  }
  if (!options.near) return &ready_;
  if (options.near->size() != dof()) return nullptr;
  for (double v : *options.near) {
    if (!std::isfinite(v)) return nullptr;
  }
  return &*options.near;
}

namespace {

// floor and ceil of a count of turns, inline: without SSE4.1 std::floor and std::ceil are
// library calls, and they were most of the cost of fitting a solution to the limits. Counts
// beyond +-1e9 turns are clamped (no joint has that range).
double floor_turns(double x) noexcept {
  const double t = std::clamp(x, -1e9, 1e9);
  const auto i = static_cast<std::int64_t>(t);
  return static_cast<double>(i - (t < static_cast<double>(i) ? 1 : 0));
}

double ceil_turns(double x) noexcept {
  const double t = std::clamp(x, -1e9, 1e9);
  const auto i = static_cast<std::int64_t>(t);
  return static_cast<double>(i + (t > static_cast<double>(i) ? 1 : 0));
}

}  // namespace

bool Kinematics::fit_to_limits(JointVector& q, const JointVector& toward) const noexcept {
  constexpr double kTurn = 2.0 * math::kPi;
  constexpr double kInvTurn = 1.0 / kTurn;
  bool within = true;
  for (std::size_t i = 0; i < dof(); ++i) {
    const Limit& l = limits_[i];
    double v = q[i];
    // The usual case, kept short: v within limits, and no other turn nearer `toward` (a joint
    // with less than a turn of range has no other turn within limits at all).
    if (v >= l.lo && v <= l.hi && (!l.multi_turn || std::abs(toward[i] - v) <= math::kPi)) {
      q[i] = std::min(std::max(v, l.lower), l.upper);
      continue;
    }
    if (l.multi_turn) {
      // Whole turns that bring v within limits: k_lo..k_hi; the one nearest `toward` wins.
      const double k_lo = ceil_turns((l.lo - v) * kInvTurn);
      const double k_hi = floor_turns((l.hi - v) * kInvTurn);
      const double k_near = floor_turns((toward[i] - v) * kInvTurn + 0.5);
      v += kTurn * std::min(std::max(k_near, k_lo), k_hi);  // out of limits when k_lo > k_hi
    } else if (l.revolute) {
      // At most one turn puts v within limits; raw angles in (-pi, pi] need one at most, other
      // values the long way.
      v += v < l.lo ? kTurn : -kTurn;
      if (!(v >= l.lo && v <= l.hi)) v = q[i] + kTurn * ceil_turns((l.lo - q[i]) * kInvTurn);
    }
    within = within && v >= l.lo && v <= l.hi;
    q[i] = std::min(std::max(v, l.lower), l.upper);
  }
  return within;
}

namespace {

double squared_distance(const JointVector& a, const JointVector& b) noexcept {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
  return s;
}

}  // namespace

IkSolutions Kinematics::inverse_all(const math::Transform& pose,
                                    const IkOptions& options) const noexcept {
  IkSolutions all;
  const IkResult one = inverse(pose, options);
  if (one) {
    all.items[0] = one;
    all.count = 1;
  } else {
    all.status = one.status;
  }
  return all;
}

IkResult AnalyticKinematics::inverse(const math::Transform& pose,
                                     const IkOptions& options) const noexcept {
  IkResult best;
  if (options.configuration) {
    const JointVector* const reference = checked_reference(pose, options);
    if (reference == nullptr) return best;  // bad_input
    if (options.configuration->index >= configuration_names().size()) {
      best.status = IkStatus::bad_configuration;
      return best;
    }
    best.status = solve(pose, *options.configuration, *reference, best);
    if (best && !fit_to_limits(best.q, *reference)) best.status = IkStatus::joint_limits;
    return best;
  }
  // The solution closest to the reference among every configuration's.
  const IkSolutions all = inverse_all(pose, options);
  best.status = all.status;
  const JointVector& reference = options.near ? *options.near : ready_pose();
  double best_distance = std::numeric_limits<double>::infinity();
  for (const IkResult& candidate : all.solutions()) {
    const double distance = squared_distance(candidate.q, reference);
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  return best;
}

IkSolutions AnalyticKinematics::inverse_all(const math::Transform& pose,
                                            const IkOptions& options) const noexcept {
  IkSolutions all;
  const JointVector* const reference = checked_reference(pose, options);
  if (reference == nullptr) {
    all.status = IkStatus::bad_input;
    return all;
  }
  all.status = IkStatus::out_of_reach;
  const auto names = configuration_names();
  for (std::size_t c = 0; c < names.size() && all.count < kMaxIkSolutions; ++c) {
    IkResult& slot = all.items[all.count];
    if (solve(pose, Configuration{static_cast<std::uint8_t>(c)}, *reference, slot) !=
        IkStatus::ok) {
      continue;
    }
    if (!fit_to_limits(slot.q, *reference)) {
      all.status = IkStatus::joint_limits;
      continue;
    }
    slot.status = IkStatus::ok;
    ++all.count;
  }
  if (all.count > 0) all.status = IkStatus::ok;
  return all;
}

math::Transform Kinematics::chain_forward(const JointVector& q,
                                          math::Transform* frames) const noexcept {
  // All the joint angles' sines and cosines first, four at a time.
  double theta[kMaxJoints] = {}, st[kMaxJoints], ct[kMaxJoints];
  for (std::size_t i = 0; i < dof(); ++i) {
    theta[i] = general_ ? (steps_[i].prismatic ? 0.0 : q[i])
                        : links_[i].theta + (links_[i].prismatic ? 0.0 : q[i]);
  }
  if (dof() > 4) {
    math::sincos8(theta, st, ct);
  } else {
    math::sincos4(theta, st, ct);
  }
  math::Transform T;
  for (std::size_t i = 0; i < dof(); ++i) {
    if (general_) {
      apply_chain_step(T, steps_[i], q[i], ct[i], st[i]);
    } else {
      const Link& l = links_[i];
      apply_dh_link(T, ct[i], st[i], l.ca, l.sa, l.a, l.d + (l.prismatic ? q[i] : 0.0));
    }
    if (frames != nullptr) frames[i] = T;
  }
  return T;
}

Jacobian Kinematics::jacobian(const JointVector& q) const noexcept {
  std::array<math::Transform, kMaxJoints> frames;
  chain_forward(q, frames.data());
  return jacobian_from_frames(frames.data());
}

Jacobian Kinematics::jacobian_from_frames(const math::Transform* frames) const noexcept {
  const math::Vec3& tip = frames[dof() - 1].p;
  Jacobian J(6, static_cast<Eigen::Index>(dof()));
  if (general_) {
    for (std::size_t i = 0; i < dof(); ++i) {
      // Joint i+1 moves about / along its axis in the frame (link i) * origin.
      const math::Transform G = i == 0 ? steps_[i].origin : frames[i - 1] * steps_[i].origin;
      const math::Vec3 z = G.R * steps_[i].axis;
      const math::Vec3 v = steps_[i].prismatic ? z : math::cross(z, tip - G.p);
      const math::Vec3 w = steps_[i].prismatic ? math::Vec3{} : z;
      J.col(static_cast<Eigen::Index>(i)) << v.x, v.y, v.z, w.x, w.y, w.z;
    }
    return J;
  }
  for (std::size_t i = 0; i < dof(); ++i) {
    // Joint i+1 moves about / along z of frame i (the base frame for the first joint).
    const math::Vec3 z = i == 0 ? math::Vec3{0, 0, 1} : frames[i - 1].R.a;
    const math::Vec3 origin = i == 0 ? math::Vec3{} : frames[i - 1].p;
    const math::Vec3 v = links_[i].prismatic ? z : math::cross(z, tip - origin);
    const math::Vec3 w = links_[i].prismatic ? math::Vec3{} : z;
    const auto col = static_cast<Eigen::Index>(i);
    J.col(col) << v.x, v.y, v.z, w.x, w.y, w.z;
  }
  return J;
}

namespace detail {

RobotFileError not_of_form(const RobotModel& model, std::string_view solver,
                           std::string_view what) {
  return RobotFileError(
      fmt::format("robot \"{}\" asks for the {} closed form, but {}; use \"solver\": \"dh\" for a "
                  "different chain",
                  model.name, solver, what));
}

void require_dh_form(const RobotModel& m, std::string_view solver,
                     const std::array<double, 6>& alpha_deg, const std::array<bool, 6>& a_allowed) {
  auto fail = [&](const std::string& what) { throw not_of_form(m, solver, what); };
  if (m.geometry != Geometry::dh) fail("its geometry is not a DH table");
  if (m.dof() != 6) fail(fmt::format("it has {} joints, not 6", m.dof()));
  for (std::size_t i = 0; i < 6; ++i) {
    const Joint& j = m.joints[i];
    if (j.type != JointType::revolute) fail(fmt::format("joint {} is not revolute", i + 1));
    if (std::abs(j.dh.alpha_rad - math::deg_to_rad(alpha_deg[i])) > 1e-12) {
      fail(fmt::format("joint {} has alpha {} deg, not {}", i + 1, math::rad_to_deg(j.dh.alpha_rad),
                       alpha_deg[i]));
    }
    if (std::abs(j.dh.theta_rad) > 1e-12) fail(fmt::format("joint {} has a theta offset", i + 1));
    if (!a_allowed[i] && std::abs(j.dh.a_m) > 1e-12)
      fail(fmt::format("joint {} has a != 0", i + 1));
  }
}

}  // namespace detail

namespace {

/// Configurations spread over the joint ranges (a golden-ratio lattice), k = 1, 2, ...
JointVector spread_configuration(const RobotModel& model, int k) {
  JointVector q(model.dof());
  for (std::size_t i = 0; i < model.dof(); ++i) {
    const Joint& j = model.joints[i];
    const double lo = std::isfinite(j.lower) ? j.lower : -math::kPi;
    const double hi = std::isfinite(j.upper) ? j.upper : math::kPi;
    q[i] = lo + (hi - lo) * std::fmod(0.618033988749895 * static_cast<double>(k * (i + 3)), 1.0);
  }
  return q;
}

/// The 7-axis closed form for a chain of its structure, checked on load: each of 16 spread
/// configurations is among the solutions of its own pose at its own q7. nullptr when it does
/// not fit.
std::unique_ptr<Kinematics> seven_axis_for_chain(const RobotModel& model) {
  std::unique_ptr<SevenAxisKinematics> k;
  try {
    k = std::make_unique<SevenAxisKinematics>(model);
  } catch (const RobotFileError&) {  // not of that structure
    return nullptr;
  }
  for (int n = 1; n <= 16; ++n) {
    const JointVector q = spread_configuration(model, n);
    IkOptions o;
    o.near = q;
    o.redundant = q[6];
    o.configuration = k->configuration_of(q);
    const IkResult r = k->inverse(k->forward(q), o);
    if (!r) return nullptr;
    for (std::size_t i = 0; i < q.size(); ++i) {
      if (!(std::abs(r.q[i] - q[i]) <= 1e-7)) return nullptr;
    }
  }
  return k;
}

/// A closed form for a general chain (a URDF's) whose DH table has a structure one serves (the
/// UR family's, the PUMA's), checked against the chain at configurations spread over the joint
/// ranges; nullptr when none fits (the numeric solver serves it).
std::unique_ptr<Kinematics> closed_form_for_chain(const RobotModel& model) {
  if (model.dof() == 7) return seven_axis_for_chain(model);
  const std::optional<DhEquivalent> dh = dh_equivalent(model);
  if (!dh) return nullptr;
  std::unique_ptr<Kinematics> inner;
  for (int kind = 0; kind < 2 && inner == nullptr; ++kind) {
    try {
      if (kind == 0) inner = std::make_unique<UrKinematics>(dh->model);
      if (kind == 1) inner = std::make_unique<PumaKinematics>(dh->model);
    } catch (const RobotFileError&) {  // not of that structure
    }
  }
  if (inner == nullptr) return nullptr;
  auto placed = std::make_unique<PlacedKinematics>(model, std::move(inner), dh->base, dh->tool);
  const DhKinematics chain(model);
  JointVector q(model.dof());
  for (int k = 1; k <= 16; ++k) {
    q = spread_configuration(model, k);
    const auto a = placed->forward(q).rows();
    const auto b = chain.forward(q).rows();
    for (std::size_t e = 0; e < a.size(); ++e) {
      if (!(std::abs(a[e] - b[e]) <= 1e-9)) return nullptr;
    }
  }
  return placed;
}

}  // namespace

std::unique_ptr<Kinematics> make_kinematics(const RobotModel& model) {
  if (model.geometry == Geometry::chain) {
    if (auto closed = closed_form_for_chain(model)) return closed;
    return std::make_unique<DhKinematics>(model);
  }
  switch (model.solver) {
    case SolverKind::microbo:
      return std::make_unique<MicroboKinematics>(model);
    case SolverKind::puma:
      return std::make_unique<PumaKinematics>(model);
    case SolverKind::dh:
      return std::make_unique<DhKinematics>(model);
  }
  return std::make_unique<DhKinematics>(model);
}

}  // namespace rccx::kin
