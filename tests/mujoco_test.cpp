// The MuJoCo plant (src/rccx/hw/mjcf.hpp, mujoco_arm.hpp): the generated MJCF against rccx's
// forward kinematics, the servo holding and following, the wrist sensor's sign (a hanging tool,
// a tool pressed on a box), a prismatic joint, the plant chosen by a robot file, and no
// allocation in the servo tick (counting operator new and MuJoCo's malloc hook: its own
// executable).
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <new>
#include <numbers>
#include <random>
#include <string>

#include "counting_new.hpp"
#include "rccx/hw/mjcf.hpp"
#include "rccx/hw/mujoco_arm.hpp"
#include "rccx/hw/rcu.hpp"
#include "rccx/hw/simulated_arm.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rtc/simulated_robot.hpp"

// ---- counting allocations: C++'s operator new (counting_new.cpp) and MuJoCo's mju_malloc -----

namespace {
std::atomic<long> g_mujoco_allocations{0};

/// Every allocation so far: operator new's and MuJoCo's.
long allocations() {
  return rccx::test_support::allocations() + g_mujoco_allocations.load(std::memory_order_relaxed);
}

void* counting_malloc(std::size_t size) {
  g_mujoco_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size);
}
void counting_free(void* p) {
  std::free(p);
}
// Installed before main(), before any MuJoCo model exists (mju_free must match mju_malloc).
const bool g_hooks_installed = [] {
  mju_user_malloc = counting_malloc;
  mju_user_free = counting_free;
  return true;
}();

using namespace rccx;
using hw::MujocoArm;
using hw::ServoCommand;

constexpr const char* kShipped[] = {"microbo", "puma260", "puma560", "stanford"};

std::unique_ptr<MujocoArm> make_arm(const kin::RobotModel& model, const hw::Scene& scene = {},
                                    const kin::JointVector& initial = {}) {
  hw::SimulatedArmOptions o;
  o.initial = initial;
  o.scene = std::make_shared<const hw::Scene>(scene);
  return std::make_unique<MujocoArm>(model, o);
}

double rotation_error(const math::Rot3& a, const math::Rot3& b) {
  math::Vec3 axis;
  double angle = 0;
  (a.transposed() * b).to_axis_angle(axis, angle);
  return angle;
}

// ---- the MJCF reproduces the forward kinematics --------------------------------------------

TEST(MujocoMjcf, EveryShippedRobotMatchesForwardKinematicsAt1000Configurations) {
  std::mt19937_64 rng(20261125);
  for (const char* name : kShipped) {
    const kin::RobotModel model = kin::builtin_robot(name);
    const auto kin = kin::make_kinematics(model);
    // A base away from the world's origin, turned: the site must carry it too.
    hw::Scene scene;
    scene.base_m = {math::Rot3::from_rpy(0.3, -0.2, 0.1), {0.4, -0.25, 0.8}};
    const auto arm = make_arm(model, scene);
    const mjModel* m = arm->mj_model();
    mjData* d = arm->mj_data();
    double worst_p = 0, worst_r = 0;
    for (int trial = 0; trial < 1000; ++trial) {
      kin::JointVector q(model.dof());
      for (std::size_t j = 0; j < model.dof(); ++j) {
        std::uniform_real_distribution<double> u(model.joints[j].lower, model.joints[j].upper);
        q[j] = u(rng);
        d->qpos[m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, ("j" + std::to_string(j + 1)).c_str())]] =
            q[j];
      }
      mj_kinematics(m, d);
      const math::Transform want = scene.base_m * kin->forward(q);
      const math::Transform got = arm->site_pose("t6");
      worst_p = std::max(worst_p, (got.p - want.p).norm());
      worst_r = std::max(worst_r, rotation_error(got.R, want.R));
      // The sensor's site is at T6 too.
      const math::Transform ft = arm->site_pose("ft");
      worst_p = std::max(worst_p, (ft.p - want.p).norm());
      worst_r = std::max(worst_r, rotation_error(ft.R, want.R));
    }
    EXPECT_LT(worst_p, 1e-9) << name;
    EXPECT_LT(worst_r, 1e-9) << name;
    std::printf("%s: MuJoCo's t6 against forward(), worst of 1000: %.2g m, %.2g rad\n", name,
                worst_p, worst_r);
  }
}

