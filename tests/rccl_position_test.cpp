// Transforms and position equations (thesis 2.4.1): malformed equations are refused with a
// message saying what is wrong; the goal and tool products, with constants folded, solve the
// equation as written; functional transforms are evaluated once a sample; holds latch.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "rccx/math/units.hpp"
#include "rccx/rccl/position.hpp"

namespace {

using namespace rccx;
using namespace rccx::math::literals;
using rccl::EquationError;

math::Transform random_transform(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return {math::Rot3::about({u(rng), u(rng), u(rng)}, 3.0 * u(rng)), {u(rng), u(rng), u(rng)}};
}

double difference(const math::Transform& a, const math::Transform& b) {
  double m = 0.0;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m = std::max(m, std::abs(a(r, c) - b(r, c)));
  }
  return m;
}

/// The message of the EquationError `make` throws ("" when it does not throw).
template <class F>
std::string equation_error(F make) {
  try {
    make();
  } catch (const EquationError& e) {
    std::printf("  refused: %s\n", e.what());
    return e.what();
  }
  return "";
}

TEST(Position, MalformedEquationsAreRefusedWithTheReason) {
  const auto t6 = rccl::t6();
  const auto a = rccl::constant("A", math::Transform::translation(0.1, 0, 0));
  const auto b = rccl::constant("B", math::Transform::translation(0, 0.2, 0));
  const auto tool = rccl::constant("TOOL", math::Transform::translation(0, 0, 0.1));
  using rccl::Position;
  EXPECT_NE(equation_error([&] { Position::make("P", {a}, {b}, t6); }).find("T6"),
            std::string::npos);
  EXPECT_NE(equation_error([&] {
              Position::make("P", {a}, {t6, b}, t6);
            }).find("T6"),
            std::string::npos);
  EXPECT_NE(equation_error([&] {
              Position::make("P", {t6, t6}, {b}, t6);
            }).find("T6"),
            std::string::npos);
  EXPECT_NE(equation_error([&] { Position::make("P", {t6}, {}, t6); }), "");
  EXPECT_NE(equation_error([&] { Position::make("P", {t6}, {b}, tool); }).find("TOOL"),
            std::string::npos);  // the tool is not in the equation
  EXPECT_NE(equation_error([&] {
              Position::make("P", {tool, t6}, {b}, tool);
            }).find("TOOL"),
            std::string::npos);  // the tool before T6
  EXPECT_NE(equation_error([&] {
              Position::make("P", {t6, a}, {a, b}, t6);
            }).find("A"),
            std::string::npos);  // a transform twice
  EXPECT_NE(equation_error([&] { Position::make("P", {t6, nullptr}, {b}, t6); }), "");
  std::vector<rccl::TransformPtr> holds;
  for (std::size_t i = 0; i <= rccl::kMaxHolds; ++i)
    holds.push_back(rccl::hold("H" + std::to_string(i)));
  EXPECT_NE(equation_error([&] { Position::make("P", {t6}, holds, t6); }), "");
  EXPECT_NO_THROW(Position::make("P", {a, t6, tool}, {b}, tool));
}

TEST(Position, NonRigidTransformsAreRefused) {
  math::Transform bad = math::Transform::identity();
  bad.R = math::Rot3::rot_x(0.3);
  bad.p = {0, 0, 0};
  math::Transform skew = bad;
  skew.R.n = skew.R.n * 1.01;
  EXPECT_THROW(rccl::constant("S", skew), std::invalid_argument);
  const auto h = rccl::hold("H");
  EXPECT_THROW(h->set(skew), std::invalid_argument);
  EXPECT_THROW(rccl::constant("N", math::Transform::translation(NAN, 0, 0)), std::invalid_argument);
}

// A1 A2 T6 B1 B2(tool) B3 = C1 CONV C2 C3: the goal and tool products solve the equation as
// written, for random values, and the constants were folded (C2 C3 into one factor, the left
// side's A2⁻¹ A1⁻¹ C1 into one).
TEST(Position, GoalAndToolSolveTheEquationWithConstantsFolded) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const math::Transform A1 = random_transform(rng), A2 = random_transform(rng),
                          B1 = random_transform(rng), B2 = random_transform(rng),
                          B3 = random_transform(rng), C1 = random_transform(rng),
                          C2 = random_transform(rng), C3 = random_transform(rng),
                          CONV = random_transform(rng);
    const auto conv = rccl::functional("CONV", [&](const rccl::SampleContext&) { return CONV; });
    const auto t6 = rccl::t6();
    const auto b2 = rccl::constant("B2", B2);
    const auto p = rccl::Position::make(
        "P",
        {rccl::constant("A1", A1), rccl::constant("A2", A2), t6, rccl::constant("B1", B1), b2,
         rccl::constant("B3", B3)},
        {rccl::constant("C1", C1), conv, rccl::constant("C2", C2), rccl::constant("C3", C3)}, b2);
    ASSERT_TRUE(p->moves());
    EXPECT_EQ(p->goal_factor_count(), 3u);  // (A2⁻¹ A1⁻¹ C1) CONV (C2 C3 B3⁻¹)
    EXPECT_EQ(p->tool_factor_count(), 1u);  // B1 B2
    rccl::LatchedHolds holds;
    p->latch(holds);
    math::Transform goal, tool;
    p->evaluate({0.0, 1, nullptr}, holds, goal, tool);
    const math::Transform T6 = goal * tool.inverse();
    EXPECT_LT(difference(A1 * A2 * T6 * B1 * B2 * B3, C1 * CONV * C2 * C3), 1e-12);
    EXPECT_LT(difference(tool, B1 * B2), 1e-12);
  }
}

