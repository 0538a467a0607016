// The rccx command as a user meets it: exit codes, JSON shapes, round trips through the shell.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "rccx/kinematics/kinematics.hpp"

namespace {

using nlohmann::json;
using namespace rccx;

struct CliRun {
  int exit_code = -1;
  std::string out;
};

CliRun rccx_cli(const std::string& arguments, bool with_stderr = true) {
  const std::string command =
      std::string(RCCX_CLI) + " " + arguments + (with_stderr ? " 2>&1" : " 2>/dev/null");
  CliRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe) != nullptr) {
    run.out += buffer.data();
  }
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

std::string pose_argument(const math::Transform& T) {
  std::string s;
  for (double v : T.rows()) s += fmt::format("{}{}", s.empty() ? "" : ",", v);
  return s;
}

TEST(Cli, ForwardJsonGivesThePublishedZeroPose) {
  const CliRun run = rccx_cli("kin fk --robot puma560 0 0 0 0 0 0 --json", false);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const json j = json::parse(run.out);
  EXPECT_EQ(j["robot"], "puma560");
  ASSERT_EQ(j["q"].size(), 6u);
  ASSERT_EQ(j["T"].size(), 4u);
  EXPECT_NEAR(j["T"][0][3].get<double>(), 0.4521, 1e-15);
  EXPECT_NEAR(j["T"][1][3].get<double>(), -0.15005, 1e-15);
  EXPECT_NEAR(j["T"][2][3].get<double>(), 0.4318, 1e-15);
  EXPECT_EQ(j["T"][3], json({0.0, 0.0, 0.0, 1.0}));
}

TEST(Cli, ForwardTakesNegativeValuesAndDegrees) {
  const CliRun rad =
      rccx_cli("kin fk --robot microbo -0.5 0.25 0.3 1.5707963267948966 -2 0 --json", false);
  const CliRun deg = rccx_cli(
      "kin fk --robot microbo --deg --json -28.64788975654116 0.25 0.3 90 "
      "-114.59155902616465 0",
      false);
  ASSERT_EQ(rad.exit_code, 0) << rad.out;
  ASSERT_EQ(deg.exit_code, 0) << deg.out;
  const json a = json::parse(rad.out)["T"], b = json::parse(deg.out)["T"];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(a[r][c].get<double>(), b[r][c].get<double>(), 1e-14);
  }
}

TEST(Cli, InverseRoundTripsEveryConfiguration) {
  const auto k = kin::make_kinematics(kin::builtin_robot("puma560"));
  const kin::JointVector q{0.3, 0.7, -2.6, 0.4, 0.9, -0.5};
  const std::string T = pose_argument(k->forward(q));

  const CliRun one = rccx_cli("kin ik --robot puma560 --T " + T + " --config run --json", false);
  ASSERT_EQ(one.exit_code, 0) << one.out;
  const json j = json::parse(one.out);
  EXPECT_EQ(j["config"], "run");
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(j["q"][i].get<double>(), q[i], 1e-12);

  const CliRun all = rccx_cli("kin ik --robot puma560 --T " + T + " --all --json", false);
  ASSERT_EQ(all.exit_code, 0) << all.out;
  const json solutions = json::parse(all.out)["solutions"];
  EXPECT_EQ(solutions.size(), k->inverse_all(k->forward(q)).count);
  for (const json& s : solutions) {
    kin::JointVector sq(6);
    for (std::size_t i = 0; i < 6; ++i) sq[i] = s["q"][i].get<double>();
    EXPECT_LT(math::max_abs_difference(k->forward(sq), k->forward(q)), 1e-10);
    EXPECT_EQ(s["config"].get<std::string>(), k->configuration_name(k->configuration_of(sq)));
  }

  const CliRun near = rccx_cli(
      "kin ik --robot puma560 --T " + T + " --near=0.3,-0.4,-0.4,2,0.4,-2.4 --json", false);
  ASSERT_EQ(near.exit_code, 0) << near.out;
  EXPECT_EQ(json::parse(near.out)["config"], "rdn");
}

