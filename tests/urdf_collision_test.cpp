// A URDF's <collision> geometry as the cell's capsules (kin::CollisionModel, cell::RobotCapsules)
// and URDF robots in cells: the capsules enclose every primitive (points sampled on each
// primitive's surface, placed by link frames computed here by hand from the URDF's numbers, lie
// inside); the shipped PUMA 560 URDF's capsules are the DH model's; two arms whose flanges meet
// are in collision and apart they are not, and the capsules' distance never exceeds that of two
// points inside the arms (their joint centres, from forward kinematics).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "rccx/cell/capsule.hpp"
#include "rccx/cell/cell.hpp"
#include "rccx/cell/cell_model.hpp"
#include "rccx/cell/collision.hpp"
#include "rccx/cell/robot_capsules.hpp"
#include "rccx/kinematics/collision_geometry.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/link_frames.hpp"
#include "rccx/kinematics/urdf.hpp"

namespace rccx {
namespace {

using math::Rot3;
using math::Transform;
using math::Vec3;
constexpr double kPi = std::numbers::pi;

// Two revolute joints; a box on the base, a cylinder on link 1, a sphere on a fixed child of
// link 1, a rotated box on link 2, a cylinder on a fixed tool link past the last joint.
constexpr const char* kArm = R"(<robot name="two">
  <link name="base"><collision><origin xyz="0 0 0.05" rpy="0.3 0 0"/>
    <geometry><box size="0.2 0.3 0.1"/></geometry></collision></link>
  <link name="link1"><collision><origin xyz="0.2 0 0" rpy="0 1.5707963267948966 0"/>
    <geometry><cylinder radius="0.05" length="0.4"/></geometry></collision></link>
  <link name="link1b"><collision><origin xyz="0.01 0.02 0.03"/>
    <geometry><sphere radius="0.06"/></geometry></collision></link>
  <link name="link2"><collision><origin xyz="0.15 0 0" rpy="0.1 0.2 0.3"/>
    <geometry><box size="0.3 0.04 0.06"/></geometry></collision></link>
  <link name="tool"><collision><origin xyz="0 0 0.05"/>
    <geometry><cylinder radius="0.02" length="0.1"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="link1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="1" effort="1"/></joint>
  <joint name="f1" type="fixed"><parent link="link1"/><child link="link1b"/>
    <origin xyz="0.4 0 0" rpy="0 0 1.5707963267948966"/></joint>
  <joint name="j2" type="revolute"><parent link="link1b"/><child link="link2"/>
    <origin xyz="0.1 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" velocity="1" effort="1"/></joint>
  <joint name="tip" type="fixed"><parent link="link2"/><child link="tool"/>
    <origin xyz="0.3 0 0" rpy="0 1.5707963267948966 0"/></joint>
</robot>)";

Transform rz(double a) {
  return {Rot3::rot_z(a), {}};
}
Transform ry(double a) {
  return {Rot3::rot_y(a), {}};
}
Transform at(double x, double y, double z, double r = 0, double p = 0, double yaw = 0) {
  // URDF's rpy: about the fixed x, y, z axes, Rot(z, yaw) Rot(y, p) Rot(x, r).
  return {Rot3::rot_z(yaw) * Rot3::rot_y(p) * Rot3::rot_x(r), {x, y, z}};
}

struct Primitive {
  enum Kind { box, cylinder, sphere } kind;
  Vec3 size;       // box edges; cylinder (r, length, 0); sphere (r, 0, 0)
  Transform pose;  // world <- the primitive's frame
};

/// Points on the primitive's surface, in the world: a grid over every face, the side and caps.
std::vector<Vec3> surface(const Primitive& p) {
  std::vector<Vec3> out;
  const int n = 12;
  for (int i = 0; i <= n; ++i) {
    for (int k = 0; k <= n; ++k) {
      const double u = static_cast<double>(i) / n, v = static_cast<double>(k) / n;
      if (p.kind == Primitive::box) {
        const Vec3 h = p.size / 2;
        const double a = (2 * u - 1), b = (2 * v - 1);
        for (const double s : {-1.0, 1.0}) {
          out.push_back(p.pose * Vec3{s * h.x, a * h.y, b * h.z});
          out.push_back(p.pose * Vec3{a * h.x, s * h.y, b * h.z});
          out.push_back(p.pose * Vec3{a * h.x, b * h.y, s * h.z});
        }
      } else if (p.kind == Primitive::cylinder) {
        const double r = p.size.x, half = p.size.y / 2, t = 2 * kPi * u;
        out.push_back(p.pose * Vec3{r * std::cos(t), r * std::sin(t), (2 * v - 1) * half});
        for (const double s : {-1.0, 1.0}) {
          out.push_back(p.pose * Vec3{v * r * std::cos(t), v * r * std::sin(t), s * half});
        }
      } else {
        const double r = p.size.x, t = 2 * kPi * u, f = kPi * v;
        out.push_back(p.pose * Vec3{r * std::sin(f) * std::cos(t), r * std::sin(f) * std::sin(t),
                                    r * std::cos(f)});
      }
    }
  }
  return out;
}

double outside(const Vec3& point, std::span<const cell::Capsule> capsules) {
  double best = INFINITY;
  for (const cell::Capsule& c : capsules) {
    const double d = cell::segment_distance(point, point, c.p0_m, c.p1_m).distance_m - c.radius_m;
    best = std::min(best, d);
  }
  return best;
}

TEST(UrdfCollision, CapsulesEncloseEveryPrimitiveInEveryConfiguration) {
  const kin::RobotModel m = kin::parse_urdf(kArm, "two.urdf");
  ASSERT_EQ(m.dof(), 2U);
  EXPECT_TRUE(m.collision.mesh_links.empty());
  ASSERT_EQ(m.collision.capsules.size(), 5U);  // one per primitive
  cell::RobotCapsules robot(m, {});            // no link radii: the URDF's capsules alone
  std::mt19937 random(7);
  std::uniform_real_distribution<double> angle(-3, 3);
  double worst = -INFINITY;
  for (int trial = 0; trial < 200; ++trial) {
    const double q1 = angle(random), q2 = angle(random);
    ASSERT_TRUE(robot.update(kin::JointVector{q1, q2}));
    // The link frames by hand, from the URDF's joints.
    const Transform link1 = at(0, 0, 0.1) * rz(q1);
    const Transform link1b = link1 * at(0.4, 0, 0, 0, 0, kPi / 2);
    const Transform link2 = link1b * at(0.1, 0, 0) * ry(q2);
    const Transform tool = link2 * at(0.3, 0, 0, 0, kPi / 2, 0);
    const std::vector<Primitive> primitives{
        {Primitive::box, {0.2, 0.3, 0.1}, at(0, 0, 0.05, 0.3, 0, 0)},
        {Primitive::cylinder, {0.05, 0.4, 0}, link1 * at(0.2, 0, 0, 0, kPi / 2, 0)},
        {Primitive::sphere, {0.06, 0, 0}, link1b * at(0.01, 0.02, 0.03)},
        {Primitive::box, {0.3, 0.04, 0.06}, link2 * at(0.15, 0, 0, 0.1, 0.2, 0.3)},
        {Primitive::cylinder, {0.02, 0.1, 0}, tool * at(0, 0, 0.05)}};
    for (const Primitive& p : primitives) {
      for (const Vec3& point : surface(p))
        worst = std::max(worst, outside(point, robot.capsules()));
    }
  }
  EXPECT_LE(worst, 1e-12) << "a surface point lies outside every capsule by " << worst << " m";
  // And the capsules are not needlessly fat: a box's is its cross-section's half diagonal.
  const kin::LinkCapsule box = kin::enclose_box(Transform::identity(), {0.3, 0.04, 0.06});
  EXPECT_NEAR(box.radius_m, 0.5 * std::hypot(0.04, 0.06), 1e-15);
  EXPECT_NEAR((box.to_m - box.from_m).norm(), 0.3, 1e-15);
}

TEST(UrdfCollision, ACapsuleWrittenAsCylinderAndSpheresIsOneAndMeshesAreListed) {
  const std::string capsule = R"(<robot name="one">
    <link name="base"/>
    <link name="l1">
      <collision><origin xyz="0 0 0.1"/><geometry><cylinder radius="0.05" length="0.2"/></geometry></collision>
      <collision><origin xyz="0 0 0"/><geometry><sphere radius="0.05"/></geometry></collision>
      <collision><origin xyz="0 0 0.2"/><geometry><sphere radius="0.05"/></geometry></collision>
      <collision><geometry><mesh filename="package://x/l1.stl"/></geometry></collision>
    </link>
    <joint name="j" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
  </robot>)";
  const kin::RobotModel m = kin::parse_urdf(capsule, "one.urdf");
  ASSERT_EQ(m.collision.capsules.size(), 1U);
  EXPECT_EQ(m.collision.capsules[0].link, "l1");
  EXPECT_EQ(m.collision.capsules[0].frame, 1U);
  ASSERT_EQ(m.collision.mesh_links, std::vector<std::string>{"l1"});
  // A cell refuses it without link radii, saying which link and what to do.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "rccx_urdf_collision";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "one.urdf") << capsule;
  const std::string cell = R"({"name": "c", "title": "t", "source": "s", "base_period_ms": 4,
    "collision_margin_m": 0.01, "robots": [{"name": "a", "urdf": "one.urdf",
    "base": {"xyz_m": [0, 0, 0]}, "period_multiple": 1}]})";
  try {
    (void)cell::parse_cell(cell, "c.json", dir);
    ADD_FAILURE() << "a mesh without link radii was taken";
  } catch (const cell::CellFileError& e) {
    EXPECT_NE(std::string(e.what()).find("link l1 is a mesh"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("link_radius_m"), std::string::npos) << e.what();
  }
}

