#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/math/units.hpp"

namespace {

using namespace rccx;
using namespace rccx::math::literals;

TEST(BuiltinRobots, AreShippedAndConsistent) {
  const auto names = kin::builtin_robot_names();
  for (const char* expected : {"microbo", "puma560", "puma260"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  }
  for (const auto& name : names) {
    const kin::RobotModel model = kin::builtin_robot(name);
    EXPECT_EQ(model.name, name);
    EXPECT_EQ(model.dof(), name == "panda" ? 7u : 6u) << name;
    EXPECT_FALSE(model.source.empty());
    EXPECT_TRUE(model.within_limits(model.ready())) << name;
    EXPECT_NO_THROW((void)kin::make_kinematics(model)) << name;
  }
  EXPECT_THROW((void)kin::builtin_robot("puma600"), kin::RobotFileError);
}

TEST(BuiltinRobots, Puma560IsCorkesStandardDhModel) {
  const kin::RobotModel m = kin::builtin_robot("puma560");
  EXPECT_EQ(m.joints[1].dh.a_m, 0.4318);
  EXPECT_EQ(m.joints[2].dh.a_m, 0.0203);
  EXPECT_EQ(m.joints[2].dh.d_m, 0.15005);
  EXPECT_EQ(m.joints[3].dh.d_m, 0.4318);
}

// Thesis 2.5 and the reading guide: 16-bit encoders are too small for joints 1 and 3, 18 bits
// are enough; the others fit in 16 bits.
TEST(BuiltinRobots, MicroboRangesFitItsEncoders) {
  const kin::RobotModel m = kin::builtin_robot("microbo");
  const double thesis_resolution[6] = {0.0031_deg, 0.0020_mm,  0.0013_mm,
                                       0.0041_deg, 0.0056_deg, 0.0182_deg};
  for (std::size_t i = 0; i < 6; ++i) {
    const kin::Joint& j = m.joints[i];
    EXPECT_NEAR(j.resolution_per_count, thesis_resolution[i], 1e-15);
    const double counts = (j.upper - j.lower) / j.resolution_per_count;
    EXPECT_LE(counts, 262143.0) << j.name;
    if (i == 0 || i == 2) {
      EXPECT_GT(counts, 65535.0) << j.name;
    } else {
      EXPECT_LE(counts, 65535.0) << j.name;
    }
  }
  // Joint 5 covers the thesis's approximate range -pi/2 .. -3 pi/2.
  EXPECT_LE(m.joints[4].lower, -270.0_deg);
  EXPECT_GE(m.joints[4].upper, -90.0_deg);
}

TEST(BuiltinRobots, MicroboLimitsHoldTheWasherCornersWithMargin) {
  const kin::RobotModel m = kin::builtin_robot("microbo");
  // theta1, d2, d3, theta4, theta5, theta6 at the washer's extremes (reading guide).
  const double corners[][6] = {
      {24.8_deg, 250_mm, 325_mm, 90_deg, -90_deg, -155.2_deg},
      {-24.8_deg, 300_mm, 358_mm, 90_deg, -90_deg, 155.2_deg},
  };
  for (const auto& c : corners) {
    for (std::size_t i = 0; i < 6; ++i) {
      const bool revolute = m.joints[i].type == kin::JointType::revolute;
      const double margin = revolute ? 4_deg : 20_mm;
      EXPECT_GE(c[i] - m.joints[i].lower, margin) << m.joints[i].name;
      EXPECT_GE(m.joints[i].upper - c[i], margin) << m.joints[i].name;
    }
  }
}

constexpr const char* kGoodRobot = R"({
  "name": "two", "title": "Two links", "source": "test", "solver": "dh",
  // comments are allowed
  "joints": [
    {"name": "j1", "type": "revolute", "a_m": 0.5, "alpha_deg": 0, "lower_deg": -90,
     "upper_deg": 90, "resolution_deg_per_count": 0.01, "ready_deg": 0,
     "max_velocity_deg_per_s": 90,
     "dynamics": {"inertia_kg_m2": 2, "viscous_N_m_s_per_rad": 3, "coulomb_N_m": 4,
                  "max_effort_N_m": 50, "link_mass_kg": 6, "link_com_m": [-0.25, 0, 0.01],
                  "link_inertia_kg_m2": [0.1, 0.2, 0.25, -0.01, 0.02, 0]}},
    {"name": "j2", "type": "prismatic", "a_m": 0, "alpha_deg": 0, "lower_m": 0, "upper_m": 0.2,
     "resolution_mm_per_count": 0.01, "ready_m": 0.1, "max_velocity_mm_per_s": 250}
  ]
})";

