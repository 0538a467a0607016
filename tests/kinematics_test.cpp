#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <map>
#include <random>
#include <tuple>

#include "rccx/kinematics/dh_kinematics.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/math/units.hpp"

namespace {

using namespace rccx;
using namespace rccx::math::literals;

// Every shipped robot, and those with a closed form (the Stanford arm has only the DH solver).
const char* const kRobots[] = {"microbo", "puma560", "puma260", "stanford"};
const char* const kClosedForms[] = {"microbo", "puma560", "puma260"};

// The oracle: the same DH table, multiplied out by Orocos KDL.
KDL::Chain kdl_chain(const kin::RobotModel& model) {
  KDL::Chain chain;
  for (const kin::Joint& j : model.joints) {
    const KDL::Joint joint(j.type == kin::JointType::revolute ? KDL::Joint::RotZ
                                                              : KDL::Joint::TransZ);
    chain.addSegment(
        KDL::Segment(joint, KDL::Frame::DH(j.dh.a_m, j.dh.alpha_rad, j.dh.d_m, j.dh.theta_rad)));
  }
  return chain;
}

double max_difference(const math::Transform& T, const KDL::Frame& F) {
  double m = 0.0;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m = std::max(m, std::abs(T(r, c) - F.M(r, c)));
    m = std::max(m, std::abs(T(r, 3) - F.p(r)));
  }
  return m;
}

class RandomJoints {
 public:
  explicit RandomJoints(const kin::RobotModel& model, std::uint64_t seed = 1986)
      : model_(model), rng_(seed) {}
  kin::JointVector operator()() {
    kin::JointVector q(model_.dof());
    for (std::size_t i = 0; i < model_.dof(); ++i) {
      q[i] = std::uniform_real_distribution<double>(model_.joints[i].lower,
                                                    model_.joints[i].upper)(rng_);
    }
    return q;
  }

 private:
  const kin::RobotModel& model_;
  std::mt19937_64 rng_;
};

bool all_finite(const kin::JointVector& q) {
  return std::all_of(q.begin(), q.end(), [](double v) { return std::isfinite(v); });
}

// How far a recovered joint may drift: theta4 and theta6 come from atan2 of numbers scaled by
// sin(theta5), so near the wrist singularity their error grows as 1/|sin(theta5)|.
// Near the stretched elbow theta2 and theta3 lose precision the same way; 1e-9 rad is far below
// any difference between configurations.
double joint_tolerance(double sin_theta5) {
  return std::max(1e-9, 1e-14 / std::abs(sin_theta5));
}

class EveryRobot : public ::testing::TestWithParam<const char*> {};
INSTANTIATE_TEST_SUITE_P(Kinematics, EveryRobot, ::testing::ValuesIn(kRobots));
class ClosedForm : public ::testing::TestWithParam<const char*> {};
INSTANTIATE_TEST_SUITE_P(Kinematics, ClosedForm, ::testing::ValuesIn(kClosedForms));

TEST_P(EveryRobot, ForwardMatchesKdl) {
  const kin::RobotModel model = kin::builtin_robot(GetParam());
  const auto closed = kin::make_kinematics(model);
  const kin::DhKinematics dh(model);
  const KDL::Chain chain = kdl_chain(model);
  KDL::ChainFkSolverPos_recursive kdl(chain);
  RandomJoints random(model);
  for (int i = 0; i < 10000; ++i) {
    const kin::JointVector q = random();
    KDL::JntArray jq(static_cast<unsigned>(q.size()));
    for (std::size_t j = 0; j < q.size(); ++j) jq(static_cast<unsigned>(j)) = q[j];
    KDL::Frame F;
    ASSERT_GE(kdl.JntToCart(jq, F), 0);
    ASSERT_LT(max_difference(closed->forward(q), F), 1e-12) << "closed form, sample " << i;
    ASSERT_LT(max_difference(dh.forward(q), F), 1e-12) << "DH chain, sample " << i;
  }
}

TEST_P(EveryRobot, JacobianMatchesKdl) {
  const kin::RobotModel model = kin::builtin_robot(GetParam());
  const auto k = kin::make_kinematics(model);
  const KDL::Chain chain = kdl_chain(model);
  KDL::ChainJntToJacSolver kdl(chain);
  RandomJoints random(model, 7);
  for (int i = 0; i < 2000; ++i) {
    const kin::JointVector q = random();
    KDL::JntArray jq(6);
    for (unsigned j = 0; j < 6; ++j) jq(j) = q[j];
    KDL::Jacobian expected(6);
    ASSERT_GE(kdl.JntToJac(jq, expected), 0);
    const kin::Jacobian J = k->jacobian(q);
    ASSERT_EQ(J.cols(), 6);
    ASSERT_LT((J - expected.data).cwiseAbs().maxCoeff(), 1e-12) << "sample " << i;
  }
}

