// URDF robots (kin::load_urdf): forward kinematics and Jacobians of the shipped UR5e, Panda and
// PUMA 560 URDFs against KDL chains this test builds from the same files on its own (urdfdom's
// tree walked as kdl_parser walks it: each joint a KDL::Joint about its axis in the joint
// frame, each segment's frame the joint origin), the PUMA's URDF against rccx's closed form,
// and bad files refused with messages that say what is wrong.
#include <gtest/gtest.h>

#include <urdf_parser/urdf_parser.h>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <random>
#include <string>

#include "rccx/kinematics/dh_equivalent.hpp"
#include "rccx/kinematics/dh_kinematics.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/link_frames.hpp"
#include "rccx/kinematics/seven_axis_kinematics.hpp"
#include "rccx/kinematics/ur_kinematics.hpp"
#include "rccx/kinematics/urdf.hpp"
#include "rccx/math/units.hpp"
#include "urdf_kdl.hpp"

namespace kin = rccx::kin;
namespace math = rccx::math;

namespace {

const std::filesystem::path kRobots = RCCX_ROBOTS_DIR;

/// The KDL chain from `base` to `tip` of a URDF file, built as kdl_parser builds it.
KDL::Chain kdl_chain_from_urdf(const std::filesystem::path& file, const std::string& base,
                               const std::string& tip) {
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(file.string());
  EXPECT_NE(model, nullptr) << file;
  return rccx::test::kdl_chain_from_urdf(*model, base, tip);
}

double max_difference(const math::Transform& T, const KDL::Frame& F) {
  double worst = 0.0;
  for (int r = 0; r < 3; ++r) {
    worst = std::max(worst, std::abs(T.p[r] - F.p(r)));
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(T.R(r, c) - F.M(r, c)));
  }
  return worst;
}

/// IkOptions in full (designated initializers must name every member to stay warning-free).
kin::IkOptions ik(std::optional<kin::Configuration> configuration,
                  std::optional<kin::JointVector> near, std::optional<double> redundant = {}) {
  kin::IkOptions o;
  o.configuration = configuration;
  o.near = std::move(near);
  o.redundant = redundant;
  return o;
}

using rccx::test::random_within_limits;

struct Case {
  const char* file;
  const char* base;
  const char* tip;
  std::size_t dof;
};

class UrdfAgainstKdl : public testing::TestWithParam<Case> {};

TEST_P(UrdfAgainstKdl, ForwardAndJacobianAgreeOver10000RandomConfigurations) {
  const Case c = GetParam();
  const kin::RobotModel model = kin::load_urdf(kRobots / c.file);
  ASSERT_EQ(model.dof(), c.dof);
  EXPECT_EQ(model.geometry, kin::Geometry::chain);
  const auto k = kin::make_kinematics(model);
  const KDL::Chain chain = kdl_chain_from_urdf(kRobots / c.file, c.base, c.tip);
  ASSERT_EQ(chain.getNrOfJoints(), c.dof);
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::ChainJntToJacSolver jac(chain);
  std::mt19937_64 rng(26);
  const kin::DhChain links(model);
  double worst_pose = 0.0, worst_jacobian = 0.0, worst_link = 0.0;
  for (int n = 0; n < 10'000; ++n) {
    const kin::JointVector q = random_within_limits(model, rng);
    KDL::JntArray jq(static_cast<unsigned>(q.size()));
    for (std::size_t i = 0; i < q.size(); ++i) jq(static_cast<unsigned>(i)) = q[i];
    KDL::Frame F;
    ASSERT_GE(fk.JntToCart(jq, F), 0);
    worst_pose = std::max(worst_pose, max_difference(k->forward(q), F));
    // Every link frame (the collision capsules' and the view's): KDL's segment i is link i
    // (these chains have no fixed joint but the flange, the last frame).
    std::array<math::Transform, kin::kMaxJoints> frames;
    kin::link_frames(links, q, frames);
    for (std::size_t i = 0; i + 1 < q.size(); ++i) {
      KDL::Frame Fi;
      ASSERT_GE(fk.JntToCart(jq, Fi, static_cast<int>(i + 1)), 0);
      worst_link = std::max(worst_link, max_difference(frames[i], Fi));
    }
    worst_link = std::max(worst_link, max_difference(frames[q.size() - 1], F));
    KDL::Jacobian J(static_cast<unsigned>(q.size()));
    ASSERT_GE(jac.JntToJac(jq, J), 0);
    const kin::Jacobian mine = k->jacobian(q);
    for (int r = 0; r < 6; ++r) {
      for (std::size_t i = 0; i < q.size(); ++i) {
        const auto col = static_cast<Eigen::Index>(i);
        worst_jacobian = std::max(
            worst_jacobian,
            std::abs(mine(r, col) - J(static_cast<unsigned>(r), static_cast<unsigned>(i))));
      }
    }
  }
  EXPECT_LE(worst_pose, 1e-12) << c.file;
  EXPECT_LE(worst_jacobian, 1e-12) << c.file;
  EXPECT_LE(worst_link, 1e-12) << c.file;
  RecordProperty("worst_pose_difference", std::to_string(worst_pose));
}