TEST(MujocoMjcf, JointsCarryTheFilesLimitsAndKinds) {
  const kin::RobotModel model = kin::builtin_robot("microbo");
  const auto arm = make_arm(model);
  const mjModel* m = arm->mj_model();
  for (std::size_t j = 0; j < model.dof(); ++j) {
    const int id = mj_name2id(m, mjOBJ_JOINT, ("j" + std::to_string(j + 1)).c_str());
    ASSERT_GE(id, 0);
    const bool prismatic = model.joints[j].type == kin::JointType::prismatic;
    EXPECT_EQ(m->jnt_type[id], prismatic ? mjJNT_SLIDE : mjJNT_HINGE) << j;
    EXPECT_NEAR(m->jnt_range[2 * id], arm->lower_stop(j), 1e-12);
    EXPECT_NEAR(m->jnt_range[2 * id + 1], arm->upper_stop(j), 1e-12);
  }
  EXPECT_EQ(m->nu, static_cast<int>(model.dof()));
}

TEST(MujocoMjcf, RefusesABadScene) {
  const kin::RobotModel model = kin::builtin_robot("puma560");
  hw::Scene scene;
  scene.boxes.push_back({"bad name", {}, {0.1, 0.1, 0.1}});
  EXPECT_THROW((void)hw::make_mjcf(model, scene), std::invalid_argument);
  scene.boxes = {{"flat", {}, {0.1, 0.1, 0.0}}};
  EXPECT_THROW((void)hw::make_mjcf(model, scene), std::invalid_argument);
  scene.boxes = {{"a", {}, {0.1, 0.1, 0.1}}, {"a", {}, {0.1, 0.1, 0.1}}};  // MuJoCo refuses
  EXPECT_THROW((void)make_arm(model, scene), std::invalid_argument);
}

// ---- the plant --------------------------------------------------------------------------------

void run_for(hw::SimulatedArm& arm, double seconds) {
  arm.advance_to(arm.time_s() + seconds);
}

ServoCommand move(double target, double rate) {
  return {ServoCommand::Kind::move, target, rate};
}

double max_joint_error(const hw::SimulatedArm& arm, const kin::JointVector& want) {
  const kin::JointVector q = arm.true_position();
  double worst = 0;
  for (std::size_t j = 0; j < q.size(); ++j) worst = std::max(worst, std::abs(q[j] - want[j]));
  return worst;
}

TEST(MujocoArm, HoldsTheReadyPoseUnderGravity) {
  for (const char* name : kShipped) {
    const kin::RobotModel model = kin::builtin_robot(name);
    hw::Scene scene;
    scene.tool_mass_kg = 1.5;
    scene.tool_com_m = {0.0, 0.02, 0.05};
    scene.tool_length_m = 0.1;
    const auto arm = make_arm(model, scene);
    run_for(*arm, 0.2);
    const double early = max_joint_error(*arm, model.ready());
    run_for(*arm, 2.0);
    // The integrator pulls every joint back in against gravity and friction.
    EXPECT_LT(max_joint_error(*arm, model.ready()), 2e-4)
        << name << " (after 0.2 s: " << early << ")";
    for (double v : arm->true_velocity()) EXPECT_LT(std::abs(v), 1e-3) << name;
  }
}

