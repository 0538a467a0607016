// Safety between arms: segment and capsule distances against brute force, capsules that follow
// the links (and the link frames against forward), the broad phase against all pairs, two PUMAs
// meeting, and no allocation after construction (a counting operator new, below).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "counting_new.hpp"
#include "rccx/cell/capsule.hpp"
#include "rccx/cell/collision.hpp"
#include "rccx/cell/robot_capsules.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/link_frames.hpp"
#include "rccx/math/units.hpp"

namespace {

using namespace rccx;
using cell::Capsule;
using cell::CollisionWorld;
using cell::Contact;
using cell::RobotCapsules;
using math::Transform;
using math::Vec3;

const char* const kCapsuleRobots[] = {"puma560", "puma260", "microbo"};
const char* const kAllRobots[] = {"puma560", "puma260", "microbo", "stanford"};

Vec3 random_vec(std::mt19937_64& rng, double half_width) {
  std::uniform_real_distribution<double> u(-half_width, half_width);
  return {u(rng), u(rng), u(rng)};
}

kin::JointVector random_q(const kin::RobotModel& model, std::mt19937_64& rng) {
  kin::JointVector q(model.dof());
  for (std::size_t i = 0; i < model.dof(); ++i) {
    std::uniform_real_distribution<double> u(model.joints[i].lower, model.joints[i].upper);
    q[i] = u(rng);
  }
  return q;
}

// The distance from x to the segment q0..q1, exactly (the projection, clamped).
double point_segment(const Vec3& x, const Vec3& q0, const Vec3& q1) {
  const Vec3 d = q1 - q0;
  const double dd = math::dot(d, d);
  const double t = dd > 0.0 ? std::clamp(math::dot(x - q0, d) / dd, 0.0, 1.0) : 0.0;
  return (x - (q0 + d * t)).norm();
}

// Brute force: both segments sampled densely, each sample's exact distance to the other.
double sampled_distance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, int n) {
  double best = INFINITY;
  for (int k = 0; k <= n; ++k) {
    const double s = static_cast<double>(k) / n;
    best = std::min(best, point_segment(p0 + (p1 - p0) * s, q0, q1));
    best = std::min(best, point_segment(q0 + (q1 - q0) * s, p0, p1));
  }
  return best;
}

// The same minimum, tight: the distance from p(s) to a segment is convex in s, so a ternary
// search finds it to rounding.
double convex_distance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  auto f = [&](double s) { return point_segment(p0 + (p1 - p0) * s, q0, q1); };
  double lo = 0.0, hi = 1.0;
  for (int k = 0; k < 200; ++k) {
    const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
    if (f(m1) < f(m2)) {
      hi = m2;
    } else {
      lo = m1;
    }
  }
  return std::min({f(lo), f(0.0), f(1.0)});
}

// ---- narrow phase ---------------------------------------------------------------------------

enum class Kind {
  general,
  parallel,
  collinear,
  crossing,
  nearly_parallel,
  point_a,
  point_b,
  points
};