TEST_P(ClosedForm, ForwardOfInverseAndInverseOfForwardRoundTrip) {
  const kin::RobotModel model = kin::builtin_robot(GetParam());
  const auto k = kin::make_kinematics(model);
  const auto names = k->configuration_names();
  ASSERT_FALSE(names.empty());
  RandomJoints random(model, 42);
  std::map<std::string_view, int> solved_per_configuration;
  constexpr int kSamples = 100000;
  for (int i = 0; i < kSamples; ++i) {
    const kin::JointVector q = random();
    const math::Transform T = k->forward(q);
    const kin::Configuration config = k->configuration_of(q);

    // IK(FK(q)) recovers q: its own configuration, staying near q for the 2 pi choices.
    kin::IkOptions options;
    options.configuration = config;
    options.near = q;
    const kin::IkResult r = k->inverse(T, options);
    ASSERT_TRUE(r) << kin::describe(r.status) << " at sample " << i;
    EXPECT_EQ(r.configuration, config);
    const double tolerance = joint_tolerance(std::sin(q[4]));
    for (std::size_t j = 0; j < 6; ++j) {
      ASSERT_NEAR(r.q[j], q[j], tolerance) << "joint " << j + 1 << ", sample " << i;
    }

    // Every configuration's solution within limits puts T6 back at T and is what it says.
    const kin::IkSolutions all = k->inverse_all(T);
    ASSERT_GE(all.count, 1u) << "sample " << i;
    for (const kin::IkResult& s : all.solutions()) {
      ASSERT_TRUE(all_finite(s.q));
      ASSERT_TRUE(model.within_limits(s.q));
      ASSERT_LT(math::max_abs_difference(k->forward(s.q), T), 1e-10)
          << k->configuration_name(s.configuration) << ", sample " << i;
      ASSERT_EQ(k->configuration_of(s.q), s.configuration) << "sample " << i;
      ++solved_per_configuration[k->configuration_name(s.configuration)];
    }
  }
  // Every configuration name was exercised; report how often.
  for (std::string_view name : names) {
    EXPECT_GT(solved_per_configuration[name], 0) << name;
    RecordProperty(std::string("solved_") + std::string(name), solved_per_configuration[name]);
  }
}

TEST_P(ClosedForm, ConfigurationsGiveDistinctSolutionsOfTheSamePose) {
  const kin::RobotModel model = kin::builtin_robot(GetParam());
  // Solve every configuration of the ready pose without limits (a model with wide limits).
  kin::RobotModel wide = model;
  for (kin::Joint& j : wide.joints) {
    if (j.type == kin::JointType::revolute) {
      j.lower = -4.0 * math::kPi;
      j.upper = 4.0 * math::kPi;
    }
  }
  const auto k = kin::make_kinematics(wide);
  const math::Transform T = k->forward(model.ready());
  const kin::IkSolutions all = k->inverse_all(T);
  EXPECT_EQ(all.count, k->configuration_names().size());
  for (std::size_t a = 0; a < all.count; ++a) {
    EXPECT_LT(math::max_abs_difference(k->forward(all.items[a].q), T), 1e-12);
    for (std::size_t b = a + 1; b < all.count; ++b) {
      double d = 0.0;
      for (std::size_t j = 0; j < 6; ++j) {
        d = std::max(
            d, std::abs(std::remainder(all.items[a].q[j] - all.items[b].q[j], 2 * math::kPi)));
      }
      EXPECT_GT(d, 1e-3) << k->configuration_name(all.items[a].configuration) << " vs "
                         << k->configuration_name(all.items[b].configuration);
    }
  }
}

