// Homogeneous transforms in the notation of the thesis (section 3.2.1): a frame is the four
// columns n (normal), o (orientation), a (approach) and p (position) of a 4x4 matrix whose last
// row is 0 0 0 1. Lengths are in metres, angles in radians.
//
//   using namespace rccx::math::literals;
//   const math::Transform down{math::Rot3::rot_x(180_deg), {325_mm, 0.0, 250_mm}};
//   const math::Transform T = base * down * math::Transform::translation(0, 0, 0.1);
//   const math::Vec3 tip = T * math::Vec3{0, 0, 0.02};   // a point of frame T, in base's m
//   const math::Transform back = T.inverse_times(goal);  // T^-1 goal
//   const math::DriveTransform drive(T, goal);
//   const math::Transform half_way = drive.at(0.5);      // Paul's drive, r in [0, 1]
//
// Small value types written out by hand rather than Eigen types: the kinematics and the
// trajectory generator multiply a few of them per sample, and the closed-form solvers read
// individual elements by name (n.x, a.z ...) exactly as the thesis's equations do.
#pragma once

#include <array>
#include <cmath>

namespace rccx::math {

/// A 3-vector: a position in m or a direction (unitless).
struct Vec3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;

  constexpr Vec3 operator+(const Vec3& b) const noexcept { return {x + b.x, y + b.y, z + b.z}; }
  constexpr Vec3 operator-(const Vec3& b) const noexcept { return {x - b.x, y - b.y, z - b.z}; }
  constexpr Vec3 operator-() const noexcept { return {-x, -y, -z}; }
  constexpr Vec3 operator*(double s) const noexcept { return {x * s, y * s, z * s}; }
  constexpr Vec3 operator/(double s) const noexcept { return {x / s, y / s, z / s}; }
  constexpr Vec3& operator+=(const Vec3& b) noexcept { return *this = *this + b; }
  constexpr Vec3& operator-=(const Vec3& b) noexcept { return *this = *this - b; }
  constexpr bool operator==(const Vec3&) const noexcept = default;
  constexpr double operator[](int i) const noexcept { return i == 0 ? x : (i == 1 ? y : z); }

  [[nodiscard]] double norm() const noexcept { return std::sqrt(x * x + y * y + z * z); }
  /// Unit vector along this one; the zero vector stays zero.
  [[nodiscard]] Vec3 normalized() const noexcept {
    const double n = norm();
    return n > 0.0 ? *this / n : Vec3{};
  }
};