INSTANTIATE_TEST_SUITE_P(ShippedRobots, UrdfAgainstKdl,
                         testing::Values(Case{"ur5e.urdf", "base_link", "tool0", 6},
                                         Case{"panda.urdf", "panda_link0", "panda_link8", 7},
                                         Case{"puma560.urdf", "base_link", "flange", 6}),
                         [](const auto& test) {
                           std::string name = test.param.file;
                           return name.substr(0, name.find('.'));
                         });

TEST(Urdf, ThePuma560UrdfIsRccxsClosedFormPuma) {
  const kin::RobotModel urdf = kin::load_urdf(kRobots / "puma560.urdf");
  const kin::RobotModel dh = kin::builtin_robot("puma560");
  ASSERT_EQ(urdf.dof(), dh.dof());
  for (std::size_t i = 0; i < dh.dof(); ++i) {
    EXPECT_NEAR(urdf.joints[i].lower, dh.joints[i].lower, 1e-12) << i;
    EXPECT_NEAR(urdf.joints[i].upper, dh.joints[i].upper, 1e-12) << i;
    EXPECT_NEAR(urdf.joints[i].max_velocity, dh.joints[i].max_velocity, 1e-12) << i;
    EXPECT_NEAR(urdf.joints[i].dynamics.link_mass_kg, dh.joints[i].dynamics.link_mass_kg, 1e-12);
  }
  const auto closed = kin::make_kinematics(dh);
  const auto chain = kin::make_kinematics(urdf);
  std::mt19937_64 rng(560);
  double worst = 0.0;
  for (int n = 0; n < 10'000; ++n) {
    const kin::JointVector q = random_within_limits(dh, rng);
    const auto a = closed->forward(q).rows();
    const auto b = chain->forward(q).rows();
    for (std::size_t e = 0; e < a.size(); ++e) worst = std::max(worst, std::abs(a[e] - b[e]));
  }
  EXPECT_LE(worst, 1e-12);
}

TEST(Urdf, TheNumericSolverRoundTripsTheImportedArms) {
  for (const char* file : {"ur5e.urdf", "panda.urdf"}) {
    const kin::RobotModel model = kin::load_urdf(kRobots / file);
    const auto k = kin::make_kinematics(model);
    std::mt19937_64 rng(7);
    int solved = 0;
    const int n = 200;
    for (int t = 0; t < n; ++t) {
      const kin::JointVector q = random_within_limits(model, rng);
      const math::Transform T = k->forward(q);
      kin::JointVector near = q;
      for (double& v : near) v += 0.05;  // a seed close by, as the generator gives one
      const kin::IkResult r = k->inverse(T, ik(std::nullopt, near));
      if (!r) continue;
      ++solved;
      const auto a = k->forward(r.q).rows();
      const auto b = T.rows();
      for (std::size_t e = 0; e < a.size(); ++e) ASSERT_NEAR(a[e], b[e], 1e-9) << file;
      EXPECT_TRUE(model.within_limits(r.q, 1e-9)) << file;
    }
    EXPECT_GE(solved, n * 95 / 100) << file;
  }
}

