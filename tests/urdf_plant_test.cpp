// URDF robots on the plants (issue 26): link inertias lumped as KDL's RigidBodyInertia sums and
// moves them; hw::GravityModel over a URDF chain against KDL's ChainDynParam::JntToGravity on
// chains this test builds from the same files with urdfdom (as kdl_parser does); the MuJoCo model
// of a chain (hw::make_mjcf) against the kinematics, KDL's joint-space inertia and the gravity
// model; puma560.urdf's plant against the DH puma560's; robot files that point at a URDF; and the
// UR5e and the Panda holding poses against gravity on the MuJoCo plant, measured at MuJoCo's own
// flange.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <unistd.h>
#include <urdf_parser/urdf_parser.h>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/rotationalinertia.hpp>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "rccx/hw/gravity.hpp"
#include "rccx/hw/mjcf.hpp"
#include "rccx/hw/mujoco_arm.hpp"
#include "rccx/hw/simulated_arm.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/urdf.hpp"
#include "rccx/math/units.hpp"
#include "urdf_kdl.hpp"

namespace {

using namespace rccx;
const std::filesystem::path kRobots = RCCX_ROBOTS_DIR;

using test::kdl_chain_from_urdf;
using test::kdl_frame;
using test::kdl_inertia;

struct Case {
  const char* file;
  const char* base;
  const char* tip;
};
constexpr Case kShippedUrdfs[] = {{"ur5e.urdf", "base_link", "tool0"},
                                  {"panda.urdf", "panda_link0", "panda_link8"},
                                  {"puma560.urdf", "base_link", "flange"}};

using test::random_within_limits;

KDL::JntArray kdl_joints(const kin::JointVector& q) {
  KDL::JntArray jq(static_cast<unsigned>(q.size()));
  for (std::size_t i = 0; i < q.size(); ++i) jq(static_cast<unsigned>(i)) = q[i];
  return jq;
}

// ---- 1. inertias -------------------------------------------------------------------------------

/// A URDF with a fixed child in the middle of the chain and one at the tip, every inertial
/// turned and offset, each tensor full.
const char* const kLumped = R"(<robot name="lumped">
  <link name="base"/>
  <link name="a"><inertial><origin xyz="0.1 -0.02 0.3" rpy="0.3 -0.5 1.1"/><mass value="2.5"/>
    <inertia ixx="0.04" iyy="0.05" izz="0.03" ixy="0.002" ixz="-0.004" iyz="0.001"/></inertial></link>
  <link name="bracket"><inertial><origin xyz="0.02 0.05 -0.01" rpy="-0.7 0.2 0.4"/><mass value="0.8"/>
    <inertia ixx="0.003" iyy="0.002" izz="0.004" ixy="-0.0003" ixz="0.0002" iyz="0.0005"/></inertial></link>
  <link name="c"><inertial><origin xyz="0.0 0.15 0.05" rpy="1.2 0.1 -0.3"/><mass value="1.7"/>
    <inertia ixx="0.02" iyy="0.01" izz="0.025" ixy="0.001" ixz="0.0" iyz="-0.002"/></inertial></link>
  <link name="flange"><inertial><origin xyz="0.01 0.0 0.02" rpy="0 0.4 0"/><mass value="0.3"/>
    <inertia ixx="0.0004" iyy="0.0005" izz="0.0003" ixy="0" ixz="0.00005" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.4" rpy="0 0 0.2"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="100"/></joint>
  <joint name="mount" type="fixed"><parent link="a"/><child link="bracket"/>
    <origin xyz="0.2 0.1 0.05" rpy="0.5 -0.3 0.9"/></joint>
  <joint name="j2" type="revolute"><parent link="bracket"/><child link="c"/>
    <origin xyz="0 0 0.3" rpy="1.5707963267948966 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" velocity="1" effort="100"/></joint>
  <joint name="tool" type="fixed"><parent link="c"/><child link="flange"/>
    <origin xyz="0.05 0.3 -0.02" rpy="-0.2 0.6 0.3"/></joint>
</robot>)";

