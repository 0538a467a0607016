#include "rccx/kinematics/dh_equivalent.hpp"

#include <cmath>

namespace rccx::kin {

namespace {

using math::Vec3;

/// Below this, two unit axes are parallel, and a length is zero (m).
constexpr double kEps = 1e-12;

/// The unit vector along v, flipped if needed so that it does not point against `toward`:
/// x axes kept as continuous as they can be, so that a table written with theta = 0 comes back
/// with theta = 0 (and a signed a) rather than with theta = pi.
Vec3 along(const Vec3& v, const Vec3& toward) {
  const Vec3 u = v.normalized();
  return math::dot(u, toward) < 0.0 ? -u : u;
}

double angle_about(const Vec3& from, const Vec3& to, const Vec3& axis) {
  return std::atan2(math::dot(math::cross(from, to), axis), math::dot(from, to));
}

}  // namespace

std::optional<DhEquivalent> dh_equivalent(const RobotModel& chain) {
  if (chain.geometry == Geometry::dh) return DhEquivalent{chain, {}, {}};
  const std::size_t n = chain.dof();
  if (n == 0) return std::nullopt;
  // The joint axes at q = 0, in the base frame: a point and a direction each; then the flange.
  std::vector<Vec3> point(n), dir(n);
  math::Transform F;
  for (std::size_t i = 0; i < n; ++i) {
    const Joint& j = chain.joints[i];
    if (j.type != JointType::revolute) return std::nullopt;
    const math::Transform G = F * j.chain.origin;
    point[i] = G.p;
    dir[i] = (G.R * j.chain.axis).normalized();
    F = G * j.chain.after;
  }
  DhEquivalent out{chain, {}, {}};
  out.model.geometry = Geometry::dh;
  // Frame 0: z along axis 1, its origin the point of axis 1 nearest the base's origin.
  Vec3 z = dir[0];
  Vec3 o = point[0] + z * math::dot(-point[0], z);
  Vec3 x = Vec3{1, 0, 0} - z * z.x;
  if (x.norm() < 1e-6) x = Vec3{0, 1, 0} - z * z.y;
  x = x.normalized();
  out.base = {{x, math::cross(z, x), z}, o};
  for (std::size_t i = 0; i < n; ++i) {
    Joint& j = out.model.joints[i];
    j.chain = {};
    const bool last = i + 1 == n;
    const Vec3 z_next = last ? z : dir[i + 1];
    const Vec3 p_next = last ? o : point[i + 1];
    Vec3 foot;    // where x_i leaves axis i (on the line through o along z)
    Vec3 o_next;  // frame i's origin, on axis i+1
    Vec3 x_next;
    double a = 0.0;
    if (last) {
      // The last frame keeps z and x; its origin is the point of the last axis nearest the
      // flange.
      foot = o + z * math::dot(F.p - o, z);
      o_next = foot;
      x_next = x;
    } else if (const Vec3 c = math::cross(z, z_next); c.norm() > kEps) {
      // Skew or meeting axes: the common normal, from the closest points of the two lines.
      const Vec3 w = o - p_next;
      const double b = math::dot(z, z_next), d = math::dot(z, w), e = math::dot(z_next, w);
      const double den = 1.0 - b * b;
      foot = o + z * ((b * e - d) / den);
      o_next = p_next + z_next * ((e - b * d) / den);
      x_next = along(c, x);
      a = math::dot(o_next - foot, x_next);
    } else {
      // Parallel axes: the normal through o, so that d = 0.
      foot = o;
      o_next = p_next + z_next * math::dot(o - p_next, z_next);
      const Vec3 v = o_next - foot;
      if (v.norm() > kEps) {
        x_next = along(v, x);
        a = math::dot(v, x_next);
      } else {
        x_next = x;
      }
    }
    j.dh.a_m = a;
    j.dh.alpha_rad = angle_about(z, z_next, x_next);
    j.dh.d_m = math::dot(foot - o, z);
    j.dh.theta_rad = angle_about(x, x_next, z);
    o = o_next;
    z = z_next;
    x = x_next;
  }
  const math::Transform frame_n{{x, math::cross(z, x), z}, o};
  out.tool = frame_n.inverse_times(F);
  return out;
}

}  // namespace rccx::kin