TEST(Urdf, ContinuousJointsHaveNoLimitsAndFixedOnesAreLumped) {
  const std::string xml = R"(<robot name="two">
    <link name="base"/><link name="a"/><link name="b"/><link name="c"/>
    <joint name="spin" type="continuous"><parent link="base"/><child link="a"/>
      <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/></joint>
    <joint name="bracket" type="fixed"><parent link="a"/><child link="b"/>
      <origin xyz="0.1 0 0" rpy="0 1.5707963267948966 0"/></joint>
    <joint name="slide" type="prismatic"><parent link="b"/><child link="c"/>
      <origin xyz="0 0 0.2"/><axis xyz="1 0 0"/>
      <limit lower="-0.1" upper="0.3" velocity="0.5" effort="100"/></joint>
  </robot>)";
  const kin::RobotModel m = kin::parse_urdf(xml, "two.urdf");
  ASSERT_EQ(m.dof(), 2u);
  EXPECT_TRUE(m.joints[0].continuous);
  EXPECT_TRUE(std::isinf(m.joints[0].lower) && std::isinf(m.joints[0].upper));
  EXPECT_EQ(m.joints[1].type, kin::JointType::prismatic);
  EXPECT_DOUBLE_EQ(m.joints[1].upper, 0.3);
  const auto k = kin::make_kinematics(m);
  // Turned 90 deg about z, the bracket's 0.1 m and the slide's 0.2 m offset (turned to x by
  // the bracket's pitch) point along y; the slide's 0.3 m along its x, pitched, points down.
  const math::Transform T = k->forward(kin::JointVector{math::kPi / 2, 0.3});
  EXPECT_NEAR(T.p.x, 0.0, 1e-12);
  EXPECT_NEAR(T.p.y, 0.1 + 0.2, 1e-12);
  EXPECT_NEAR(T.p.z, 0.5 - 0.3, 1e-12);
}

/// The largest element difference of two poses.
double difference(const math::Transform& a, const math::Transform& b) {
  double worst = 0.0;
  const auto ra = a.rows(), rb = b.rows();
  for (std::size_t e = 0; e < ra.size(); ++e) worst = std::max(worst, std::abs(ra[e] - rb[e]));
  return worst;
}

TEST(DhEquivalent, BaseTimesTheTableTimesToolIsTheChainAnywhereItIsPlaced) {
  std::mt19937_64 rng(1986);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const char* file : {"ur5e.urdf", "panda.urdf", "puma560.urdf"}) {
    for (const bool moved : {false, true}) {
      kin::RobotModel chain = kin::load_urdf(kRobots / file);
      if (moved) {  // the same arm mounted elsewhere, with a tool: the table must not change
        const math::Transform mount{math::Rot3::from_urdf_rpy(u(rng), u(rng), u(rng)),
                                    {u(rng), u(rng), u(rng)}};
        const math::Transform tool{math::Rot3::from_urdf_rpy(u(rng), u(rng), u(rng)),
                                   {0.1 * u(rng), 0.1 * u(rng), 0.2}};
        chain.joints.front().chain.origin = mount * chain.joints.front().chain.origin;
        chain.joints.back().chain.after = chain.joints.back().chain.after * tool;
      }
      const auto dh = kin::dh_equivalent(chain);
      ASSERT_TRUE(dh.has_value()) << file;
      EXPECT_EQ(dh->model.geometry, kin::Geometry::dh);
      const auto by_chain = kin::make_kinematics(chain);
      const auto by_table = kin::make_kinematics(dh->model);
      double worst = 0.0;
      for (int n = 0; n < 2'000; ++n) {
        const kin::JointVector q = random_within_limits(chain, rng);
        worst = std::max(
            worst, difference(dh->base * by_table->forward(q) * dh->tool, by_chain->forward(q)));
      }
      EXPECT_LE(worst, 1e-12) << file << (moved ? ", moved" : "");
    }
  }
}