/// KDL's mass, centre of mass and tensor about it of a RigidBodyInertia.
void expect_same_inertia(const kin::JointDynamics& d, KDL::RigidBodyInertia I, const char* what) {
  EXPECT_NEAR(d.link_mass_kg, I.getMass(), 1e-12) << what;
  const KDL::Vector cog = I.getCOG();
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(d.link_com_m[k], cog(k), 1e-12) << what << " com " << k;
  const KDL::RotationalInertia Ic = I.RefPoint(cog).getRotationalInertia();
  // ixx iyy izz ixy ixz iyz: elements (0,0) (1,1) (2,2) (0,1) (0,2) (1,2) of the row-major data.
  const int at[6] = {0, 4, 8, 1, 2, 5};
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(d.link_inertia_kg_m2[k], Ic.data[at[k]], 1e-12) << what << " inertia " << k;
  }
}

TEST(UrdfInertia, FixedLinksAreLumpedAsKdlSumsAndMovesTheirInertias) {
  const kin::RobotModel m = kin::parse_urdf(kLumped, "lumped.urdf");
  ASSERT_EQ(m.dof(), 2u);
  const urdf::ModelInterfaceSharedPtr u = urdf::parseURDF(kLumped);
  ASSERT_NE(u, nullptr);
  const auto frame_of = [&](const char* joint) {
    return kdl_frame(u->getJoint(joint)->parent_to_joint_origin_transform);
  };
  // Link a carries the bracket: a's own inertia plus the bracket's moved by the fixed joint.
  expect_same_inertia(
      m.joints[0].dynamics,
      kdl_inertia(*u->getLink("a")) + frame_of("mount") * kdl_inertia(*u->getLink("bracket")),
      "link a");
  // Link c carries the flange; its frame is the flange's (T6): the sum seen from the flange.
  const KDL::Frame tool = frame_of("tool");
  expect_same_inertia(
      m.joints[1].dynamics,
      tool.Inverse() * (kdl_inertia(*u->getLink("c")) + tool * kdl_inertia(*u->getLink("flange"))),
      "link c");
  // The URDF's own tensors come through as they are where nothing is lumped.
  const kin::RobotModel ur = kin::load_urdf(kRobots / "ur5e.urdf");
  EXPECT_NEAR(ur.joints[1].dynamics.link_inertia_kg_m2[0], 0.1285418875, 1e-15);
  EXPECT_NEAR(ur.joints[1].dynamics.link_inertia_kg_m2[2], 0.0145044, 1e-15);
  // Zeros say "not given": puma560.urdf's links have none.
  for (const kin::Joint& j : kin::load_urdf(kRobots / "puma560.urdf").joints) {
    for (const double v : j.dynamics.link_inertia_kg_m2) EXPECT_EQ(v, 0.0) << j.name;
  }
}

TEST(UrdfInertia, ANonFiniteTensorIsRefused) {
  std::string bad = kLumped;
  bad.replace(bad.find("ixx=\"0.04\""), 10, "ixx=\"1e99\"");
  try {
    (void)kin::parse_urdf(bad, "bad.urdf");
    FAIL() << "no error";
  } catch (const kin::RobotFileError& e) {
    EXPECT_NE(std::string(e.what()).find("link 'a': an inertia element"), std::string::npos)
        << e.what();
  }
}

// ---- 2. gravity and the MuJoCo model ---------------------------------------------------------

class ShippedUrdf : public testing::TestWithParam<Case> {};

TEST_P(ShippedUrdf, GravityLoadIsKdlsJntToGravity) {
  const Case c = GetParam();
  const kin::RobotModel model = kin::load_urdf(kRobots / c.file);
  const urdf::ModelInterfaceSharedPtr u = urdf::parseURDFFile((kRobots / c.file).string());
  ASSERT_NE(u, nullptr);
  const KDL::Chain chain = kdl_chain_from_urdf(*u, c.base, c.tip);
  KDL::ChainDynParam dyn(chain, KDL::Vector(0, 0, -hw::kGravity_m_per_s2));
  const hw::GravityModel gravity(model);
  std::mt19937_64 rng(26);
  double worst = 0.0, largest = 0.0;
  for (int n = 0; n < 2'000; ++n) {
    const kin::JointVector q = random_within_limits(model, rng);
    KDL::JntArray g(static_cast<unsigned>(q.size()));
    ASSERT_GE(dyn.JntToGravity(kdl_joints(q), g), 0);
    const kin::JointVector mine = gravity.load(q);
    for (std::size_t i = 0; i < q.size(); ++i) {
      worst = std::max(worst, std::abs(mine[i] - g(static_cast<unsigned>(i))));
      largest = std::max(largest, std::abs(g(static_cast<unsigned>(i))));
    }
  }
  EXPECT_LE(worst, 1e-10) << c.file;
  EXPECT_GT(largest, 10.0) << c.file;  // the arms are heavy: the check has something to check
  std::printf("%s: gravity load against KDL over 2000 configurations: %.2g N m (largest %.1f)\n",
              c.file, worst, largest);
}