TEST(MujocoArm, FollowsACommandedSetpoint) {
  const kin::RobotModel model = kin::builtin_robot("puma560");
  const auto arm = make_arm(model);
  kin::JointVector goal = model.ready();
  const double rates[] = {0.5, 0.5, 0.5, 1.0, 1.0, 1.0};
  const double steps[] = {0.3, -0.2, 0.25, 0.5, -0.4, 0.6};
  for (std::size_t j = 0; j < model.dof(); ++j) {
    goal[j] += steps[j];
    ASSERT_TRUE(arm->command(j, move(goal[j], rates[j])));
  }
  // While moving, the joints track their setpoints closely (velocity feedforward).
  double worst_lag = 0;
  for (int ms = 0; ms < 500; ++ms) {
    run_for(*arm, 1e-3);
    if (ms < 100) continue;  // the start
    for (std::size_t j = 0; j < model.dof(); ++j) {
      worst_lag = std::max(worst_lag, std::abs(arm->setpoint(j) - arm->true_position()[j]));
    }
  }
  EXPECT_LT(worst_lag, 0.02);
  run_for(*arm, 2.0);
  EXPECT_LT(max_joint_error(*arm, goal), 2e-4);
  // And T6 is where the kinematics says.
  const auto k = kin::make_kinematics(model);
  EXPECT_LT((arm->site_pose("t6").p - k->forward(arm->true_position()).p).norm(), 1e-12);
}

TEST(MujocoArm, APrismaticJointSlides) {
  const kin::RobotModel model = kin::builtin_robot("microbo");
  const auto arm = make_arm(model);
  run_for(*arm, 0.1);
  const math::Vec3 before = arm->site_pose("t6").p;
  ASSERT_EQ(model.joints[2].type, kin::JointType::prismatic);
  const double d3 = model.ready()[2] + 0.08;
  ASSERT_TRUE(arm->command(2, move(d3, 0.1)));
  const double d2 = model.ready()[1] - 0.05;  // the vertical slide, against gravity's help
  ASSERT_TRUE(arm->command(1, move(d2, 0.1)));
  run_for(*arm, 2.0);
  EXPECT_NEAR(arm->true_position()[2], d3, 1e-5);
  EXPECT_NEAR(arm->true_position()[1], d2, 1e-5);
  const math::Vec3 after = arm->site_pose("t6").p;
  // At the ready pose d3 runs along the base's x and d2 along its z.
  EXPECT_NEAR(after.x - before.x, 0.08, 1e-5);
  EXPECT_NEAR(after.z - before.z, -0.05, 1e-5);
  EXPECT_NEAR(after.y - before.y, 0.0, 1e-5);
}

TEST(MujocoArm, ZeroGravityYieldsToAPushAndStaysWhereLeft) {
  const kin::RobotModel model = kin::builtin_robot("puma560");
  const auto arm = make_arm(model);
  run_for(*arm, 0.1);
  arm->set_zero_gravity(true);
  const double q0 = arm->true_position()[0];
  arm->set_external_effort(0, 60.0);  // above joint 1's Coulomb friction (26 N m)
  run_for(*arm, 0.5);
  arm->set_external_effort(0, 0.0);
  run_for(*arm, 1.0);
  const double q1 = arm->true_position()[0];
  EXPECT_GT(q1 - q0, 0.05);
  run_for(*arm, 1.0);
  EXPECT_NEAR(arm->true_position()[0], q1, 1e-4);  // friction holds it there
  // Gravity is compensated: the other joints stayed.
  for (std::size_t j = 1; j < model.dof(); ++j) {
    EXPECT_NEAR(arm->true_position()[j], model.ready()[j], 0.02) << j;
  }
}

// ---- the wrist sensor ------------------------------------------------------------------------