TEST_P(EveryRobot, NeverNanWhateverThePose) {
  const auto k = kin::make_kinematics(kin::builtin_robot(GetParam()));
  const bool numeric = k->configuration_names().empty();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> box(-1.5, 1.5), angle(-math::kPi, math::kPi);
  int solved = 0, refused = 0;
  for (int i = 0; i < (numeric ? 300 : 20000); ++i) {
    const math::Transform T{math::Rot3::from_rpy(angle(rng), angle(rng) / 2, angle(rng)),
                            {box(rng), box(rng), box(rng)}};
    const kin::IkResult r = k->inverse(T);
    if (r) {
      ++solved;
      ASSERT_TRUE(all_finite(r.q));
      ASSERT_LT(math::max_abs_difference(k->forward(r.q), T), 1e-10);
    } else {
      ++refused;
      ASSERT_TRUE(r.status == kin::IkStatus::out_of_reach ||
                  r.status == kin::IkStatus::joint_limits ||
                  (numeric && (r.status == kin::IkStatus::no_convergence ||
                               r.status == kin::IkStatus::singular)))
          << kin::to_string(r.status);
    }
  }
  EXPECT_GT(refused, 0);  // the box reaches beyond every arm
}

TEST_P(ClosedForm, BadInputIsRefused) {
  const auto k = kin::make_kinematics(kin::builtin_robot(GetParam()));
  math::Transform T = k->forward(k->model().ready());
  kin::IkOptions wrong_size;
  wrong_size.near = kin::JointVector{0.0, 0.0};
  EXPECT_EQ(k->inverse(T, wrong_size).status, kin::IkStatus::bad_input);
  kin::IkOptions bad_config;
  bad_config.configuration = kin::Configuration{42};
  EXPECT_EQ(k->inverse(T, bad_config).status, kin::IkStatus::bad_configuration);
  T.p.y = std::nan("");
  EXPECT_EQ(k->inverse(T).status, kin::IkStatus::bad_input);
  EXPECT_EQ(k->inverse_all(T).count, 0u);
  EXPECT_EQ(k->inverse_all(T).status, kin::IkStatus::bad_input);
}

// ---- PUMA 560 ----

TEST(Puma560, PublishedPoses) {
  const auto k = kin::make_kinematics(kin::builtin_robot("puma560"));
  // Zero pose: p = (0.4521, -0.15005, 0.4318) m, R = I.
  const math::Transform zero = k->forward({0, 0, 0, 0, 0, 0});
  EXPECT_LT(math::max_abs_difference(zero, math::Transform::translation(0.4521, -0.15005, 0.4318)),
            1e-15);
  // Corke, Robotics, Vision and Control: qr (arm straight up) and qn (nominal) poses.
  const math::Transform ready = k->forward({0, 90_deg, -90_deg, 0, 0, 0});
  EXPECT_NEAR(ready.p.x, 0.0203, 1e-12);
  EXPECT_NEAR(ready.p.y, -0.15005, 1e-12);
  EXPECT_NEAR(ready.p.z, 0.8636, 1e-12);
  const math::Transform nominal = k->forward({0, 45_deg, 180_deg, 0, 45_deg, 0});
  EXPECT_NEAR(nominal.p.x, 0.5963, 5e-5);
  EXPECT_NEAR(nominal.p.y, -0.15005, 1e-12);
  EXPECT_NEAR(nominal.p.z, -0.0144, 5e-5);
  EXPECT_NEAR(nominal.R.a.x, 1.0, 1e-12);  // tool pointing forward
  EXPECT_NEAR(nominal.R.n.z, -1.0, 1e-12);
  EXPECT_EQ(k->configuration_name(k->configuration_of({0, 45_deg, 180_deg, 0, 45_deg, 0})), "run");
  EXPECT_EQ(k->configuration_name(k->configuration_of({0, 0, 0, 0, 0, 0})), "rdn");
}

TEST(Puma560, ConfigurationNamesAreRccls) {
  const auto k = kin::make_kinematics(kin::builtin_robot("puma560"));
  const auto names = k->configuration_names();
  ASSERT_EQ(names.size(), 8u);
  for (const char* n : {"lun", "luf", "ldn", "ldf", "run", "ruf", "rdn", "rdf"}) {
    const auto c = k->find_configuration(n);
    ASSERT_TRUE(c) << n;
    EXPECT_EQ(k->configuration_name(*c), n);
  }
  EXPECT_FALSE(k->find_configuration("xyz"));
}