TEST(UrdfCollision, ThePuma560UrdfsCapsulesAreTheDhModels) {
  const kin::RobotModel urdf = kin::load_urdf(RCCX_ROBOTS_DIR "/puma560.urdf");
  const kin::RobotModel dh = kin::builtin_robot("puma560");
  const std::vector<double> radii{0.12, 0.10, 0.08, 0.06, 0.05, 0.04};  // as the URDF says
  cell::RobotCapsules a(urdf, {});
  cell::RobotCapsules b(dh, radii);
  ASSERT_EQ(a.capsules().size(), b.capsules().size());
  std::mt19937 random(3);
  double worst = 0.0;
  for (int trial = 0; trial < 500; ++trial) {
    kin::JointVector q(6);
    for (std::size_t i = 0; i < 6; ++i) {
      q[i] = std::uniform_real_distribution<double>(dh.joints[i].lower, dh.joints[i].upper)(random);
    }
    ASSERT_TRUE(a.update(q));
    ASSERT_TRUE(b.update(q));
    // Each DH capsule is one of the URDF's: the same segment (either way round), the same radius.
    for (const cell::Capsule& c : b.capsules()) {
      double best = INFINITY;
      for (const cell::Capsule& d : a.capsules()) {
        const double same = std::max((c.p0_m - d.p0_m).norm(), (c.p1_m - d.p1_m).norm());
        const double swapped = std::max((c.p0_m - d.p1_m).norm(), (c.p1_m - d.p0_m).norm());
        best = std::min(best, std::min(same, swapped) + std::abs(c.radius_m - d.radius_m));
      }
      worst = std::max(worst, best);
    }
  }
  EXPECT_LE(worst, 1e-12);
}

