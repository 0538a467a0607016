#include "rccx/kinematics/seven_axis_kinematics.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "rccx/kinematics/dh_step.hpp"
#include "rccx/math/batch_trig.hpp"
#include "rccx/math/units.hpp"

namespace rccx::kin {

namespace {

using math::Rot3;
using math::Transform;
using math::Vec3;

// Index = 4 shoulder + 2 elbow + wrist, with shoulder 0 = l, elbow 0 = u, wrist 0 = n.
constexpr std::array<std::string_view, 8> kConfigurationNames{"lun", "luf", "ldn", "ldf",
                                                              "run", "ruf", "rdn", "rdf"};
/// Axes closer than this (m) meet.
constexpr double kMeet_m = 1e-9;
/// A vector this much shorter than its length (relative) normal to an axis lies along it.
constexpr double kAlong = 1e-10;
/// Bisection steps after the search over q7 found a q7 that solves: 0.05 rad / 2^16, 1e-6 rad.
constexpr int kBisections = 16;

/// An angle as its cosine and sine: the solver turns vectors by them and takes the angles
/// themselves (atan2) once, in a batch, at the end.
struct Turn {
  double c = 1.0, s = 0.0;
  [[nodiscard]] Turn inverse() const noexcept { return {c, -s}; }
  static Turn of(double angle) noexcept {
    Turn t;
    ::sincos(angle, &t.s, &t.c);
    return t;
  }
};

/// Rot(k, t) v, k a unit vector (Rodrigues).
Vec3 rotate(const Vec3& k, Turn t, const Vec3& v) noexcept {
  return v * t.c + math::cross(k, v) * t.s + k * (math::dot(k, v) * (1.0 - t.c));
}

/// Rot(k, t) as a matrix.
Rot3 rotation(const Vec3& k, Turn t) noexcept {
  return {rotate(k, t, {1, 0, 0}), rotate(k, t, {0, 1, 0}), rotate(k, t, {0, 0, 1})};
}

/// Subproblem 1 (Paden-Kahan): the turn about unit k that takes p onto t (both the same
/// distance from k's line). False when p lies along k: any turn does.
bool turn_about(const Vec3& k, const Vec3& p, const Vec3& t, Turn& out) noexcept {
  const Vec3 pp = p - k * math::dot(k, p);
  const Vec3 tp = t - k * math::dot(k, t);
  const double scale = std::max(math::dot(p, p), 1e-300);
  if (math::dot(pp, pp) < kAlong * kAlong * scale) return false;
  const double c = math::dot(pp, tp), s = math::dot(k, math::cross(pp, tp));
  const double h = std::sqrt(c * c + s * s);  // hypot is exact and slow; no overflow here
  if (!(h > 0.0)) return false;
  out = {c / h, s / h};
  return true;
}

/// Subproblem 2 (Paden-Kahan): Rot(k1, a1) Rot(k2, a2) p = t for unit axes k1, k2 through one
/// point. c = Rot(k2, a2) p = alpha k1 + beta k2 + gamma k1 x k2; the sign of gamma picks one of
/// the two solutions. A turn the vectors leave free (p along k2, or c along k1) is taken from
/// `free2` / `free1`, and `singular` set.
struct TwoAxes {
  Vec3 k1, k2, n;  ///< n = k1 x k2
  double k12 = 0.0, n2 = 0.0;

  TwoAxes() = default;
  TwoAxes(const Vec3& a1, const Vec3& a2) noexcept
      : k1(a1), k2(a2), n(math::cross(a1, a2)), k12(math::dot(a1, a2)), n2(math::dot(n, n)) {}

  /// alpha, beta and |gamma|; false when gamma^2 is negative beyond rounding (no solution).
  bool coefficients(const Vec3& p, const Vec3& t, double& alpha, double& beta,
                    double& gamma) const noexcept {
    const double k2p = math::dot(k2, p), k1t = math::dot(k1, t);
    const double den = k12 * k12 - 1.0;
    alpha = (k12 * k2p - k1t) / den;
    beta = (k12 * k1t - k2p) / den;
    const double pp = math::dot(p, p);
    const double g2 = pp - alpha * alpha - beta * beta - 2.0 * alpha * beta * k12;
    if (g2 < -1e-10 * pp) return false;
    gamma = std::sqrt(std::max(g2, 0.0) / n2);
    return true;
  }