void expect_error(const std::string& text, const std::string& fragment) {
  try {
    (void)kin::parse_robot(text, "bad.json");
    ADD_FAILURE() << "accepted: " << fragment;
  } catch (const kin::RobotFileError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("bad.json"), std::string::npos) << message;
    EXPECT_NE(message.find(fragment), std::string::npos) << message;
  }
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}

TEST(RobotFile, ParsesWithUnitsConverted) {
  const kin::RobotModel m = kin::parse_robot(kGoodRobot, "test");
  ASSERT_EQ(m.dof(), 2u);
  EXPECT_EQ(m.solver, kin::SolverKind::dh);
  EXPECT_DOUBLE_EQ(m.joints[0].upper, 90_deg);
  EXPECT_DOUBLE_EQ(m.joints[1].resolution_per_count, 1e-5);
  EXPECT_EQ(m.joints[1].type, kin::JointType::prismatic);
  EXPECT_DOUBLE_EQ(m.joints[0].max_velocity, 90_deg);
  EXPECT_DOUBLE_EQ(m.joints[1].max_velocity, 0.25);
  const kin::JointDynamics& d = m.joints[0].dynamics;
  EXPECT_EQ(d.inertia, 2.0);
  EXPECT_EQ(d.viscous_friction, 3.0);
  EXPECT_EQ(d.coulomb_friction, 4.0);
  EXPECT_EQ(d.max_effort, 50.0);
  EXPECT_EQ(d.link_mass_kg, 6.0);
  EXPECT_EQ(d.link_com_m, (std::array<double, 3>{-0.25, 0.0, 0.01}));
  EXPECT_EQ(d.link_inertia_kg_m2, (std::array<double, 6>{0.1, 0.2, 0.25, -0.01, 0.02, 0.0}));
  // No "dynamics": all zeros ("not given").
  EXPECT_EQ(m.joints[1].dynamics.inertia, 0.0);
  EXPECT_EQ(m.joints[1].dynamics.link_mass_kg, 0.0);
}

TEST(RobotFile, ReadsPrismaticDynamicsInTheirOwnUnits) {
  const kin::RobotModel m = kin::parse_robot(
      replaced(kGoodRobot, "\"max_velocity_mm_per_s\": 250",
               "\"max_velocity_mm_per_s\": 250, \"dynamics\": {\"inertia_kg\": 7, "
               "\"viscous_N_s_per_m\": 8, \"coulomb_N\": 9, \"max_effort_N\": 300}"),
      "test");
  const kin::JointDynamics& d = m.joints[1].dynamics;
  EXPECT_EQ(d.inertia, 7.0);
  EXPECT_EQ(d.viscous_friction, 8.0);
  EXPECT_EQ(d.coulomb_friction, 9.0);
  EXPECT_EQ(d.max_effort, 300.0);
}

