// The rccx command as a user meets it: exit codes, JSON shapes, round trips through the shell.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "rccx/hw/rcu.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/urdf.hpp"
#include "rccx/math/units.hpp"

#include "shell_run.hpp"

namespace {

using nlohmann::json;
using namespace rccx;

using CliRun = rccx::test::ShellRun;

CliRun rccx_cli(const std::string& arguments, bool with_stderr = true) {
  return rccx::test::rccx_run(arguments, with_stderr);
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

TEST(Cli, ThePandaHoldsJoint7WhereToldAndRefusesItElsewhere) {
  const std::string urdf = std::string(RCCX_ROBOTS_DIR) + "/panda.urdf";
  const auto k = kin::make_kinematics(kin::load_urdf(urdf));
  const kin::JointVector q{0.2, -0.4, 0.3, -2.0, 0.5, 1.9, -0.6};
  const std::string T = pose_argument(k->forward(q));
  const CliRun held = rccx_cli(
      "kin ik --urdf " + urdf + " --T " + T + " --redundant -34.3774677 --deg --json", false);
  ASSERT_EQ(held.exit_code, 0) << held.out;
  const json j = json::parse(held.out);
  kin::JointVector got(7);
  for (std::size_t i = 0; i < 7; ++i) got[i] = j["q"][i].get<double>();
  EXPECT_NEAR(got[6], -0.6, 1e-8);
  EXPECT_LT(math::max_abs_difference(k->forward(got), k->forward(q)), 1e-10);
  // Joint 7 outside its limits: unreachable (exit 3) with the reason; a 6-axis arm: exit 2.
  const CliRun beyond = rccx_cli("kin ik --urdf " + urdf + " --T " + T + " --redundant 3.0");
  EXPECT_EQ(beyond.exit_code, 3) << beyond.out;
  EXPECT_NE(beyond.out.find("joint limits"), std::string::npos) << beyond.out;
  const CliRun puma =
      rccx_cli("kin ik --robot puma560 --xyz 0.4,0.1,0.3 --rpy 180deg,0,0 --redundant 0.5");
  EXPECT_EQ(puma.exit_code, 2) << puma.out;
  EXPECT_NE(puma.out.find("--redundant"), std::string::npos) << puma.out;
}

TEST(Cli, KinDefaultsToTheMicroboAsEveryCommand) {
  const CliRun fk = rccx_cli("kin fk 0 0 0.3 0 0 0 --json", false);
  ASSERT_EQ(fk.exit_code, 0) << fk.out;
  EXPECT_EQ(json::parse(fk.out)["robot"], "microbo");
  const CliRun help = rccx_cli("kin ik --help");
  EXPECT_NE(help.out.find("microbo"), std::string::npos) << help.out;
}

TEST(Cli, InverseTakesXyzAndUrdfRpyWithUnitsAsTheSamePoseAsT) {
  // The PUMA's pose of the published zero, turned: URDF's roll 30 deg about x, pitch -20 deg
  // about y, yaw 50 deg about z.
  const math::Transform T{
      math::Rot3::from_urdf_rpy(math::deg_to_rad(30), math::deg_to_rad(-20), math::deg_to_rad(50)),
      {0.45, -0.15005, 0.3}};
  const CliRun by_t =
      rccx_cli("kin ik --robot puma560 --all --json --T " + pose_argument(T), false);
  ASSERT_EQ(by_t.exit_code, 0) << by_t.out;
  for (const char* xyz_rpy : {"--xyz 0.45,-0.15005,0.3 --rpy 30deg,-20deg,50deg",
                              "--xyz 450mm,-150.05mm,300mm --rpy 0.5235987755982988rad,"
                              "-0.3490658503988659,0.8726646259971648"}) {
    const CliRun by_xyz =
        rccx_cli(std::string("kin ik --robot puma560 --all --json ") + xyz_rpy, false);
    ASSERT_EQ(by_xyz.exit_code, 0) << xyz_rpy << "\n" << by_xyz.out;
    const json a = json::parse(by_t.out)["solutions"], b = json::parse(by_xyz.out)["solutions"];
    ASSERT_EQ(a.size(), b.size()) << xyz_rpy;
    for (std::size_t s = 0; s < a.size(); ++s) {
      EXPECT_EQ(a[s]["config"], b[s]["config"]);
      for (std::size_t i = 0; i < 6; ++i) {
        EXPECT_NEAR(a[s]["q"][i].get<double>(), b[s]["q"][i].get<double>(), 1e-9) << xyz_rpy;
      }
    }
  }
  const CliRun help = rccx_cli("kin ik --help");
  for (const char* word : {"--xyz", "--rpy", "URDF", "roll about x", "bare number is rad"}) {
    EXPECT_NE(help.out.find(word), std::string::npos) << word << "\n" << help.out;
  }
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
      {"kin ik --robot puma560 --T 1,0,0,0.5,0,1,0,0,0,0,1", "12 needed"},
      {"kin ik --robot puma560 --T 1,0,0,0.5,0,2,0,0,0,0,1,0", "not a rotation matrix"},
      {"kin ik --robot puma560 --T 1,0,0,0.5,0,1,0,0,0,0,1,0 --config xyz", "use one of"},
      {"kin ik --robot puma560 --T 1,0,0,0.5,0,1,0,0,0,0,1,0 --config lun --near 0,0,0,0,0,0",
       "excludes"},
      {"kin ik --robot puma560 --T 1,0,0,0.5,0,1,0,0,0,0,1,0 --near 0,0", "6 joints, got 2"},
      {"kin ik --robot puma560", "give --T (12 numbers), or --xyz and --rpy"},
      {"kin ik --robot puma560 --T 1,0,0,500,0,1,0,0,0,0,1,0", "from -100 to 100"},
      {"kin ik --xyz 0.3,0.1,0.2", "--xyz requires --rpy"},
      {"kin ik --rpy 0,0,0", "--rpy requires --xyz"},
      {"kin ik --T 1,0,0,0.5,0,1,0,0,0,0,1,0 --xyz 0.3,0.1,0.2 --rpy 0,0,0", "excludes"},
      {"kin ik --xyz 0.3,0.1 --rpy 0,0,0", "--xyz: 2 values given, 3 needed"},
      {"kin ik --xyz 30cm,0.1,0.2 --rpy 0,0,0", "--xyz (x): \"30cm\" is not a length"},
      {"kin ik --xyz 0.3,0.1,200 --rpy 0,0,0", "--xyz (z): \"200\" is out of range"},
      {"kin ik --xyz 0.3,0.1,inf --rpy 0,0,0", "is not a length"},
      {"kin ik --xyz 0.3,0.1,1e400mm --rpy 0,0,0", "too large"},
      // A bare angle is rad: 180 is more than a turn, so a forgotten deg is refused.
      {"kin ik --xyz 0.3,0.1,0.2 --rpy 180,0,0", "--rpy (roll): \"180\" is out of range"},
      {"kin ik --xyz 0.3,0.1,0.2 --rpy 0,0,90grad", "--rpy (yaw): \"90grad\" is not an angle"},
      {"kin fk --robot-file /nonexistent.json 0", "File does not exist"},
      {"kin", "needs a command: fk, ik, robots"},
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

// ---------------------------------------------------------------------------------------------
// The RTC control programs on simulated robots (simulated time: deterministic and fast).

namespace {

/// Runs rccx with `input` on its standard input.
CliRun rccx_cli_with_input(const std::string& arguments, const std::string& input) {
  char path[] = "/tmp/rccx_cli_input_XXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0) return {};
  FILE* f = fdopen(fd, "w");
  std::fputs(input.c_str(), f);
  std::fclose(f);
  CliRun run = rccx_cli(arguments + " < " + path);
  std::remove(path);
  return run;
}

/// Every value printed after " NAME " (the control programs' position lines), in order.
std::vector<double> values_of(const std::string& out, const std::string& name) {
  std::vector<double> values;
  const std::string key = " " + name + " ";
  for (std::size_t at = out.find(key); at != std::string::npos; at = out.find(key, at + 1)) {
    values.push_back(std::stod(out.substr(at + key.size())));
  }
  return values;
}

/// The value printed after "NAME " on the last line that has it (report's position lines).
double last_value_of(const std::string& out, const std::string& name) {
  const auto at = out.rfind(" " + name + " ");
  if (at == std::string::npos) return std::nan("");
  return std::stod(out.substr(at + name.size() + 2));
}

}  // namespace

TEST(CliRtc, ReportPrintsPositionsInDegreesAndMillimetres) {
  const CliRun run = rccx_cli("report --robot microbo --seconds 1 --every 0.25");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 4) << run.out;
  const auto model = kin::builtin_robot("microbo");
  // The ready pose, as the simulated arm starts there.
  EXPECT_NEAR(last_value_of(run.out, model.joints[0].name),
              model.joints[0].ready * 180 / 3.141592653589793, 0.01);
  EXPECT_NEAR(last_value_of(run.out, model.joints[1].name), model.joints[1].ready * 1e3, 0.01);
  EXPECT_NE(run.out.find(" mm"), std::string::npos);
}

TEST(CliRtc, BadPeriodsAndRobotsAreRefusedWithExitCode2) {
  for (const char* args : {"report --period 0.1ms", "report --period 60ms", "report --period fast",
                           "report --robot nosuchrobot", "marsh --push 9:1",
                           "report --period 5ms"}) {  // the Microbo's bus needs 11.2 ms
    const CliRun run = rccx_cli(args);
    EXPECT_EQ(run.exit_code, 2) << args << ": " << run.out;
    EXPECT_NE(run.out.find("error"), std::string::npos) << args << ": " << run.out;
  }
}

TEST(CliRtc, CalibCalibratesAnUncalibratedRobot) {
  const CliRun run = rccx_cli("calib --robot puma560 --uncalibrated");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("ALL JOINTS calibrated"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("  not calibrated"), std::string::npos) << run.out;
}

TEST(CliRtc, LimpTurnsArmPowerOff) {
  const CliRun run = rccx_cli("limp --robot puma260");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("arm power off"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("(power off)"), std::string::npos) << run.out;
}

TEST(CliRtc, MarshLetsAPushedJointMoveAndStay) {
  const auto model = kin::builtin_robot("puma560");
  // 40 N m: more than joint 1's Coulomb friction (26 N m), so the joint moves.
  const CliRun run = rccx_cli("marsh --robot puma560 --seconds 2 --every 0.5 --push 1:40");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  // Four position lines: two while pushed, two after. Joint 1 moved up and then stayed.
  const std::vector<double> theta1 = values_of(run.out, "theta1");
  ASSERT_EQ(theta1.size(), 4U) << run.out;
  EXPECT_GT(theta1[1], theta1[0]) << "joint 1 did not follow the push";
  EXPECT_GT(theta1[2], model.joints[0].ready * 180 / 3.141592653589793 + 0.5) << run.out;
  EXPECT_NEAR(theta1[3], theta1[2], 0.05) << "joint 1 did not stay where it was left";
}

TEST(CliRtc, JointtestMovesAJointFromScriptedCommands) {
  const CliRun run = rccx_cli_with_input(
      "jointtest --robot puma560", "?\nj 2\nv 20\nm 60\nw 3\nx\nO 3\nH\nM 40\nw 3\nx\nzz\nq\n");
  ASSERT_EQ(run.exit_code, 1) << run.out;  // everything done but "zz", which failed
  EXPECT_NE(run.out.find("commands (one per line"), std::string::npos) << "no menu";
  EXPECT_NE(run.out.find("unknown command \"zz\""), std::string::npos) << run.out;
  // The two examinations: joint 2 at 60 then 40 degrees.
  const auto first = run.out.find("  2 theta2");
  ASSERT_NE(first, std::string::npos) << run.out;
  EXPECT_NEAR(std::stod(run.out.substr(first + 11)), 60.0, 0.01) << run.out;
  const auto second = run.out.find("  2 theta2", first + 1);
  ASSERT_NE(second, std::string::npos) << run.out;
  EXPECT_NEAR(std::stod(run.out.substr(second + 11)), 40.0, 0.01) << run.out;
  EXPECT_NE(run.out.find("hand closed, outputs 0x0008"), std::string::npos) << run.out;
}

TEST(CliRtc, JointtestReportsALimitAndCarriesOn) {
  const CliRun run = rccx_cli_with_input("jointtest --robot puma560", "j 1\nm 500\nw 0.1\nq\n");
  EXPECT_EQ(run.exit_code, 1) << run.out;
  EXPECT_NE(run.out.find("commanded outside its limits"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("control restarted"), std::string::npos) << run.out;
}

TEST(CliRtc, CodesListsEveryTerminateCode) {
  const CliRun run = rccx_cli("codes");
  ASSERT_EQ(run.exit_code, 0);
  for (const char* name : {"overrun", "observed_position", "power_failure", "user_interrupt"}) {
    EXPECT_NE(run.out.find(name), std::string::npos) << name;
  }
}

// ---------------------------------------------------------------------------------------------
// The Microbo: the register console and the control programs through its emulated RCU.

TEST(CliRcu, ConsoleReadsAPositionThroughTheHandshake) {
  const auto model = kin::builtin_robot("microbo");
  hw::Rcu reference(model);  // where joint 3's register stands in the ready pose
  const std::int64_t e =
      reference.absolute_counts(2) - std::int64_t{hw::kWorkAreaShift} * reference.work_area(2);
  const CliRun run = rccx_cli_with_input(
      "rcu", "in 5805\nout 5805 04\nin 5805\nstep 0.1\nin 5805\nin 5804\nstep 0.1\nin 5804\n");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  // Status idle; busy (IBE) right after the command; then a byte waiting (OBF); low, high.
  const std::string expected =
      fmt::format("00\n02\n01\n{:02X}\n{:02X}\n", e & 0xff, (e >> 8) & 0xff);
  EXPECT_EQ(run.out, expected);
}

TEST(CliRcu, ABusyJointShowsIbeToTheConsole) {
  // SET TARGET, then a data byte with no time between: the joint has not taken the command,
  // so the status still shows IBE (the byte is lost: RcuHandshake tests count it). After the
  // joint's service time the register is free again.
  const CliRun run =
      rccx_cli_with_input("rcu", "out 5801 0C\nout 5800 10\nin 5801\nstep 0.1\nin 5801\n");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_EQ(run.out, "02\n00\n");
}

TEST(CliRcu, BadLinesSayWhyOnOneLineAndExit1) {
  const CliRun run = rccx_cli_with_input(
      "rcu",
      "in 5900\nout 5800 1FF\nstep -1\nfault 7 encoder_error\nfault 1 gremlins\nbogus\nin 5801\n");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 7) << run.out;  // 6 errors + 1 byte
  EXPECT_NE(run.out.find("5800 to 580B"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("00 to FF"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("the joint must be 1 to 6"), std::string::npos) << run.out;
}

TEST(CliRtc, TheMicroboIsTheDefaultRobotAndCalibratesThroughItsRcu) {
  const CliRun run = rccx_cli("calib --uncalibrated");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("Microbo Ecureuil"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("ALL JOINTS calibrated"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("not calibrated\n  "), std::string::npos) << run.out;
}

TEST(CliRtc, JointtestSetsAndExaminesMicroboMotorParameters) {
  const CliRun run = rccx_cli_with_input("jointtest", "j 3\nX\nk 40\nX\nk 300\nq\n");
  ASSERT_EQ(run.exit_code, 1) << run.out;  // "k 300" failed
  const auto first = run.out.find("joint 3 motor parameters:");
  const auto second = run.out.find("joint 3 motor parameters:", first + 1);
  ASSERT_NE(second, std::string::npos) << run.out;
  // Parameter 6 (dynamic integration) reads back as 40 from the joint micro's RAM.
  std::istringstream after(run.out.substr(second + 25));
  std::vector<int> p(16);
  for (int& b : p) after >> b;
  EXPECT_EQ(p[5], 40) << run.out;
  EXPECT_NE(run.out.find("k: the value: \"300\" is out of range"), std::string::npos) << run.out;
}

TEST(CliRtc, MarshOnTheMicroboLetsAPushedJointStayWhereItIsLeft) {
  // Joint 3 (d3) pushed with 60 N for the first second: it moves out, then stays, because zero
  // gravity turns the joint law's integration off (thesis 4.5.4.4) and the target follows it.
  const CliRun run = rccx_cli("marsh --seconds 2 --every 0.5 --push 3:60");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const std::vector<double> d3 = values_of(run.out, "d3");
  ASSERT_EQ(d3.size(), 4U) << run.out;
  const double ready_mm = kin::builtin_robot("microbo").joints[2].ready * 1e3;
  EXPECT_GT(d3[2], ready_mm + 0.2) << "d3 did not follow the push";
  EXPECT_NEAR(d3[3], d3[2], 0.01) << "d3 did not stay where it was left";
}

namespace {

// `rccx db`: put, show, export, import into another file, export again: the same text, so
// positions round-trip exactly through JSON (and version control); refusals exit non-zero.
TEST(Cli, DbExportThenImportRoundTripsExactly) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("rccx_cli_db_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string a = (dir / "a.db").string(), b = (dir / "b.db").string();
  const std::string e1 = (dir / "a.json").string(), e2 = (dir / "b.json").string();
  const math::Transform pick{math::Rot3::rot_x(3.14159265358979) * math::Rot3::rot_z(0.1),
                             {0.325, 0.15, 0.25}};
  ASSERT_EQ(rccx_cli("db --db " + a + " put --robot microbo PICK --T " + pose_argument(pick), true)
                .exit_code,
            0);
  const CliRun show = rccx_cli("db --db " + a + " show --robot microbo PICK", true);
  EXPECT_EQ(show.exit_code, 0);
  EXPECT_NE(show.out.find("x 325.000 y 150.000 z 250.000 mm"), std::string::npos) << show.out;
  EXPECT_NE(rccx_cli("db --db " + a + " put --robot microbo BAD --T 1,0,0,0,0,1,0,0,0,0,2,0", true)
                .exit_code,
            0);
  ASSERT_EQ(rccx_cli("db --db " + a + " export " + e1, true).exit_code, 0);
  ASSERT_EQ(rccx_cli("db --db " + b + " import " + e1, true).exit_code, 0);
  ASSERT_EQ(rccx_cli("db --db " + b + " export " + e2, true).exit_code, 0);
  std::ifstream f1(e1), f2(e2);
  const std::string s1((std::istreambuf_iterator<char>(f1)), {});
  const std::string s2((std::istreambuf_iterator<char>(f2)), {});
  EXPECT_FALSE(s1.empty());
  EXPECT_EQ(s1, s2);
  const json j = json::parse(s1);
  ASSERT_EQ(j["transforms"].size(), 1u);
  for (std::size_t i = 0; i < 12; ++i) {
    EXPECT_EQ(j["transforms"][0]["T_rows_m"][i].get<double>(), pick.rows()[i]);  // exact
  }
  EXPECT_NE(rccx_cli("db --db " + (dir / "missing.db").string() + " list", true).exit_code, 0);
  std::filesystem::remove_all(dir);
}

}  // namespace