std::unique_ptr<hw::MujocoArm> mujoco_arm(const kin::RobotModel& model, const hw::Scene& scene = {},
                                          const kin::JointVector& initial = {}) {
  hw::SimulatedArmOptions o;
  o.initial = initial;
  o.plant = kin::Plant::mujoco;
  o.scene = std::make_shared<const hw::Scene>(scene);
  return std::make_unique<hw::MujocoArm>(model, o);
}

/// Puts q into MuJoCo at rest and runs its kinematics and dynamics terms.
void set_joints(hw::MujocoArm& arm, const kin::JointVector& q) {
  const mjModel* m = arm.mj_model();
  mjData* d = arm.mj_data();
  for (std::size_t j = 0; j < q.size(); ++j) {
    const int id = mj_name2id(m, mjOBJ_JOINT, ("j" + std::to_string(j + 1)).c_str());
    d->qpos[m->jnt_qposadr[id]] = q[j];
    d->qvel[m->jnt_dofadr[id]] = 0.0;
  }
  mj_forward(m, d);
}

double rotation_error(const math::Rot3& a, const math::Rot3& b) {
  math::Vec3 axis;
  double angle = 0;
  (a.transposed() * b).to_axis_angle(axis, angle);
  return angle;
}

TEST_P(ShippedUrdf, MujocoModelIsTheChainItsInertiaAndItsGravity) {
  const Case c = GetParam();
  const kin::RobotModel model = kin::load_urdf(kRobots / c.file);
  const auto k = kin::make_kinematics(model);
  hw::Scene scene;
  scene.base_m = {math::Rot3::from_rpy(0.3, -0.2, 0.1), {0.4, -0.25, 0.8}};
  const auto arm = mujoco_arm(model, scene);
  const mjModel* m = arm->mj_model();
  mjData* d = arm->mj_data();
  const urdf::ModelInterfaceSharedPtr u = urdf::parseURDFFile((kRobots / c.file).string());
  const KDL::Chain chain = kdl_chain_from_urdf(*u, c.base, c.tip);
  // KDL with gravity along the base's own -z as the MuJoCo base is turned: the world's.
  const math::Vec3 g_base = scene.base_m.R.transposed() * math::Vec3{0, 0, -hw::kGravity_m_per_s2};
  KDL::ChainDynParam dyn(chain, KDL::Vector(g_base.x, g_base.y, g_base.z));
  const bool has_tensors = std::string(c.file) != "puma560.urdf";  // its links have none
  const std::size_t n = model.dof();
  std::vector<mjtNum> M(static_cast<std::size_t>(m->nv * m->nv));
  std::mt19937_64 rng(2026);
  double worst_p = 0, worst_r = 0, worst_bias = 0, worst_mass = 0, worst_hold = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const kin::JointVector q = random_within_limits(model, rng);
    set_joints(*arm, q);
    const math::Transform want = scene.base_m * k->forward(q);
    const math::Transform got = arm->site_pose("t6");
    worst_p = std::max(worst_p, (got.p - want.p).norm());
    worst_r = std::max(worst_r, rotation_error(got.R, want.R));
    // At rest MuJoCo's bias force is gravity alone: what the motors must hold (its sign: the
    // force the joints feel is -qfrc_bias).
    KDL::JntArray g(static_cast<unsigned>(n));
    ASSERT_GE(dyn.JntToGravity(kdl_joints(q), g), 0);
    const kin::JointVector hold = arm->gravity_load();
    for (std::size_t j = 0; j < n; ++j) {
      const int dof =
          m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, ("j" + std::to_string(j + 1)).c_str())];
      worst_bias = std::max(worst_bias, std::abs(d->qfrc_bias[dof] - g(static_cast<unsigned>(j))));
      worst_hold = std::max(worst_hold, std::abs(hold[j] - d->qfrc_bias[dof]));
    }
    // The joint-space inertia: KDL's from the URDF's tensors, MuJoCo's less the armature.
    if (has_tensors) {
      KDL::JntSpaceInertiaMatrix H(static_cast<unsigned>(n));
      ASSERT_GE(dyn.JntToMass(kdl_joints(q), H), 0);
      mj_fullM(m, M.data(), d->qM);
      for (std::size_t r = 0; r < n; ++r) {
        for (std::size_t col = 0; col < n; ++col) {
          double mj = M[r * static_cast<std::size_t>(m->nv) + col];
          if (r == col) mj -= arm->plant(r).inertia;
          worst_mass = std::max(
              worst_mass, std::abs(mj - H(static_cast<unsigned>(r), static_cast<unsigned>(col))));
        }
      }
    }
  }
  EXPECT_LT(worst_p, 1e-9) << c.file;
  EXPECT_LT(worst_r, 1e-9) << c.file;
  EXPECT_LT(worst_bias, 1e-9) << c.file;
  EXPECT_LT(worst_hold, 1e-9) << c.file;
  EXPECT_LT(worst_mass, 1e-9) << c.file;
  std::printf(
      "%s in MuJoCo over 500 configurations: t6 %.2g m %.2g rad; qfrc_bias - KDL gravity %.2g "
      "N m; mass matrix - KDL %.2g kg m^2\n",
      c.file, worst_p, worst_r, worst_bias, worst_mass);
}

