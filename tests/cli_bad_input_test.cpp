// The bad-input table of the commands that run robots and kinematics (the database and the
// consoles have their own): each row is an abuse of an argument, a file or the environment,
// with the exit code and the words of the message it must get, and what it must not leave.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "shell_run.hpp"

namespace {

namespace fs = std::filesystem;

using CommandRun = rccx::test::ShellRun;

CommandRun run(const std::string& command) {
  return rccx::test::run_shell(command + " 2>&1");
}

struct Row {
  std::string environment;  ///< NAME=VALUE ... before the command, or empty
  std::string arguments;
  int exit_code;
  std::string says;            ///< a part of the message
  std::string must_not_exist;  ///< a file the command must not leave (relative to the dir)
};

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rccx-bad-input-" + std::to_string(getpid()));
    fs::create_directories(dir_);
    write("huge.json", robot_with(R"("a_m": 1e400)"));
    write("long.json", robot_with(R"("a_m": 1e9)"));
    write("unknown_key.json", robot_with(R"("a_m": 0, "upper_mm": 3)"));
    write("latin1.json", std::string(R"({"name": "caf)") + "\xe9" + R"(", "title": "t"})");
    write("not_json.json", "name = puma\n");
    write("empty.json", "");
    ::mkfifo(path("fifo.json").c_str(), 0600);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// A one-joint robot file whose joint has `joint_keys` for its DH a (and maybe more).
  static std::string robot_with(const std::string& joint_keys) {
    return fmt::format(
        R"({{"name": "r1", "title": "t", "source": "s", "solver": "dh", "joints": [{{"name": "j1",
        "type": "revolute", {}, "alpha_deg": 0, "lower_deg": -90, "upper_deg": 90,
        "resolution_deg_per_count": 0.01, "ready_deg": 0, "max_velocity_deg_per_s": 90}}]}})",
        joint_keys);
  }
  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  void check(const std::vector<Row>& rows) {
    for (const Row& row : rows) {
      std::string args = row.arguments;
      for (std::size_t at; (at = args.find("DIR/")) != std::string::npos;) {
        args.replace(at, 4, dir_.string() + "/");
      }
      std::string env = row.environment;
      for (std::size_t at; (at = env.find("DIR/")) != std::string::npos;) {
        env.replace(at, 4, dir_.string() + "/");
      }
      // timeout: a command that hangs fails its row (exit 124) rather than the whole run.
      const std::string command = "timeout -k 5 60 " + (env.empty() ? "" : "env " + env + " ") +
                                  std::string(RCCX_CLI) + " " + args;
      const CommandRun r = run(command);
      EXPECT_EQ(r.exit_code, row.exit_code) << command << "\n" << r.out;
      EXPECT_NE(r.out.find(row.says), std::string::npos)
          << command << "\nshould say: " << row.says << "\nsaid: " << r.out;
      if (row.exit_code == 2) {
        EXPECT_EQ(r.out.rfind("error: ", 0), 0U) << command << ": one wording\n" << r.out;
      }
      if (!row.must_not_exist.empty()) {
        EXPECT_FALSE(fs::exists(dir_ / row.must_not_exist)) << command;
      }
    }
  }
  fs::path dir_;
};

