// rccx::force: gravity compensation of a wrist sensor (signs from a hanging tool), the tool-load
// estimator on synthetic readings (exact without noise, within the noise's reach with it, refused
// when the orientations cannot determine it), the force transform to the tool against KDL, the
// virtual work of a twist and the thesis's F_{4,6} for the Microbo's wrist, and the wrench from
// the motors' efforts: exact against finite-difference virtual work, allocation-free, and on the
// simulated PUMA 560 exact without friction and off by what friction hides with it (the numbers
// of docs/FORCE.md come from ForceFromMotorEfforts.PrintTheTable).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <kdl/frames.hpp>
#include <map>
#include <memory>
#include <new>
#include <random>
#include <string>
#include <vector>

#include "counting_new.hpp"
#include "rccx/force/current_estimate.hpp"
#include "rccx/force/tool_load.hpp"
#include "rccx/hw/simulated_puma.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/link_frames.hpp"
#include "rccx/math/units.hpp"

namespace {

using namespace rccx;
using namespace rccx::math::literals;
using math::Rot3;
using math::Transform;
using math::Vec3;
using math::Wrench;

constexpr double g = 9.81;

Eigen::Vector3d E(const Vec3& v) {
  return {v.x, v.y, v.z};
}
Eigen::Matrix3d E(const Rot3& R) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = R(r, c);
  }
  return m;
}
double max_diff(const Wrench& a, const Wrench& b) {
  double d = 0.0;
  const auto x = a.to_array(), y = b.to_array();
  for (std::size_t i = 0; i < 6; ++i) d = std::max(d, std::abs(x[i] - y[i]));
  return d;
}

class Random {
 public:
  explicit Random(std::uint64_t seed) : rng_(seed) {}
  double uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  double normal(double sd) { return std::normal_distribution<double>(0.0, sd)(rng_); }
  Vec3 vec(double scale) {
    return {uniform(-scale, scale), uniform(-scale, scale), uniform(-scale, scale)};
  }
  Rot3 rotation() {
    Vec3 axis;
    do {
      axis = vec(1.0);
    } while (axis.norm() < 0.1);
    return Rot3::about(axis, uniform(-math::kPi, math::kPi));
  }
  Transform transform(double reach_m) { return {rotation(), vec(reach_m)}; }
  Wrench wrench(double force_N, double torque_N_m) { return {vec(force_N), vec(torque_N_m)}; }

 private:
  std::mt19937_64 rng_;
};

// ---- gravity compensation ----------------------------------------------------------------------

TEST(ExternalWrench, AHangingToolReadsItsWeightAndCompensatesToZero) {
  // T6 with its z down (the tool hangs below it), 1.5 kg 0.1 m out along T6's z and 0.02 m
  // along its x. Its weight, worked out by hand: the force is 1.5 g along world -z, which is
  // T6's +z; the torque about T6's origin is c x f = (0.02, 0, 0.1) x (0, 0, 1.5 g).
  const Rot3 down = Rot3::rot_x(180_deg);
  const double m = 1.5;
  const Vec3 c{0.02, 0.0, 0.1};
  const Wrench weight{{0, 0, m * g}, {0, -0.02 * m * g, 0}};
  const Wrench bias{{0.3, -0.2, 1.1}, {0.01, 0.02, -0.03}};
  const force::ToolLoad load{bias, m, c};
  EXPECT_LT(max_diff(force::external_wrench(load, down, bias + weight), {}), 1e-12);
  // A contact pushing the tool up (world +z, T6's -z) with 5 N at the tool tip reads as +that.
  const Wrench push{{0, 0, -5.0}, {0, 0, 0}};
  EXPECT_LT(max_diff(force::external_wrench(load, down, bias + weight + push), push), 1e-12);
  // The same tool on a wrist turned 90 deg about world y: the weight now lies along T6's +x, so
  // the compensation must follow the orientation (a fixed offset would not do).
  const Rot3 side = Rot3::rot_y(90_deg);
  const Eigen::Vector3d f = E(side).transpose() * Eigen::Vector3d(0, 0, -m * g);
  const Eigen::Vector3d t = E(c).cross(f);
  const Wrench weight_side{{f.x(), f.y(), f.z()}, {t.x(), t.y(), t.z()}};
  EXPECT_NEAR(f.x(), m * g, 1e-12);
  EXPECT_LT(max_diff(force::external_wrench(load, side, bias + weight_side), {}), 1e-12);
  EXPECT_GT(max_diff(force::external_wrench(load, down, bias + weight_side), {}), 10.0);
}

