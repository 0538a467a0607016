#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "rccx/math/batch_trig.hpp"
#include "rccx/math/transform.hpp"
#include "rccx/math/units.hpp"

namespace {

using namespace rccx::math;
using namespace rccx::math::literals;

Eigen::Matrix3d to_eigen(const Rot3& R) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = R(r, c);
  }
  return m;
}

double max_diff(const Rot3& a, const Rot3& b) {
  return (to_eigen(a) - to_eigen(b)).cwiseAbs().maxCoeff();
}

class RandomFrames : public ::testing::Test {
 protected:
  std::mt19937_64 rng{20261122};
  std::uniform_real_distribution<double> unit{-1.0, 1.0};
  std::uniform_real_distribution<double> angle{-kPi, kPi};

  Vec3 random_axis() {
    Vec3 v;
    do {
      v = {unit(rng), unit(rng), unit(rng)};
    } while (v.norm() < 0.1);
    return v.normalized();
  }
  Transform random_transform() {
    return {Rot3::about(random_axis(), angle(rng)), {unit(rng), unit(rng), unit(rng)}};
  }
};

TEST(Units, LiteralsAreSi) {
  EXPECT_DOUBLE_EQ(325_mm, 0.325);
  EXPECT_DOUBLE_EQ(2_m, 2.0);
  EXPECT_DOUBLE_EQ(180_deg, kPi);
  EXPECT_DOUBLE_EQ(-24.8_deg, -24.8 * kPi / 180.0);
  EXPECT_DOUBLE_EQ(56_ms, 0.056);
  EXPECT_DOUBLE_EQ(rad_to_deg(deg_to_rad(155.2)), 155.2);
}

TEST_F(RandomFrames, RotationAboutAnAxisMatchesEigenAngleAxis) {
  for (int i = 0; i < 1000; ++i) {
    const Vec3 k = random_axis();
    const double theta = angle(rng);
    const Eigen::Matrix3d expected =
        Eigen::AngleAxisd(theta, Eigen::Vector3d(k.x, k.y, k.z)).matrix();
    EXPECT_LT((to_eigen(Rot3::about(k * 3.0, theta)) - expected).cwiseAbs().maxCoeff(), 4e-15);
  }
}

TEST_F(RandomFrames, RotatedByIsTheAngularVelocitysFlow) {
  for (int i = 0; i < 200; ++i) {
    const Rot3 R = Rot3::about(random_axis(), angle(rng));
    const Vec3 w = random_axis() * (3.0 * unit(rng));  // rad/s
    const double dt = 0.5 * unit(rng);                 // s
    // Its derivative at dt = 0 is [w]x R (finite difference), and it composes in time.
    const double h = 1e-6;
    const Eigen::Matrix3d wx =
        (Eigen::Matrix3d() << 0, -w.z, w.y, w.z, 0, -w.x, -w.y, w.x, 0).finished();
    const Eigen::Matrix3d derivative =
        (to_eigen(rotated_by(R, w, h)) - to_eigen(rotated_by(R, w, -h))) / (2 * h);
    EXPECT_LT((derivative - wx * to_eigen(R)).cwiseAbs().maxCoeff(), 1e-8);
    EXPECT_LT(max_diff(rotated_by(rotated_by(R, w, dt), w, 0.3), rotated_by(R, w, dt + 0.3)),
              1e-14);
  }
  const Rot3 R = Rot3::about({0, 0, 1}, 0.4);
  EXPECT_EQ(max_diff(rotated_by(R, {}, 1.0), R), 0.0);  // no rate: unchanged, no NaN
}