TEST_P(ShippedUrdf, GravityModelEqualsMujocosBiasAtRest) {
  const Case c = GetParam();
  const kin::RobotModel model = kin::load_urdf(kRobots / c.file);
  const hw::GravityModel gravity(model);
  const auto arm = mujoco_arm(model);
  std::mt19937_64 rng(7);
  double worst = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const kin::JointVector q = random_within_limits(model, rng);
    set_joints(*arm, q);
    const kin::JointVector mine = gravity.load(q);
    for (std::size_t j = 0; j < model.dof(); ++j) {
      worst = std::max(worst, std::abs(mine[j] - arm->mj_data()->qfrc_bias[j]));
    }
  }
  // puma560.urdf's link 1 has no mass: the MJCF gives it kDefaultLinkMass_kg on joint 1's
  // vertical axis, where it loads no joint.
  EXPECT_LT(worst, 1e-9) << c.file;
}

INSTANTIATE_TEST_SUITE_P(Robots, ShippedUrdf, testing::ValuesIn(kShippedUrdfs),
                         [](const auto& test) {
                           std::string name = test.param.file;
                           return name.substr(0, name.find('.'));
                         });

// ---- puma560.urdf's plant is the DH puma560's ------------------------------------------------

std::filesystem::path temp_dir(const char* name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   (std::string(name) + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

void write(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file);
  out << text;
}

TEST(UrdfPlant, Puma560UrdfWithTheFilesDynamicsIsTheDhPumasPlant) {
  // A robot file pointing at puma560.urdf that adds puma560.json's motor and friction
  // dynamics, encoder resolutions and ready pose (what URDF lacks).
  const kin::RobotModel dh = kin::builtin_robot("puma560");
  std::string joints;
  for (const kin::Joint& j : dh.joints) {
    joints += fmt::format(
        R"({}{{"name": "{}", "resolution_deg_per_count": {}, "ready_deg": {}, "dynamics": {{"inertia_kg_m2": {}, "viscous_N_m_s_per_rad": {}, "coulomb_N_m": {}}}}})",
        joints.empty() ? "" : ",\n", j.name, math::rad_to_deg(j.resolution_per_count),
        math::rad_to_deg(j.ready), j.dynamics.inertia, j.dynamics.viscous_friction,
        j.dynamics.coulomb_friction);
  }
  const auto dir = temp_dir("rccx_puma_urdf");
  write(dir / "puma.json",
        fmt::format(R"({{"name": "puma560u", "title": "t", "source": "s", "urdf": "{}",
                        "plant": "mujoco", "joints": [{}]}})",
                    (kRobots / "puma560.urdf").string(), joints));
  const kin::RobotModel urdf = kin::load_robot_file(dir / "puma.json");
  std::filesystem::remove_all(dir);
  EXPECT_EQ(urdf.geometry, kin::Geometry::chain);
  EXPECT_EQ(urdf.plant, kin::Plant::mujoco);
  const hw::GravityModel g_dh(dh), g_urdf(urdf);
  const auto a = mujoco_arm(dh), b = mujoco_arm(urdf);
  ASSERT_EQ(a->mj_model()->nv, b->mj_model()->nv);
  const int nv = a->mj_model()->nv;
  std::vector<mjtNum> Ma(static_cast<std::size_t>(nv * nv)), Mb(Ma.size());
  std::mt19937_64 rng(560);
  double worst_g = 0, worst_bias = 0, worst_mass = 0, worst_t6 = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const kin::JointVector q = random_within_limits(dh, rng);
    const kin::JointVector ga = g_dh.load(q), gb = g_urdf.load(q);
    for (std::size_t j = 0; j < q.size(); ++j) worst_g = std::max(worst_g, std::abs(ga[j] - gb[j]));
    set_joints(*a, q);
    set_joints(*b, q);
    mj_fullM(a->mj_model(), Ma.data(), a->mj_data()->qM);
    mj_fullM(b->mj_model(), Mb.data(), b->mj_data()->qM);
    for (std::size_t e = 0; e < Ma.size(); ++e)
      worst_mass = std::max(worst_mass, std::abs(Ma[e] - Mb[e]));
    for (int j = 0; j < nv; ++j) {
      worst_bias =
          std::max(worst_bias, std::abs(a->mj_data()->qfrc_bias[j] - b->mj_data()->qfrc_bias[j]));
    }
    worst_t6 = std::max(worst_t6, (a->site_pose("t6").p - b->site_pose("t6").p).norm());
  }
  EXPECT_LT(worst_g, 1e-12);
  EXPECT_LT(worst_bias, 1e-12);
  EXPECT_LT(worst_mass, 1e-12);
  EXPECT_LT(worst_t6, 1e-12);
  // The same servo on the same plant: the same motion from the same start.
  for (std::size_t j = 0; j < dh.dof(); ++j) {
    EXPECT_DOUBLE_EQ(a->gains(j).kp, b->gains(j).kp) << j;
    EXPECT_DOUBLE_EQ(a->plant(j).max_effort, b->plant(j).max_effort) << j;
  }
  const auto arm_a = mujoco_arm(dh), arm_b = mujoco_arm(urdf);
  for (std::size_t j = 0; j < dh.dof(); ++j) {
    ASSERT_TRUE(arm_a->command(j, {hw::ServoCommand::Kind::move, dh.ready()[j] + 0.2, 0.5}));
    ASSERT_TRUE(arm_b->command(j, {hw::ServoCommand::Kind::move, dh.ready()[j] + 0.2, 0.5}));
  }
  arm_a->advance_to(1.0);
  arm_b->advance_to(1.0);
  double worst_q = 0;
  for (std::size_t j = 0; j < dh.dof(); ++j) {
    worst_q = std::max(worst_q, std::abs(arm_a->true_position()[j] - arm_b->true_position()[j]));
  }
  EXPECT_LT(worst_q, 1e-9);
  std::printf(
      "puma560.urdf against the DH puma560: gravity %.2g N m, bias %.2g, mass %.2g, t6 "
      "%.2g m, after 1 s of motion %.2g rad\n",
      worst_g, worst_bias, worst_mass, worst_t6, worst_q);
}