TEST(Cli, UnreachableExitsThreeWithAReason) {
  const CliRun run = rccx_cli("kin ik --robot puma560 --T 1,0,0,2,0,1,0,0,0,0,1,0");
  EXPECT_EQ(run.exit_code, 3);
  EXPECT_NE(run.out.find("out of reach"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("nan"), std::string::npos);
  const CliRun limits = rccx_cli("kin ik --robot microbo --T 1,0,0,0.6,0,-1,0,0,0,0,-1,0.25");
  EXPECT_EQ(limits.exit_code, 3);
  EXPECT_NE(limits.out.find("joint limits"), std::string::npos) << limits.out;
}

TEST(Cli, BadArgumentsExitTwoAndSayWhatToDo) {
  const char* cases[][2] = {
      {"kin fk --robot puma560 0 0", "6 joints, got 2"},
      {"kin fk --robot nosuch 0 0 0 0 0 0", "known robots"},
      {"kin ik --robot puma560 --T 1,0,0,0.5,0,1,0,0,0,0,1", "12 numbers"},
      {"kin ik --robot puma560 --T 1,0,0,0.5,0,2,0,0,0,0,1,0", "not a rotation matrix"},
      {"kin ik --robot puma560 --T 1,0,0,0.5,0,1,0,0,0,0,1,0 --config xyz", "use one of"},
      {"kin ik --robot puma560 --T 1,0,0,0.5,0,1,0,0,0,0,1,0 --config lun --near 0,0,0,0,0,0",
       "excludes"},
      {"kin ik --robot puma560 --T 1,0,0,0.5,0,1,0,0,0,0,1,0 --near 0,0", "6 joints, got 2"},
      {"kin ik --robot puma560", "--T is required"},
      {"kin fk --robot-file /nonexistent.json 0", "File does not exist"},
      {"kin", "subcommand"},
  };
  for (const auto& c : cases) {
    const CliRun run = rccx_cli(c[0]);
    EXPECT_EQ(run.exit_code, 2) << c[0] << "\n" << run.out;
    EXPECT_NE(run.out.find(c[1]), std::string::npos) << c[0] << "\n" << run.out;
  }
}

TEST(Cli, HelpDescribesOptionsWithUnits) {
  const CliRun top = rccx_cli("--help");
  EXPECT_EQ(top.exit_code, 0);
  EXPECT_NE(top.out.find("kin"), std::string::npos);
  const CliRun ik = rccx_cli("kin ik --help");
  EXPECT_EQ(ik.exit_code, 0);
  for (const char* word : {"--T", "--config", "--near", "--all", "--json", "in m", "rad"}) {
    EXPECT_NE(ik.out.find(word), std::string::npos) << word;
  }
  const CliRun fk = rccx_cli("kin fk --help");
  EXPECT_NE(fk.out.find("rad or m"), std::string::npos) << fk.out;
}

TEST(Cli, RobotsListsJointsAndLimits) {
  const CliRun run = rccx_cli("kin robots --json", false);
  ASSERT_EQ(run.exit_code, 0);
  const json robots = json::parse(run.out);
  ASSERT_EQ(robots.size(), kin::builtin_robot_names().size());
  for (const json& r : robots) {
    const kin::RobotModel m = kin::builtin_robot(r["name"].get<std::string>());
    ASSERT_EQ(r["joints"].size(), m.dof());
    for (std::size_t i = 0; i < m.dof(); ++i) {
      EXPECT_EQ(r["joints"][i]["lower"].get<double>(), m.joints[i].lower);
      EXPECT_EQ(r["joints"][i]["type"], std::string(kin::to_string(m.joints[i].type)));
    }
  }
  const CliRun text = rccx_cli("kin robots");
  EXPECT_NE(text.out.find("prismatic"), std::string::npos);
  EXPECT_NE(text.out.find("deg"), std::string::npos);
}

}  // namespace