TEST(SegmentDistance, MatchesBruteForceOverRandomSegments) {
  std::mt19937_64 rng(20240601);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  constexpr int kCases = 8000;
  for (int k = 0; k < kCases; ++k) {
    const auto kind = static_cast<Kind>(k % 8);
    Vec3 p0 = random_vec(rng, 1.0), p1 = random_vec(rng, 1.0);
    Vec3 q0 = random_vec(rng, 1.0), q1 = random_vec(rng, 1.0);
    const Vec3 d = p1 - p0;
    switch (kind) {
      case Kind::general:
        break;
      case Kind::parallel:  // same or opposite direction, offset and scaled
        q1 = q0 + d * u(rng) * 2.0;
        break;
      case Kind::collinear:  // on one line, overlapping or not
        q0 = p0 + d * (2.0 * u(rng));
        q1 = p0 + d * (2.0 * u(rng));
        break;
      case Kind::crossing: {  // both through one point
        const Vec3 x = p0 + d * (0.5 + 0.5 * u(rng));
        const Vec3 e = random_vec(rng, 1.0);
        q0 = x - e * (0.5 + 0.5 * u(rng));
        q1 = x + e * (0.5 + 0.5 * u(rng));
        break;
      }
      case Kind::nearly_parallel:
        q1 = q0 + d + random_vec(rng, 1e-9);
        break;
      case Kind::point_a:
        p1 = p0;
        break;
      case Kind::point_b:
        q1 = q0;
        break;
      case Kind::points:
        p1 = p0;
        q1 = q0;
        break;
    }
    const cell::SegmentClosest c = cell::segment_distance(p0, p1, q0, q1);
    SCOPED_TRACE(testing::Message() << "case " << k << " kind " << static_cast<int>(kind));
    // The answer is consistent: fractions within the segments, points on them, distance theirs.
    ASSERT_GE(c.s, 0.0);
    ASSERT_LE(c.s, 1.0);
    ASSERT_GE(c.t, 0.0);
    ASSERT_LE(c.t, 1.0);
    ASSERT_LT((c.on_first_m - (p0 + (p1 - p0) * c.s)).norm(), 1e-12);
    ASSERT_LT((c.on_second_m - (q0 + (q1 - q0) * c.t)).norm(), 1e-12);
    ASSERT_NEAR(c.distance_m, (c.on_first_m - c.on_second_m).norm(), 1e-15);
    // No sample is closer, and the samples come within their spacing of it.
    constexpr int kSamples = 200;
    const double sampled = sampled_distance(p0, p1, q0, q1, kSamples);
    const double spacing = std::max((p1 - p0).norm(), (q1 - q0).norm()) / kSamples;
    ASSERT_LE(c.distance_m, sampled + 1e-12);
    ASSERT_GE(c.distance_m, sampled - spacing);
    // And the convex search agrees to rounding.
    ASSERT_NEAR(c.distance_m, convex_distance(p0, p1, q0, q1), 1e-9);
    if (kind == Kind::crossing) {
      ASSERT_LT(c.distance_m, 1e-12);
    }
  }
}

TEST(SegmentDistance, IsSymmetric) {
  std::mt19937_64 rng(7);
  for (int k = 0; k < 1000; ++k) {
    const Vec3 p0 = random_vec(rng, 1), p1 = random_vec(rng, 1);
    const Vec3 q0 = random_vec(rng, 1), q1 = random_vec(rng, 1);
    EXPECT_NEAR(cell::segment_distance(p0, p1, q0, q1).distance_m,
                cell::segment_distance(q1, q0, p1, p0).distance_m, 1e-12);
  }
}

TEST(CapsuleDistance, SubtractsTheRadiiAndGivesSurfacePoints) {
  Capsule a{{0, 0, 0}, {1, 0, 0}, 0.1, {}, 0};
  Capsule b{{0.5, 1, -1}, {0.5, 1, 1}, 0.2, {}, 0};  // crosses above a's middle at 1 m
  const cell::CapsuleDistance d = cell::capsule_distance(a, b);
  EXPECT_NEAR(d.distance_m, 0.7, 1e-15);
  EXPECT_LT((d.on_a_m - Vec3{0.5, 0.1, 0}).norm(), 1e-15);
  EXPECT_LT((d.on_b_m - Vec3{0.5, 0.8, 0}).norm(), 1e-15);
  // Overlapping: negative, by the depth.
  b.p0_m.y = b.p1_m.y = 0.25;
  EXPECT_NEAR(cell::capsule_distance(a, b).distance_m, -0.05, 1e-15);
  // Axes that meet: both points are the meeting point.
  b.p0_m.y = b.p1_m.y = 0.0;
  const cell::CapsuleDistance m = cell::capsule_distance(a, b);
  EXPECT_NEAR(m.distance_m, -0.3, 1e-15);
  EXPECT_EQ(m.on_a_m, (Vec3{0.5, 0, 0}));
  EXPECT_EQ(m.on_b_m, (Vec3{0.5, 0, 0}));
}

// ---- link frames and capsules ---------------------------------------------------------------

// A_i of thesis eq. 3.3 built from its factors: Rot(z, theta) Trans(0, 0, d) Trans(a, 0, 0)
// Rot(x, alpha).
Transform dh_matrix(const kin::Joint& j, double q) {
  const bool revolute = j.type == kin::JointType::revolute;
  const double theta = j.dh.theta_rad + (revolute ? q : 0.0);
  const double d = j.dh.d_m + (revolute ? 0.0 : q);
  return Transform::rotation({0, 0, 1}, theta) * Transform::translation(0, 0, d) *
         Transform::translation(j.dh.a_m, 0, 0) * Transform::rotation({1, 0, 0}, j.dh.alpha_rad);
}