// ---- robot files that point at a URDF --------------------------------------------------------

double max_difference(const math::Transform& a, const math::Transform& b) {
  double worst = 0.0;
  const auto ra = a.rows(), rb = b.rows();
  for (std::size_t e = 0; e < ra.size(); ++e) worst = std::max(worst, std::abs(ra[e] - rb[e]));
  return worst;
}

TEST(UrdfRobotFile, TheShippedUr5eAndPandaAreTheirUrdfsWithWhatUrdfLacks) {
  struct Shipped {
    const char* name;
    const char* urdf;
    std::vector<double> ready_deg;
  };
  const Shipped shipped[] = {{"ur5e", "ur5e.urdf", {0, -90, 90, -90, -90, 0}},
                             {"panda", "panda.urdf", {0, -45, 0, -135, 0, 90, 45}}};
  for (const Shipped& s : shipped) {
    const kin::RobotModel file = kin::builtin_robot(s.name);
    const kin::RobotModel urdf = kin::load_urdf(kRobots / s.urdf);
    EXPECT_EQ(file.name, s.name);
    EXPECT_EQ(file.geometry, kin::Geometry::chain);
    EXPECT_EQ(file.plant, kin::Plant::mujoco);
    ASSERT_EQ(file.dof(), s.ready_deg.size());
    ASSERT_EQ(file.dof(), urdf.dof());
    for (std::size_t i = 0; i < file.dof(); ++i) {
      const kin::Joint &f = file.joints[i], &u = urdf.joints[i];
      EXPECT_EQ(f.name, u.name);
      EXPECT_EQ(f.lower, u.lower);
      EXPECT_EQ(f.upper, u.upper);
      EXPECT_EQ(f.dynamics.link_mass_kg, u.dynamics.link_mass_kg);
      EXPECT_EQ(f.dynamics.link_inertia_kg_m2, u.dynamics.link_inertia_kg_m2);
      EXPECT_NEAR(f.ready, math::deg_to_rad(s.ready_deg[i]), 1e-12) << s.name << " " << i;
      EXPECT_NEAR(f.resolution_per_count, 2 * math::kPi / (1 << 20), 1e-15);
      EXPECT_NEAR(f.max_velocity, u.max_velocity, 1e-6) << s.name << " " << i;  // deg rounding
    }
    EXPECT_TRUE(file.within_limits(file.ready()));
    // The same chain: the same forward kinematics.
    const auto kf = kin::make_kinematics(file), ku = kin::make_kinematics(urdf);
    std::mt19937_64 rng(3);
    for (int n = 0; n < 100; ++n) {
      const kin::JointVector q = random_within_limits(file, rng);
      ASSERT_LE(max_difference(kf->forward(q), ku->forward(q)), 1e-12);
    }
    // The file on disk, its URDF found beside it, is the compiled-in one.
    const kin::RobotModel disk = kin::load_robot_file(kRobots / (std::string(s.name) + ".json"));
    EXPECT_EQ(disk.joints[1].chain.origin.rows(), file.joints[1].chain.origin.rows());
    EXPECT_EQ(disk.ready().size(), file.ready().size());
  }
}

