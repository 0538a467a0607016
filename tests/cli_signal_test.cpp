// SIGINT, SIGTERM and SIGHUP at random moments in the rccx commands: each ends within a bound (no
// hang), with 128 + the signal as its exit code (never an abort), its log ending on a row
// boundary, its database whole. Also: stderr closed, stdout a full pipe.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

struct Child {
  pid_t pid = -1;
  int stdin_fd = -1;  ///< write end of the child's stdin, when asked for
};

struct Options {
  bool stdin_pipe = false;    ///< a pipe the test keeps open (a console waiting for input)
  bool stdout_stuck = false;  ///< a pipe nobody reads: writes block once it is full
  bool close_stderr = false;
  std::string stdout_file = "/dev/null";
  std::string stderr_file = "/dev/null";
  std::vector<std::string> env;  ///< NAME=VALUE added
};

Child spawn(const std::vector<std::string>& args, const Options& o, int* stuck_read_end) {
  int in[2] = {-1, -1};
  int out[2] = {-1, -1};
  if (o.stdin_pipe && pipe(in) != 0) return {};
  if (o.stdout_stuck && pipe(out) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    if (o.stdin_pipe) {
      dup2(in[0], 0);
      close(in[1]);
    } else {
      const int null = open("/dev/null", O_RDONLY);
      dup2(null, 0);
    }
    if (o.stdout_stuck) {
      dup2(out[1], 1);
      close(out[0]);
    } else {
      const int f = open(o.stdout_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(f, 1);
    }
    if (o.close_stderr) {
      close(2);
    } else {
      const int f = open(o.stderr_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(f, 2);
    }
    for (const std::string& e : o.env) putenv(const_cast<char*>(e.c_str()));
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(RCCX_CLI));
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(RCCX_CLI, argv.data());
    _exit(127);
  }
  Child c;
  c.pid = pid;
  if (o.stdin_pipe) {
    close(in[0]);
    c.stdin_fd = in[1];
  }
  if (o.stdout_stuck) {
    close(out[1]);
    *stuck_read_end = out[0];
  }
  return c;
}

/// Waits until `pid` catches SIGINT and SIGTERM (its handlers are installed: /proc's SigCgt),
/// so that a signal sent after it tests the program, not the moment before main().
void wait_until_catching(pid_t pid) {
  const std::uint64_t both = (1ULL << (SIGINT - 1)) | (1ULL << (SIGTERM - 1));
  for (int i = 0; i < 1000; ++i) {
    std::ifstream status("/proc/" + std::to_string(pid) + "/status");
    std::string line;
    while (std::getline(status, line)) {
      if (line.rfind("SigCgt:", 0) == 0 &&
          (std::stoull(line.substr(7), nullptr, 16) & both) == both) {
        return;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

/// The child's exit status, or -1 when it has not ended within `limit` (then it is killed).
int wait_exit(pid_t pid, std::chrono::milliseconds limit, bool* signalled = nullptr) {
  const auto end = std::chrono::steady_clock::now() + limit;
  int status = 0;
  while (std::chrono::steady_clock::now() < end) {
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) {
      if (signalled != nullptr) *signalled = WIFSIGNALED(status);
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    std::this_thread::sleep_for(10ms);
  }
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  return -1;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class Signals : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("rccx-signal-" + std::to_string(getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  /// A random moment in [lo, hi].
  std::chrono::milliseconds moment(int lo_ms, int hi_ms) {
    return std::chrono::milliseconds(std::uniform_int_distribution<int>(lo_ms, hi_ms)(random_));
  }
  /// Every line of a CSV has as many fields as its header, and the file ends with a newline.
  static void expect_whole_rows(const fs::path& csv) {
    const std::string text = slurp(csv);
    ASSERT_FALSE(text.empty()) << csv;
    EXPECT_EQ(text.back(), '\n') << "the log ends mid-row";
    std::istringstream in(text);
    std::string line;
    std::getline(in, line);
    if (line.starts_with("# rccx-log")) std::getline(in, line);  // the header line, then columns
    const auto fields = std::count(line.begin(), line.end(), ',');
    std::size_t rows = 0;
    while (std::getline(in, line)) {
      ++rows;
      ASSERT_EQ(std::count(line.begin(), line.end(), ','), fields)
          << "row " << rows << ": " << line;
    }
    (void)rows;  // none when the signal came before the first sample: still whole
  }
  fs::path dir_;
  std::mt19937 random_{
      static_cast<std::mt19937::result_type>(::testing::UnitTest::GetInstance()->random_seed())};
};

TEST_F(Signals, ReportEndsOnSigintAndSigtermWithItsLogWhole) {
  // SIGHUP: the terminal went away (a closed ssh session); it too ends cleanly.
  for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGINT, SIGTERM}) {
    const fs::path log = dir_ / "report.csv";
    fs::remove(log);
    Options o;
    o.stderr_file = (dir_ / "stderr").string();
    int unused = -1;
    const Child c = spawn({"report", "--robot", "puma560", "--seconds", "1e6", "--every", "0.05",
                           "--log", log.string()},
                          o, &unused);
    wait_until_catching(c.pid);
    std::this_thread::sleep_for(moment(100, 1500));
    kill(c.pid, sig);
    bool signalled = false;
    const int code = wait_exit(c.pid, 10s, &signalled);
    ASSERT_NE(code, -1) << "report did not end within 10 s of signal " << sig;
    EXPECT_FALSE(signalled) << "killed by the signal instead of ending cleanly";
    EXPECT_EQ(code, 128 + sig) << slurp(dir_ / "stderr");
    expect_whole_rows(log);
    EXPECT_TRUE(fs::is_empty(dir_ / "stderr") == false);
    for (const auto& e : fs::directory_iterator(dir_)) {
      EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos)
          << "a temporary file was left: " << e.path();
    }
  }
}

TEST_F(Signals, RealTimeReportEndsWithinAPeriod) {
  Options o;
  int unused = -1;
  const Child c = spawn({"report", "--robot", "puma560", "--realtime", "--period", "10ms",
                         "--seconds", "100", "--every", "5"},
                        o, &unused);
  wait_until_catching(c.pid);
  std::this_thread::sleep_for(moment(300, 800));
  const auto sent = std::chrono::steady_clock::now();
  kill(c.pid, SIGINT);
  const int code = wait_exit(c.pid, 5s);
  const auto took = std::chrono::steady_clock::now() - sent;
  EXPECT_EQ(code, 130);
  EXPECT_LT(took, 1s) << "the program waited for its interval to end";
}

TEST_F(Signals, ConsolesEndWhileWaitingForInputOrInALongWait) {
  struct Case {
    std::vector<std::string> args;
    std::string input;  ///< typed first; then the console waits (or works)
  };
  const fs::path db = dir_ / "teach.db";
  const std::vector<Case> cases = {
      {{"jointtest", "--robot", "puma560"}, ""},
      {{"jointtest", "--robot", "puma560"}, "w 1e5\n"},
      {{"teach", "--robot", "puma560", "--db", db.string()}, ""},
      {{"teach", "--robot", "puma560", "--db", db.string()}, "push 1 1 500\n"},
      {{"rcu"}, ""},
  };
  for (const Case& k : cases) {
    for (const int sig : {SIGINT, SIGTERM}) {
      Options o;
      o.stdin_pipe = true;
      int unused = -1;
      const Child c = spawn(k.args, o, &unused);
      if (!k.input.empty()) {
        ASSERT_EQ(write(c.stdin_fd, k.input.data(), k.input.size()),
                  static_cast<ssize_t>(k.input.size()));
      }
      wait_until_catching(c.pid);
      std::this_thread::sleep_for(moment(100, 1000));
      kill(c.pid, sig);
      bool signalled = false;
      const int code = wait_exit(c.pid, 10s, &signalled);
      close(c.stdin_fd);
      EXPECT_NE(code, -1) << k.args[0] << " '" << k.input << "' hung after signal " << sig;
      EXPECT_FALSE(signalled) << k.args[0] << " was killed by signal " << sig;
      EXPECT_EQ(code, 128 + sig) << k.args[0] << " '" << k.input << "'";
    }
  }
}

TEST_F(Signals, AStuckStandardOutputDoesNotHoldCtrlC) {
  // report prints a line every 10 ms into a pipe nobody reads: it fills, the write blocks.
  Options o;
  o.stdout_stuck = true;
  int read_end = -1;
  const Child c =
      spawn({"report", "--robot", "puma560", "--seconds", "1e6", "--every", "0.01"}, o, &read_end);
  std::this_thread::sleep_for(2s);  // 64 KiB of lines: long full
  kill(c.pid, SIGINT);
  bool signalled = false;
  const int code = wait_exit(c.pid, 10s, &signalled);
  close(read_end);
  ASSERT_NE(code, -1) << "a write to a full pipe held the program after Ctrl-C";
  EXPECT_FALSE(signalled);
  EXPECT_NE(code, 134) << "aborted";
  EXPECT_EQ(code, 130);
}

TEST_F(Signals, AnImportStoppedAtARandomMomentIsAllOrNothing) {
  const fs::path json = dir_ / "many.json";
  {
    std::ofstream out(json);
    out << R"({"rccx_position_database": 1, "units": "m, rad", "transforms": [)";
    for (int i = 0; i < 2000; ++i) {
      out << (i ? "," : "") << R"({"robot": "puma560", "name": "P)" << i
          << R"(", "T_rows_m": [1,0,0,0.4,0,1,0,0.1,0,0,1,0.3]})";
    }
    out << "]}\n";
  }
  for (int round = 0; round < 4; ++round) {
    const fs::path db = dir_ / ("import" + std::to_string(round) + ".db");
    Options o;
    int unused = -1;
    const Child c = spawn({"db", "--db", db.string(), "import", json.string()}, o, &unused);
    wait_until_catching(c.pid);
    std::this_thread::sleep_for(moment(0, 3000));
    kill(c.pid, round % 2 ? SIGTERM : SIGINT);
    bool signalled = false;
    const int code = wait_exit(c.pid, 20s, &signalled);
    ASSERT_NE(code, -1);
    EXPECT_FALSE(signalled);
    EXPECT_TRUE(code == 0 || code == 130 || code == 143) << code;
    if (!fs::exists(db)) continue;  // stopped before the database was made
    sqlite3* handle = nullptr;
    ASSERT_EQ(sqlite3_open_v2(db.c_str(), &handle, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    sqlite3_stmt* count = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(handle, "SELECT count(*) FROM transforms", -1, &count, nullptr),
              SQLITE_OK)
        << sqlite3_errmsg(handle);
    ASSERT_EQ(sqlite3_step(count), SQLITE_ROW);
    const auto rows = sqlite3_column_int64(count, 0);
    sqlite3_finalize(count);
    sqlite3_close(handle);
    EXPECT_TRUE(rows == 0 || rows == 2000) << rows << " rows: not all or nothing";
    if (code != 0) {
      EXPECT_EQ(rows, 0) << "an import that reported a stop kept rows";
    }
  }
}

TEST_F(Signals, ErrorsWithStderrClosedDoNotCrash) {
  Options o;
  o.close_stderr = true;
  int unused = -1;
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"kin", "fk", "--robot", "puma560", "x", "0", "0", "0", "0", "0"},
        std::vector<std::string>{"report", "--seconds", "inf"},
        std::vector<std::string>{"db", "--db", (dir_ / "none.db").string(), "list"}}) {
    const Child c = spawn(args, o, &unused);
    bool signalled = false;
    const int code = wait_exit(c.pid, 20s, &signalled);
    EXPECT_FALSE(signalled) << args[0];
    EXPECT_TRUE(code == 1 || code == 2) << args[0] << ": " << code;
  }
}

}  // namespace