TEST(RobotFile, RefusesBadInputWithMessagesThatSayWhere) {
  expect_error("{ not json", "not valid JSON");
  expect_error(replaced(kGoodRobot, "\"ready_m\": 0.1,", "\"ready_m\": 0.1, \"speed\": 1,"),
               "unknown key \"speed\"");
  expect_error(replaced(kGoodRobot, "\"solver\": \"dh\"", "\"solver\": \"ikfast\""), "solver");
  expect_error(replaced(kGoodRobot, "\"type\": \"revolute\"", "\"type\": \"ball\""), "joint 1");
  expect_error(replaced(kGoodRobot, "\"lower_deg\": -90", "\"lower_deg\": 100"), "lower limit");
  expect_error(replaced(kGoodRobot, "\"ready_m\": 0.1", "\"ready_m\": 0.5"), "ready");
  expect_error(replaced(kGoodRobot, "\"a_m\": 0.5", "\"a_m\": \"x\""), "\"a_m\" must be a number");
  expect_error(replaced(kGoodRobot, "\"name\": \"two\", ", ""), "missing \"name\"");
  // The JSON library would keep the last of a repeated key: a limit given twice is refused.
  expect_error(replaced(kGoodRobot, "\"lower_deg\": -90", "\"lower_deg\": -90, \"lower_deg\": -80"),
               "key \"lower_deg\" is given twice");
  // Deep nesting is refused while parsing (dump() of it overflowed the stack).
  const std::size_t deep = 100000;
  expect_error(replaced(kGoodRobot, "\"solver\": \"dh\"",
                        "\"solver\": \"dh\", \"hardware\": {\"rcu\": " + std::string(deep, '[') +
                            std::string(deep, ']') + "}"),
               "nested more than 32 deep");
}

TEST(RobotFile, ChoosesItsSimulatedPlant) {
  EXPECT_EQ(kin::parse_robot(kGoodRobot, "test").plant, kin::Plant::automatic);
  for (const auto& [text, plant] :
       {std::pair{"ideal", kin::Plant::ideal}, std::pair{"servo", kin::Plant::servo},
        std::pair{"mujoco", kin::Plant::mujoco}}) {
    const kin::RobotModel m =
        kin::parse_robot(replaced(kGoodRobot, "\"solver\": \"dh\"",
                                  "\"solver\": \"dh\", \"plant\": \"" + std::string(text) + "\""),
                         "test");
    EXPECT_EQ(m.plant, plant) << text;
    EXPECT_EQ(kin::to_string(m.plant), text);
  }
  expect_error(
      replaced(kGoodRobot, "\"solver\": \"dh\"", "\"solver\": \"dh\", \"plant\": \"bullet\""),
      "\"plant\" is \"bullet\"; use \"ideal\", \"servo\" or \"mujoco\"");
  expect_error(replaced(kGoodRobot, "\"solver\": \"dh\"", "\"solver\": \"dh\", \"plant\": 1"),
               "\"plant\" must be a string");
}

TEST(RobotFile, RefusesAMissingOrBadMaxVelocity) {
  expect_error(replaced(kGoodRobot, ", \"max_velocity_mm_per_s\": 250", ""),
               "joint 2: missing \"max_velocity_mm_per_s\"");
  expect_error(replaced(kGoodRobot, "\"max_velocity_deg_per_s\": 90,", ""),
               "joint 1: missing \"max_velocity_deg_per_s\"");
  expect_error(
      replaced(kGoodRobot, "\"max_velocity_deg_per_s\": 90", "\"max_velocity_deg_per_s\": 0"),
      "joint 1: \"max_velocity_deg_per_s\" must be positive");
  expect_error(
      replaced(kGoodRobot, "\"max_velocity_mm_per_s\": 250", "\"max_velocity_mm_per_s\": -1"),
      "joint 2: \"max_velocity_mm_per_s\" must be positive");
  expect_error(
      replaced(kGoodRobot, "\"max_velocity_mm_per_s\": 250", "\"max_velocity_mm_per_s\": \"fast\""),
      "\"max_velocity_mm_per_s\" must be a number");
  // The unit must match the joint type.
  expect_error(
      replaced(kGoodRobot, "\"max_velocity_mm_per_s\": 250", "\"max_velocity_deg_per_s\": 250"),
      "joint 2: missing \"max_velocity_mm_per_s\"");
}