TEST(Puma560, ConfigurationsMeanWhatTheirNamesSay) {
  const auto k = kin::make_kinematics(kin::builtin_robot("puma560"));
  const kin::RobotModel& m = k->model();
  RandomJoints random(m, 11);
  for (int i = 0; i < 2000; ++i) {
    const kin::JointVector q = random();
    const std::string_view name = k->configuration_name(k->configuration_of(q));
    // Geometry, from the DH frames: shoulder (frame 1 origin), elbow (frame 2 origin) and wrist
    // centre, in the plane of the arm.
    const double a2 = 0.4318;
    const double C1 = std::cos(q[0]), S1 = std::sin(q[0]);
    const math::Vec3 x1{C1, S1, 0};
    const math::Vec3 wrist = k->forward(q).p;
    const math::Vec3 elbow{a2 * std::cos(q[1]) * C1, a2 * std::cos(q[1]) * S1, a2 * std::sin(q[1])};
    const double wrist_reach = math::dot(wrist, x1);
    EXPECT_EQ(name[0], wrist_reach >= 0 ? 'r' : 'l') << i;
    // Elbow above the shoulder-wrist line, measured in the vertical plane of the arm.
    const double elbow_reach = math::dot(elbow, x1);
    const double line_height = wrist.z * elbow_reach / wrist_reach;
    EXPECT_EQ(name[1], elbow.z > line_height ? 'u' : 'd') << i;
    EXPECT_EQ(name[2], std::sin(q[4]) >= 0 ? 'n' : 'f') << i;
  }
}

TEST(Puma560, WristSingularityKeepsTheNearTheta4) {
  const auto k = kin::make_kinematics(kin::builtin_robot("puma560"));
  const kin::JointVector q{0.3, 0.5, -2.0, 0.7, 0.0, 0.2};
  const math::Transform T = k->forward(q);
  kin::IkOptions options;
  options.near = kin::JointVector{0.3, 0.5, -2.0, 1.1, 0.1, 0.0};
  const kin::IkResult r = k->inverse(T, options);
  ASSERT_TRUE(r);
  EXPECT_EQ(r.singularity, kin::Singularity::wrist);
  EXPECT_TRUE(all_finite(r.q));
  EXPECT_DOUBLE_EQ(r.q[3], 1.1);
  EXPECT_NEAR(r.q[4], 0.0, 1e-12);
  EXPECT_NEAR(r.q[3] + r.q[5], q[3] + q[5], 1e-12);  // only theta4 + theta6 is determined
  EXPECT_LT(math::max_abs_difference(k->forward(r.q), T), 1e-12);
}

TEST(Puma560, ShoulderSingularityWithoutOffsetKeepsTheNearTheta1) {
  kin::RobotModel m = kin::builtin_robot("puma560");
  m.joints[2].dh.d_m = 0.0;  // no lateral offset: the wrist can sit on joint 1's axis
  const auto k = kin::make_kinematics(m);
  const double a3 = 0.0203, d4 = 0.4318;
  const kin::JointVector q{0.4, 90_deg, std::atan2(-d4, a3), 0.3, 0.6, -0.2};
  const math::Transform T = k->forward(q);
  ASSERT_LT(std::hypot(T.p.x, T.p.y), 1e-15);
  kin::IkOptions options;
  options.near = kin::JointVector{-0.25, 1.5, -1.5, 0.3, 0.6, -0.2};
  const kin::IkResult r = k->inverse(T, options);
  ASSERT_TRUE(r);
  EXPECT_EQ(r.singularity, kin::Singularity::shoulder);
  EXPECT_DOUBLE_EQ(r.q[0], -0.25);
  EXPECT_LT(math::max_abs_difference(k->forward(r.q), T), 1e-12);
}

TEST(Puma560, UnreachablePosesGiveReasons) {
  const auto k = kin::make_kinematics(kin::builtin_robot("puma560"));
  // Beyond the stretched arm.
  EXPECT_EQ(k->inverse(math::Transform::translation(2.0, 0.0, 0.0)).status,
            kin::IkStatus::out_of_reach);
  // Inside the cylinder the shoulder offset d3 = 0.15005 m keeps the wrist out of.
  EXPECT_EQ(k->inverse(math::Transform::translation(0.05, 0.02, 0.3)).status,
            kin::IkStatus::out_of_reach);
  for (std::string_view name : k->configuration_names()) {
    kin::IkOptions options;
    options.configuration = k->find_configuration(name);
    EXPECT_EQ(k->inverse(math::Transform::translation(2.0, 0.0, 0.0), options).status,
              kin::IkStatus::out_of_reach);
  }
  const kin::IkSolutions none = k->inverse_all(math::Transform::translation(0.0, 0.0, 1.5));
  EXPECT_EQ(none.count, 0u);
  EXPECT_EQ(none.status, kin::IkStatus::out_of_reach);
}