TEST(MujocoArm, AHangingToolReadsItsWeightAtT6) {
  for (const char* name : kShipped) {
    const kin::RobotModel model = kin::builtin_robot(name);
    hw::Scene scene;
    scene.tool_mass_kg = 2.0;
    scene.tool_com_m = {0.01, -0.02, 0.08};
    scene.tool_length_m = 0.15;
    scene.base_m = {math::Rot3::rot_z(0.4), {0.1, 0.2, 0.3}};
    const auto arm = make_arm(model, scene);
    math::Wrench w;
    // Before the first tick the motors already hold the arm: the weight is there at once.
    ASSERT_TRUE(arm->wrist_wrench(w));
    EXPECT_NEAR((arm->site_pose("t6").R * w.force_N).z, -2.0 * 9.81, 0.2) << name;
    run_for(*arm, 1.0);
    ASSERT_TRUE(arm->wrist_wrench(w));
    const math::Transform t6 = arm->site_pose("t6");
    // The weight, as the tool side exerts it on the arm, about T6 in T6's axes.
    const math::Wrench want = math::weight_wrench(t6.R, 2.0, scene.tool_com_m);
    for (int i = 0; i < 6; ++i) {
      EXPECT_NEAR(w.to_array()[i], want.to_array()[i], 0.02) << name << " component " << i;
    }
    // In the world: 19.6 N straight down.
    const math::Vec3 f_world = t6.R * w.force_N;
    EXPECT_NEAR(f_world.z, -2.0 * 9.81, 0.02) << name;
  }
}

TEST(MujocoArm, WithoutAToolTheSensorReadsNothing) {
  const auto arm = make_arm(kin::builtin_robot("puma560"));
  run_for(*arm, 0.5);
  math::Wrench w;
  ASSERT_TRUE(arm->wrist_wrench(w));
  EXPECT_LT(w.force_N.norm(), 1e-6);
  EXPECT_LT(w.torque_N_m.norm(), 1e-6);
}

/// The Microbo at its ready pose points its tool straight down over a table.
struct Pressing {
  static constexpr double kTool = 0.1;      // m
  static constexpr double kToolMass = 0.5;  // kg
  kin::RobotModel model = kin::builtin_robot("microbo");
  hw::Scene scene;
  double tip_z = 0;
  double top_z = 0;
  std::unique_ptr<MujocoArm> arm;

  explicit Pressing(double gap_m) {
    scene.tool_mass_kg = kToolMass;
    scene.tool_com_m = {0.0, 0.0, kTool / 2};
    scene.tool_length_m = kTool;
    const auto k = kin::make_kinematics(model);
    const math::Transform t6 = k->forward(model.ready());
    tip_z = (t6 * math::Vec3{0.0, 0.0, kTool}).z;
    top_z = tip_z - gap_m;
    scene.boxes.push_back(
        {"table", math::Transform::translation(t6.p.x, t6.p.y, top_z - 0.02), {0.1, 0.1, 0.02}});
    arm = make_arm(model, scene);
  }
};

math::Vec3 contact_force_on(const MujocoArm& arm, const char* geom) {
  const mjModel* m = arm.mj_model();
  const mjData* d = arm.mj_data();
  const int g = mj_name2id(m, mjOBJ_GEOM, geom);
  math::Vec3 total;
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    if (c.geom1 != g && c.geom2 != g) continue;
    mjtNum f[6];
    mj_contactForce(m, d, i, f);
    // f is in the contact frame (rows of c.frame: normal first), the force geom1 exerts on
    // geom2... as seen from geom2's side: turn it to the world, signed onto `geom`.
    math::Vec3 world;
    for (int r = 0; r < 3; ++r) {
      world += math::Vec3{c.frame[3 * r], c.frame[3 * r + 1], c.frame[3 * r + 2]} * f[r];
    }
    total += c.geom2 == g ? world : -world;
  }
  return total;
}