TEST(DhEquivalent, ATableWrittenAsUrdfComesBackAsItWas) {
  const auto puma = kin::dh_equivalent(kin::load_urdf(kRobots / "puma560.urdf"));
  ASSERT_TRUE(puma.has_value());
  const kin::RobotModel table = kin::builtin_robot("puma560");
  for (std::size_t i = 0; i < table.dof(); ++i) {
    EXPECT_NEAR(puma->model.joints[i].dh.a_m, table.joints[i].dh.a_m, 1e-12) << i;
    EXPECT_NEAR(puma->model.joints[i].dh.alpha_rad, table.joints[i].dh.alpha_rad, 1e-12) << i;
    EXPECT_NEAR(puma->model.joints[i].dh.d_m, table.joints[i].dh.d_m, 1e-12) << i;
    EXPECT_NEAR(puma->model.joints[i].dh.theta_rad, table.joints[i].dh.theta_rad, 1e-12) << i;
  }
  EXPECT_LE(difference(puma->base, {}), 1e-12);
  EXPECT_LE(difference(puma->tool, {}), 1e-12);
  // The UR5e's published table (d1, a2, a3, d4, d5, d6; alpha 90, 0, 0, 90, -90, 0 deg).
  const auto ur = kin::dh_equivalent(kin::load_urdf(kRobots / "ur5e.urdf"));
  ASSERT_TRUE(ur.has_value());
  const double a[] = {0, -0.425, -0.3922, 0, 0, 0};
  const double d[] = {0.1625, 0, 0, 0.1333, 0.0997, 0.0996};
  const double alpha[] = {math::kPi / 2, 0, 0, math::kPi / 2, -math::kPi / 2, 0};
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_NEAR(ur->model.joints[i].dh.a_m, a[i], 1e-12) << i;
    EXPECT_NEAR(ur->model.joints[i].dh.d_m, d[i], 1e-12) << i;
    EXPECT_NEAR(ur->model.joints[i].dh.alpha_rad, alpha[i], 1e-12) << i;
    EXPECT_NEAR(ur->model.joints[i].dh.theta_rad, 0.0, 1e-12) << i;
  }
  EXPECT_LE(difference(ur->tool, {}), 1e-12);
}

TEST(UrClosedForm, TheUr5eUrdfGetsAllEightSolutionsEachRoundTripping) {
  const kin::RobotModel model = kin::load_urdf(kRobots / "ur5e.urdf");
  const auto k = kin::make_kinematics(model);
  ASSERT_NE(dynamic_cast<const kin::PlacedKinematics*>(k.get()), nullptr)
      << "the UR structure was not recognised";
  EXPECT_EQ(k->configuration_names().size(), 8u);
  std::mt19937_64 rng(5);
  int original_found = 0;
  std::array<int, 9> counts{};
  double worst = 0.0;
  const int n = 10'000;
  for (int t = 0; t < n; ++t) {
    const kin::JointVector q = random_within_limits(model, rng);
    const math::Transform T = k->forward(q);
    const kin::IkSolutions all = k->inverse_all(T);
    ++counts[all.count];
    bool found = false;
    for (const kin::IkResult& r : all.solutions()) {
      worst = std::max(worst, difference(k->forward(r.q), T));
      EXPECT_EQ(k->configuration_of(r.q), r.configuration);
      bool same = true;
      for (std::size_t i = 0; i < 6; ++i) {
        same = same && std::abs(std::remainder(r.q[i] - q[i], 2 * math::kPi)) < 1e-6;
      }
      found = found || same;
    }
    if (found) ++original_found;
  }
  EXPECT_LE(worst, 1e-9);
  EXPECT_GE(original_found, n - 1);  // q itself among them (up to whole turns)
  std::printf("UR5e solutions per pose (0..8):");
  for (const int c : counts) std::printf(" %d", c);
  std::printf("\n");
  EXPECT_GT(counts[8], n / 2);
}