TEST(Puma560, JointRangesBeyondATurnFollowNear) {
  const auto k = kin::make_kinematics(kin::builtin_robot("puma560"));
  const kin::JointVector q{0.2, 0.6, -2.2, 0.4, 0.8, 250_deg};  // theta6 range is +-266 deg
  kin::IkOptions options;
  options.near = q;
  const kin::IkResult r = k->inverse(k->forward(q), options);
  ASSERT_TRUE(r);
  EXPECT_NEAR(r.q[5], 250_deg, 1e-12);
  options.near = kin::JointVector{0.2, 0.6, -2.2, 0.4, 0.8, -100_deg};
  const kin::IkResult r2 = k->inverse(k->forward(q), options);
  ASSERT_TRUE(r2);
  EXPECT_NEAR(r2.q[5], 250_deg - 360_deg, 1e-12);
}

TEST(Puma560, LimitsAwayFromZeroAreReachedByWholeTurns) {
  kin::RobotModel m = kin::builtin_robot("puma560");
  for (const auto& [lower, upper, value] : {std::tuple{190.0, 330.0, 250.0},     // one turn up
                                            std::tuple{-330.0, -190.0, -250.0},  // one turn down
                                            std::tuple{600.0, 700.0, 650.0}}) {  // two turns
    m.joints[0].lower = math::deg_to_rad(lower);
    m.joints[0].upper = math::deg_to_rad(upper);
    m.joints[0].ready = math::deg_to_rad(value);
    const auto k = kin::make_kinematics(m);
    const kin::JointVector q{math::deg_to_rad(value), 0.6, -2.2, 0.4, 0.8, 0.3};
    kin::IkOptions options;
    options.configuration = k->configuration_of(q);
    const kin::IkResult r = k->inverse(k->forward(q), options);
    ASSERT_TRUE(r) << kin::describe(r.status) << " for theta1 = " << value;
    EXPECT_NEAR(r.q[0], q[0], 1e-9) << value;
    // Half a turn further the same pose is out of joint 1's limits.
    m.joints[0].ready = m.joints[0].lower;
    const auto k2 = kin::make_kinematics(m);
    const kin::JointVector q2{math::deg_to_rad(value + 180.0), 0.6, -2.2, 0.4, 0.8, 0.3};
    EXPECT_EQ(k2->inverse(k2->forward(q2), options).status, kin::IkStatus::joint_limits) << value;
  }
}

TEST(Puma560, AskedConfigurationOutsideLimitsIsSaid) {
  const auto k = kin::make_kinematics(kin::builtin_robot("puma560"));
  const math::Transform T = k->forward({0.3, 0.7, -2.6, 0.4, 0.9, -0.5});
  kin::IkOptions options;
  options.configuration = k->find_configuration("lun");  // needs theta1 beyond 160 deg
  EXPECT_EQ(k->inverse(T, options).status, kin::IkStatus::joint_limits);
}

// ---- Microbo ----

TEST(Microbo, WasherCornersSolveToTheThesisJointValues) {
  const auto k = kin::make_kinematics(kin::builtin_robot("microbo"));
  const math::Rot3 tool_down = math::Rot3::rot_x(180_deg);
  for (double y : {-150_mm, 150_mm}) {
    for (double z : {250_mm, 300_mm}) {
      const kin::IkResult r = k->inverse({tool_down, {325_mm, y, z}});
      ASSERT_TRUE(r) << kin::describe(r.status);
      const double s = y > 0 ? 1.0 : -1.0;
      EXPECT_NEAR(r.q[0], s * 24.78_deg, 0.01_deg);
      EXPECT_NEAR(r.q[1], z, 1e-15);
      EXPECT_NEAR(r.q[2], std::hypot(325_mm, 150_mm), 1e-15);
      EXPECT_NEAR(r.q[3], 90_deg, 1e-12);
      EXPECT_NEAR(r.q[4], -90_deg, 1e-12);
      EXPECT_NEAR(r.q[5], -s * 155.22_deg, 0.01_deg);
    }
  }
}