TEST(LinkFrames, EachIsTheProductOfTheDhMatricesAndTheLastIsForward) {
  std::mt19937_64 rng(3);
  for (const char* name : kAllRobots) {
    SCOPED_TRACE(name);
    const kin::RobotModel model = kin::builtin_robot(name);
    const auto kinematics = kin::make_kinematics(model);
    for (int k = 0; k < 500; ++k) {
      const kin::JointVector q = random_q(model, rng);
      std::array<Transform, kin::kMaxJoints> frames;
      kin::link_frames(model, q, frames);
      Transform product;
      for (std::size_t i = 0; i < model.dof(); ++i) {
        product = product * dh_matrix(model.joints[i], q[i]);
        ASSERT_LT(math::max_abs_difference(frames[i], product), 1e-12) << "frame " << i + 1;
      }
      ASSERT_LT(math::max_abs_difference(frames[model.dof() - 1], kinematics->forward(q)), 1e-12);
    }
  }
}

TEST(LinkFrames, StartsAtTheBaseAndWritesNoMoreThanAsked) {
  const kin::RobotModel model = kin::builtin_robot("puma560");
  const kin::DhChain chain(model);
  const kin::JointVector q = model.ready();
  const Transform base = Transform{math::Rot3::rot_z(0.7), {1, 2, 3}};
  std::array<Transform, kin::kMaxJoints> plain, placed;
  kin::link_frames(chain, q, plain);
  kin::link_frames(chain, q, placed, base);
  for (std::size_t i = 0; i < model.dof(); ++i) {
    EXPECT_LT(math::max_abs_difference(placed[i], base * plain[i]), 1e-12);
  }
  std::array<Transform, 2> two;
  two.fill(Transform::translation(9, 9, 9));
  kin::link_frames(chain, q, two);  // fewer than dof: only these
  EXPECT_LT(math::max_abs_difference(two[1], plain[1]), 1e-15);
}

TEST(RobotCapsules, FollowTheLinksFromFrameOriginToFrameOrigin) {
  std::mt19937_64 rng(11);
  for (const char* name : kCapsuleRobots) {
    SCOPED_TRACE(name);
    const kin::RobotModel model = kin::builtin_robot(name);
    std::vector<double> radii;
    for (std::size_t i = 0; i < model.dof(); ++i)
      radii.push_back(0.01 * static_cast<double>(i + 1));
    const Transform base{math::Rot3::from_rpy(0.3, -0.2, 0.1), {0.5, -1.0, 0.25}};
    RobotCapsules robot(model, radii, base);
    for (int k = 0; k < 300; ++k) {
      const kin::JointVector q = random_q(model, rng);
      ASSERT_TRUE(robot.update(q));
      std::array<Transform, kin::kMaxJoints> frames;
      kin::link_frames(model, q, frames);
      auto origin = [&](std::size_t frame) {
        return frame == 0 ? base.p : base * frames[frame - 1].p;
      };
      const auto caps = robot.capsules();
      std::size_t k_cap = 0;
      for (std::size_t i = 0; i < model.dof(); ++i) {
        // The pieces of link i+1 chain from frame i's origin to frame i+1's.
        Vec3 at = origin(i);
        for (; k_cap < caps.size() && caps[k_cap].link == i; ++k_cap) {
          const Capsule& c = caps[k_cap];
          ASSERT_LT((c.p0_m - at).norm(), 1e-12) << "link " << i;
          ASSERT_EQ(c.radius_m, radii[i]);
          for (const Vec3& p : {c.p0_m, c.p1_m}) {
            for (int ax = 0; ax < 3; ++ax) {
              ASSERT_LE(robot.bounds().lo_m[ax], p[ax] - c.radius_m + 1e-15);
              ASSERT_GE(robot.bounds().hi_m[ax], p[ax] + c.radius_m - 1e-15);
            }
          }
          at = c.p1_m;
        }
        ASSERT_LT((at - origin(i + 1)).norm(), 1e-12) << "link " << i;
      }
      ASSERT_EQ(k_cap, caps.size());
    }
  }
}