  void turns(const Vec3& p, const Vec3& t, double alpha, double beta, double gamma, Turn free1,
             Turn free2, Turn& a1, Turn& a2, bool& singular) const noexcept {
    const Vec3 c = k1 * alpha + k2 * beta + n * gamma;
    if (!turn_about(k2, p, c, a2)) {
      a2 = free2;
      singular = true;
    }
    if (!turn_about(k1, rotate(k2, a2, p), t, a1)) {
      a1 = free1;
      singular = true;
    }
  }

  /// The sign of gamma for c = Rot(k2, a2) p: which root gave it.
  [[nodiscard]] bool negative_root(const Vec3& c) const noexcept { return math::dot(c, n) < 0.0; }
};

struct Line {
  Vec3 point, direction;
};

/// The point where two lines meet, if they do (within kMeet_m) and are not parallel.
std::optional<Vec3> meet(const Line& a, const Line& b) {
  const double ab = math::dot(a.direction, b.direction);
  const double den = 1.0 - ab * ab;
  if (den < 1e-12) return std::nullopt;
  const Vec3 w = a.point - b.point;
  const double d = math::dot(a.direction, w), e = math::dot(b.direction, w);
  const Vec3 pa = a.point + a.direction * ((ab * e - d) / den);
  const Vec3 pb = b.point + b.direction * ((e - ab * d) / den);
  if ((pa - pb).norm() > kMeet_m) return std::nullopt;
  return (pa + pb) * 0.5;
}

double distance_to(const Line& l, const Vec3& x) {
  const Vec3 v = x - l.point;
  return (v - l.direction * math::dot(l.direction, v)).norm();
}

}  // namespace

SevenAxisKinematics::SevenAxisKinematics(RobotModel model) : Kinematics(std::move(model)) {
  const RobotModel& m = this->model();
  auto fail = [&](const std::string& what) {
    throw RobotFileError(fmt::format(
        "robot \"{}\" has no 7-axis closed form: {} (it is solved numerically)", m.name, what));
  };
  if (m.geometry != Geometry::chain) fail("its geometry is not a general chain");
  if (m.dof() != 7) fail(fmt::format("it has {} joints, not 7", m.dof()));
  for (std::size_t i = 0; i < 7; ++i) {
    if (m.joints[i].type != JointType::revolute) fail(fmt::format("joint {} slides", i + 1));
  }
  // The link frames at q = 0 and each axis's line in the base frame.
  std::array<Transform, kMaxJoints> link{};
  chain_forward(JointVector(7), link.data());
  std::array<Line, 7> axis{};
  for (std::size_t i = 0; i < 7; ++i) {
    const Transform g = i == 0 ? steps_[0].origin : link[i - 1] * steps_[i].origin;
    axis[i] = {g.p, g.R * steps_[i].axis};
  }
  const auto s = meet(axis[0], axis[1]);
  if (!s || distance_to(axis[2], *s) > kMeet_m) fail("the axes of joints 1, 2, 3 do not meet");
  const auto w = meet(axis[4], axis[5]);
  if (!w) fail("the axes of joints 5 and 6 do not meet");
  shoulder_ = *s;
  wrist_in_6_ = link[5].inverse() * *w;
  wrist_in_4_ = link[3].inverse() * *w;

  // |SW|^2 = |Rot(k4, q4) W4 + e|^2, e = origin4.R^T (origin4.p - S3), S3 = S in link 3.
  const Transform& o4 = steps_[3].origin;
  k4_ = steps_[3].axis;
  const Vec3 s3 = link[2].inverse() * shoulder_;
  elbow_e_ = o4.R.transpose_times(o4.p - s3);
  const Vec3& v = wrist_in_4_;
  const Vec3 along = k4_ * math::dot(k4_, v);
  elbow_a_ = math::dot(v, v) + math::dot(elbow_e_, elbow_e_) + 2.0 * math::dot(elbow_e_, along);
  const double b = 2.0 * math::dot(elbow_e_, v - along);
  const double c = 2.0 * math::dot(elbow_e_, math::cross(k4_, v));
  elbow_r_ = std::hypot(b, c);
  elbow_phi_ = std::atan2(c, b);
  elbow_cos_phi_ = b / elbow_r_;
  elbow_sin_phi_ = c / elbow_r_;
  if (elbow_r_ < 1e-9) fail("the elbow (joint 4) does not change the shoulder-wrist distance");

  origin1_R_ = steps_[0].origin.R;
  k1_ = steps_[0].axis;
  k2_ = steps_[1].origin.R * steps_[1].axis;
  shoulder_C_ = steps_[1].origin.R * steps_[2].origin.R;
  k3_ = shoulder_C_ * steps_[2].axis;
  k3_perp_ = math::cross(k3_, std::abs(k3_.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}).normalized();
  if (math::cross(k1_, k2_).norm() < 1e-9 || math::cross(k2_, k3_).norm() < 1e-9) {
    fail("joint 2's axis is parallel to joint 1's or joint 3's");
  }
  origin5_R_ = steps_[4].origin.R;
  origin6_R_ = steps_[5].origin.R;
  k5_ = steps_[4].axis;
  k6_ = origin6_R_ * steps_[5].axis;
}

Transform SevenAxisKinematics::forward(const JointVector& q) const noexcept {
  return chain_forward(q);
}

std::span<const std::string_view> SevenAxisKinematics::configuration_names() const noexcept {
  return kConfigurationNames;
}

Configuration SevenAxisKinematics::configuration_of(const JointVector& q) const noexcept {
  const bool down = std::sin(q[3] - elbow_phi_) < 0.0;
  // The wrist's c = Rot(k6, q6) p = Rot(k5, -q5) t, t from q4 alone (see solve_at).
  const Vec3 t = origin5_R_.transpose_times(wrist_in_4_ + rotate(k4_, Turn::of(-q[3]), elbow_e_));
  const bool flip = TwoAxes(k5_, k6_).negative_root(rotate(k5_, Turn::of(-q[4]), t));
  const bool right = TwoAxes(k1_, k2_).negative_root(rotate(k2_, Turn::of(q[1]), k3_));
  return {static_cast<std::uint8_t>((right ? 4 : 0) + (down ? 2 : 0) + (flip ? 1 : 0))};
}

std::size_t SevenAxisKinematics::solve_at(
    const Transform& pose, double q7, std::optional<Configuration> only,
    const JointVector& reference, std::array<IkResult, kMaxIkSolutions>& out) const noexcept {
  // Link 6's frame from the pose and q7, and the wrist point W in the base frame.
  const Turn t7 = Turn::of(q7);
  Transform tail;
  apply_chain_step(tail, steps_[6], q7, t7.c, t7.s);
  const Transform f6 = pose * tail.inverse();
  const Vec3 sw = f6 * wrist_in_6_ - shoulder_;

  // The elbow: |SW|^2 = a + r cos(q4 - phi), q4 = phi +- beta.
  const double ratio = (math::dot(sw, sw) - elbow_a_) / elbow_r_;
  if (!(std::abs(ratio) <= 1.0 + 1e-12)) return 0;
  const double cb = std::clamp(ratio, -1.0, 1.0);
  const double sb = std::sqrt(1.0 - cb * cb);
  const bool elbow_singular = sb < 1e-10;

  // The wrist: Rot(k5, q5) Rot(k6, q6) p = t, p = SW in link 5's frame after origin6 at q6 = 0,
  // t = SW in origin5's frame at q5 = 0.
  const Vec3 p = origin6_R_ * f6.R.transpose_times(sw);
  const TwoAxes wrist(k5_, k6_);
  const TwoAxes shoulder(k1_, k2_);
  const Turn free[6] = {Turn::of(reference[0]), {}, {}, {}, Turn::of(reference[4]),
                        Turn::of(reference[5])};
  // Each solution's six turns; the angles come from them in one batch of atan2 at the end.
  struct Raw {
    Turn turn[6];
  };
  std::array<Raw, kMaxIkSolutions> raw;
  std::size_t count = 0;
  for (int down = 0; down < 2; ++down) {
    if (only && ((only->index >> 1) & 1) != down) continue;
    const double s = down != 0 ? -sb : sb;
    const Turn t4{elbow_cos_phi_ * cb - elbow_sin_phi_ * s,
                  elbow_sin_phi_ * cb + elbow_cos_phi_ * s};
    const Vec3 t = origin5_R_.transpose_times(wrist_in_4_ + rotate(k4_, t4.inverse(), elbow_e_));
    double wa, wb, wg;
    if (!wrist.coefficients(p, t, wa, wb, wg)) continue;
    // Link 4's orientation up to origin4 Rot(k4, q4): R3 = R4 (origin4 Rot4)^T.
    const Rot3 r34 = steps_[3].origin.R * rotation(k4_, t4);
    for (int flip = 0; flip < 2; ++flip) {
      if (only && (only->index & 1) != flip) continue;
      bool wrist_free = false;
      Turn t5, t6;
      wrist.turns(p, t, wa, wb, flip != 0 ? -wg : wg, free[4], free[5], t5, t6, wrist_free);
      // Link 3's orientation: R3 = R6 (origin5 Rot5 origin6 Rot6)^T (origin4 Rot4)^T, then
      // Z = origin1^T R3 C^T = Rot(k1, q1) Rot(k2, q2) Rot(k3, q3).
      const Rot3 r46 = origin5_R_ * rotation(k5_, t5) * origin6_R_ * rotation(steps_[5].axis, t6);
      const Rot3 r3 = f6.R * (r34 * r46).transposed();
      const Rot3 z = origin1_R_.transposed() * r3 * shoulder_C_.transposed();
      const Vec3 zk3 = z * k3_;
      double sa, sbeta, sg;
      if (!shoulder.coefficients(k3_, zk3, sa, sbeta, sg)) continue;
      const Vec3 zp = z * k3_perp_;
      for (int right = 0; right < 2; ++right) {
        if (only && ((only->index >> 2) & 1) != right) continue;
        bool shoulder_free = false;
        Turn t1, t2, t3;
        shoulder.turns(k3_, zk3, sa, sbeta, right != 0 ? -sg : sg, free[0], {}, t1, t2,
                       shoulder_free);
        turn_about(k3_, k3_perp_, rotate(k2_, t2.inverse(), rotate(k1_, t1.inverse(), zp)), t3);
        raw[count] = {{t1, t2, t3, t4, t5, t6}};
        IkResult& r = out[count++];
        r.status = IkStatus::ok;
        r.configuration = {static_cast<std::uint8_t>(4 * right + 2 * down + flip)};
        r.singularity = shoulder_free    ? Singularity::shoulder
                        : wrist_free     ? Singularity::wrist
                        : elbow_singular ? Singularity::elbow
                                         : Singularity::none;
      }
    }
  }
  // The angles: six atan2 per solution, eight at a time.
  double y[kMaxIkSolutions * 6] = {}, x[kMaxIkSolutions * 6] = {}, angle[kMaxIkSolutions * 6];
  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t j = 0; j < 6; ++j) {
      y[6 * i + j] = raw[i].turn[j].s;
      x[6 * i + j] = raw[i].turn[j].c;
    }
  }
  for (std::size_t b = 0; b < 6 * count; b += 8) math::atan2_8(y + b, x + b, angle + b);
  for (std::size_t i = 0; i < count; ++i) {
    out[i].q = JointVector(7);
    for (std::size_t j = 0; j < 6; ++j) out[i].q[j] = angle[6 * i + j];
    out[i].q[6] = q7;
  }
  return count;
}

