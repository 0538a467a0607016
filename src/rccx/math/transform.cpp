#include "rccx/math/transform.hpp"

#include <algorithm>

namespace rccx::math {

Rot3 Rot3::rot_x(double angle_rad) noexcept {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  return {{1, 0, 0}, {0, c, s}, {0, -s, c}};
}

Rot3 Rot3::rot_y(double angle_rad) noexcept {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  return {{c, 0, -s}, {0, 1, 0}, {s, 0, c}};
}

Rot3 Rot3::rot_z(double angle_rad) noexcept {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  return {{c, s, 0}, {-s, c, 0}, {0, 0, 1}};
}

Rot3 Rot3::about(const Vec3& axis, double angle_rad) noexcept {
  const Vec3 k = axis.normalized();
  if (k == Vec3{}) return {};
  // Paul's Rot(k, theta), the Rodrigues form.
  const double c = std::cos(angle_rad), s = std::sin(angle_rad), v = 1.0 - c;
  return {{k.x * k.x * v + c, k.x * k.y * v + k.z * s, k.x * k.z * v - k.y * s},
          {k.x * k.y * v - k.z * s, k.y * k.y * v + c, k.y * k.z * v + k.x * s},
          {k.x * k.z * v + k.y * s, k.y * k.z * v - k.x * s, k.z * k.z * v + c}};
}

Rot3 Rot3::from_rpy(double roll_rad, double pitch_rad, double yaw_rad) noexcept {
  return rot_z(roll_rad) * rot_y(pitch_rad) * rot_x(yaw_rad);
}

Rot3 Rot3::from_urdf_rpy(double roll_rad, double pitch_rad, double yaw_rad) noexcept {
  return from_rpy(yaw_rad, pitch_rad, roll_rad);  // the same product, the angles named apart
}

Rot3 Rot3::from_zyz(double phi_rad, double theta_rad, double psi_rad) noexcept {
  return rot_z(phi_rad) * rot_y(theta_rad) * rot_z(psi_rad);
}

std::array<double, 3> Rot3::to_rpy() const noexcept {
  // R = Rz(roll) Ry(pitch) Rx(yaw): n = (cr cp, sr cp, -sp), o_z = cp sy, a_z = cp cy.
  const double cp = std::hypot(n.x, n.y);
  const double pitch = std::atan2(-n.z, cp);
  if (cp < 1e-12) {
    // Gimbal lock: only roll -+ yaw is defined; give it all to roll.
    const double roll = std::atan2(-o.x, o.y);
    return {roll, pitch, 0.0};
  }
  return {std::atan2(n.y, n.x), pitch, std::atan2(o.z, a.z)};
}

std::array<double, 3> Rot3::to_urdf_rpy() const noexcept {
  const auto paul = to_rpy();
  return {paul[2], paul[1], paul[0]};
}

std::array<double, 3> Rot3::to_zyz() const noexcept {
  // R = Rz(phi) Ry(theta) Rz(psi): a = (cphi stheta, sphi stheta, ctheta), n_z = -st cpsi,
  // o_z = st spsi.
  const double st = std::hypot(a.x, a.y);
  const double theta = std::atan2(st, a.z);
  if (st < 1e-12) {
    // theta = 0: R = Rz(phi + psi); theta = pi: R = Rz(phi - psi) diag(-1, 1, -1).
    const double phi = a.z > 0 ? std::atan2(n.y, n.x) : std::atan2(-n.y, -n.x);
    return {phi, theta, 0.0};
  }
  return {std::atan2(a.y, a.x), theta, std::atan2(o.z, -n.z)};
}

void Rot3::to_axis_angle(Vec3& axis, double& angle_rad) const noexcept {
  const Vec3 w{o.z - a.y, a.x - n.z, n.y - o.x};  // 2 sin(angle) axis
  const double s2 = w.norm();
  const double c2 = n.x + o.y + a.z - 1.0;  // 2 cos(angle)
  angle_rad = std::atan2(s2, c2);
  if (c2 >= 0.0) {
    // Up to a quarter turn w is well conditioned, down to the smallest rotations.
    axis = s2 > 0.0 ? w / s2 : Vec3{0, 0, 1};
    return;
  }
  // Beyond a quarter turn w shrinks towards the half turn; read the axis from the symmetric part
  // instead, (R + Rt)/2 - cos(angle) I = (1 - cos(angle)) k kt, and its sign from w.
  const double one_minus_c = 1.0 - 0.5 * c2;
  const double diag[3] = {n.x - 0.5 * c2, o.y - 0.5 * c2, a.z - 0.5 * c2};
  const int i = diag[0] >= diag[1] ? (diag[0] >= diag[2] ? 0 : 2) : (diag[1] >= diag[2] ? 1 : 2);
  const double ki = std::sqrt(std::max(diag[i], 0.0) / one_minus_c);
  const double scale = 1.0 / (one_minus_c * ki);
  Vec3 k;
  if (i == 0) {
    k = {ki, 0.5 * (n.y + o.x) * scale, 0.5 * (n.z + a.x) * scale};
  } else if (i == 1) {
    k = {0.5 * (n.y + o.x) * scale, ki, 0.5 * (o.z + a.y) * scale};
  } else {
    k = {0.5 * (n.z + a.x) * scale, 0.5 * (o.z + a.y) * scale, ki};
  }
  axis = dot(k, w) < 0.0 ? -k : k;
}

Rot3 Rot3::orthonormalized() const noexcept {
  const Vec3 az = a.normalized();
  const Vec3 nn = cross(o, az).normalized();
  return {nn, cross(az, nn), az};
}

double max_abs_difference(const Transform& a, const Transform& b) noexcept {
  const auto ra = a.rows(), rb = b.rows();
  double m = 0.0;
  for (std::size_t i = 0; i < ra.size(); ++i) m = std::max(m, std::abs(ra[i] - rb[i]));
  return m;
}

Rot3 rotated_by(const Rot3& R, const Vec3& w_rad_per_s, double dt_s) noexcept {
  const double rate = w_rad_per_s.norm();
  if (!(rate * std::abs(dt_s) > 1e-12)) return R;
  return Rot3::about(w_rad_per_s * (1.0 / rate), rate * dt_s) * R;
}

DriveTransform::DriveTransform(const Transform& from, const Transform& to) noexcept
    : from_(from), to_(to) {
  const Transform rel = from.inverse_times(to);
  xyz_ = rel.p;
  const Vec3& a = rel.R.a;
  psi_ = std::atan2(a.y, a.x);
  theta_ = std::atan2(std::hypot(a.x, a.y), a.z);
  // What remains after swinging the approach vector is a rotation about it by phi.
  const Rot3 swing = Rot3::about({-std::sin(psi_), std::cos(psi_), 0.0}, theta_);
  const Vec3 n_left = swing.transpose_times(rel.R.n);
  phi_ = std::atan2(n_left.y, n_left.x);
}

Transform DriveTransform::relative(double r) const noexcept {
  const Rot3 swing = Rot3::about({-std::sin(psi_), std::cos(psi_), 0.0}, r * theta_);
  return {swing * Rot3::rot_z(r * phi_), xyz_ * r};
}

Transform DriveTransform::at(double r) const noexcept {
  // The end points are returned as given so that a segment ends exactly where it was asked to.
  if (r == 0.0) return from_;
  if (r == 1.0) return to_;
  return from_ * relative(r);
}

}  // namespace rccx::math