TEST(RobotCapsules, EveryJointHasACapsuleAndShapesFollowTheirFrames) {
  // The wrists (the PUMA's links 5 and 6, the Microbo's 1, 4, 5 and 6) have no DH length: each
  // is a sphere at its joint, so that no part of the arm is left out.
  std::mt19937_64 rng(5);
  const double r = 0.05;
  for (const char* name : kCapsuleRobots) {
    SCOPED_TRACE(name);
    const kin::RobotModel model = kin::builtin_robot(name);
    const std::vector<cell::RobotShape> shapes{
        {"pedestal", 0, {0, 0, -0.3}, {0, 0, -0.1}, 0.07, ""},
        {"probe", model.dof(), {0, 0, 0.02}, {0.01, 0, 0.12}, 0.004, ""}};
    const Transform base{math::Rot3::from_rpy(0.4, 0.1, -0.2), {0.2, 0.3, -0.1}};
    RobotCapsules robot(model, std::span(&r, 1), base, shapes);
    const auto kinematics = kin::make_kinematics(model);
    for (int k = 0; k < 200; ++k) {
      const kin::JointVector q = random_q(model, rng);
      ASSERT_TRUE(robot.update(q));
      std::array<Transform, kin::kMaxJoints> frames;
      kin::link_frames(model, q, frames);
      std::vector<bool> seen(model.dof(), false);
      std::size_t named = 0;
      for (const Capsule& c : robot.capsules()) {
        if (c.shape < 0) {
          seen[c.link] = true;
          continue;
        }
        ++named;
        const std::string_view n = robot.shape_name(c);
        // The shape's points, placed by forward kinematics (the tool) or the base alone.
        const Transform frame = n == "probe" ? base * kinematics->forward(q) : base;
        const cell::RobotShape& spec = n == "probe" ? shapes[1] : shapes[0];
        ASSERT_LT((c.p0_m - frame * spec.from_m).norm(), 1e-12) << n;
        ASSERT_LT((c.p1_m - frame * spec.to_m).norm(), 1e-12) << n;
        EXPECT_EQ(c.tool, n == "probe");
        EXPECT_EQ(c.mounting, n == "pedestal");
      }
      EXPECT_EQ(named, 2U);
      for (std::size_t i = 0; i < model.dof(); ++i) EXPECT_TRUE(seen[i]) << "link " << i + 1;
      // Mounting capsules reach the base origin whatever the joints do.
      for (const Capsule& c : robot.capsules()) {
        if (!c.mounting || c.shape >= 0) continue;
        EXPECT_LT(std::min((c.p0_m - base.p).norm(), (c.p1_m - base.p).norm()), 1e-12);
      }
    }
  }
  // The Microbo: its base joint and its column rest on what it stands on, its arm does not.
  const RobotCapsules microbo(kin::builtin_robot("microbo"), std::span(&r, 1));
  std::size_t mounting = 0;
  for (const Capsule& c : microbo.capsules()) mounting += c.mounting ? 1 : 0;
  EXPECT_EQ(mounting, 2U);
  EXPECT_EQ(microbo.capsules().size(), 6U);  // sphere, column, arm, three wrist spheres
  const std::vector<cell::RobotShape> bad{{"x", 7, {}, {}, 0.01, ""}};
  EXPECT_THROW(
      RobotCapsules(kin::builtin_robot("microbo"), std::span(&r, 1), Transform::identity(), bad),
      std::invalid_argument);
}

// The signed distance from x to an axis-aligned box of half extents h at the origin, written
// from the faces: inside, minus the nearest face's distance; outside, the clamped point's.
double box_distance(const Vec3& x, const Vec3& h) {
  const Vec3 clamped{std::clamp(x.x, -h.x, h.x), std::clamp(x.y, -h.y, h.y),
                     std::clamp(x.z, -h.z, h.z)};
  const double out = (x - clamped).norm();
  if (out > 0.0) return out;
  return -std::min({h.x - std::abs(x.x), h.y - std::abs(x.y), h.z - std::abs(x.z)});
}

double cylinder_distance(const Vec3& x, double r, double hh) {
  const double rho = std::hypot(x.x, x.y);
  if (rho <= r && std::abs(x.z) <= hh) return -std::min(r - rho, hh - std::abs(x.z));
  const double dr = std::max(rho - r, 0.0), dz = std::max(std::abs(x.z) - hh, 0.0);
  return std::hypot(dr, dz);
}