/// The UR5e at the origin and the Panda `apart_m` along x, turned to face it.
std::vector<cell::RobotCapsules> two_arms(double apart_m) {
  const kin::RobotModel ur = kin::load_urdf(RCCX_ROBOTS_DIR "/ur5e.urdf");
  const kin::RobotModel panda = kin::load_urdf(RCCX_ROBOTS_DIR "/panda.urdf");
  std::vector<cell::RobotCapsules> out;
  out.emplace_back(ur, std::span<const double>{});
  out.emplace_back(panda, std::span<const double>{}, Transform{Rot3::rot_z(kPi), {apart_m, 0, 0}});
  return out;
}

TEST(UrdfCollision, TwoArmsWhoseFlangesMeetCollideAndApartTheyDoNot) {
  const kin::RobotModel ur = kin::load_urdf(RCCX_ROBOTS_DIR "/ur5e.urdf");
  const kin::RobotModel panda = kin::load_urdf(RCCX_ROBOTS_DIR "/panda.urdf");
  const auto kur = kin::make_kinematics(ur);
  const auto kpanda = kin::make_kinematics(panda);
  // The Panda's flange at a known configuration, in the world, 1 m away and facing the UR5e.
  const double apart = 1.0;
  const Transform panda_base{Rot3::rot_z(kPi), {apart, 0, 0}};
  const kin::JointVector qp{0, 0.3, 0, -1.8, 0, 2.0, 0.785};
  const Transform panda_flange = panda_base * kpanda->forward(qp);
  // The UR5e's flange put at the same point, pointing back at the Panda's (closed-form IK).
  const Transform goal = panda_flange * Transform{Rot3::rot_x(kPi), {}};
  const kin::IkResult solved = kur->inverse(goal);
  ASSERT_TRUE(solved) << kin::describe(solved.status);
  const kin::JointVector qu = solved.q;
  EXPECT_LT((kur->forward(qu).p - panda_flange.p).norm(), 1e-9);
  cell::CollisionWorld world(two_arms(apart), 0.0);
  ASSERT_TRUE(world.set_configuration(0, qu));
  ASSERT_TRUE(world.set_configuration(1, qp));
  const cell::Contact touching = world.min_distance(0, 1);
  EXPECT_LT(touching.distance_m, 0.0) << "flanges at one point are not in collision";
  EXPECT_TRUE(world.check().has_value());
  // Apart: the UR5e folded back away from the Panda (base turned half a turn): no contact.
  kin::JointVector away = ur.ready();
  away[0] = kPi;
  away[1] = -kPi / 2;  // the upper arm straight up
  ASSERT_TRUE(world.set_configuration(0, away));
  EXPECT_GT(world.min_distance(0, 1).distance_m, 0.0);
  EXPECT_FALSE(world.check().has_value());
}