// ---- the tool-load estimator -------------------------------------------------------------------

struct SyntheticTool {
  force::ToolLoad truth{{{1.2, -0.7, 3.4}, {0.05, -0.11, 0.02}}, 0.85, {0.012, -0.008, 0.094}};

  // What the sensor reads at `R`, plus noise.
  [[nodiscard]] force::LoadSample at(const Rot3& R, Random* noise = nullptr, double sd_N = 0.0,
                                     double sd_N_m = 0.0) const {
    // Independently of weight_wrench: the weight in the world, rotated into the sensor.
    const Eigen::Vector3d f = E(R).transpose() * Eigen::Vector3d(0, 0, -truth.mass_kg * g);
    const Eigen::Vector3d t = E(truth.com_m).cross(f);
    Wrench w{{f.x(), f.y(), f.z()}, {t.x(), t.y(), t.z()}};
    w = w + truth.bias;
    if (noise != nullptr) {
      w = w + Wrench{{noise->normal(sd_N), noise->normal(sd_N), noise->normal(sd_N)},
                     {noise->normal(sd_N_m), noise->normal(sd_N_m), noise->normal(sd_N_m)}};
    }
    return {R, w};
  }
};

TEST(ToolLoadEstimate, RecoversBiasMassAndCentreOfMassExactlyWithoutNoise) {
  const SyntheticTool tool;
  Random random(11);
  for (std::size_t n : {3U, 4U, 10U}) {
    std::vector<force::LoadSample> samples;
    for (std::size_t i = 0; i < n; ++i) samples.push_back(tool.at(random.rotation()));
    force::LoadFit fit;
    const force::ToolLoad load = force::estimate_tool_load(samples, &fit);
    EXPECT_NEAR(load.mass_kg, tool.truth.mass_kg, 1e-10) << n;
    EXPECT_LT((E(load.com_m) - E(tool.truth.com_m)).norm(), 1e-10) << n;
    EXPECT_LT(max_diff(load.bias, tool.truth.bias), 1e-10) << n;
    EXPECT_LT(fit.rms_force_N, 1e-10);
    EXPECT_LT(fit.rms_torque_N_m, 1e-10);
    EXPECT_EQ(fit.samples, n);
    EXPECT_GT(fit.conditioning, force::kMinLoadConditioning);
    // Compensated with the estimate, every reading is (near) zero.
    for (const auto& s : samples) {
      EXPECT_LT(max_diff(force::external_wrench(load, s.world_from_sensor, s.reading), {}), 1e-9);
    }
  }
}

TEST(ToolLoadEstimate, WithTheSensorsNoiseRecoversWithinWhatTheNoiseAllows) {
  // The default sensor's noise (hw::ForceSensorSpec: 0.06 N, 0.002 N m) on single readings at
  // 12 random orientations: the mass to 10 g, the centre of mass to 2 mm, the bias to twice one
  // reading's noise (0.12 N, 0.004 N m, as vectors); the residuals are the noise's size.
  const SyntheticTool tool;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    Random random(seed);
    std::vector<force::LoadSample> samples;
    for (int i = 0; i < 12; ++i)
      samples.push_back(tool.at(random.rotation(), &random, 0.06, 0.002));
    force::LoadFit fit;
    const force::ToolLoad load = force::estimate_tool_load(samples, &fit);
    EXPECT_NEAR(load.mass_kg, tool.truth.mass_kg, 0.01) << seed;
    EXPECT_LT((E(load.com_m) - E(tool.truth.com_m)).norm(), 0.002) << seed;
    EXPECT_LT((E(load.bias.force_N) - E(tool.truth.bias.force_N)).norm(), 0.12) << seed;
    EXPECT_LT((E(load.bias.torque_N_m) - E(tool.truth.bias.torque_N_m)).norm(), 0.004) << seed;
    // 72 equations, 10 unknowns: the RMS residual is about sqrt(62 / 72) of the noise.
    EXPECT_GT(fit.rms_force_N, 0.03) << seed;
    EXPECT_LT(fit.rms_force_N, 0.09) << seed;
    EXPECT_GT(fit.rms_torque_N_m, 0.001) << seed;
    EXPECT_LT(fit.rms_torque_N_m, 0.003) << seed;
  }
}