TEST(MujocoArm, AToolPressedOnATableReadsTheTablesReaction) {
  Pressing p(0.005);
  math::Wrench w;
  p.arm->advance_to(0.2);
  ASSERT_TRUE(p.arm->wrist_wrench(w));
  EXPECT_EQ(p.arm->contact_count(), 0);
  // Lower the vertical slide 8 mm: the tip meets the table after 5.
  ASSERT_TRUE(p.arm->command(1, move(p.model.ready()[1] - 0.008, 0.02)));
  p.arm->advance_to(1.5);
  ASSERT_GT(p.arm->contact_count(), 0);
  ASSERT_TRUE(p.arm->wrist_wrench(w));
  const math::Transform t6 = p.arm->site_pose("t6");
  const math::Vec3 f_world = t6.R * w.force_N;
  const math::Vec3 reaction = contact_force_on(*p.arm, "tool");
  // The table pushes the tool up, and the tool the arm: the sensor reads the reaction less the
  // tool's weight.
  EXPECT_GT(reaction.z, 20.0);
  EXPECT_NEAR(f_world.z, reaction.z - Pressing::kToolMass * 9.81, 0.01 * reaction.z);
  EXPECT_NEAR(f_world.x, reaction.x, 0.01 * reaction.z + 0.01);
  EXPECT_NEAR(f_world.y, reaction.y, 0.01 * reaction.z + 0.01);
  // Along T6's z (pointing down) the arm is pushed back: negative.
  EXPECT_LT(w.force_N.z, -20.0);
  // The tip stands on the table, not in it.
  const double tip = (t6 * math::Vec3{0.0, 0.0, Pressing::kTool}).z;
  EXPECT_NEAR(tip, p.top_z, 0.5e-3);
  std::printf("pressed with %.1f N: the tip %.3g mm into the table; sensor %.2f N\n", reaction.z,
              (p.top_z - tip) * 1e3, f_world.z);
}

TEST(MujocoArm, AGentlePushInZeroGravityReadsThePush) {
  Pressing p(0.002);
  p.arm->advance_to(0.2);
  p.arm->set_zero_gravity(true);
  // 60 N down on the vertical slide; its Coulomb friction (15 N) takes part of it at rest.
  p.arm->set_external_effort(1, -60.0);
  p.arm->advance_to(1.5);
  math::Wrench w;
  ASSERT_TRUE(p.arm->wrist_wrench(w));
  const math::Vec3 f_world = p.arm->site_pose("t6").R * w.force_N;
  const math::Vec3 reaction = contact_force_on(*p.arm, "tool");
  EXPECT_GT(reaction.z, 60.0 - 15.0 - 1.0);
  EXPECT_LT(reaction.z, 60.0 + 15.0 + 1.0);
  EXPECT_NEAR(f_world.z, reaction.z - Pressing::kToolMass * 9.81, 0.5);
}

// ---- objects -----------------------------------------------------------------------------------

TEST(MujocoArm, AFreeBoxRestsOnTheTableAndMovesWhenPushed) {
  const kin::RobotModel model = kin::builtin_robot("puma560");
  hw::Scene scene;
  scene.boxes.push_back({"table", math::Transform::translation(0.6, 0.0, -0.52), {0.3, 0.3, 0.02}});
  scene.boxes.push_back(
      {"part", math::Transform::translation(0.6, 0.1, -0.47), {0.03, 0.03, 0.03}, 0.2, 0.4});
  const auto arm = make_arm(model, scene);
  run_for(*arm, 1.0);
  const math::Vec3 rest = arm->body_pose("part").p;
  EXPECT_NEAR(rest.z, -0.5 + 0.03, 1e-3);          // on the table's top
  arm->apply_body_force("part", {1.5, 0.0, 0.0});  // above friction 0.4 x 0.2 x 9.81 = 0.78 N
  run_for(*arm, 0.5);
  arm->apply_body_force("part", {});
  run_for(*arm, 0.5);
  EXPECT_GT(arm->body_pose("part").p.x - rest.x, 0.02);
  arm->set_body_pose("part", math::Transform::translation(0.5, -0.1, -0.4));
  run_for(*arm, 1.0);
  const math::Vec3 moved = arm->body_pose("part").p;
  EXPECT_NEAR(moved.x, 0.5, 1e-3);
  EXPECT_NEAR(moved.z, -0.47, 1e-3);
  EXPECT_THROW(arm->set_body_pose("table", {}), std::invalid_argument);
  EXPECT_THROW((void)arm->body_pose("nothing"), std::invalid_argument);
}

// ---- the servo tick allocates nothing
// ------------------------------------------------------------