TEST(UrdfRobotFile, ExtendingAShippedUrdfRobotKeepsItsShippedUrdf) {
  // Named from a folder without the URDF: the shipped one is meant.
  const kin::RobotModel m = kin::parse_robot(
      R"({"extends": "panda", "name": "panda_cell", "plant": "ideal"})", "/nonexistent/cell.json");
  EXPECT_EQ(m.dof(), 7u);
  EXPECT_EQ(m.plant, kin::Plant::ideal);
  EXPECT_NEAR(m.joints[3].ready, math::deg_to_rad(-135), 1e-12);
}

TEST(UrdfRobotFile, ARelativeUrdfIsReadFromTheRobotFilesFolder) {
  const auto dir = temp_dir("rccx_urdf_relative");
  std::filesystem::create_directories(dir / "arms");
  std::filesystem::copy_file(kRobots / "panda.urdf", dir / "arms" / "mine.urdf",
                             std::filesystem::copy_options::overwrite_existing);
  write(dir / "mine.json", R"({"name": "mine", "title": "t", "source": "s",
                               "urdf": "arms/mine.urdf", "tip_link": "panda_link7"})");
  const kin::RobotModel m = kin::load_robot_file(dir / "mine.json");
  std::filesystem::remove_all(dir);
  EXPECT_EQ(m.dof(), 7u);
  EXPECT_EQ(m.plant, kin::Plant::automatic);
  // Ending at panda_link7, the flange's 0.107 m is not there.
  EXPECT_EQ(m.joints.back().chain.after.p.z, 0.0);
}