TEST(UrClosedForm, NoSolutionIsMissingFromTheEight) {
  // What a numeric solver finds from seeds all over the joint ranges must be among the closed
  // form's solutions (up to whole turns): a configuration it reports out of reach has none.
  const kin::RobotModel model = kin::load_urdf(kRobots / "ur5e.urdf");
  const auto k = kin::make_kinematics(model);
  const kin::DhKinematics numeric(model, {.max_iterations = 200,
                                          .position_tolerance_m = 1e-12,
                                          .orientation_tolerance_rad = 1e-12,
                                          .damping = 1e-4,
                                          .max_step_rad_or_m = 0.5,
                                          .restarts = 0});
  std::mt19937_64 rng(11);
  int found = 0, matched = 0;
  for (int t = 0; t < 300; ++t) {
    const math::Transform T = k->forward(random_within_limits(model, rng));
    const kin::IkSolutions all = k->inverse_all(T);
    for (int s = 0; s < 16; ++s) {
      const kin::IkResult r =
          numeric.inverse(T, ik(std::nullopt, random_within_limits(model, rng)));
      if (!r) continue;
      ++found;
      for (const kin::IkResult& c : all.solutions()) {
        bool same = true;
        for (std::size_t i = 0; i < 6; ++i) {
          same = same && std::abs(std::remainder(r.q[i] - c.q[i], 2 * math::kPi)) < 1e-6;
        }
        if (same) {
          ++matched;
          break;
        }
      }
    }
  }
  EXPECT_GT(found, 1000);
  EXPECT_EQ(matched, found);
}

TEST(UrClosedForm, OutOfReachAndTheWristSingularitySaySo) {
  const auto k = kin::make_kinematics(kin::load_urdf(kRobots / "ur5e.urdf"));
  const math::Transform far{math::Rot3::rot_x(math::kPi), {1.5, 0.0, 0.3}};  // reach ~1.0 m
  EXPECT_EQ(k->inverse(far).status, kin::IkStatus::out_of_reach);
  EXPECT_EQ(k->inverse_all(far).count, 0u);
  // theta5 = 0: z5 along z1, theta6 and the arm's sum one rotation; near's theta6 is kept.
  const kin::JointVector q{0.3, -1.2, 1.1, -0.4, 0.0, 0.7};
  const math::Transform T = k->forward(q);
  const kin::IkResult r = k->inverse(T, ik(k->configuration_of(q), q));
  ASSERT_TRUE(r) << kin::describe(r.status);
  EXPECT_EQ(r.singularity, kin::Singularity::wrist);
  EXPECT_LE(difference(k->forward(r.q), T), 1e-9);
  EXPECT_NEAR(r.q[5], q[5], 1e-12);
}

TEST(UrClosedForm, ThePumaUrdfGetsThePumasClosedForm) {
  const auto k = kin::make_kinematics(kin::load_urdf(kRobots / "puma560.urdf"));
  ASSERT_NE(dynamic_cast<const kin::PlacedKinematics*>(k.get()), nullptr);
  EXPECT_EQ(k->configuration_names().size(), 8u);
  EXPECT_EQ(k->configuration_names()[0], "lun");
}

TEST(UrClosedForm, TheNumericSolverForcedOnTheUr5eFromItsReadyPose) {
  const kin::RobotModel model = kin::load_urdf(kRobots / "ur5e.urdf");
  const kin::DhKinematics numeric(model);
  std::mt19937_64 rng(99);
  int solved = 0;
  const int n = 2'000;
  for (int t = 0; t < n; ++t) {
    const math::Transform T = numeric.forward(random_within_limits(model, rng));
    const kin::IkResult r = numeric.inverse(T);
    if (r) {
      ++solved;
      ASSERT_LE(difference(numeric.forward(r.q), T), 1e-9);
    }
  }
  RecordProperty("solved_percent", std::to_string(100.0 * solved / n));
  std::printf("numeric solver on the UR5e from the ready pose: %.2f %% of %d poses\n",
              100.0 * solved / n, n);
  EXPECT_GE(solved, n * 995 / 1000);
}

bool same_angles(const kin::JointVector& a, const kin::JointVector& b, double tolerance) {
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!(std::abs(std::remainder(a[i] - b[i], 2 * math::kPi)) < tolerance)) return false;
  }
  return true;
}