TEST(UrdfCollision, TheArmsDistanceNeverExceedsThatOfPointsInsideThem) {
  // Joint centres are inside the real arms (on the joints' axes, inside their housings): the
  // capsules, which enclose the arms, can be no farther apart than any two of them.
  const kin::RobotModel ur = kin::load_urdf(RCCX_ROBOTS_DIR "/ur5e.urdf");
  const kin::RobotModel panda = kin::load_urdf(RCCX_ROBOTS_DIR "/panda.urdf");
  const double apart = 0.9;
  cell::CollisionWorld world(two_arms(apart), 0.0);
  const Transform panda_base{Rot3::rot_z(kPi), {apart, 0, 0}};
  std::mt19937 random(11);
  const auto draw = [&](const kin::RobotModel& m) {
    kin::JointVector q(m.dof());
    for (std::size_t i = 0; i < m.dof(); ++i) {
      q[i] = std::uniform_real_distribution<double>(std::max(m.joints[i].lower, -kPi),
                                                    std::min(m.joints[i].upper, kPi))(random);
    }
    return q;
  };
  int collisions = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const kin::JointVector qu = draw(ur), qp = draw(panda);
    ASSERT_TRUE(world.set_configuration(0, qu));
    ASSERT_TRUE(world.set_configuration(1, qp));
    std::array<Transform, kin::kMaxJoints> fu{}, fp{};
    kin::link_frames(ur, qu, fu);
    kin::link_frames(panda, qp, fp);
    double nearest = INFINITY;
    for (std::size_t i = 0; i < ur.dof(); ++i) {
      for (std::size_t k = 0; k < panda.dof(); ++k) {
        nearest = std::min(nearest, (fu[i].p - panda_base * fp[k].p).norm());
      }
    }
    const double d = world.min_distance(0, 1).distance_m;
    ASSERT_LE(d, nearest + 1e-12) << "trial " << trial;
    if (d < 0) ++collisions;
  }
  EXPECT_GT(collisions, 0);  // the placement makes the arms meet in some configurations
}

TEST(UrdfCollision, EachLeverBoundsHowFarTheLinksItMovesReachFromItsAxis) {
  // Cell::levers_m for a chain: every capsule surface point of frames j+1 .. n (the links and
  // tool joint j moves) lies within lever[j] of joint j's axis, measured here from the link
  // frames at random configurations.
  const cell::CellModel c = cell::load_cell_file(RCCX_CELLS_DIR "/ur5e_panda.json");
  std::mt19937 random(5);
  for (cell::CellRobot r : c.robots) {
    r.tool = Transform{Rot3::identity(), {0.02, 0.0, 0.15}};  // a tool, to be counted too
    const kin::JointVector lever = cell::Cell::levers_m(r);
    cell::RobotCapsules robot(r.model, r.link_radius_m, Transform::identity(),
                              cell::Cell::shapes_of(r));
    double tightest = INFINITY;
    for (int trial = 0; trial < 300; ++trial) {
      kin::JointVector q(r.model.dof());
      for (std::size_t i = 0; i < q.size(); ++i) {
        q[i] =
            std::uniform_real_distribution<double>(std::max(r.model.joints[i].lower, -kPi),
                                                   std::min(r.model.joints[i].upper, kPi))(random);
      }
      ASSERT_TRUE(robot.update(q));
      std::array<Transform, kin::kMaxJoints> f{};
      kin::link_frames(r.model, q, f);
      for (std::size_t j = 0; j < r.model.dof(); ++j) {
        const Transform joint =
            (j == 0 ? Transform::identity() : f[j - 1]) * r.model.joints[j].chain.origin;
        const Vec3 axis = joint.R * r.model.joints[j].chain.axis;
        double far = 0.0;
        for (std::size_t k = 0; k < robot.capsules().size(); ++k) {
          if (robot.pieces()[k].frame < j + 1) continue;  // not moved by joint j
          const cell::Capsule& cap = robot.capsules()[k];
          for (const Vec3& p : {cap.p0_m, cap.p1_m}) {
            const Vec3 d = p - joint.p;
            far = std::max(far, (d - axis * math::dot(d, axis)).norm() + cap.radius_m);
          }
        }
        ASSERT_LE(far, lever[j] + 1e-12) << r.name << " joint " << j + 1;
        tightest = std::min(tightest, lever[j] - far);
      }
    }
    EXPECT_GE(tightest, 0.0) << r.name;
  }
}

}  // namespace
}  // namespace rccx