constexpr Vec3 operator*(double s, const Vec3& v) noexcept {
  return v * s;
}
constexpr double dot(const Vec3& a, const Vec3& b) noexcept {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3 cross(const Vec3& a, const Vec3& b) noexcept {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

/// A rotation matrix stored as its three columns n, o, a (each a unit vector, n = o x a).
struct Rot3 {
  Vec3 n{1, 0, 0};
  Vec3 o{0, 1, 0};
  Vec3 a{0, 0, 1};

  static constexpr Rot3 identity() noexcept { return {}; }
  /// Rotation by `angle_rad` about the x, y or z axis (Paul's Rot(x, angle) ...).
  static Rot3 rot_x(double angle_rad) noexcept;
  static Rot3 rot_y(double angle_rad) noexcept;
  static Rot3 rot_z(double angle_rad) noexcept;
  /// Rotation by `angle_rad` about any axis (normalised here; a zero axis gives identity).
  static Rot3 about(const Vec3& axis, double angle_rad) noexcept;
  /// Roll-pitch-yaw as Paul defines it: Rot(z, roll) Rot(y, pitch) Rot(x, yaw).
  static Rot3 from_rpy(double roll_rad, double pitch_rad, double yaw_rad) noexcept;
  /// Roll-pitch-yaw as URDF (and ROS) define it, the reverse of Paul's: about the fixed axes,
  /// roll about x first, then pitch about y, then yaw about z: Rot(z, yaw) Rot(y, pitch)
  /// Rot(x, roll). Paul's from_rpy(yaw, pitch, roll) is the same rotation.
  static Rot3 from_urdf_rpy(double roll_rad, double pitch_rad, double yaw_rad) noexcept;
  /// Z-Y-Z Euler angles: Rot(z, phi) Rot(y, theta) Rot(z, psi).
  static Rot3 from_zyz(double phi_rad, double theta_rad, double psi_rad) noexcept;

  /// Element (row, col), both 0..2.
  [[nodiscard]] constexpr double operator()(int row, int col) const noexcept {
    const Vec3& c = col == 0 ? n : (col == 1 ? o : a);
    return c[row];
  }
  [[nodiscard]] constexpr Vec3 row(int r) const noexcept { return {n[r], o[r], a[r]}; }
  [[nodiscard]] constexpr Vec3 operator*(const Vec3& v) const noexcept {
    return n * v.x + o * v.y + a * v.z;
  }
  [[nodiscard]] constexpr Rot3 operator*(const Rot3& b) const noexcept {
    return {*this * b.n, *this * b.o, *this * b.a};
  }
  /// The inverse of a rotation is its transpose.
  [[nodiscard]] constexpr Rot3 transposed() const noexcept { return {row(0), row(1), row(2)}; }
  /// Rᵀ v, without forming Rᵀ.
  [[nodiscard]] constexpr Vec3 transpose_times(const Vec3& v) const noexcept {
    return {dot(n, v), dot(o, v), dot(a, v)};
  }

  /// {roll, pitch, yaw} with pitch in [-pi/2, pi/2]; at pitch = +-pi/2 roll takes all of the
  /// rotation about z and yaw is 0.
  [[nodiscard]] std::array<double, 3> to_rpy() const noexcept;
  /// {roll about x, pitch about y, yaw about z} of URDF (see from_urdf_rpy), pitch in
  /// [-pi/2, pi/2]; at pitch = +-pi/2 yaw takes all of the rotation about z and roll is 0.
  [[nodiscard]] std::array<double, 3> to_urdf_rpy() const noexcept;
  /// {phi, theta, psi} with theta in [0, pi]; at theta = 0 or pi, psi is 0.
  [[nodiscard]] std::array<double, 3> to_zyz() const noexcept;
  /// The angle-axis form: unit axis and angle in [0, pi].
  void to_axis_angle(Vec3& axis, double& angle_rad) const noexcept;
  /// Rebuilds an orthonormal right-handed matrix from o and a (n = o x a), as RCCL did after
  /// long chains of products.
  [[nodiscard]] Rot3 orthonormalized() const noexcept;
};

/// A homogeneous transform: rotation R (columns n, o, a) and position p in m.
struct Transform {
  Rot3 R;
  Vec3 p;

  static constexpr Transform identity() noexcept { return {}; }
  static constexpr Transform translation(const Vec3& p_m) noexcept { return {Rot3{}, p_m}; }
  static constexpr Transform translation(double x_m, double y_m, double z_m) noexcept {
    return {Rot3{}, {x_m, y_m, z_m}};
  }
  static Transform rotation(const Vec3& axis, double angle_rad) noexcept {
    return {Rot3::about(axis, angle_rad), {}};
  }
  /// From the 12 numbers of the top three rows, row by row:
  /// r11 r12 r13 px, r21 r22 r23 py, r31 r32 r33 pz.
  static constexpr Transform from_rows(const std::array<double, 12>& m) noexcept {
    return {{{m[0], m[4], m[8]}, {m[1], m[5], m[9]}, {m[2], m[6], m[10]}}, {m[3], m[7], m[11]}};
  }
  /// The top three rows, row by row (the inverse of from_rows).
  [[nodiscard]] constexpr std::array<double, 12> rows() const noexcept {
    return {R.n.x, R.o.x, R.a.x, p.x, R.n.y, R.o.y, R.a.y, p.y, R.n.z, R.o.z, R.a.z, p.z};
  }

  [[nodiscard]] constexpr const Vec3& n() const noexcept { return R.n; }
  [[nodiscard]] constexpr const Vec3& o() const noexcept { return R.o; }
  [[nodiscard]] constexpr const Vec3& a() const noexcept { return R.a; }

  /// Element (row, col) of the 4x4 matrix, row and col 0..3.
  [[nodiscard]] constexpr double operator()(int row, int col) const noexcept {
    if (row == 3) return col == 3 ? 1.0 : 0.0;
    return col == 3 ? p[row] : R(row, col);
  }
  [[nodiscard]] constexpr Transform operator*(const Transform& b) const noexcept {
    return {R * b.R, R * b.p + p};
  }
  /// Maps a point given in this frame into the reference frame.
  [[nodiscard]] constexpr Vec3 operator*(const Vec3& point) const noexcept { return R * point + p; }
  [[nodiscard]] constexpr Transform inverse() const noexcept {
    const Rot3 Rt = R.transposed();
    return {Rt, -(Rt * p)};
  }
  /// this⁻¹ b, without forming the inverse.
  [[nodiscard]] constexpr Transform inverse_times(const Transform& b) const noexcept {
    return {{R.transpose_times(b.R.n), R.transpose_times(b.R.o), R.transpose_times(b.R.a)},
            R.transpose_times(b.p - p)};
  }
};

/// Largest absolute difference between corresponding elements of the top three rows.
double max_abs_difference(const Transform& a, const Transform& b) noexcept;

/// R turned for dt_s at the constant angular velocity w_rad_per_s (in R's parent frame):
/// exp([w] dt) R, what extrapolating a moving frame's orientation needs.
Rot3 rotated_by(const Rot3& R, const Vec3& w_rad_per_s, double dt_s) noexcept;

/// Paul's drive transform (Robot Manipulators, 1981, ch. 5): the motion from frame A to frame B
/// split into a translation, a rotation about an axis perpendicular to A's approach vector that
/// swings it onto B's, and a rotation about the approach vector, each scaled by the fraction r.
/// Built once per segment; `at(r)` gives A D(r), equal to A at r = 0 and to B at r = 1.
class DriveTransform {
 public:
  DriveTransform() = default;
  DriveTransform(const Transform& from, const Transform& to) noexcept;

  /// The frame at fraction r of the way, r in [0, 1] (values outside extrapolate).
  [[nodiscard]] Transform at(double r) const noexcept;
  /// D(r) alone, expressed in frame A.
  [[nodiscard]] Transform relative(double r) const noexcept;

  /// The drive parameters (Paul's x, y, z in m and psi, theta, phi in rad).
  [[nodiscard]] const Vec3& translation_m() const noexcept { return xyz_; }
  [[nodiscard]] double psi_rad() const noexcept { return psi_; }
  [[nodiscard]] double theta_rad() const noexcept { return theta_; }
  [[nodiscard]] double phi_rad() const noexcept { return phi_; }

 private:
  Transform from_{};
  Transform to_{};
  Vec3 xyz_{};
  double psi_ = 0.0;
  double theta_ = 0.0;
  double phi_ = 0.0;
};

}  // namespace rccx::math