IkResult SevenAxisKinematics::best_at(const Transform& pose, double q7,
                                      std::optional<Configuration> only,
                                      const JointVector& reference) const noexcept {
  std::array<IkResult, kMaxIkSolutions> raw;
  const std::size_t n = solve_at(pose, q7, only, reference, raw);
  IkResult best;
  best.status = n == 0 ? IkStatus::out_of_reach : IkStatus::joint_limits;
  double best_distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    IkResult& r = raw[i];
    if (!fit_to_limits(r.q, reference)) continue;
    double d = 0.0;
    for (std::size_t j = 0; j < 7; ++j) d += (r.q[j] - reference[j]) * (r.q[j] - reference[j]);
    if (d < best_distance) {
      best_distance = d;
      best = r;
    }
  }
  return best;
}

IkResult SevenAxisKinematics::inverse(const Transform& pose,
                                      const IkOptions& options) const noexcept {
  IkResult none;
  const JointVector* const reference = checked_reference(pose, options);
  if (reference == nullptr) return none;  // bad_input
  if (options.configuration && options.configuration->index >= kConfigurationNames.size()) {
    none.status = IkStatus::bad_configuration;
    return none;
  }
  const Joint& j7 = model().joints[6];
  const double lo = std::isfinite(j7.lower) ? j7.lower : (*reference)[6] - math::kPi;
  const double hi = std::isfinite(j7.upper) ? j7.upper : (*reference)[6] + math::kPi;
  if (options.redundant) {
    const double q7 = *options.redundant;
    if (!std::isfinite(q7)) return none;
    if (q7 < lo - kLimitTolerance || q7 > hi + kLimitTolerance) {
      none.status = IkStatus::joint_limits;
      return none;
    }
    return best_at(pose, q7, options.configuration, *reference);
  }
  const double q0 = std::clamp((*reference)[6], lo, hi);
  IkResult best = best_at(pose, q0, options.configuration, *reference);
  if (best) return best;
  IkStatus why = best.status;
  // Outward from q0 on both sides; the first step that solves is narrowed down by bisection
  // to the q7 nearest q0 that solves.
  for (int k = 1;; ++k) {
    bool inside = false;
    double best_distance = std::numeric_limits<double>::infinity();
    for (const double side : {1.0, -1.0}) {
      const double before = q0 + side * (k - 1) * kRedundantStep_rad;
      const double q = std::clamp(q0 + side * k * kRedundantStep_rad, lo, hi);
      if (q == before || (side > 0 ? before >= hi : before <= lo)) continue;
      inside = true;
      IkResult r = best_at(pose, q, options.configuration, *reference);
      if (r.status == IkStatus::joint_limits) why = IkStatus::joint_limits;
      if (!r) continue;
      double failing = before, solving = q;
      for (int b = 0; b < kBisections; ++b) {
        const double mid = 0.5 * (failing + solving);
        IkResult m = best_at(pose, mid, options.configuration, *reference);
        if (m) {
          solving = mid;
          r = m;
        } else {
          failing = mid;
        }
      }
      double d = 0.0;
      for (std::size_t j = 0; j < 7; ++j) {
        d += (r.q[j] - (*reference)[j]) * (r.q[j] - (*reference)[j]);
      }
      if (d < best_distance) {
        best_distance = d;
        best = r;
      }
    }
    if (best) return best;
    if (!inside) break;
  }
  none.status = why;
  return none;
}

IkSolutions SevenAxisKinematics::inverse_all(const Transform& pose,
                                             const IkOptions& options) const noexcept {
  IkSolutions all;
  IkOptions any = options;
  any.configuration.reset();
  const IkResult first = inverse(pose, any);
  if (!first) {
    all.status = first.status;
    return all;
  }
  const JointVector& reference = options.near ? *options.near : ready_pose();
  std::array<IkResult, kMaxIkSolutions> raw;
  const std::size_t n = solve_at(pose, first.q[6], std::nullopt, reference, raw);
  for (std::size_t i = 0; i < n; ++i) {
    if (!fit_to_limits(raw[i].q, reference)) continue;
    all.items[all.count++] = raw[i];
  }
  all.status = all.count > 0 ? IkStatus::ok : IkStatus::joint_limits;
  return all;
}

}  // namespace rccx::kin