TEST(CapsuleSolid, DistanceAgreesWithDenseSampling) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(0.02, 0.3);
  for (int k = 0; k < 400; ++k) {
    const Transform pose{math::Rot3::from_rpy(u(rng) * 10, u(rng) * 10, u(rng) * 10),
                         random_vec(rng, 0.2)};
    const bool box = k % 2 == 0;
    const Vec3 size{u(rng), u(rng), u(rng)};
    const cell::Solid solid =
        box ? cell::make_box(size, pose) : cell::make_cylinder(size.x / 2, size.z, pose);
    Capsule c;
    c.p0_m = random_vec(rng, 0.4);
    c.p1_m = k % 7 == 0 ? c.p0_m : random_vec(rng, 0.4);
    c.radius_m = u(rng) * 0.1;
    const Transform inv = pose.inverse();
    double best = INFINITY;
    constexpr int kSamples = 20000;
    for (int i = 0; i <= kSamples; ++i) {
      const Vec3 x = inv * (c.p0_m + (c.p1_m - c.p0_m) * (static_cast<double>(i) / kSamples));
      best = std::min(
          best, box ? box_distance(x, size * 0.5) : cylinder_distance(x, size.x / 2, size.z / 2));
    }
    const double expected = best - c.radius_m;
    const cell::SolidDistance d = cell::capsule_solid_distance(c, solid);
    // Sampling finds the minimum within one step of the axis (Lipschitz 1 along it).
    const double step = (c.p1_m - c.p0_m).norm() / kSamples;
    EXPECT_LE(d.distance_m, expected + 1e-9) << k;
    EXPECT_GE(d.distance_m, expected - step - 1e-9) << k;
    // The box of the solid holds it.
    for (int ax = 0; ax < 3; ++ax) {
      const Vec3 centre = pose.p;
      EXPECT_LE(solid.bounds.lo_m[ax], centre[ax]);
      EXPECT_GE(solid.bounds.hi_m[ax], centre[ax]);
    }
  }
}

TEST(CollisionWorld, ThreatsOnlyWhilePartsApproach) {
  // Two Microbos facing each other 1 m apart, arms drawn in, and a table under both.
  const kin::RobotModel m = kin::builtin_robot("microbo");
  const double r = 0.04;
  const std::vector<cell::RobotShape> tool{{"probe", m.dof(), {0, 0, 0}, {0, 0, 0.125}, 0.005, ""}};
  std::vector<RobotCapsules> robots;
  robots.emplace_back(m, std::span(&r, 1), Transform::translation(-0.5, 0, 0), tool);
  robots.emplace_back(m, std::span(&r, 1), Transform{math::Rot3::rot_z(math::kPi), {0.5, 0, 0}},
                      tool);
  robots[0].set_mounted_on(0);
  robots[1].set_mounted_on(0);
  std::vector<cell::Solid> solids{
      cell::make_box({2, 1, 0.04}, Transform::translation(0, 0, -0.02)),
      cell::make_box({0.1, 0.1, 0.05}, Transform::translation(-0.05, 0, 0.025))};
  CollisionWorld world(std::move(robots), 0.01, std::move(solids));
  std::array<cell::Threat, 8> out{};
  kin::JointVector a = m.ready(), b = m.ready();
  a[2] = 0.3;   // d3: the first wrist at x = -0.2 m
  b[2] = 0.45;  // the second at x = 0.05 m
  world.set_configuration(0, a);
  world.set_configuration(1, b);
  EXPECT_EQ(world.threats(out), 0U) << "standing on the table is not a collision";
  EXPECT_EQ(world.threats(out), 0U);
  // The first arm reaches out towards the second: the hands approach.
  world.set_allowance(0, 0.05);
  const long allocations_before = rccx::test_support::allocations();
  for (double d3 = 0.3; d3 < 0.45; d3 += 0.01) {
    a[2] = d3;
    world.set_configuration(0, a);
    const std::size_t n = world.threats(out);
    const double gap = world.min_distance(0, 1).distance_m;
    if (gap < 0.01 + 0.05) {
      ASSERT_GE(n, 1U) << "d3 " << d3;
      EXPECT_FALSE(out[0].solid);
      EXPECT_LT(out[0].distance_m, out[0].before_m);
      break;
    }
    EXPECT_EQ(n, 0U) << "d3 " << d3 << " gap " << gap;
  }
  // Moving back apart, even within the zone, is no threat.
  for (double d3 = a[2]; d3 > 0.3; d3 -= 0.01) {
    a[2] = d3;
    world.set_configuration(0, a);
    EXPECT_EQ(world.threats(out), 0U) << "d3 " << d3;
  }
  // Down onto the block: the probe approaches it, a threat, unless the motion may touch it.
  b[2] = 0.3;  // the second arm drawn in first (moving apart: no threat)
  world.set_configuration(1, b);
  EXPECT_EQ(world.threats(out), 0U);
  a[2] = 0.45;  // the first wrist over the block's edge, x = -0.05 m
  world.set_configuration(0, a);
  EXPECT_EQ(world.threats(out), 0U);
  a[1] = 0.2;  // d2 lowest: the probe's tip 75 mm above the table, 25 mm above the block
  world.set_configuration(0, a);
  std::size_t n = world.threats(out);
  ASSERT_EQ(n, 1U);
  EXPECT_TRUE(out[0].solid);
  EXPECT_EQ(out[0].b, 1U);
  world.set_touch(0, 0b10);
  a[1] = 0.275;
  world.set_configuration(0, a);
  (void)world.threats(out);
  a[1] = 0.2;
  world.set_configuration(0, a);
  EXPECT_EQ(world.threats(out), 0U) << "the probe may touch the block";
  // Against robots and solids alike, the check allocated nothing.
  EXPECT_EQ(rccx::test_support::allocations(), allocations_before);
}

