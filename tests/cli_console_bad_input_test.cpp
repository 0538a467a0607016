// The consoles (rccx teach, jointtest, rcu) fed bad lines on stdin, table-driven: each run's exit
// code, a message that says why, and that the refused line moved nothing.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "shell_run.hpp"

namespace {

using Run = rccx::test::ShellRun;  // stdout and stderr

/// rccx ARGUMENTS with `input` on stdin.
Run rccx_with_input(const std::string& arguments, const std::string& input) {
  char path[] = "/tmp/rccx_console_input_XXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0) return {};
  FILE* f = fdopen(fd, "w");
  std::fwrite(input.data(), 1, input.size(), f);
  std::fclose(f);
  const std::string command = std::string(RCCX_CLI) + " " + arguments + " < " + path + " 2>&1";
  const rccx::test::ShellRun r = rccx::test::run_shell(command);
  std::remove(path);
  return r;
}

struct Case {
  const char* arguments;
  std::string input;
  int exit_code;
  std::vector<const char*> says;      ///< substrings of the output
  std::vector<const char*> not_says;  ///< substrings that must not appear
};

class TempFile {
 public:
  TempFile()
      : path_(std::filesystem::temp_directory_path() /
              fmt::format("rccx_console_{}_{}.db", ::getpid(), counter_++)) {}
  ~TempFile() { std::filesystem::remove(path_); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  [[nodiscard]] std::string path() const { return path_.string(); }

 private:
  static inline int counter_ = 0;
  std::filesystem::path path_;
};

void check(const Case& c, const Run& run) {
  SCOPED_TRACE(fmt::format("rccx {} <<< {:?}", c.arguments, c.input));
  EXPECT_EQ(run.exit_code, c.exit_code) << run.out;
  for (const char* s : c.says)
    EXPECT_NE(run.out.find(s), std::string::npos) << s << "\n" << run.out;
  for (const char* s : c.not_says) {
    EXPECT_EQ(run.out.find(s), std::string::npos) << s << "\n" << run.out;
  }
}

TEST(CliConsole, TeachRefusesBadLinesMovesNothingAndExits1) {
  // puma560 joint 1 stands at 0 deg in the ready pose: the last xd shows whether it moved.
  const std::vector<Case> cases = {
      {"teach --robot puma560",
       "m 1.5 10\nxd\ne\n",
       1,
       {"\"1.5\" is not a joint of this robot", "joints 0.000deg", "1 command failed"},
       {}},
      {"teach --robot puma560",
       "m 1 5abc\nxd\ne\n",
       1,
       {"\"5abc\" is not a number", "joints 0.000deg"},
       {}},
      {"teach --robot puma560",
       "m 1 500\nxd\ne\n",
       1,
       {"from -160 to 160 deg", "joints 0.000deg"},
       {}},
      {"teach --robot puma560",
       "m 1 10 20\nxd\ne\n",
       1,
       {"one word too many", "joints 0.000deg"},
       {}},
      {"teach --robot puma560",
       "p\ns 1e308\nrz+\nq\nxd\ne\n",
       1,
       {"from 0.001 to 90 deg or mm", "joints 0.000deg"},
       {}},
      {"teach --robot puma560",
       "p\ns 90\n1+\n1+\nq\nxd\ne\n",
       1,
       {"beyond its upper limit 160.000 deg", "joints 89.9"},
       {}},
      {"teach --robot puma560",
       "push 1 1 1e5\npush 1 nan 1\ne\n",
       1,
       {"from 0.001 to 600 s", "is not a number"},
       {}},
      {"teach --robot puma560",
       "save PICK UP\nsave P/Q\ne\n",
       1,
       {"\"UP\" is one word too many", "save: the name"},
       {"saved"}},
      {"teach --robot puma560", "bogus\ne\n", 1, {"unknown command \"bogus\""}, {}},
      // Control ends (the arm pushed past its speed limit): said at once, motion refused after.
      {"teach --robot puma560",
       "Z\npush 1 1000 1\nm 1 10\nh\ne\n",
       1,
       {"control has ended (observed_velocity", "motion commands are refused; e exits",
        "rccx teach: control ended"},
       {"the arm holds", "hand open"}},
      // Everything done: 0.
      {"teach --robot puma560", "m 1 10\nxd\ne\n", 0, {"joints 9.9"}, {"error"}},
      {"teach --robot puma560",
       "m 1 10" + std::string(5000, ' ') + "5\nxd\ne\n",
       1,
       {"refused whole", "joints 0.0"},
       {}},
  };
  for (const Case& c : cases) {
    const TempFile db;
    check(c, rccx_with_input(fmt::format("{} --db {}", c.arguments, db.path()), c.input));
  }
}

TEST(CliConsole, TeachCreatesTheDatabaseAtTheFirstSaveOnly) {
  const TempFile db;
  namespace fs = std::filesystem;
  // Nothing saved (a refused save included): no file, here or as ./rccx.db.
  check({"teach", "", 1, {"save: the name"}, {}},
        rccx_with_input("teach --db " + db.path(), "m 1 10\nsave A/B\ne\n"));
  EXPECT_FALSE(fs::exists(db.path()));
  const fs::path cwd = fs::temp_directory_path() / fmt::format("rccx_teach_cwd_{}", ::getpid());
  fs::create_directories(cwd);
  const std::string in_cwd =
      "cd " + cwd.string() + " && env -u RCCX_DB " + RCCX_CLI + " teach < /dev/null 2>&1";
  EXPECT_EQ(rccx::test::run_shell(in_cwd).exit_code, 0);
  EXPECT_TRUE(fs::is_empty(cwd)) << "teach without save left a file in " << cwd;
  fs::remove_all(cwd);
  // The first save creates it; a second session adds to it.
  check({"teach", "", 0, {"saved P for microbo in"}, {"error"}},
        rccx_with_input("teach --db " + db.path(), "m 1 10\nsave P\ne\n"));
  EXPECT_TRUE(fs::exists(db.path()));
  check({"teach", "", 0, {"saved Q for microbo"}, {"error"}},
        rccx_with_input("teach --db " + db.path(), "save Q\ne\n"));
  const rccx::test::ShellRun list = rccx_with_input("db --db " + db.path() + " list", "");
  EXPECT_NE(list.out.find("microbo P:"), std::string::npos) << list.out;
  EXPECT_NE(list.out.find("microbo Q:"), std::string::npos) << list.out;
}

TEST(CliConsole, JointtestRefusesBadLinesAndExits1) {
  const std::vector<Case> cases = {
      {"jointtest --robot puma560", "j 2.5\nx\nq\n", 1, {"its joints are 1 to 6"}, {"joint 2 ("}},
      {"jointtest --robot puma560",
       "w 1e10\nq\n",
       1,
       {"w: the wait: \"1e10\" is out of range"},
       {}},
      {"jointtest --robot puma560",
       "r 0.1\nr 5abc\nq\n",
       1,
       {"0.25 to 56 ms", "\"5abc\""},
       {"sample period 0.100 ms"}},
      {"jointtest --robot puma560",
       "o 16\nO 3.5\nx\nq\n",
       1,
       {"from 0 to 15", "not a whole number", "outputs 0x0000"},
       {}},
      {"jointtest --robot puma560",
       "m 5abc\nv 0\nx\nq\n",
       1,
       {"\"5abc\" is not a number", "out of range"},
       {}},
      {"jointtest --robot puma560", "k 40\nq\n", 1, {"has no Microbo joint controllers"}, {}},
      {"jointtest", "k 300\nk 40.5\nq\n", 1, {"from 0 to 255", "not a whole number"}, {"dynamic"}},
      {"jointtest --robot puma560", "q now\nq\n", 1, {"one word too many"}, {}},
      {"jointtest --robot puma560", "j 2\nm 10\nw 2\nq\n", 0, {"joint 2 (theta2)"}, {}},
      // A line too long for a command is refused whole; endless input ends the console.
      {"jointtest", std::string(5000, 'x') + "\nx\nq\n", 1, {"refused whole", "theta1"}, {}},
      // M while an m move is under way: the ramp starts where the joint is, not too fast.
      {"jointtest", "m 10\nM 20\nw 1\nx\nq\n", 0, {"theta1      20.0"}, {"control ended"}},
  };
  for (const Case& c : cases) check(c, rccx_with_input(c.arguments, c.input));
}

TEST(CliConsole, RcuRefusesBadLinesAndExits1) {
  const std::vector<Case> cases = {
      {"rcu", "step 5abc\n", 1, {"\"5abc\" is not a number"}, {}},
      {"rcu", "step 1e10\n", 1, {"out of range"}, {}},
      {"rcu", "in 0x5805\n", 1, {"5800 to 580B"}, {}},
      {"rcu", "out 5805 04 05\n", 1, {"one word too many"}, {}},
      {"rcu", "fault 1.0 encoder_error\n", 1, {"the joint must be 1 to 6"}, {}},
      {"rcu", "in 5801\n# note\n\nstep 0.1\n", 0, {"00\n"}, {"error"}},
      {"rcu", std::string(2u << 20, '\0') + "\nin 5801\n", 1, {"not lines of commands"}, {"00\n"}},
      {"rcu", "in 5801\r\nin 5800", 0, {"00\n"}, {"error"}},  // CRLF, no last line end
  };
  for (const Case& c : cases) check(c, rccx_with_input(c.arguments, c.input));
}

}  // namespace
