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
      {"", "report --seconds ''", 2, "--seconds: \"\" is empty", ""},
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
      {"", "nosuch", 2, "unknown command 'nosuch'", ""},
      {"", "report --seconds 0.2 --every 0.1", 0, "theta", ""},
      {"", "calib --robot puma560 --uncalibrated --timeout 60", 0, "ALL JOINTS", ""},
      {"", "cell-load --robots 0", 2, "--robots", ""},
      {"", "cell-load --robots 2 --period 0.1ms", 2, "--period", ""},
      {"", "cell-load --robots 2 --seconds inf", 2, "--seconds", ""},
      {"", "cell-load --robots 2 --robot microbo", 2, "puma560 or puma260", ""},
      {"", "cell-load --robots 2 --spacing 0.5", 2, "--spacing", ""},
      {"", "cell-load --robots 3 --seconds 0.3", 0, "cycle compute over 30", ""},
      // A log that cannot be written (a full disk: /dev/full) is lost: the run fails (exit 1).
      {"", "report --seconds 0.2 --log /dev/full", 1, "the sample log is lost", ""},
      {"RCCX_LOG=/dev/full", "report --seconds 0.2", 1, "the sample log is lost", ""},
      {"", "jointtest --log /dev/full < /dev/null", 1, "the sample log is lost", ""},
      {"RCCX_LOG=/dev/full", "jointtest < /dev/null", 1, "the sample log is lost", ""},
      {"RCCX_LOG=/dev/full", "teach --db DIR/t.db < /dev/null", 1, "the sample log is lost", ""},
      {"RCCX_LOG=/dev/full", "view --robot microbo --port 0 --fast --seconds 0.5", 1,
       "the sample log is lost", ""},
  });
}

// Unknown words: the word, the nearest known one at that level (or the list), and the help of
// the command it was given to.
TEST_F(BadInput, UnknownWords) {
  check({
      {"", "rprt", 2, "unknown command 'rprt'; did you mean 'report'?", ""},
      {"", "rprt", 2, "Run `rccx --help`", ""},
      {"", "kin fx", 2, "unknown command 'fx'; did you mean 'fk'?", ""},
      {"", "kin fx", 2, "Run `rccx kin --help`", ""},
      {"", "kin xyzzy", 2, "the commands of `rccx kin` are fk, ik, robots", ""},
      {"", "db lst", 2, "did you mean 'list'?", ""},
      {"", "cell shw", 2, "did you mean 'show'?", ""},
      {"", "completion bsh", 2, "did you mean 'bash'?", ""},
      {"", "kin", 2, "`rccx kin` needs a command: fk, ik, robots", ""},
      {"", "report --secnds 2", 2,
       "unknown option '--secnds' for `rccx report`; did you mean "
       "'--seconds'?",
       ""},
      {"", "report --secnds 2", 2, "Run `rccx report --help`", ""},
      {"", "kin ik --nera 0 --T 1", 2, "did you mean '--near'?", ""},
      {"", "db list --rbot microbo", 2, "did you mean '--robot'?", ""},
      {"", "db list --rbot microbo", 2, "Run `rccx db list --help`", ""},
      {"", "view --prot 0", 2, "did you mean '--port'?", ""},
      {"", "report --zzzzzzz", 2, "unknown option '--zzzzzzz' for `rccx report`\nRun", ""},
      {"", "limp --seconds 3", 2, "unknown option '--seconds' for `rccx limp`", ""},
      // CLI11's own errors point at the command's help too.
      {"", "kin fk --robot", 2, "Run `rccx kin fk --help`", ""},
  });
}

// An empty value is refused for every option of every command, before anything runs.
TEST_F(BadInput, EmptyValues) {
  check({
      {"", "kin ik --robot puma560 --T 1,0,0,0.4521,0,1,0,-0.15005,0,0,1,0.4318 --near ''", 2,
       "--near: \"\" is empty; give a value", ""},
      {"", "kin ik --robot puma560 --T 1,0,0,0.4521,0,1,0,-0.15005,0,0,1,0.4318 --config ''", 2,
       "--config: \"\" is empty", ""},
      {"", "kin fk --robot '' 0", 2, "--robot: \"\" is empty", ""},
      {"", "kin fk --robot-file= 0", 2, "--robot-file: \"\" is empty", ""},
      {"", "db put --robot microbo P --T 1,0,0,0,0,1,0,0,0,0,1,0 --config '' --db DIR/e.db", 2,
       "--config: \"\" is empty", "e.db"},
      {"", "db put --robot microbo P --T 1,0,0,0,0,1,0,0,0,0,1,0 --note '' --db DIR/e.db", 2,
       "--note: \"\" is empty", "e.db"},
      {"", "db --db '' list", 2, "--db: \"\" is empty", ""},
      {"", "db list --db ''", 2, "--db: \"\" is empty", ""},
      {"", "plot DIR/empty.json -o out.svg --title ''", 2, "--title: \"\" is empty", ""},
      {"", "view --address ''", 2, "--address: \"\" is empty", ""},
      {"", "view --port ''", 2, "--port: \"\" is empty", ""},
      {"", "marsh --push ''", 2, "--push: \"\" is empty", ""},
      {"", "cell-load --robot ''", 2, "--robot: \"\" is empty", ""},
  });
}

// One log a robot of a cell, named by its name in the cell: three robots of one model, three
// files, each with its own header and rows.
TEST_F(BadInput, ACellLogsOneFileARobotNamedByItsName) {
  const std::string command = fmt::format(
      "timeout -k 5 60 env RCCX_LOG={} {} cell-load --robots 3 "
      "--period 10ms --seconds 0.3",
      path("run.csv"), RCCX_CLI);
  const CommandRun r = run(command);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir_)) {
    const std::string f = e.path().filename().string();
    if (f.starts_with("run")) names.push_back(f);
  }
  ASSERT_EQ(names.size(), 3U) << "three robots, three logs";
  std::vector<std::string> headers;
  for (const std::string& f : names) {
    std::ifstream in(dir_ / f);
    std::string header;
    std::getline(in, header);
    const std::string name = f.substr(4, f.size() - 8);  // run-NAME.csv
    EXPECT_NE(header.find(" name=" + name + " "), std::string::npos) << f << ": " << header;
    EXPECT_NE(header.find("robot=puma560 "), std::string::npos) << header;
    int rows = 0;
    for (std::string line; std::getline(in, line);) ++rows;
    // The column line and a row a 10 ms sample (and the few samples of the other robots' close).
    EXPECT_NEAR(rows, 1 + 30, 3) << f;
  }
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