TEST(RobotCapsules, RefuseBadRadiiAndBadJointValues) {
  const kin::RobotModel model = kin::builtin_robot("puma560");
  const std::vector<double> two{0.1, 0.1}, negative{-0.1}, nan{NAN};
  EXPECT_THROW(RobotCapsules(model, two), std::invalid_argument);
  EXPECT_THROW(RobotCapsules(model, negative), std::invalid_argument);
  EXPECT_THROW(RobotCapsules(model, nan), std::invalid_argument);
  const double r = 0.05;
  RobotCapsules robot(model, std::span(&r, 1));
  const Vec3 before = robot.capsules()[0].p1_m;
  EXPECT_FALSE(robot.update(kin::JointVector{0.0, 0.1}));
  EXPECT_FALSE(robot.update(kin::JointVector{0.0, NAN, 0.0, 0.0, 0.0, 0.0}));
  EXPECT_EQ(robot.capsules()[0].p1_m, before);
  EXPECT_THROW(CollisionWorld({robot}, -0.01), std::invalid_argument);
  CollisionWorld world({robot}, 0.01);
  EXPECT_FALSE(world.set_configuration(1, model.ready()));
  EXPECT_FALSE(world.check());
}

// ---- the broad phase against all pairs -------------------------------------------------------

struct RandomCell {
  std::vector<kin::RobotModel> models;
  std::unique_ptr<CollisionWorld> world;
};

// The three models, parsed once (a cell holds copies).
const kin::RobotModel& capsule_model(std::size_t i) {
  static const std::vector<kin::RobotModel> models = [] {
    std::vector<kin::RobotModel> m;
    for (const char* name : kCapsuleRobots) m.push_back(kin::builtin_robot(name));
    return m;
  }();
  return models[i % models.size()];
}

// n robots of the three kinds at random places (dense enough for contacts), some tilted.
RandomCell random_cell(std::mt19937_64& rng, std::size_t n, double margin_m, double spacing_m) {
  RandomCell cell_;
  std::vector<RobotCapsules> robots;
  const double side_m = spacing_m * std::sqrt(static_cast<double>(n));
  std::uniform_real_distribution<double> place(0.0, side_m), angle(-M_PI, M_PI), r(0.0, 0.1);
  std::bernoulli_distribution tilted(0.2);
  for (std::size_t i = 0; i < n; ++i) {
    const kin::RobotModel& model = cell_.models.emplace_back(capsule_model(i));
    math::Rot3 R = math::Rot3::rot_z(angle(rng));
    if (tilted(rng)) R = R * math::Rot3::rot_x(angle(rng));
    const Transform base{R, {place(rng), place(rng), 0.3 * r(rng)}};
    std::vector<double> radii(model.dof());
    for (double& x : radii) x = 0.02 + r(rng);
    robots.emplace_back(model, radii, base);
    robots.back().update(random_q(model, rng));
  }
  cell_.world = std::make_unique<CollisionWorld>(std::move(robots), margin_m);
  return cell_;
}