TEST(Position, FunctionalTransformsAreEvaluatedOncePerSample) {
  int calls = 0;
  const auto f = rccl::functional("F", [&](const rccl::SampleContext& c) {
    ++calls;
    return math::Transform::translation(c.t_s, 0, 0);
  });
  EXPECT_EQ(f->evaluate({0.5, 10, nullptr}).p.x, 0.5);
  EXPECT_EQ(f->evaluate({0.5, 10, nullptr}).p.x, 0.5);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(f->evaluate({0.6, 11, nullptr}).p.x, 0.6);
  EXPECT_EQ(calls, 2);
}

TEST(Position, HoldTransformsLatchTheValueWhenTheMotionStarts) {
  const auto h = rccl::hold("GRASP", math::Transform::translation(0, 0, 0.1));
  const auto t6 = rccl::t6();
  const auto p =
      rccl::Position::make("P", {t6}, {rccl::constant("OBJ", math::Transform::identity()), h}, t6);
  EXPECT_FALSE(p->moves());
  EXPECT_NEAR(p->t6_now().p.z, 0.1, 1e-15);
  rccl::LatchedHolds first;
  p->latch(first);
  h->set(math::Transform::translation(0, 0, 0.2));  // a queued update: the next motion's
  rccl::LatchedHolds second;
  p->latch(second);
  math::Transform goal, tool;
  p->evaluate({0.0, 1, nullptr}, first, goal, tool);
  EXPECT_NEAR(goal.p.z, 0.1, 1e-15);
  p->evaluate({0.0, 1, nullptr}, second, goal, tool);
  EXPECT_NEAR(goal.p.z, 0.2, 1e-15);
  EXPECT_NEAR(p->t6_now().p.z, 0.2, 1e-15);
  EXPECT_THROW(rccl::constant("C", math::Transform::identity())->set(math::Transform::identity()),
               std::logic_error);
}

// RCCL's update: solve one transform so that the equation holds at a given T6, with the unknown
// on the right side (a taught object: T6 TOOL = CONV OBJ) or on the left (a calibrated base:
// BASE T6 TOOL = OBJ), functional transforms at their present value.
TEST(Position, SolveForMakesTheEquationHoldAtTheGivenT6) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const math::Transform T6 = random_transform(rng), TOOL = random_transform(rng),
                          CONV = random_transform(rng), A = random_transform(rng),
                          C = random_transform(rng);
    const auto t6 = rccl::t6();
    const auto tool = rccl::constant("TOOL", TOOL);
    const auto conv = rccl::functional("CONV", [&](const rccl::SampleContext&) { return CONV; });
    const auto obj = rccl::hold("OBJ");
    const auto right =
        rccl::Position::make("R", {t6, tool}, {conv, obj, rccl::constant("C", C)}, tool);
    const math::Transform OBJ = right->solve_for(*obj, T6);
    EXPECT_LT(difference(T6 * TOOL, CONV * OBJ * C), 1e-9);

    const auto base = rccl::hold("BASE");
    const auto left = rccl::Position::make("L", {rccl::constant("A", A), base, t6, tool},
                                           {rccl::constant("O", CONV)}, tool);
    const math::Transform BASE = left->solve_for(*base, T6);
    EXPECT_LT(difference(A * BASE * T6 * TOOL, CONV), 1e-9);
    // Stored in the hold, the equation's T6 is the one taught.
    base->set(BASE);
    EXPECT_LT(difference(left->t6_now(), T6), 1e-9);
  }
  const auto t6 = rccl::t6();
  const auto p = rccl::Position::make("P", {t6}, {rccl::hold("H")}, t6);
  EXPECT_THROW((void)p->solve_for(*t6, math::Transform::identity()), EquationError);
  EXPECT_THROW((void)p->solve_for(*rccl::hold("ELSEWHERE"), math::Transform::identity()),
               EquationError);
}

TEST(Position, WithoutAToolArgumentTheToolIsTheLeftSidesLastTransform) {
  std::mt19937 rng(11);
  const auto t6 = rccl::t6();
  const auto a = rccl::constant("A", random_transform(rng));
  const auto tool = rccl::constant("TOOL", random_transform(rng));
  const auto obj = rccl::constant("OBJ", random_transform(rng));
  // T6 TOOL = OBJ and A T6 = OBJ, each written with and without naming the tool again.
  const std::vector<std::pair<std::vector<rccl::TransformPtr>, rccl::TransformPtr>> lefts = {
      {{t6, tool}, tool}, {{a, t6}, t6}, {{t6}, t6}};
  for (const auto& [lhs, named] : lefts) {
    const auto once = rccl::Position::make("P", lhs, {obj});
    const auto twice = rccl::Position::make("P", lhs, {obj}, named);
    EXPECT_EQ(once->describe(), twice->describe());
    EXPECT_LT(difference(once->t6_now(), twice->t6_now()), 1e-12) << once->describe();
    EXPECT_LT(difference(once->tool_now(), twice->tool_now()), 1e-12) << once->describe();
  }
  EXPECT_NE(rccl::Position::make("P", {t6, tool}, {obj})->describe().find("(tool TOOL)"),
            std::string::npos);
  EXPECT_NE(equation_error([&] { (void)rccl::Position::make("P", {}, {obj}); }).find("no T6"),
            std::string::npos);
}

TEST(Position, DescribeWritesTheEquation) {
  const auto tool = rccl::constant("TOOL", math::Transform::translation(0, 0, 0.1));
  const auto p = rccl::Position::make("P", {rccl::t6(), tool},
                                      {rccl::constant("CONV", math::Transform::identity()),
                                       rccl::constant("OBJ", math::Transform::identity())},
                                      tool);
  const std::string d = p->describe();
  EXPECT_NE(d.find("T6 TOOL = CONV OBJ"), std::string::npos) << d;
}

}  // namespace