TEST(MujocoArm, AServoTickAllocatesNothing) {
  Pressing p(0.003);
  ASSERT_TRUE(p.arm->command(1, move(p.model.ready()[1] - 0.01, 0.02)));
  ASSERT_TRUE(p.arm->command(0, move(0.02, 0.1)));
  p.arm->advance_to(0.01);
  const long before = allocations();
  math::Wrench w;
  for (int ms = 0; ms < 2000; ++ms) {
    p.arm->advance_to(p.arm->time_s() + 1e-3);
    (void)p.arm->wrist_wrench(w);
    (void)p.arm->read(1);
  }
  EXPECT_EQ(allocations() - before, 0);
  EXPECT_GT(p.arm->contact_count(), 0);  // the ticks counted include contact
}

// ---- which plant
// ---------------------------------------------------------------------------------

TEST(MujocoPlant, ARobotFileGivesItsSceneUnlessCodeDoes) {
  // A file that extends the shipped PUMA 560 with the plant, a table and a 2 kg tool.
  const kin::RobotModel model = kin::parse_robot(
      R"({"extends": "puma560", "name": "puma560_table", "plant": "mujoco",
          "hardware": {"mujoco": {
            "base_m": [0.1, 0.2, 0.3], "base_rpy_deg": [30, 0, 0],
            "tool": {"mass_kg": 2.0, "com_m": [0, 0, 0.05], "length_m": 0.1},
            "boxes": [{"name": "table", "center_m": [0.5, 0, -0.3], "rpy_deg": [10, 0, 0],
                       "half_size_m": [0.3, 0.3, 0.02], "friction": 0.3},
                      {"name": "cube", "center_m": [0.5, 0, -0.25], "half_size_m": [0.02, 0.02, 0.02],
                       "mass_kg": 0.1}],
            "contact_time_constant_s": 0.02, "substeps": 2}}})",
      "test");
  EXPECT_FALSE(hw::has_rcu(model));
  const hw::Scene scene = hw::scene_from_file(model);
  ASSERT_EQ(scene.boxes.size(), 2U);
  EXPECT_EQ(scene.boxes[0].name, "table");
  EXPECT_DOUBLE_EQ(scene.boxes[0].friction, 0.3);
  EXPECT_DOUBLE_EQ(scene.boxes[1].mass_kg, 0.1);
  EXPECT_EQ(scene.substeps, 2);
  EXPECT_DOUBLE_EQ(scene.tool_mass_kg, 2.0);

  const auto arm = hw::make_simulated_arm(model);
  auto* mj = dynamic_cast<MujocoArm*>(arm.get());
  ASSERT_NE(mj, nullptr);
  // The base moved and turned 30 deg, as the file says.
  const math::Transform base = mj->body_pose("base");
  EXPECT_LT((base.p - math::Vec3{0.1, 0.2, 0.3}).norm(), 1e-12);
  EXPECT_NEAR(std::atan2(base.R(1, 0), base.R(0, 0)), 30.0 * std::numbers::pi / 180.0, 1e-12);
  EXPECT_NE(mj->mjcf().find("name=\"table\""), std::string::npos);
  EXPECT_NE(mj->mjcf().find("name=\"cube\""), std::string::npos);
  // The tool's weight is read at the wrist.
  run_for(*mj, 0.5);
  math::Wrench w;
  ASSERT_TRUE(mj->wrist_wrench(w));
  EXPECT_NEAR((mj->site_pose("t6").R * w.force_N).z, -2.0 * 9.81, 0.05);

  // A scene from code replaces the file's.
  hw::SimulatedArmOptions o;
  o.scene = std::make_shared<hw::Scene>();
  const auto bare = hw::make_simulated_arm(model, o);
  EXPECT_EQ(dynamic_cast<MujocoArm*>(bare.get())->mjcf().find("name=\"table\""), std::string::npos);

  // The Microbo's file keeps its RCU beside a scene.
  kin::RobotModel microbo = kin::builtin_robot("microbo");
  EXPECT_TRUE(hw::has_rcu(microbo));
  microbo.hardware_json.insert(1, R"("mujoco": {"tool": {"mass_kg": 0.5}}, )");
  EXPECT_TRUE(hw::has_rcu(microbo));
  EXPECT_EQ(hw::rcu_config(microbo).joints.size(), 6U);
  EXPECT_DOUBLE_EQ(hw::scene_from_file(microbo).tool_mass_kg, 0.5);
}