TEST(CollisionWorld, BroadPhaseFindsWhatAllPairsFind) {
  std::mt19937_64 rng(1986);
  std::uniform_int_distribution<std::size_t> size(2, 64);
  std::uniform_real_distribution<double> margin(0.0, 0.1), nudge(-0.05, 0.05), spacing(0.8, 3.0);
  int with_contacts = 0, without = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const std::size_t n = size(rng);
    RandomCell c = random_cell(rng, n, margin(rng), spacing(rng));
    CollisionWorld& world = *c.world;
    for (int step = 0; step < 10; ++step) {
      SCOPED_TRACE(testing::Message() << "trial " << trial << " robots " << n << " step " << step);
      // Mostly small moves (the insertion sort's case), sometimes a jump anywhere.
      for (std::size_t i = 0; i < n; ++i) {
        kin::JointVector q =
            step % 7 == 6 ? random_q(c.models[i], rng) : world.robot(i).configuration();
        if (step % 7 != 6) {
          for (double& v : q) v += nudge(rng);
        }
        ASSERT_TRUE(world.set_configuration(i, q));
      }
      const std::optional<cell::Contact> fast = world.check();
      const std::optional<cell::Contact> slow = world.check_all_pairs();
      ASSERT_EQ(fast.has_value(), slow.has_value());
      if (fast) {
        ++with_contacts;
        EXPECT_NEAR(fast->distance_m, slow->distance_m, 1e-12);
        EXPECT_LT(fast->distance_m, world.margin_m());
        EXPECT_LT(fast->robot_a, fast->robot_b);
        // The contact's points are where its distance is taken.
        const Contact pair = world.min_distance(fast->robot_a, fast->robot_b);
        EXPECT_NEAR(pair.distance_m, fast->distance_m, 1e-12);
      } else {
        ++without;
      }
      // Every robot pair closer than the margin, and no other.
      std::set<std::pair<std::size_t, std::size_t>> expected, found;
      for (std::size_t a = 0; a < n; ++a) {
        for (std::size_t b = a + 1; b < n; ++b) {
          if (world.min_distance(a, b).distance_m < world.margin_m()) expected.insert({a, b});
        }
      }
      std::vector<cell::Contact> out(n * n);
      const std::size_t count = world.contacts(out);
      ASSERT_LE(count, out.size());
      for (std::size_t k = 0; k < count; ++k) {
        found.insert({out[k].robot_a, out[k].robot_b});
        EXPECT_NEAR(out[k].distance_m,
                    world.min_distance(out[k].robot_a, out[k].robot_b).distance_m, 1e-12);
      }
      ASSERT_EQ(found, expected);
      ASSERT_EQ(count, expected.size());
    }
  }
  // The cells are built to give both answers often.
  EXPECT_GT(with_contacts, 100);
  EXPECT_GT(without, 50);
}

TEST(CollisionWorld, ChangesSweepAxisWhenTheRobotsSpreadOtherwise) {
  // Twenty PUMAs in a tight row along x; then half reach +y and half -y, so that the boxes
  // spread along y: the sweep turns to y (a full sort) and still finds what all pairs find.
  const kin::RobotModel model = kin::builtin_robot("puma560");
  const double r = 0.05;
  std::vector<RobotCapsules> robots;
  for (int i = 0; i < 20; ++i) {
    robots.emplace_back(model, std::span(&r, 1), Transform::translation(0.005 * i, 0, 0));
    robots.back().update(kin::JointVector{0, -M_PI / 2, M_PI / 2, 0, 0, 0});  // arm up
  }
  CollisionWorld world(std::move(robots), 0.01);
  EXPECT_EQ(world.sweep_axis(), 0);
  ASSERT_EQ(world.check().has_value(), world.check_all_pairs().has_value());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> nudge(-0.3, 0.3);
  for (std::size_t i = 0; i < world.size(); ++i) {
    const double side = i % 2 == 0 ? M_PI / 2 : -M_PI / 2;
    ASSERT_TRUE(
        world.set_configuration(i, kin::JointVector{side + nudge(rng), 0, M_PI / 2, 0, 0, 0}));
  }
  const std::optional<Contact> fast = world.check();
  EXPECT_EQ(world.sweep_axis(), 1);
  const std::optional<Contact> slow = world.check_all_pairs();
  ASSERT_TRUE(fast);
  ASSERT_TRUE(slow);
  EXPECT_NEAR(fast->distance_m, slow->distance_m, 1e-12);
  std::vector<Contact> out(400);
  std::size_t expected = 0;
  for (std::size_t a = 0; a < world.size(); ++a) {
    for (std::size_t b = a + 1; b < world.size(); ++b) {
      expected += world.min_distance(a, b).distance_m < world.margin_m() ? 1 : 0;
    }
  }
  EXPECT_EQ(world.contacts(out), expected);
}

// ---- two PUMAs facing each other ------------------------------------------------------------