TEST_F(BadInput, Kinematics) {
  check({
      {"", "kin fk --robot puma560 0 0 0 0 0 5abc", 2, "\"5abc\" is not a number", ""},
      {"", "kin fk --robot puma560 0 0 0 0 0 ''", 2, "a number is missing", ""},
      {"", "kin fk --robot puma560 0 0 0 0 0 inf", 2, "\"inf\" is not a number", ""},
      {"", "kin fk --robot puma560 0 0 0 0 0 nan", 2, "\"nan\" is not a number", ""},
      {"", "kin fk --robot puma560 0 0 0 0 0 1e400", 2, "too large", ""},
      {"", "kin fk --robot puma560 0 0 0 0 0 0x10", 2, "not a number", ""},
      {"", "kin fk --robot puma560 0 0 0 0 0 1e200", 2, "out of range", ""},
      {"", "kin fk --robot puma560 0 0", 2, "6 joints, got 2", ""},
      {"", "kin fk --robot pmua560 0 0 0 0 0 0", 2, "known robots", ""},
      // A pose: finite, within 100 m (a larger one is a typo, not "unreachable"), units named.
      {"", "kin ik --T 1,0,0,1e308,0,1,0,0,0,0,1,0", 2, "from -100 to 100", ""},
      {"", "kin ik --xyz 1e308,0,0 --rpy 0,0,0", 2, "--xyz (x): \"1e308\" is out of range", ""},
      {"", "kin ik --xyz 0,0,0 --rpy 0,0,inf", 2, "--rpy (yaw): \"inf\" is not an angle", ""},
      {"", "kin ik --xyz 0,0,0 --rpy ''", 2, "empty", ""},
      {"", "kin fk --robot-file DIR/huge.json 0", 2, "not valid JSON", ""},
      {"", "kin fk --robot-file DIR/long.json 0", 2, "at most 100", ""},
      {"", "kin fk --robot-file DIR/unknown_key.json 0", 2, "unknown key \"upper_mm\"", ""},
      {"", "kin fk --robot-file DIR/latin1.json 0", 2, "ill-formed UTF-8", ""},
      {"", "kin fk --robot-file DIR/not_json.json 0", 2, "not valid JSON", ""},
      {"", "kin fk --robot-file DIR/empty.json 0", 2, "not valid JSON", ""},
      {"", "kin fk --robot-file DIR/ 0", 2, "directory", ""},
      {"", "kin fk --robot-file DIR/missing.json 0", 2, "does not exist", ""},
      // A named pipe nobody writes to and an endless device: refused at once, no wait.
      {"", "kin fk --robot-file DIR/fifo.json 0", 2, "not a regular file", ""},
      {"", "kin fk --robot-file /dev/zero 0", 2, "not a regular file", ""},
      {"", "kin ik --robot puma560 --T 1,0,0,0.4,0,1,0,0,0,0,1", 2, "11 numbers given, 12 needed",
       ""},
      {"", "kin ik --robot puma560 --T 1,0,0,0.4,0,1,0,0,0,0,1,0,1", 2, "13 numbers given", ""},
      {"", "kin ik --robot puma560 --T 1,0,0,nan,0,1,0,0,0,0,1,0", 2, "\"nan\" is not a number",
       ""},
      {"", "kin ik --robot puma560 --T 1,0,0,0.4,,1,0,0,0,0,1,0", 2, "a number is missing", ""},
      {"", "kin ik --robot puma560 --T 1,0,0,0.4,0,2,0,0,0,0,1,0", 2, "not a rotation matrix", ""},
      {"",
       "kin ik --robot puma560 --T 1,0,0,0.4521,0,1,0,-0.15005,0,0,1,0.4318 --near 1e200,0,0,0,0,0",
       2, "out of range", ""},
      {"", "kin ik --robot puma560 --T 1,0,0,0.4521,0,1,0,-0.15005,0,0,1,0.4318 --near 0,0", 2,
       "6 joints, got 2", ""},
      {"", "kin ik --robot puma560 --T 1,0,0,0.4521,0,1,0,-0.15005,0,0,1,0.4318 --config xyz", 2,
       "use one of", ""},
      {"", "kin ik --robot puma560 --T 1,0,0,9,0,1,0,0,0,0,1,0", 3, "out of reach", ""},
      // The same commands well formed: the table can tell.
      {"", "kin fk --robot puma560 0 -0.5 0 0 0 0", 0, "T6", ""},
      {"", "kin ik --robot puma560 --T 1,0,0,0.4521,0,1,0,-0.15005,0,0,1,0.4318 --near 0,0,0,0,0,0",
       0, "configuration", ""},
  });
}