TEST(Rotations, PrincipalAxesAgreeWithAbout) {
  for (double t : {-2.0, -0.3, 0.0, 1.1, 3.0}) {
    EXPECT_LT(max_diff(Rot3::rot_x(t), Rot3::about({1, 0, 0}, t)), 1e-15);
    EXPECT_LT(max_diff(Rot3::rot_y(t), Rot3::about({0, 1, 0}, t)), 1e-15);
    EXPECT_LT(max_diff(Rot3::rot_z(t), Rot3::about({0, 0, 1}, t)), 1e-15);
  }
  // Rot(z, 90 deg) takes x to y (right-handed).
  const Vec3 y = Rot3::rot_z(90_deg) * Vec3{1, 0, 0};
  EXPECT_NEAR(y.x, 0.0, 1e-15);
  EXPECT_NEAR(y.y, 1.0, 1e-15);
  // A zero axis gives the identity instead of NaN.
  EXPECT_EQ(Rot3::about({0, 0, 0}, 1.0).n, (Vec3{1, 0, 0}));
}

TEST_F(RandomFrames, CompositionAndInverse) {
  for (int i = 0; i < 1000; ++i) {
    const Transform A = random_transform(), B = random_transform();
    EXPECT_LT(max_abs_difference(A * A.inverse(), Transform::identity()), 1e-14);
    EXPECT_LT(max_abs_difference(A.inverse_times(B), A.inverse() * B), 1e-14);
    // (A B) maps a point as A after B.
    const Vec3 x{unit(rng), unit(rng), unit(rng)};
    EXPECT_LT(((A * B) * x - A * (B * x)).norm(), 1e-14);
    // The 4x4 product agrees with Eigen's.
    Eigen::Matrix4d a, b;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) {
        a(r, c) = A(r, c);
        b(r, c) = B(r, c);
      }
    }
    const Eigen::Matrix4d ab = a * b;
    const Transform AB = A * B;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) EXPECT_NEAR(AB(r, c), ab(r, c), 1e-14);
    }
  }
}

TEST_F(RandomFrames, RowsRoundTrip) {
  const Transform T = random_transform();
  EXPECT_EQ(max_abs_difference(Transform::from_rows(T.rows()), T), 0.0);
  const auto m = T.rows();
  EXPECT_EQ(m[3], T.p.x);
  EXPECT_EQ(m[1], T.R.o.x);  // r12 is o_x
  EXPECT_EQ(m[8], T.R.n.z);  // r31 is n_z
}

TEST_F(RandomFrames, RpyRoundTripsAndMatchesPaulsDefinition) {
  for (int i = 0; i < 1000; ++i) {
    const double roll = angle(rng), pitch = angle(rng) / 2.0, yaw = angle(rng);
    const Rot3 R = Rot3::from_rpy(roll, pitch, yaw);
    const Eigen::Matrix3d expected = (Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitX()))
                                         .matrix();
    EXPECT_LT((to_eigen(R) - expected).cwiseAbs().maxCoeff(), 1e-15);
    const auto rpy = R.to_rpy();
    EXPECT_NEAR(rpy[0], roll, 1e-9);
    EXPECT_NEAR(rpy[1], pitch, 1e-9);
    EXPECT_NEAR(rpy[2], yaw, 1e-9);
  }
  // Gimbal lock: the angles change but the rotation they give back does not.
  const Rot3 locked = Rot3::from_rpy(0.4, 90_deg, 0.3);
  const auto rpy = locked.to_rpy();
  EXPECT_LT(max_diff(Rot3::from_rpy(rpy[0], rpy[1], rpy[2]), locked), 1e-12);
}

TEST_F(RandomFrames, UrdfRpyIsAboutFixedXThenYThenZAndRoundTrips) {
  for (int i = 0; i < 1000; ++i) {
    const double roll = angle(rng), pitch = angle(rng) / 2.0, yaw = angle(rng);
    const Rot3 R = Rot3::from_urdf_rpy(roll, pitch, yaw);
    const Eigen::Matrix3d expected = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                      Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                         .matrix();
    EXPECT_LT((to_eigen(R) - expected).cwiseAbs().maxCoeff(), 1e-15);
    const auto rpy = R.to_urdf_rpy();
    EXPECT_NEAR(rpy[0], roll, 1e-9);
    EXPECT_NEAR(rpy[1], pitch, 1e-9);
    EXPECT_NEAR(rpy[2], yaw, 1e-9);
  }
  // The tool pointing down (a turn about x): URDF's roll, Paul's yaw.
  const Rot3 down = Rot3::from_urdf_rpy(180_deg, 0, 0);
  EXPECT_LT(max_diff(down, Rot3::rot_x(180_deg)), 1e-15);
  EXPECT_NEAR(std::abs(down.to_rpy()[2]), 180_deg, 1e-12);
  // Gimbal lock: yaw takes the rotation about z and the rotation it gives back is the same.
  const Rot3 locked = Rot3::from_urdf_rpy(0.3, -90_deg, 0.4);
  const auto rpy = locked.to_urdf_rpy();
  EXPECT_EQ(rpy[0], 0.0);
  EXPECT_LT(max_diff(Rot3::from_urdf_rpy(rpy[0], rpy[1], rpy[2]), locked), 1e-12);
}