TEST(PandaClosedForm, GivenQ7EveryConfigurationRoundTripsAndTheArmsOwnIsAmongThem) {
  const kin::RobotModel model = kin::load_urdf(kRobots / "panda.urdf");
  const auto k = kin::make_kinematics(model);
  ASSERT_NE(dynamic_cast<const kin::SevenAxisKinematics*>(k.get()), nullptr)
      << "the Panda's structure was not recognised";
  std::mt19937_64 rng(7);
  double worst = 0.0;
  int own = 0, consistent = 0, solutions = 0;
  const int n = 10'000;
  for (int t = 0; t < n; ++t) {
    const kin::JointVector q = random_within_limits(model, rng);
    const math::Transform T = k->forward(q);
    const kin::IkSolutions all = k->inverse_all(T, ik(std::nullopt, q, q[6]));
    bool found = false;
    for (const kin::IkResult& r : all.solutions()) {
      ++solutions;
      worst = std::max(worst, difference(k->forward(r.q), T));
      EXPECT_EQ(r.q[6], q[6]);  // q7 held where asked
      if (k->configuration_of(r.q) == r.configuration) ++consistent;
      found = found || same_angles(r.q, q, 1e-6);
    }
    if (found) ++own;
  }
  EXPECT_LE(worst, 1e-9);
  EXPECT_GE(own, n - 1);
  EXPECT_GE(consistent, solutions - 5);  // configuration_of names each solution's own branch
  std::printf("Panda given q7: %.2f solutions within limits per pose, worst error %.2e\n",
              static_cast<double>(solutions) / n, worst);
}

TEST(PandaClosedForm, NoSolutionGivenQ7IsMissing) {
  // What a numeric solver finds with q7 locked, from seeds all over the ranges, must be among
  // the closed form's solutions at that q7.
  kin::RobotModel model = kin::load_urdf(kRobots / "panda.urdf");
  const auto k = kin::make_kinematics(model);
  std::mt19937_64 rng(13);
  int found = 0, matched = 0;
  for (int t = 0; t < 200; ++t) {
    const kin::JointVector q = random_within_limits(model, rng);
    const math::Transform T = k->forward(q);
    kin::RobotModel locked = model;  // q7 fixed: the 6-joint chain with joint 7 in the tail
    locked.joints.pop_back();
    math::Transform tail = model.joints[6].chain.origin *
                           math::Transform::rotation(model.joints[6].chain.axis, q[6]) *
                           model.joints[6].chain.after;
    locked.joints[5].chain.after = locked.joints[5].chain.after * tail;
    const kin::DhKinematics numeric(locked, {.max_iterations = 200,
                                             .position_tolerance_m = 1e-12,
                                             .orientation_tolerance_rad = 1e-12,
                                             .damping = 1e-4,
                                             .max_step_rad_or_m = 0.5,
                                             .restarts = 0});
    const kin::IkSolutions all = k->inverse_all(T, ik(std::nullopt, q, q[6]));
    for (int s = 0; s < 8; ++s) {
      const kin::IkResult r =
          numeric.inverse(T, ik(std::nullopt, random_within_limits(locked, rng)));
      if (!r) continue;
      ++found;
      kin::JointVector r7(7);
      for (std::size_t i = 0; i < 6; ++i) r7[i] = r.q[i];
      r7[6] = q[6];
      for (const kin::IkResult& c : all.solutions()) {
        if (same_angles(r7, c.q, 1e-6)) {
          ++matched;
          break;
        }
      }
    }
  }
  EXPECT_GT(found, 300);
  EXPECT_EQ(matched, found);
}