std::string robot_file_error(const std::string& json) {
  try {
    (void)kin::parse_robot(json, (kRobots / "test.json").string());
  } catch (const kin::RobotFileError& e) {
    return e.what();
  }
  return "(no error)";
}

/// A UR5e file with `joint1` for its first joint's entry and `extra` among its keys.
std::string ur5e_with(const std::string& joint1, const std::string& extra = "") {
  return fmt::format(R"({{"name": "u", "title": "t", "source": "s", "urdf": "ur5e.urdf", {}
     "joints": [{},
       {{"name": "shoulder_lift_joint"}}, {{"name": "elbow_joint"}}, {{"name": "wrist_1_joint"}},
       {{"name": "wrist_2_joint"}}, {{"name": "wrist_3_joint"}}]}})",
                     extra, joint1);
}

TEST(UrdfRobotFile, BadFilesAreRefusedSayingWhatToDo) {
  const std::string good = ur5e_with(R"({"name": "shoulder_pan_joint"})");
  ASSERT_EQ(robot_file_error(good), "(no error)");
  const struct {
    std::string json;
    std::string says;
  } cases[] = {
      {R"({"name": "u", "title": "t", "source": "s", "urdf": "nothere.urdf"})",
       "test.json: \"urdf\": " + (kRobots / "nothere.urdf").string() + ": cannot read"},
      {R"({"name": "u", "title": "t", "source": "s", "urdf": "ur5e.urdf",
           "joints": [{"name": "shoulder_pan_joint"}]})",
       "\"joints\" must list the 6 moving joints of the URDF's chain (shoulder_pan_joint, "
       "shoulder_lift_joint, elbow_joint, wrist_1_joint, wrist_2_joint, wrist_3_joint), base to "
       "tip; it lists 1"},
      {ur5e_with(R"({"name": "base"})"),
       "joint 1 (shoulder_pan_joint): \"name\" is \"base\", but joint 1 of the URDF's chain is "
       "\"shoulder_pan_joint\""},
      {ur5e_with(R"({"name": "shoulder_pan_joint", "resolution_deg": 0.001})"),
       "joint 1 (shoulder_pan_joint): unknown key \"resolution_deg\""},
      {ur5e_with(R"({"name": "shoulder_pan_joint"})", R"("colour": "blue",)"),
       "unknown key \"colour\""},
      {ur5e_with(R"({"name": "shoulder_pan_joint"})", R"("solver": "dh",)"),
       "\"solver\" is not read beside \"urdf\""},
      {ur5e_with(R"({"name": "shoulder_pan_joint", "a_m": 0.1})"),
       "\"a_m\": the URDF gives the joint's type, geometry and limits"},
      {ur5e_with(R"({"name": "shoulder_pan_joint", "dynamics": {"link_mass_kg": 3}})"),
       "dynamics: \"link_mass_kg\": the URDF gives the link's mass"},
      {ur5e_with(R"({"name": "shoulder_pan_joint", "ready_m": 0.1})"),
       "\"ready_m\" is for a prismatic joint; URDF joint \"shoulder_pan_joint\" is revolute"},
      {ur5e_with(R"({"name": "shoulder_pan_joint", "ready_deg": 400})"),
       "joint 1 (shoulder_pan_joint): the ready value lies outside the URDF's limits"},
      {ur5e_with(R"({"name": "shoulder_pan_joint", "max_velocity_deg_per_s": -1})"),
       "\"max_velocity_deg_per_s\" must be > 0"},
      {ur5e_with(R"({"name": "shoulder_pan_joint"})", R"("tip_link": "nowhere",)"),
       "no link named 'nowhere' for the tip"},
      {R"({"extends": "ur5e", "urdf": "nothere.urdf"})", "nothere.urdf: cannot read"},
  };
  for (const auto& c : cases) {
    const std::string error = robot_file_error(c.json);
    EXPECT_NE(error.find(c.says), std::string::npos) << error << "\nwanted: " << c.says;
  }
}

// ---- 4. the UR5e and the Panda hold their poses on the MuJoCo plant --------------------------