TEST_F(RandomFrames, ZyzRoundTrips) {
  for (int i = 0; i < 1000; ++i) {
    const double phi = angle(rng), theta = std::abs(angle(rng)), psi = angle(rng);
    const Rot3 R = Rot3::from_zyz(phi, theta, psi);
    const auto e = R.to_zyz();
    EXPECT_LT(max_diff(Rot3::from_zyz(e[0], e[1], e[2]), R), 1e-12);
    EXPECT_NEAR(e[1], theta, 1e-9);
  }
  for (double theta : {0.0, kPi}) {
    const Rot3 R = Rot3::from_zyz(0.7, theta, -0.2);
    const auto e = R.to_zyz();
    EXPECT_LT(max_diff(Rot3::from_zyz(e[0], e[1], e[2]), R), 1e-12) << "theta " << theta;
  }
}

TEST_F(RandomFrames, AxisAngleRoundTripsIncludingHalfTurns) {
  for (int i = 0; i < 1000; ++i) {
    const Vec3 k = random_axis();
    const double theta = i % 10 == 0 ? kPi - 1e-12 * i : std::abs(angle(rng));
    Vec3 axis;
    double a = 0.0;
    Rot3::about(k, theta).to_axis_angle(axis, a);
    EXPECT_LT(max_diff(Rot3::about(axis, a), Rot3::about(k, theta)), 1e-9);
  }
}

TEST(AxisAngle, TinyRotationsAreNotRoundedToNone) {
  Vec3 axis;
  double angle = 0.0;
  Rot3::about({0, 1, 0}, 3e-12).to_axis_angle(axis, angle);
  EXPECT_NEAR(angle, 3e-12, 1e-20);
  EXPECT_NEAR(axis.y, 1.0, 1e-6);
  Rot3::identity().to_axis_angle(axis, angle);
  EXPECT_EQ(angle, 0.0);
}