TEST(PandaClosedForm, SolvesAtLeast999Of1000RandomReachablePosesWithinLimits) {
  // From the ready pose, q7 free: the solver starts at ready's q7 and searches outward.
  const kin::RobotModel model = kin::load_urdf(kRobots / "panda.urdf");
  const auto k = kin::make_kinematics(model);
  std::mt19937_64 rng(2026);
  int solved = 0;
  double worst = 0.0;
  const int n = 10'000;
  for (int t = 0; t < n; ++t) {
    const math::Transform T = k->forward(random_within_limits(model, rng));
    const kin::IkResult r = k->inverse(T);
    if (!r) continue;
    ++solved;
    ASSERT_TRUE(model.within_limits(r.q)) << t;
    worst = std::max(worst, difference(k->forward(r.q), T));
  }
  EXPECT_LE(worst, 1e-9);
  RecordProperty("solved_percent", std::to_string(100.0 * solved / n));
  std::printf("Panda from its ready pose, q7 searched: %.2f %% of %d poses\n", 100.0 * solved / n,
              n);
  EXPECT_GE(solved, n * 999 / 1000);
}

TEST(PandaClosedForm, Q7StaysPutWhereItCanAndMovesLittleWhereItMust) {
  const kin::RobotModel model = kin::load_urdf(kRobots / "panda.urdf");
  const auto k = kin::make_kinematics(model);
  // A straight line of the flange, 1 mm a sample, solved from the last answer as the generator
  // does. For 0.3 m q7 can stay where it started; further on, joint 7 held still would take the
  // rest of the arm through a singularity of the other six (q5 -> 90 deg), and the solver moves
  // q7 instead, a little each sample.
  const kin::JointVector start{0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.785};
  const math::Transform from = k->forward(start);
  kin::JointVector q = start;
  double largest_q7_step = 0.0, largest_step = 0.0;
  for (int i = 1; i <= 420; ++i) {
    math::Transform T = from;
    T.p.y += 0.001 * i;
    const kin::IkResult r = k->inverse(T, ik(k->configuration_of(start), q));
    ASSERT_TRUE(r) << "sample " << i << ": " << kin::describe(r.status);
    ASSERT_LE(difference(k->forward(r.q), T), 1e-9);
    largest_q7_step = std::max(largest_q7_step, std::abs(r.q[6] - q[6]));
    for (std::size_t j = 0; j < 7; ++j) {
      largest_step = std::max(largest_step, std::abs(r.q[j] - q[j]));
    }
    if (i == 300) {
      EXPECT_EQ(largest_q7_step, 0.0) << "q7 moved where it need not";
      EXPECT_LT(largest_step, 0.02) << "a joint jumped";
    }
    q = r.q;
  }
  EXPECT_GT(largest_q7_step, 0.0) << "the line was meant to reach where q7 must move";
  EXPECT_LT(largest_q7_step, 0.01) << "q7 jumped";
  EXPECT_GT(std::abs(q[6] - start[6]), 0.05);
  // Asked for a q7 the pose cannot take within limits, the solver says so; free, it moves q7
  // to the nearest that solves.
  const math::Transform far = k->forward({0.0, 1.2, 0.0, -0.5, 0.0, 1.2, 0.0});
  const kin::IkResult held = k->inverse(far, ik(std::nullopt, std::nullopt, 2.8));
  const kin::IkResult free =
      k->inverse(far, ik(std::nullopt, kin::JointVector{0.0, 1.2, 0.0, -0.5, 0.0, 1.2, 2.8}));
  if (!held) {
    ASSERT_TRUE(free);
    EXPECT_LT(std::abs(free.q[6]), 2.8);
  }
  EXPECT_EQ(k->inverse(far, ik(std::nullopt, std::nullopt, 99.0)).status,
            kin::IkStatus::joint_limits);
  EXPECT_EQ(k->inverse(far, ik(std::nullopt, std::nullopt, std::nan(""))).status,
            kin::IkStatus::bad_input);
  const math::Transform out_of_reach{math::Rot3::identity(), {1.5, 0.0, 0.3}};
  EXPECT_EQ(k->inverse(out_of_reach).status, kin::IkStatus::out_of_reach);
}

std::string error_of(const std::string& xml, const kin::UrdfOptions& options = {}) {
  try {
    (void)kin::parse_urdf(xml, "bad.urdf", options);
  } catch (const kin::RobotFileError& e) {
    return e.what();
  }
  return "(no error)";
}