TEST(UrdfPlant, TheUr5eAndThePandaHoldTheirPosesWithinHalfAMillimetre) {
  struct Pose {
    const char* robot;
    const char* what;
    std::vector<double> q_deg;  ///< empty: the ready pose
  };
  const Pose poses[] = {
      {"ur5e", "ready", {}},
      {"ur5e", "outstretched", {0, 0, 0, 0, 90, 0}},  // upper arm and forearm level
      {"ur5e", "reaching up and out", {45, -30, -40, -60, 90, 30}},
      {"panda", "ready", {}},
      {"panda", "outstretched", {0, 90, 0, -5, 0, 95, 45}},  // upper arm level, elbow straight
      {"panda", "to the side", {80, 60, -50, -60, 30, 120, -20}},
  };
  // Each pose bare and with the arm's rated payload (UR5e 5 kg, Panda 3 kg) 0.1 m out: from
  // the ready pose the joints move there at 0.5 rad/s, settle for a second, then hold for two
  // while MuJoCo's flange body (the tool's, at T6) is watched every 10 ms.
  constexpr double kRate_rad_per_s = 0.5;
  double worst_all = 0;
  for (const Pose& pose : poses) {
    for (const bool loaded : {false, true}) {
      const kin::RobotModel model = kin::builtin_robot(pose.robot);
      kin::JointVector q = model.ready();
      for (std::size_t i = 0; i < pose.q_deg.size(); ++i) q[i] = math::deg_to_rad(pose.q_deg[i]);
      ASSERT_TRUE(model.within_limits(q)) << pose.robot << " " << pose.what;
      auto scene = std::make_shared<hw::Scene>();
      if (loaded) {
        scene->tool_mass_kg = std::string(pose.robot) == "ur5e" ? 5.0 : 3.0;
        scene->tool_com_m = {0.0, 0.0, 0.1};
        scene->tool_length_m = 0.15;
      }
      hw::SimulatedArmOptions o;
      o.scene = scene;
      const auto arm = hw::make_simulated_arm(model, o);  // the file's plant: MuJoCo
      auto* mj = dynamic_cast<hw::MujocoArm*>(arm.get());
      ASSERT_NE(mj, nullptr) << pose.robot;
      double travel_s = 0;
      for (std::size_t j = 0; j < model.dof(); ++j) {
        ASSERT_TRUE(arm->command(j, {hw::ServoCommand::Kind::move, q[j], kRate_rad_per_s}));
        travel_s = std::max(travel_s, std::abs(q[j] - model.ready()[j]) / kRate_rad_per_s);
      }
      const double settled_s = std::ceil(travel_s) + 1.0;
      arm->advance_to(settled_s);
      // Where the flange should be, and where MuJoCo's is.
      const math::Vec3 want = kin::make_kinematics(model)->forward(q).p;
      double worst = 0;
      for (int ms = 10; ms <= 2000; ms += 10) {
        arm->advance_to(settled_s + ms * 1e-3);
        worst = std::max(worst, (mj->body_pose("tool").p - want).norm());
      }
      if (worst > 0.5e-3) {
        const auto tq = arm->true_position();
        const auto eff = mj->motor_effort();
        const auto g = mj->gravity_load();
        for (std::size_t j = 0; j < model.dof(); ++j) {
          std::printf("  j%zu sp %.6f q %.6f want %.6f effort %.3f grav %.3f max %.1f\n", j + 1,
                      mj->setpoint(j), tq[j], q[j], eff[j], g[j], mj->plant(j).max_effort);
        }
      }
      EXPECT_LT(worst, 0.5e-3) << pose.robot << " " << pose.what << (loaded ? " loaded" : "");
      worst_all = std::max(worst_all, worst);
      std::printf("%-6s %-20s %-8s moved %.1f s; flange error over the 2 s hold: worst %.3g mm\n",
                  pose.robot, pose.what, loaded ? "payload" : "bare", travel_s, worst * 1e3);
    }
  }
  RecordProperty("worst_flange_error_mm", std::to_string(worst_all * 1e3));
  std::printf("worst flange error of all: %.3g mm\n", worst_all * 1e3);
}

}  // namespace