TEST_F(RandomFrames, OrthonormalizeRepairsDrift) {
  Rot3 R = Rot3::about(random_axis(), 1.0);
  R.o = R.o * 1.001 + Vec3{1e-4, 0, 0};
  const Rot3 fixed = R.orthonormalized();
  const Eigen::Matrix3d m = to_eigen(fixed);
  EXPECT_LT((m.transpose() * m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_NEAR(m.determinant(), 1.0, 1e-15);
  EXPECT_LT((fixed.a - R.a).norm(), 1e-15);  // the approach vector is kept
}

TEST_F(RandomFrames, DriveTransformIsExactAtItsEnds) {
  for (int i = 0; i < 1000; ++i) {
    const Transform A = random_transform(), B = random_transform();
    const DriveTransform drive(A, B);
    EXPECT_EQ(max_abs_difference(drive.at(0.0), A), 0.0);
    EXPECT_EQ(max_abs_difference(drive.at(1.0), B), 0.0);
    // Its parameters rebuild B from A on their own, without the end-point shortcut.
    EXPECT_LT(max_abs_difference(A * drive.relative(1.0), B), 1e-13);
    EXPECT_LT(max_abs_difference(drive.relative(0.0), Transform::identity()), 1e-15);
  }
}

TEST_F(RandomFrames, DriveTransformMovesAsPaulDescribes) {
  for (int i = 0; i < 200; ++i) {
    const Transform A = random_transform(), B = random_transform();
    const DriveTransform drive(A, B);
    const Vec3 k{-std::sin(drive.psi_rad()), std::cos(drive.psi_rad()), 0.0};
    for (double r : {0.1, 0.25, 0.5, 0.9}) {
      const Transform D = drive.relative(r);
      // The translation is the straight line, in proportion to r.
      EXPECT_LT((D.p - drive.translation_m() * r).norm(), 1e-15);
      // The approach vector swings in the plane perpendicular to k, by r theta.
      EXPECT_NEAR(dot(D.R.a, k), 0.0, 1e-14);
      EXPECT_NEAR(std::acos(std::clamp(D.R.a.z, -1.0, 1.0)), r * drive.theta_rad(), 1e-7);
    }
  }
  // A pure rotation about the shared approach vector is all phi.
  const Transform A = Transform::identity();
  const Transform B{Rot3::rot_z(1.2), {}};
  const DriveTransform spin(A, B);
  EXPECT_NEAR(spin.theta_rad(), 0.0, 1e-15);
  EXPECT_NEAR(spin.phi_rad(), 1.2, 1e-15);
  EXPECT_LT(max_diff(spin.at(0.5).R, Rot3::rot_z(0.6)), 1e-15);
}

}  // namespace

namespace {

TEST(BatchTrig, BothImplementationsAgreeWithGlibc) {
  using namespace rccx::math;
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> wide(-20.0, 20.0), unit(-1.0, 1.0);
  auto check = [](const double* y, const double* x, const double* angle) {
    double s[4], c[4], at[4];
    detail::sincos4_scalar(angle, s, c);
    detail::atan2_4_scalar(y, x, at);
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(s[i], std::sin(angle[i]));
      EXPECT_EQ(at[i], std::atan2(y[i], x[i]));
    }
    if (!batch_trig_uses_avx2()) return;
    double sv[4], cv[4], atv[4];
    detail::sincos4_avx2(angle, sv, cv);
    detail::atan2_4_avx2(y, x, atv);
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(sv[i], s[i], 1e-15) << angle[i];
      EXPECT_NEAR(cv[i], c[i], 1e-15) << angle[i];
      EXPECT_NEAR(atv[i], at[i], 2e-15) << y[i] << " " << x[i];
    }
  };
  for (int n = 0; n < 2000; ++n) {
    double y[4], x[4], angle[4];
    for (int i = 0; i < 4; ++i) {
      y[i] = unit(rng);
      x[i] = unit(rng);
      angle[i] = wide(rng);
    }
    check(y, x, angle);
  }
  // The edges the kinematics meet: zeros, signed zeros, half turns.
  const double y[4] = {0.0, -0.0, 0.0, 1e-300};
  const double x[4] = {0.0, -1.0, -1.0, -1.0};
  const double angle[4] = {0.0, kPi, -kPi, 2 * kPi};
  check(y, x, angle);
  double out[4];
  atan2_4(y, x, out);
  EXPECT_EQ(out[0], 0.0);
  EXPECT_NEAR(out[2], kPi, 1e-15);
  // The eight-wide calls agree with two four-wide ones.
  double angles8[8], y8[8], x8[8];
  for (int i = 0; i < 8; ++i) {
    angles8[i] = 0.7 * i - 2.0;
    y8[i] = std::sin(0.3 * i);
    x8[i] = std::cos(1.1 * i);
  }
  double s8[8], c8[8], a8[8], s4[4], c4[4], a4[4];
  sincos8(angles8, s8, c8);
  atan2_8(y8, x8, a8);
  for (int half = 0; half < 2; ++half) {
    sincos4(angles8 + 4 * half, s4, c4);
    atan2_4(y8 + 4 * half, x8 + 4 * half, a4);
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(s8[4 * half + i], s4[i]);
      EXPECT_EQ(c8[4 * half + i], c4[i]);
      EXPECT_EQ(a8[4 * half + i], a4[i]);
    }
  }
}

}  // namespace