TEST(RobotFile, RefusesBadDynamics) {
  expect_error(replaced(kGoodRobot, "\"inertia_kg_m2\": 2", "\"inertia_kg_m2\": 2, \"mass\": 1"),
               "joint 1: dynamics: unknown key \"mass\"");
  expect_error(replaced(kGoodRobot, "\"inertia_kg_m2\": 2", "\"inertia_kg\": 2"),
               "joint 1: dynamics: \"inertia_kg\" is for a prismatic joint");
  expect_error(replaced(kGoodRobot, "\"coulomb_N_m\": 4", "\"coulomb_N_m\": -4"),
               "joint 1: dynamics: \"coulomb_N_m\" must not be negative");
  expect_error(replaced(kGoodRobot, "\"max_effort_N_m\": 50", "\"max_effort_N_m\": \"big\""),
               "\"max_effort_N_m\" must be a number");
  expect_error(replaced(kGoodRobot, "[-0.25, 0, 0.01]", "[-0.25, 0]"),
               "joint 1: dynamics: \"link_com_m\" must be [x, y, z]");
  expect_error(replaced(kGoodRobot, "[-0.25, 0, 0.01]", "[-0.25, 0, \"z\"]"),
               "\"link_com_m\" must hold three finite numbers");
  expect_error(replaced(kGoodRobot, "[0.1, 0.2, 0.25, -0.01, 0.02, 0]", "[0.1, 0.2, 0.25]"),
               "joint 1: dynamics: \"link_inertia_kg_m2\" must be [ixx, iyy, izz, ixy, ixz, iyz]");
  expect_error(
      replaced(kGoodRobot, "[0.1, 0.2, 0.25, -0.01, 0.02, 0]", "[0.1, 0.2, 0.25, 0, 0, null]"),
      "\"link_inertia_kg_m2\" must hold six finite numbers");
  expect_error(replaced(kGoodRobot, "\"dynamics\": {", "\"dynamics\": 3, \"x\": {"),
               "joint 1: dynamics: expected an object");
  expect_error(replaced(kGoodRobot, "\"max_velocity_mm_per_s\": 250",
                        "\"max_velocity_mm_per_s\": 250, \"dynamics\": {\"coulomb_N_m\": 1}"),
               "joint 2: dynamics: \"coulomb_N_m\" is for a revolute joint");
}

// Every shipped robot has top speeds; the PUMAs have the dynamics their simulator needs.
TEST(BuiltinRobots, HaveTopSpeedsAndThePumasDynamics) {
  for (const auto& name : kin::builtin_robot_names()) {
    const kin::RobotModel m = kin::builtin_robot(name);
    for (const kin::Joint& j : m.joints) {
      EXPECT_GT(j.max_velocity, 0.0) << name << " " << j.name;
      if (name == "puma560" || name == "puma260") {
        EXPECT_GT(j.dynamics.inertia, 0.0) << name << " " << j.name;
        EXPECT_GT(j.dynamics.max_effort, 0.0) << name << " " << j.name;
        EXPECT_GT(j.dynamics.viscous_friction, 0.0) << name << " " << j.name;
        EXPECT_GT(j.dynamics.coulomb_friction, 0.0) << name << " " << j.name;
      }
    }
  }
  // The thesis: joint 3 of the Microbo tops out at about 200 mm/s.
  EXPECT_NEAR(kin::builtin_robot("microbo").joints[2].max_velocity, 200_mm, 1e-12);
  // mdl_puma560's link masses.
  const kin::RobotModel puma = kin::builtin_robot("puma560");
  const double masses[6] = {0, 17.4, 4.8, 0.82, 0.34, 0.09};
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(puma.joints[i].dynamics.link_mass_kg, masses[i]);
}