void expect_refused(const std::vector<force::LoadSample>& samples, const std::string& what) {
  try {
    (void)force::estimate_tool_load(samples);
    ADD_FAILURE() << what << ": accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("take readings at three or more orientations that "
                                         "differ about two axes"),
              std::string::npos)
        << what << ": " << e.what();
  }
}

TEST(ToolLoadEstimate, RefusesSamplesThatCannotDetermineTheLoad) {
  const SyntheticTool tool;
  Random random(5);
  expect_refused({}, "none");
  expect_refused({tool.at(random.rotation()), tool.at(random.rotation())}, "two");
  // Many readings, one orientation.
  const Rot3 R = random.rotation();
  expect_refused({tool.at(R), tool.at(R), tool.at(R), tool.at(R)}, "one orientation");
  // Turned about the vertical only: gravity stays where it was in the sensor frame.
  std::vector<force::LoadSample> about_vertical;
  for (double a : {0.0, 0.7, 1.9, -2.5}) about_vertical.push_back(tool.at(Rot3::rot_z(a) * R));
  expect_refused(about_vertical, "about the vertical");
  // Two orientations, repeated.
  const Rot3 R2 = Rot3::rot_x(0.8) * R;
  expect_refused({tool.at(R), tool.at(R2), tool.at(R), tool.at(R2)}, "two orientations");
  // A turn about a horizontal axis does determine it (three gravity directions).
  std::vector<force::LoadSample> about_x;
  for (double a : {0.0, 0.9, -0.9}) about_x.push_back(tool.at(Rot3::rot_x(a)));
  EXPECT_NEAR(force::estimate_tool_load(about_x).mass_kg, tool.truth.mass_kg, 1e-9);
  // Not finite.
  std::vector<force::LoadSample> bad{tool.at(R), tool.at(R2), tool.at(Rot3::rot_y(1.0))};
  bad[1].reading.force_N.y = std::nan("");
  EXPECT_THROW((void)force::estimate_tool_load(bad), std::invalid_argument);
}

// ---- the force transform to the tool -----------------------------------------------------------

KDL::Frame kdl(const Transform& T) {
  return {KDL::Rotation(T.R.n.x, T.R.o.x, T.R.a.x, T.R.n.y, T.R.o.y, T.R.a.y, T.R.n.z, T.R.o.z,
                        T.R.a.z),
          KDL::Vector(T.p.x, T.p.y, T.p.z)};
}

TEST(AtTool, AgreesWithKdlsFrameTimesWrench) {
  Random random(3);
  for (int i = 0; i < 500; ++i) {
    const Transform t6_from_tool = random.transform(0.3);
    const Wrench w = random.wrench(50.0, 5.0);
    // KDL: Frame * Wrench re-expresses a wrench given in the frame's own coordinates in its
    // reference's; the inverse takes T6's to the tool's.
    const KDL::Wrench k = kdl(t6_from_tool).Inverse() *
                          KDL::Wrench(KDL::Vector(w.force_N.x, w.force_N.y, w.force_N.z),
                                      KDL::Vector(w.torque_N_m.x, w.torque_N_m.y, w.torque_N_m.z));
    const Wrench expected{{k.force.x(), k.force.y(), k.force.z()},
                          {k.torque.x(), k.torque.y(), k.torque.z()}};
    EXPECT_LT(max_diff(force::at_tool(t6_from_tool, w), expected), 1e-12);
  }
}

TEST(AtTool, KeepsThePowerOfEveryTwist) {
  // A wrench and a rigid-body twist give the same power in any frame: the twist given at the
  // tool (v of the tool's origin and w, tool axes) seen at T6 (v of T6's origin and w, T6 axes).
  Random random(4);
  for (int i = 0; i < 500; ++i) {
    const Transform T = random.transform(0.3);  // the tool in T6
    const Wrench w6 = random.wrench(50.0, 5.0);
    const Eigen::Vector3d v_tool = E(random.vec(1.0)), w_tool = E(random.vec(2.0));
    const Eigen::Matrix3d R = E(T.R);
    const Eigen::Vector3d w_6 = R * w_tool;
    const Eigen::Vector3d v_6 = R * v_tool + w_6.cross(-E(T.p));  // T6's origin is at -p
    const double power_6 = E(w6.force_N).dot(v_6) + E(w6.torque_N_m).dot(w_6);
    const Wrench wt = force::at_tool(T, w6);
    const double power_tool = E(wt.force_N).dot(v_tool) + E(wt.torque_N_m).dot(w_tool);
    EXPECT_NEAR(power_tool, power_6, 1e-10 * (1.0 + std::abs(power_6)));
  }
}