TEST(MujocoPlant, ABadSceneInTheFileIsRefusedNamingTheKey) {
  const auto refused = [](const std::string& mujoco, const std::string& says) {
    kin::RobotModel m = kin::builtin_robot("puma560");
    m.hardware_json = R"({"mujoco": )" + mujoco + "}";
    try {
      (void)hw::scene_from_file(m);
      ADD_FAILURE() << mujoco << ": accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("\"mujoco\""), std::string::npos) << e.what();
    }
  };
  refused(R"({"tabel": {}})", "unknown key \"tabel\"");
  refused(R"({"tool": {"mass_kg": -1}})", "\"mass_kg\" must not be negative");
  refused(R"({"tool": {"radius_m": 0}})", "\"radius_m\" must be > 0");
  refused(R"({"boxes": {}})", "\"boxes\" must be a list");
  refused(R"({"boxes": [{"name": "t", "half_size_m": [0.1, 0, 0.1]}]})", "\"half_size_m\"");
  refused(R"({"boxes": [{"name": "t", "half_size_m": [0.1, 0.1]}]})", "\"half_size_m\"");
  refused(R"({"boxes": [{"half_size_m": [0.1, 0.1, 0.1]}]})", "\"name\"");
  refused(R"({"substeps": 0})", "\"substeps\"");
  refused(R"({"base_m": [0, 0, "up"]})", "\"base_m\"");
  // A scene the MJCF cannot take is refused when the plant is made, saying why.
  kin::RobotModel m = kin::builtin_robot("puma560");
  m.plant = kin::Plant::mujoco;
  m.hardware_json = R"({"mujoco": {"contact_time_constant_s": 0.0001}})";
  EXPECT_THROW((void)hw::make_simulated_arm(m), std::invalid_argument);
  // Keys beside "rcu" and "mujoco" are refused where the RCU is read too.
  kin::RobotModel microbo = kin::builtin_robot("microbo");
  microbo.hardware_json.insert(1, R"("bullet": {}, )");
  EXPECT_THROW((void)hw::rcu_config(microbo), std::invalid_argument);
}

TEST(MujocoPlant, ARobotFileChoosesItAndOptionsOverride) {
  kin::RobotModel model = kin::builtin_robot("stanford");
  EXPECT_EQ(model.plant, kin::Plant::automatic);
  model.plant = kin::Plant::mujoco;
  EXPECT_NE(dynamic_cast<MujocoArm*>(hw::make_simulated_arm(model).get()), nullptr);
  hw::SimulatedArmOptions o;
  o.plant = hw::Plant::ideal;
  EXPECT_EQ(dynamic_cast<MujocoArm*>(hw::make_simulated_arm(model, o).get()), nullptr);
  o.plant = hw::Plant::mujoco;
  EXPECT_NE(
      dynamic_cast<MujocoArm*>(hw::make_simulated_arm(kin::builtin_robot("puma560"), o).get()),
      nullptr);
  // The servo plant needs dynamics.
  o.plant = hw::Plant::servo;
  EXPECT_THROW((void)hw::make_simulated_arm(kin::builtin_robot("stanford"), o),
               std::invalid_argument);
}