TEST(CollisionWorld, TwoPumasFacingEachOther) {
  const kin::RobotModel model = kin::builtin_robot("puma560");
  const auto kinematics = kin::make_kinematics(model);
  // Forearm horizontal, pointing along +x of the robot's base.
  kin::JointVector reach{0, 0, M_PI / 2, 0, 0, 0};
  if (kinematics->forward(reach).p.x <
      kinematics->forward(kin::JointVector{0, 0, -M_PI / 2, 0, 0, 0}).p.x) {
    reach[2] = -M_PI / 2;
  }
  const Vec3 wrist = kinematics->forward(reach).p;  // d6 = 0: T6 is the wrist centre
  ASSERT_GT(wrist.x, 0.8);
  const double r = 0.06, margin = 0.05;
  // B turned half a turn about z, placed so that both forearms lie on one line: its wrist at
  // (x_B - wrist.x, y_B - wrist.y), so y_B = 2 wrist.y and the wrists are gap apart along x.
  auto world_at = [&](double gap_m) {
    const Transform a = Transform::identity();
    const Transform b{math::Rot3::rot_z(M_PI), {2 * wrist.x + gap_m, 2 * wrist.y, 0}};
    std::vector<RobotCapsules> robots;
    robots.emplace_back(model, std::span(&r, 1), a);
    robots.emplace_back(model, std::span(&r, 1), b);
    CollisionWorld world(std::move(robots), margin);
    EXPECT_TRUE(world.set_configuration(0, reach));
    EXPECT_TRUE(world.set_configuration(1, reach));
    return world;
  };

  CollisionWorld far = world_at(2.0);
  EXPECT_FALSE(far.check());
  EXPECT_NEAR(far.min_distance(0, 1).distance_m, 2.0 - 2 * r, 1e-9);

  CollisionWorld near = world_at(0.1);  // wrists 0.1 m apart, surfaces 0.1 - 2r = -0.02
  const std::optional<Contact> hit = near.check();
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->robot_a, 0U);
  EXPECT_EQ(hit->robot_b, 1U);
  EXPECT_EQ(hit->link_a, 3U);  // the forearm: link 4, d4 along z3, ending at the wrist
  EXPECT_EQ(hit->link_b, 3U);
  EXPECT_NEAR(hit->distance_m, 0.1 - 2 * r, 1e-9);
  EXPECT_LT((hit->point_a_m - (wrist + Vec3{r, 0, 0})).norm(), 1e-9);
  EXPECT_LT((hit->point_b_m - (wrist + Vec3{0.1 - r, 0, 0})).norm(), 1e-9);

  // Just outside the margin: nothing; just inside: a contact.
  EXPECT_FALSE(world_at(2 * r + margin + 1e-6).check());
  EXPECT_TRUE(world_at(2 * r + margin - 1e-6).check());
}

// ---- no allocation after construction -------------------------------------------------------

TEST(CollisionWorld, SetConfigurationAndCheckAllocateNothing) {
  std::mt19937_64 rng(42);
  RandomCell c = random_cell(rng, 64, 0.05, 1.0);
  CollisionWorld& world = *c.world;
  // Joint values drawn before counting; the loop below only uses them.
  std::vector<kin::JointVector> qs;
  for (int k = 0; k < 8; ++k) {
    for (std::size_t i = 0; i < world.size(); ++i) qs.push_back(random_q(c.models[i], rng));
  }
  std::vector<Contact> out(64);
  std::vector<cell::Threat> threats(world.max_threats() + 1);
  std::size_t contacts = 0, found = 0;
  const long before = rccx::test_support::allocations();
  for (int k = 0; k < 8; ++k) {
    for (std::size_t i = 0; i < world.size(); ++i) {
      world.set_configuration(i, qs[static_cast<std::size_t>(k) * world.size() + i]);
    }
    if (world.check()) ++found;
    contacts += world.contacts(out);
    if (world.check_all_pairs()) ++found;
    contacts += world.min_distance(0, 1).distance_m < 0.0 ? 1 : 0;
    world.set_allowance(k % world.size(), 0.01 * k);
    world.set_touch(k % world.size(), 1U);
    contacts += world.threats(threats);
  }
  const long after = rccx::test_support::allocations();
  EXPECT_EQ(after - before, 0);
  EXPECT_GT(found + contacts, 0U);  // the loop did work that was not optimised away
  // The counter itself works.
  auto* p = new int(1);
  EXPECT_GT(rccx::test_support::allocations(), after);
  delete p;
}

}  // namespace