// The thesis's theta4 branch is stated the wrong way round (reading guide, errata): check our
// branches against the forward solution on both sides of theta5 = -pi.
TEST(Microbo, Theta4BranchFollowsTheSignOfS5) {
  const auto k = kin::make_kinematics(kin::builtin_robot("microbo"));
  for (double theta5 : {-100_deg, -170_deg, -190_deg, -260_deg}) {
    const kin::JointVector q{0.2, 0.25, 0.3, 0.5, theta5, 0.4};
    kin::IkOptions options;
    options.near = q;
    const kin::IkResult r = k->inverse(k->forward(q), options);
    ASSERT_TRUE(r);
    EXPECT_EQ(k->configuration_name(r.configuration), std::sin(theta5) < 0 ? "n" : "f");
    EXPECT_NEAR(r.q[3], 0.5, 1e-12);
    EXPECT_NEAR(r.q[4], theta5, 1e-12);
    EXPECT_NEAR(r.q[5], 0.4, 1e-12);
  }
}

TEST(Microbo, Theta5AtMinusPiKeepsThePreviousTheta4) {
  const auto k = kin::make_kinematics(kin::builtin_robot("microbo"));
  const kin::JointVector q{0.1, 0.26, 0.31, 0.6, -180_deg, -0.3};
  const math::Transform T = k->forward(q);
  kin::IkOptions options;
  options.near = kin::JointVector{0.1, 0.26, 0.31, -0.2, -175_deg, 0.0};
  const kin::IkResult r = k->inverse(T, options);
  ASSERT_TRUE(r);
  EXPECT_EQ(r.singularity, kin::Singularity::wrist);
  EXPECT_DOUBLE_EQ(r.q[3], -0.2);
  EXPECT_NEAR(r.q[4], -180_deg, 1e-12);
  EXPECT_TRUE(all_finite(r.q));
  EXPECT_LT(math::max_abs_difference(k->forward(r.q), T), 1e-12);
}

TEST(Microbo, PosesBeyondTheSlidesAreOutOfJointLimits) {
  const auto k = kin::make_kinematics(kin::builtin_robot("microbo"));
  const math::Rot3 down = math::Rot3::rot_x(180_deg);
  EXPECT_EQ(k->inverse({down, {0.5, 0.0, 0.25}}).status, kin::IkStatus::joint_limits);   // d3
  EXPECT_EQ(k->inverse({down, {0.3, 0.0, 0.5}}).status, kin::IkStatus::joint_limits);    // d2
  EXPECT_EQ(k->inverse({down, {-0.3, 0.0, 0.25}}).status, kin::IkStatus::joint_limits);  // theta1
  // On joint 1's axis: theta1 is free, but d3 = 0 is below its limit.
  EXPECT_EQ(k->inverse({down, {0.0, 0.0, 0.25}}).status, kin::IkStatus::joint_limits);
}

// ---- Any DH robot ----

TEST_P(EveryRobot, NumericInverseConvergesWithinLimits) {
  const kin::RobotModel model = kin::builtin_robot(GetParam());
  const kin::DhKinematics dh(model);
  RandomJoints random(model, 5);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> perturb(-0.1, 0.1);
  int converged = 0;
  constexpr int kSamples = 500;
  for (int i = 0; i < kSamples; ++i) {
    const kin::JointVector q = random();
    const math::Transform T = dh.forward(q);
    kin::IkOptions options;
    options.near = q;
    for (std::size_t j = 0; j < q.size(); ++j) {
      const bool prismatic = model.joints[j].type == kin::JointType::prismatic;
      (*options.near)[j] += prismatic ? perturb(rng) * 0.1 : perturb(rng);
    }
    const kin::IkResult r = dh.inverse(T, options);
    if (!r) continue;
    ++converged;
    ASSERT_TRUE(model.within_limits(r.q));
    ASSERT_LT(math::max_abs_difference(dh.forward(r.q), T), 1e-10) << "sample " << i;
  }
  EXPECT_GE(converged, kSamples * 95 / 100);
}

TEST(DhKinematics, StaysWithinLimitsAndSaysWhenItCannotReach) {
  const kin::DhKinematics dh(kin::builtin_robot("puma560"));
  const kin::IkResult far = dh.inverse(math::Transform::translation(2.0, 0.0, 0.0));
  EXPECT_FALSE(far);
  EXPECT_TRUE(far.status == kin::IkStatus::no_convergence || far.status == kin::IkStatus::singular);
  EXPECT_TRUE(dh.configuration_names().empty());
  math::Transform nan_pose;
  nan_pose.p.x = std::nan("");
  EXPECT_EQ(dh.inverse(nan_pose).status, kin::IkStatus::bad_input);
}

}  // namespace