TEST(RobotFile, LoadsFromDiskAndReportsMissingFiles) {
  const auto path = std::filesystem::temp_directory_path() / "rccx_robot_test.json";
  {
    std::ofstream out(path);
    out << kGoodRobot;
  }
  EXPECT_EQ(kin::load_robot_file(path).name, "two");
  std::filesystem::remove(path);
  EXPECT_THROW((void)kin::load_robot_file(path), kin::RobotFileError);
}

TEST(RobotFile, ClosedFormsRefuseChainsOfAnotherShape) {
  kin::RobotModel m = kin::builtin_robot("puma560");
  m.joints[3].dh.alpha_rad = 0.0;
  EXPECT_THROW((void)kin::make_kinematics(m), kin::RobotFileError);
  kin::RobotModel microbo = kin::builtin_robot("microbo");
  microbo.joints[0].dh.a_m = 0.1;
  EXPECT_THROW((void)kin::make_kinematics(microbo), kin::RobotFileError);
  // The same chain served numerically is fine.
  microbo.solver = kin::SolverKind::dh;
  EXPECT_NO_THROW((void)kin::make_kinematics(microbo));
}

}  // namespace

namespace {

TEST(RobotFile, ExtendsAShippedRobotWithItsOwnKeysOverIt) {
  const kin::RobotModel base = kin::builtin_robot("puma560");
  const kin::RobotModel m = kin::parse_robot(
      R"({"extends": "puma560", "name": "puma560_table", "plant": "mujoco",
          // a comment, as in any robot file
          "hardware": {"mujoco": {"substeps": 2}}})",
      "test");
  EXPECT_EQ(m.name, "puma560_table");
  EXPECT_EQ(m.title, base.title);
  EXPECT_EQ(m.plant, kin::Plant::mujoco);
  EXPECT_EQ(m.hardware_json, R"({"mujoco":{"substeps":2}})");
  ASSERT_EQ(m.dof(), base.dof());
  for (std::size_t i = 0; i < m.dof(); ++i) {
    EXPECT_EQ(m.joints[i].dh.a_m, base.joints[i].dh.a_m);
    EXPECT_EQ(m.joints[i].upper, base.joints[i].upper);
    EXPECT_EQ(m.joints[i].dynamics.inertia, base.joints[i].dynamics.inertia);
  }
  // The same kinematics as the robot it extends.
  const auto k = kin::make_kinematics(m), kb = kin::make_kinematics(base);
  const kin::JointVector q = base.ready();
  EXPECT_LT((k->forward(q).p - kb->forward(q).p).norm(), 1e-15);

  // A joint list given replaces the whole list (a merge patch): one joint is a 1-joint robot.
  const kin::RobotModel one = kin::parse_robot(
      R"({"extends": "stanford", "name": "one", "solver": "dh", "joints": [
          {"name": "q1", "type": "revolute", "a_m": 0.1, "alpha_deg": 0, "d_m": 0,
           "theta_deg": 0, "lower_deg": -90, "upper_deg": 90,
           "resolution_deg_per_count": 0.01, "ready_deg": 0, "max_velocity_deg_per_s": 90}]})",
      "test");
  EXPECT_EQ(one.dof(), 1U);

  // What is merged is checked as any file is: an unknown key, a name that is no robot.
  EXPECT_THROW((void)kin::parse_robot(R"({"extends": "puma560", "colour": "red"})", "t"),
               kin::RobotFileError);
  try {
    (void)kin::parse_robot(R"({"extends": "puma600"})", "t");
    ADD_FAILURE() << "an unknown robot was extended";
  } catch (const kin::RobotFileError& e) {
    EXPECT_NE(std::string(e.what()).find("puma560"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("\"extends\""), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)kin::parse_robot(R"({"extends": 3})", "t"), kin::RobotFileError);
}

}  // namespace