TEST(MujocoPlant, TheMicroboRunsInMujocoBehindTheServoDriver) {
  using namespace std::chrono_literals;
  rtc::SimulatedRobotOptions o;
  o.plant = hw::Plant::mujoco;
  rtc::SimulatedRobot robot(kin::builtin_robot("microbo"), o);
  EXPECT_EQ(robot.rcu, nullptr);
  ASSERT_NE(dynamic_cast<MujocoArm*>(robot.arm.get()), nullptr);
  EXPECT_DOUBLE_EQ(robot.period_s(), 0.010);
  // A session moves the vertical slide down 20 mm through the servo driver.
  const kin::RobotModel model = kin::builtin_robot("microbo");
  const kin::JointVector ready = model.ready();
  const double goal = ready[1] - 0.02;
  robot.session->control(
      [&](rtc::Control& c) {
        for (std::size_t j = 0; j < ready.size(); ++j) {
          // Range values: above the joint's lower limit.
          const double target = (j == 1 ? goal : ready[j]) - model.joints[j].lower;
          c.chg().pos(j, target, j == 1 ? 0.05 : 0.0);
        }
      },
      {});
  const rtc::Termination t = robot.session->wait_for(1500ms);
  EXPECT_FALSE(t.ended()) << rtc::describe(t.code);
  EXPECT_NEAR(robot.arm->true_position()[1], goal, 2e-5);
  EXPECT_TRUE(robot.finish().empty());
  // Without a plant named, the Microbo's file still means its RCU.
  const rtc::SimulatedRobot plain(kin::builtin_robot("microbo"));
  EXPECT_NE(plain.rcu, nullptr);
  EXPECT_DOUBLE_EQ(plain.period_s(), 0.028);
}

}  // namespace
namespace {

// ---- force control over the plant: the acceptance the force layer builds on --------------------

/// A force loop in the test: the vertical slide's goal moves at 2e-5 m/s per N of error in the
/// table's reaction (5 mm/s down until the first touch), read from the wrist. Returns the
/// reactions seen from `from_ms` on; joint 1 turns at 0.1 rad/s (the tip slides at 3 cm/s)
/// from `slide_ms` on when it is >= 0.
struct ForceLoop {
  Pressing p{0.002};
  double lo = 1e9, hi = -1e9, sum = 0;
  int n = 0;

  void run(int until_ms, int from_ms, int slide_ms) {
    const double mg = Pressing::kToolMass * 9.81;
    double goal = p.model.ready()[1];
    bool touched = false;
    const double q0 = p.arm->true_position()[0];
    for (int ms = 0; ms < until_ms; ++ms) {
      math::Wrench w;
      w = p.arm->raw_wrist_wrench();  // the plant's own load, not the sensor's filtered one
      const double f = (p.arm->site_pose("t6").R * w.force_N).z + mg;  // the table's reaction
      if (f > 1.0) touched = true;
      goal -= touched ? 2e-5 * (5.0 - f) * 1e-3 : 5e-3 * 1e-3;
      (void)p.arm->command(1, move(goal, 0.0));
      if (ms == slide_ms) (void)p.arm->command(0, move(q0 + 0.3, 0.1));
      p.arm->advance_to(p.arm->time_s() + 1e-3);
      if (ms < from_ms) continue;
      lo = std::min(lo, f);
      hi = std::max(hi, f);
      sum += f;
      ++n;
    }
  }
};

TEST(MujocoArm, AForceLoopHolds5NSteadyOnTheTable) {
  ForceLoop loop;
  loop.run(2000, 1200, -1);
  EXPECT_NEAR(loop.sum / loop.n, 5.0, 0.05);
  EXPECT_GT(loop.lo, 4.5);  // within 10 % at every sample
  EXPECT_LT(loop.hi, 5.5);
}

// Not yet: sliding at 3 cm/s the contact chatters (with friction 0.5, stick-slip spikes of about
// 200 N; without friction the tip still leaves the table every 10 ms, its force flicking between
// 0 and 10 N), though the mean stays 5 N. docs/FORCE.md, "Limits".
TEST(MujocoArm, DISABLED_AForceLoopHolds5NSteadyWhileSliding) {
  ForceLoop loop;
  loop.run(4000, 2000, 1500);
  EXPECT_NEAR(loop.sum / loop.n, 5.0, 0.5);
  EXPECT_GT(loop.lo, 4.5);
  EXPECT_LT(loop.hi, 5.5);
}

}  // namespace