TEST_F(BadInput, ControlPrograms) {
  check({
      {"", "report --seconds inf", 2, "--seconds: \"inf\" is not a duration", ""},
      {"", "report --seconds -1", 2, "--seconds: \"-1\" is out of range", ""},
      {"", "report --seconds 0", 2, "out of range", ""},
      {"", "report --seconds 1e7", 2, "out of range", ""},
      {"", "report --seconds ''", 2, "a duration is missing", ""},
      {"", "report --seconds 2x", 2, "not a duration", ""},
      {"", "report --every 1ms", 2, "shorter than the sample period", ""},
      {"", "report --robot puma560 --period 1ms --every 0.5ms", 2, "shorter than the sample period",
       ""},
      {"", "report --every nan", 2, "not a duration", ""},
      {"", "report --period 0.1ms", 2, "0.25 to 56 ms", ""},
      {"", "report --period 100ms", 2, "0.25 to 56 ms", ""},
      {"", "report --period 1e400", 2, "out of range", ""},
      {"", "report --period abc", 2, "not a duration", ""},
      {"", "report --period 5ms", 2, "--period", ""},  // the Microbo's bus needs ~10 ms
      {"", "report --robot nosuch", 2, "known robots", ""},
      {"", "report --log DIR/missing/x.csv --seconds 0.1", 2, "--log", "missing"},
      {"", "report --log DIR/ --seconds 0.1", 2, "directory", ""},
      {"RCCX_LOG=DIR/missing/x.csv", "report --seconds 0.1", 2, "RCCX_LOG", "missing"},
      {"", "report extra", 2, "extra", ""},
      // An empty value is a variable that was not set, not the default.
      {"", "report --period '' --seconds 0.1", 2, "--period: \"\" is empty", ""},
      {"", "report --log '' --seconds 0.1", 2, "--log: \"\" is empty", ""},
      {"", "jointtest --log '' < /dev/null", 2, "--log: \"\" is empty", ""},
      {"", "teach --db '' < /dev/null", 2, "--db: \"\" is empty", ""},
      {"", "teach --db DIR/ < /dev/null", 2, "is a directory; name a database file", ""},
      {"RCCX_DB=/dev/null", "teach < /dev/null", 2, "not a regular file", ""},
      // A bad robot creates no database.
      {"", "teach --robot nosuch --db DIR/t.db < /dev/null", 2, "known robots", "t.db"},
      {"", "teach --robot-file DIR/empty.json --db DIR/t.db < /dev/null", 2, "not valid JSON",
       "t.db"},
      {"", "calib --timeout inf", 2, "--timeout", ""},
      {"", "calib --timeout 0", 2, "--timeout", ""},
      {"", "marsh --push 3:1e400", 2, "too large", ""},
      {"", "marsh --push 3.5:10", 2, "not a joint", ""},
      {"", "marsh --push 9:10", 2, "its joints are 1 to 6", ""},
      {"", "marsh --push 3", 2, "JOINT:EFFORT", ""},
      {"", "marsh --push 3:abc", 2, "not a number", ""},
      {"", "marsh --push :", 2, "missing", ""},
      {"", "limp --seconds 3", 2, "--seconds", ""},
      {"", "nosuch", 2, "subcommand", ""},
      {"", "report --seconds 0.2 --every 0.1", 0, "theta", ""},
      {"", "calib --robot puma560 --uncalibrated --timeout 60", 0, "ALL JOINTS", ""},
      {"", "cell-load --robots 0", 2, "--robots", ""},
      {"", "cell-load --robots 2 --period 0.1ms", 2, "--period", ""},
      {"", "cell-load --robots 2 --seconds inf", 2, "--seconds", ""},
      {"", "cell-load --robots 2 --robot microbo", 2, "puma560 or puma260", ""},
      {"", "cell-load --robots 2 --spacing 0.5", 2, "--spacing", ""},
      {"", "cell-load --robots 3 --seconds 0.3", 0, "cycle compute over 30", ""},
  });
}

// A log is written through a symbolic link (the link stays) and into a named pipe (never
// replaced by a regular file: `--log /dev/null` as root must not replace /dev/null).
TEST_F(BadInput, ALogThroughALinkOrIntoAPipeLeavesItWhatItIs) {
  fs::create_symlink("target.csv", dir_ / "link.csv");
  const std::string rccx = "timeout -k 5 60 " + std::string(RCCX_CLI);
  const CommandRun linked = run(rccx + " report --seconds 0.1 --log " + path("link.csv"));
  EXPECT_EQ(linked.exit_code, 0) << linked.out;
  EXPECT_TRUE(fs::is_symlink(dir_ / "link.csv"));
  EXPECT_NE(std::ifstream(dir_ / "target.csv").peek(), EOF) << "the log is not where the link goes";
  const CommandRun piped = run(rccx + " report --seconds 0.1 --log " + path("fifo.json"));
  EXPECT_EQ(piped.exit_code, 2) << piped.out;
  EXPECT_NE(piped.out.find("no process reads"), std::string::npos) << piped.out;
  EXPECT_TRUE(fs::is_fifo(dir_ / "fifo.json")) << "the pipe was replaced by a regular file";
  const CommandRun out = run(rccx + " report --seconds 0.1 --log /dev/stdout");
  EXPECT_EQ(out.exit_code, 0) << out.out;
  EXPECT_NE(out.out.find("t,seg,q1"), std::string::npos) << out.out;
  EXPECT_TRUE(fs::is_character_file("/dev/stdout") || fs::is_fifo("/dev/stdout"));
}

}  // namespace