const char* const kTwoLinks = R"(<robot name="r">
  <link name="base"/><link name="a"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="X Y Z" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>)";

std::string two_links(const std::string& xyz) {
  std::string s = kTwoLinks;
  s.replace(s.find("X Y Z"), 5, xyz);
  return s;
}

TEST(UrdfBadInput, EachBadFileIsRefusedSayingWhatIsWrong) {
  EXPECT_NE(error_of(two_links("0 0 nan")).find("Unable to parse component [nan]"),
            std::string::npos)
      << error_of(two_links("0 0 nan"));
  EXPECT_NE(error_of(two_links("0 0 1e9")).find("more than 100 m"), std::string::npos)
      << error_of(two_links("0 0 1e9"));
  const std::string cycle = R"(<robot name="r"><link name="a"/><link name="b"/>
    <joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>
    <joint name="ba" type="fixed"><parent link="b"/><child link="a"/></joint></robot>)";
  EXPECT_NE(error_of(cycle).find("the joints make a cycle: a -> b -> a"), std::string::npos)
      << error_of(cycle);
  const std::string orphan = R"(<robot name="r"><link name="a"/>
    <joint name="j" type="fixed"><parent link="nobody"/><child link="a"/></joint></robot>)";
  EXPECT_NE(error_of(orphan).find("joint 'j' names link 'nobody', which the file does not declare"),
            std::string::npos)
      << error_of(orphan);
  const std::string branches =
      R"(<robot name="r"><link name="base"/><link name="l"/><link name="r"/>
    <joint name="jl" type="continuous"><parent link="base"/><child link="l"/></joint>
    <joint name="jr" type="continuous"><parent link="base"/><child link="r"/></joint></robot>)";
  EXPECT_NE(error_of(branches).find("name the tip link (--tip): one of l, r"), std::string::npos)
      << error_of(branches);
  EXPECT_EQ(kin::parse_urdf(branches, "ok", {.base_link = "", .tip_link = "r"}).joints[0].name,
            "jr");
  EXPECT_NE(
      error_of(branches, {.base_link = "", .tip_link = "nowhere"}).find("no link named 'nowhere'"),
      std::string::npos);
  const std::string floating = R"(<robot name="r"><link name="base"/><link name="a"/>
    <joint name="free" type="floating"><parent link="base"/><child link="a"/></joint></robot>)";
  EXPECT_NE(error_of(floating).find("joint 'free' is floating"), std::string::npos)
      << error_of(floating);
  const std::string mimic = R"(<robot name="r"><link name="base"/><link name="a"/><link name="b"/>
    <joint name="j1" type="continuous"><parent link="base"/><child link="a"/></joint>
    <joint name="j2" type="continuous"><parent link="a"/><child link="b"/>
      <mimic joint="j1" multiplier="2"/></joint></robot>)";
  EXPECT_NE(error_of(mimic).find("mimics joint 'j1'"), std::string::npos) << error_of(mimic);
  const std::string xacro = R"(<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
    <xacro:property name="a" value="1"/></robot>)";
  EXPECT_NE(error_of(xacro).find("run `xacro"), std::string::npos) << error_of(xacro);
  EXPECT_NE(error_of("<robot").find("not a usable URDF"), std::string::npos);
  std::string huge(kin::kMaxUrdfBytes + 1, ' ');
  EXPECT_NE(error_of(huge).find("MB a URDF may have"), std::string::npos);
  std::string no_limit = two_links("0 0 0");
  no_limit.replace(no_limit.find("<limit"),
                   no_limit.find("/></joint>") - no_limit.find("<limit") + 2, "");
  EXPECT_NE(error_of(no_limit).find("REVOLUTE but it does not specify limits"), std::string::npos)
      << error_of(no_limit);
}

TEST(UrdfBadInput, AMissingFileSaysSo) {
  try {
    (void)kin::load_urdf("/nonexistent/robot.urdf");
    FAIL() << "no error";
  } catch (const kin::RobotFileError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/robot.urdf: cannot read"), std::string::npos)
        << e.what();
  }
}

}  // namespace