TEST(AtTool, IsTheThesisF46OnTheMicrobosWrist) {
  // Thesis 4.4.2 (F_{4,6}, B with C5 C6 ...) carries a wrench in link frame 4 of the Microbo to
  // link frame 6, the two apart by joints 5 and 6 only (alpha5 = 90 deg, alpha6 = 0, no a or
  // d): 4T6 = A5 A6, a pure rotation, and B = (4R6)^T. Printed as [[0 B] [B 0]] it takes
  // (f4; t4) to (t6; f6): each of force and torque turned by B.
  const kin::RobotModel microbo = kin::builtin_robot("microbo");
  ASSERT_EQ(microbo.dof(), 6U);
  Random random(6);
  for (int i = 0; i < 200; ++i) {
    kin::JointVector q = microbo.ready();
    q[4] = random.uniform(-math::kPi, math::kPi);
    q[5] = random.uniform(-math::kPi, math::kPi);
    std::array<Transform, 6> frames;
    kin::link_frames(microbo, q, frames);
    const Transform t4_from_t6 = frames[3].inverse_times(frames[5]);
    ASSERT_LT(E(t4_from_t6.p).norm(), 1e-12) << "frames 4 and 6 share their origin";

    const double C5 = std::cos(q[4]), S5 = std::sin(q[4]), C6 = std::cos(q[5]), S6 = std::sin(q[5]);
    Eigen::Matrix3d B;
    B << C5 * C6, S5 * C6, S6, -C5 * S6, -S5 * S6, C6, S5, -C5, 0.0;
    Eigen::Matrix<double, 6, 6> F46 = Eigen::Matrix<double, 6, 6>::Zero();
    F46.topRightCorner<3, 3>() = B;
    F46.bottomLeftCorner<3, 3>() = B;

    const Wrench w4 = random.wrench(50.0, 5.0);
    Eigen::Matrix<double, 6, 1> x;
    x << E(w4.force_N), E(w4.torque_N_m);
    const Eigen::Matrix<double, 6, 1> y = F46 * x;  // (t6; f6)
    const Wrench w6 = force::at_tool(t4_from_t6, w4);
    EXPECT_LT((E(w6.torque_N_m) - y.head<3>()).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((E(w6.force_N) - y.tail<3>()).cwiseAbs().maxCoeff(), 1e-12);
  }
}

// ---- the wrench from the motors' efforts -------------------------------------------------------

/// The effort contacts put on the joints for a wrench `F` (force at the tool's origin, torque,
/// both in base axes) by virtual work, with the tool's motion per joint by central differences
/// of forward(): no Jacobian involved.
kin::JointVector effort_by_virtual_work(const kin::Kinematics& k, const kin::JointVector& q,
                                        const Transform& t6_from_tool, const Eigen::Vector3d& f,
                                        const Eigen::Vector3d& t) {
  const double h = 1e-6;
  kin::JointVector tau(q.size());
  for (std::size_t j = 0; j < q.size(); ++j) {
    kin::JointVector qp = q, qm = q;
    qp[j] += h;
    qm[j] -= h;
    const Transform Tp = k.forward(qp) * t6_from_tool, Tm = k.forward(qm) * t6_from_tool;
    const Eigen::Vector3d v = (E(Tp.p) - E(Tm.p)) / (2 * h);
    const Eigen::Matrix3d W =
        (E(Tp.R) - E(Tm.R)) / (2 * h) * E(k.forward(q).R * t6_from_tool.R).transpose();
    const Eigen::Vector3d w(W(2, 1), W(0, 2), W(1, 0));
    tau[j] = f.dot(v) + t.dot(w);
  }
  return tau;
}

TEST(MotorWrench, InvertsVirtualWorkExactlyOnThePuma) {
  const kin::RobotModel model = kin::builtin_robot("puma560");
  const auto kinematics = kin::make_kinematics(model);
  Random random(7);
  int checked = 0;
  for (int i = 0; i < 200; ++i) {
    kin::JointVector q(model.dof());
    for (std::size_t j = 0; j < q.size(); ++j) {
      q[j] = random.uniform(model.joints[j].lower, model.joints[j].upper);
    }
    if (std::abs(q[4]) < 0.2) continue;  // keep away from the wrist singularity
    const Transform tool{random.rotation(), random.vec(0.15)};
    const Eigen::Vector3d f = E(random.vec(30.0)), t = E(random.vec(3.0));
    const kin::JointVector tau_ext = effort_by_virtual_work(*kinematics, q, tool, f, t);
    // The motors hold gravity (any numbers will do here) against what the contact adds.
    kin::JointVector gravity(q.size()), motor(q.size());
    for (std::size_t j = 0; j < q.size(); ++j) {
      gravity[j] = random.uniform(-40.0, 40.0);
      motor[j] = gravity[j] - tau_ext[j];
    }
    const auto est =
        force::wrench_from_motor_effort(*kinematics, q, motor, gravity, {}, {.t6_from_tool = tool});
    ASSERT_TRUE(est.ok);
    if (est.min_singular_value < 0.02) continue;  // near the shoulder or elbow singularities
    // The truth in the tool's axes.
    const Eigen::Matrix3d Rt = E(kinematics->forward(q).R * tool.R).transpose();
    const double scale = 1.0 / est.min_singular_value;
    EXPECT_LT((E(est.wrench.force_N) - Rt * f).norm(), 1e-6 * scale) << i;
    EXPECT_LT((E(est.wrench.torque_N_m) - Rt * t).norm(), 1e-6 * scale) << i;
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST(MotorWrench, RefusesMismatchedSizesAndDampsNearSingularities) {
  const kin::RobotModel model = kin::builtin_robot("puma560");
  const auto kinematics = kin::make_kinematics(model);
  const kin::JointVector q = model.ready();
  const kin::JointVector five(5);
  EXPECT_FALSE(force::wrench_from_motor_effort(*kinematics, q, five, q).ok);
  EXPECT_FALSE(force::wrench_from_motor_effort(*kinematics, q, q, q, five).ok);
  // At the wrist singularity (theta5 = 0) the pseudo-inverse drops the lost direction instead
  // of dividing by zero; damping keeps every number finite and small.
  kin::JointVector qs = q;
  qs[4] = 0.0;
  kin::JointVector motor(6), gravity(6);
  motor[3] = 1.0;
  motor[5] = -1.0;
  for (double damping : {0.0, 0.01}) {
    const auto est =
        force::wrench_from_motor_effort(*kinematics, qs, motor, gravity, {}, {.damping = damping});
    ASSERT_TRUE(est.ok);
    EXPECT_LT(est.min_singular_value, 1e-9);
    for (double v : est.wrench.to_array()) EXPECT_TRUE(std::isfinite(v));
    EXPECT_LT(E(est.wrench.torque_N_m).norm(), 10.0);
  }
}

TEST(MotorWrench, AllocatesNothing) {
  const kin::RobotModel model = kin::builtin_robot("puma560");
  const auto kinematics = kin::make_kinematics(model);
  const kin::JointVector q = model.ready();
  kin::JointVector motor(6), gravity(6), qd(6);
  for (std::size_t j = 0; j < 6; ++j) {
    motor[j] = 0.3 * static_cast<double>(j) - 1.0;
    qd[j] = 0.1 * static_cast<double>(j) - 0.2;
  }
  const Transform tool = Transform::translation(0, 0, 0.1);
  const long before = rccx::test_support::thread_allocations();
  const kin::JointVector friction = force::friction_effort(model, qd);
  const auto a = force::wrench_from_motor_effort(*kinematics, q, motor, gravity, friction,
                                                 {.t6_from_tool = tool});
  const auto b = force::wrench_from_motor_effort(*kinematics, q, motor, gravity, friction,
                                                 {.t6_from_tool = tool, .damping = 0.01});
  const Wrench c = force::external_wrench({}, Rot3::rot_x(0.3), a.wrench);
  const Wrench d = force::at_tool(tool, b.wrench);
  EXPECT_EQ(rccx::test_support::thread_allocations(), before);
  { const auto counted = std::make_unique<double>(1.0); }  // the counter does count
  EXPECT_EQ(rccx::test_support::thread_allocations(), before + 1);
  EXPECT_TRUE(a.ok && b.ok && std::isfinite(c.force_N.x) && std::isfinite(d.force_N.x));
}

TEST(MotorWrench, FrictionEffortIsTheRobotFilesModel) {
  const kin::RobotModel model = kin::builtin_robot("puma560");
  const kin::JointVector qd{0.5, -0.5, 0.0, 1.0, -2.0, 0.0};
  const kin::JointVector f = force::friction_effort(model, qd);
  ASSERT_EQ(f.size(), 6U);
  EXPECT_DOUBLE_EQ(f[0], 5.80 * 0.5 + 26.0);  // robots/puma560.json
  EXPECT_DOUBLE_EQ(f[1], -9.50 * 0.5 - 10.6);
  EXPECT_DOUBLE_EQ(f[2], 0.0);  // at rest: unknown static friction, taken as none
  EXPECT_DOUBLE_EQ(f[4], -0.427 * 2.0 - 0.854);
}

// ---- the VAX estimate on the simulated PUMA 560 ------------------------------------------------

enum class Friction { none, file };  ///< the plant's joint friction: none, or robots/puma560.json's

struct PumaCase {
  Friction plant = Friction::file;
  bool model_friction = false;  ///< the estimate subtracts the file's friction model at qd
  int axis = 0;                 ///< 10 N along base x, y or z on the tool's tip
  double speed = 0.0;           ///< every joint at this fraction of its top speed (0: at rest)
  auto operator<=>(const PumaCase&) const = default;
};

struct PumaResult {
  double error_N = 0.0;  ///< |estimated - true force|, mean over the measuring window
  /// What friction may hide, derived from the plant: moving, |J^-T friction(qd)| at the tool;
  /// at rest, the largest |J^-T dtau| over the box |dtau_j| <= Coulomb_j.
  double friction_N = 0.0;
  /// Moving: |J^-T I qdd| at the tool, what the quasi-static estimate leaves out.
  double inertia_N = 0.0;
  double tool_speed_m_per_s = 0.0;
  double min_singular_value = 1e9;  ///< of J over the window
  bool all_joints_stick = false;    ///< at rest: every |tau_ext| below the joint's Coulomb
};

constexpr double kForce_N = 10.0;
const Transform kTool = Transform::translation(0.0, 0.0, 0.1);  // a 0.1 m tool along a

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

Mat6 jacobian6(const kin::Kinematics& k, const kin::JointVector& q) {
  return k.jacobian(q);
}

// Runs the arm at its ready pose (or moving from it) with the force on the tool; returns the
// motor-current estimate's error and what the plant says it should be.
PumaResult run_puma(const PumaCase& c) {
  kin::RobotModel model = kin::builtin_robot("puma560");
  if (c.plant == Friction::none) {
    for (auto& j : model.joints) j.dynamics.viscous_friction = j.dynamics.coulomb_friction = 0.0;
  }
  const kin::RobotModel file = kin::builtin_robot("puma560");  // the estimate's friction model
  const auto kinematics = kin::make_kinematics(model);
  hw::SimulatedPuma arm(model);
  const std::size_t n = model.dof();
  const kin::JointVector q0 = model.ready();
  Eigen::Vector3d F = Eigen::Vector3d::Zero();
  F(c.axis) = kForce_N;

  // The contact: the force on the tool's tip as joint efforts, tau = J^T (f, (R p_tool) x f).
  auto apply_force = [&] {
    const kin::JointVector q = arm.true_position();
    Vec6 w;
    w << F, E(kinematics->forward(q).R * kTool.p).cross(F);
    const Vec6 tau = jacobian6(*kinematics, q).transpose() * w;
    for (std::size_t j = 0; j < n; ++j) arm.set_external_effort(j, tau(static_cast<int>(j)));
    return tau;
  };
  // The force part at the tool (tool axes) of J^-T tau, by a full solve.
  auto at_tool_force = [&](const kin::JointVector& q, const Vec6& tau) {
    const Vec6 w = jacobian6(*kinematics, q).transpose().fullPivLu().solve(tau);
    return Eigen::Vector3d(E((kinematics->forward(q) * kTool).R).transpose() * w.head<3>());
  };

  PumaResult result;
  double t = 0.0;
  const double dt = hw::kServoPeriod_s;
  auto step = [&] {
    apply_force();
    t += dt;
    arm.advance_to(t);
  };
  auto estimate_error = [&] {
    const kin::JointVector q = arm.true_position(), qd = arm.true_velocity();
    const kin::JointVector friction =
        c.model_friction ? force::friction_effort(file, qd) : kin::JointVector{};
    const auto est = force::wrench_from_motor_effort(
        *kinematics, q, arm.motor_effort(), arm.gravity_load(q), friction, {.t6_from_tool = kTool});
    result.min_singular_value = std::min(result.min_singular_value, est.min_singular_value);
    const Eigen::Vector3d truth = E((kinematics->forward(q) * kTool).R).transpose() * F;
    return (E(est.wrench.force_N) - truth).norm();
  };

  if (c.speed == 0.0) {
    const Vec6 tau = apply_force();
    result.all_joints_stick = true;
    for (std::size_t j = 0; j < n; ++j) {
      if (std::abs(tau(static_cast<int>(j))) >= model.joints[j].dynamics.coulomb_friction) {
        result.all_joints_stick = false;
      }
    }
    // The box |dtau_j| <= Fc_j: its largest image is at a corner.
    for (int corner = 0; corner < 64; ++corner) {
      Vec6 d;
      for (int j = 0; j < 6; ++j) {
        const double fc = model.joints[static_cast<std::size_t>(j)].dynamics.coulomb_friction;
        d(j) = (corner >> j & 1) != 0 ? fc : -fc;
      }
      result.friction_N = std::max(result.friction_N, at_tool_force(q0, d).norm());
    }
    while (t < 0.6 - 1e-9) step();
    result.error_N = estimate_error();
    return result;
  }

  // Moving: every joint at `speed` of its top speed (the rate ramped up over 0.1 s, as a
  // trajectory would), away from the ready pose in directions that stay clear of the limits
  // and the singularities while it runs (0.4 s); measured every 5 ms over its last 0.1 s.
  const std::array<double, 6> direction{1, 1, -1, 1, 1, 1};
  int window = 0;
  kin::JointVector qd_before;
  while (t < 0.4 - 1e-9) {
    for (std::size_t j = 0; j < n; ++j) {
      const double rate = c.speed * model.joints[j].max_velocity * std::min(1.0, (t + dt) / 0.1);
      (void)arm.command(j, {hw::ServoCommand::Kind::move, q0[j] + direction[j] * 3.0, rate});
    }
    const bool measure = t > 0.3 - 1e-9 && std::lround(t / dt) % 5 == 4;
    if (measure) qd_before = arm.true_velocity();
    step();
    if (!measure) continue;
    result.error_N += estimate_error();
    const kin::JointVector q = arm.true_position(), qd = arm.true_velocity();
    const kin::JointVector f = force::friction_effort(model, qd);
    Vec6 fv, inertia, qdv;
    for (std::size_t j = 0; j < n; ++j) {
      const int i = static_cast<int>(j);
      fv(i) = f[j];
      inertia(i) = model.joints[j].dynamics.inertia * (qd[j] - qd_before[j]) / dt;
      qdv(i) = qd[j];
    }
    result.friction_N += at_tool_force(q, fv).norm();
    result.inertia_N += at_tool_force(q, inertia).norm();
    const Vec6 twist = jacobian6(*kinematics, q) * qdv;
    const Eigen::Vector3d v_tool =
        twist.head<3>() + twist.tail<3>().cross(E(kinematics->forward(q).R * kTool.p));
    result.tool_speed_m_per_s += v_tool.norm();
    ++window;
  }
  result.error_N /= window;
  result.friction_N /= window;
  result.inertia_N /= window;
  result.tool_speed_m_per_s /= window;
  return result;
}

// Each case is run once and shared by the tests below.
const PumaResult& puma(const PumaCase& c) {
  static std::map<PumaCase, PumaResult> results;
  auto it = results.find(c);
  if (it == results.end()) it = results.emplace(c, run_puma(c)).first;
  return it->second;
}

constexpr std::array<double, 3> kSpeeds{0.05, 0.15, 0.3};

TEST(ForceFromMotorEfforts, IsExactWithoutFrictionAtRestAndOffOnlyByInertiaMoving) {
  // No friction in the plant: at rest the motors' efforts hold gravity and the contact exactly
  // (the servo's integrator has settled). Moving at constant joint speeds, what is left is the
  // servo's transient (I qdd, which the quasi-static estimate leaves out): within 2 % of F.
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LT(puma({.plant = Friction::none, .axis = axis}).error_N, 1e-6) << axis;
    for (double speed : kSpeeds) {
      const PumaResult& r = puma({.plant = Friction::none, .axis = axis, .speed = speed});
      EXPECT_GT(r.min_singular_value, 0.1);
      EXPECT_LT(r.error_N, 0.02 * kForce_N) << axis << " at " << speed;
      EXPECT_LT(r.error_N, 1.2 * r.inertia_N + 1e-3) << axis << " at " << speed;
    }
  }
}

TEST(ForceFromMotorEfforts, AtRestFrictionHidesUpToItsBox) {
  // At rest a joint holds up to its Coulomb friction without its motor's effort changing. When
  // the load asks less of every joint than that, nothing moves and the estimate stays at zero:
  // the whole force is missed. Either way the error is within the box's image at the tool, and
  // the friction model cannot help (a joint at rest has no sign to take).
  int all_stuck = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const PumaResult& r = puma({.axis = axis});
    if (r.all_joints_stick) {
      EXPECT_NEAR(r.error_N, kForce_N, 1e-6) << axis;
      ++all_stuck;
    }
    EXPECT_GT(r.error_N, 0.5 * kForce_N) << axis;
    EXPECT_LE(r.error_N, r.friction_N) << axis;
    EXPECT_GT(r.friction_N, 5.0 * kForce_N) << axis;  // what friction may hide, about any load
    EXPECT_NEAR(puma({.model_friction = true, .axis = axis}).error_N, r.error_N, 1e-9) << axis;
  }
  EXPECT_GE(all_stuck, 2);  // 10 N along x and y ask less of every joint than its friction
}

TEST(ForceFromMotorEfforts, MovingItIsOffByTheFrictionAndTheModelTakesThatAway) {
  for (int axis = 0; axis < 3; ++axis) {
    for (double speed : kSpeeds) {
      const PumaResult& raw = puma({.axis = axis, .speed = speed});
      // The friction the motors overcome, seen at the tool, is the estimate's error.
      EXPECT_GT(raw.friction_N, 5.0 * kForce_N) << axis << " at " << speed;
      EXPECT_NEAR(raw.error_N, raw.friction_N, 0.05 * raw.friction_N) << axis << " at " << speed;
      // With the robot file's friction model (the plant's own: a real arm's is known far
      // worse), what is left is the servo's transient, as without friction.
      const PumaResult& modelled = puma({.model_friction = true, .axis = axis, .speed = speed});
      EXPECT_LT(modelled.error_N, 0.02 * kForce_N) << axis << " at " << speed;
    }
  }
}

TEST(ForceFromMotorEfforts, Table) {
  // docs/FORCE.md, "Force from motor currents": the estimate's error (N) for 10 N along base x,
  // y, z on a 0.1 m tool, beside the wrist sensor's noise (0.06 N).
  std::printf(
      "| F 10 N along | motion | tool speed (m/s) | no friction | friction | friction "
      "modelled | friction's bound | inertia |\n");
  for (int axis = 0; axis < 3; ++axis) {
    for (double speed : {0.0, kSpeeds[0], kSpeeds[1], kSpeeds[2]}) {
      const PumaResult& none = puma({.plant = Friction::none, .axis = axis, .speed = speed});
      const PumaResult& raw = puma({.axis = axis, .speed = speed});
      const PumaResult& modelled = puma({.model_friction = true, .axis = axis, .speed = speed});
      const std::string motion =
          speed == 0.0 ? "at rest" : std::to_string(std::lround(speed * 100)) + " % top speed";
      std::printf("| %c | %s | %.2f | %.2g | %.1f | %.2g | %.1f | %.2g |\n", "xyz"[axis],
                  motion.c_str(), raw.tool_speed_m_per_s, none.error_N, raw.error_N,
                  modelled.error_N, raw.friction_N, raw.inertia_N);
    }
  }
}

}  // namespace
