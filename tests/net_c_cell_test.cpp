// The C layer's cell calls across processes (issue 29, item 2): one C program in the manual's
// style (c_cell_remote.c) run with its robots in its own process, and with RCCX_CELL_REMOTE=1
// against two `rccx serve` processes on loopback (a DDS domain of this test's own). Both exit 0
// and print the same events in the same order; their times agree within a tolerance (the
// remote one adds request round trips and state latency, on a loaded machine).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

using namespace std::chrono_literals;

namespace {

const std::string kCell = std::string(RCCX_CELLS_DIR) + "/cvarl.json";
constexpr int kDetectionMs = 50;  // as net_serve_test: a loaded machine's stalls are not losses

/// A domain of this test process's own, apart from net_serve_test's (140 .. 219).
std::uint32_t domain() {
  return 60 + static_cast<std::uint32_t>(getpid() % 40);
}

std::string read_file(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// A child process with `env` added to this one's environment, its output in files; killed at
/// the end if still running.
class Child {
 public:
  Child(const std::vector<std::string>& args, const std::vector<std::string>& env,
        const std::string& tag) {
    out_ = ::testing::TempDir() + "rccx_c_" + tag + "_" + std::to_string(getpid()) + ".out";
    err_ = ::testing::TempDir() + "rccx_c_" + tag + "_" + std::to_string(getpid()) + ".err";
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, out_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&fa, 2, err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    std::vector<std::string> all = env;
    for (char** e = environ; *e != nullptr; ++e) {
      const std::string kv(*e);
      bool given = false;
      for (const auto& g : env)
        given = given || kv.substr(0, kv.find('=')) == g.substr(0, g.find('='));
      if (!given) all.push_back(kv);
    }
    std::vector<char*> envp;
    for (auto& kv : all) envp.push_back(kv.data());
    envp.push_back(nullptr);
    env_ = std::move(all);
    if (posix_spawn(&pid_, argv[0], &fa, nullptr, argv.data(), envp.data()) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&fa);
  }
  ~Child() {
    if (pid_ <= 0 || exited_) return;
    kill(pid_, SIGTERM);
    if (wait_exit(5s) == -1) {
      kill(pid_, SIGKILL);
      (void)wait_exit(5s);
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  [[nodiscard]] bool started() const { return pid_ > 0; }
  /// The exit code, 128 + signal, or -1 when still running after `timeout`.
  int wait_exit(std::chrono::nanoseconds timeout) {
    if (exited_) return code_;
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return code_;
      }
      std::this_thread::sleep_for(10ms);
    }
    return -1;
  }
  [[nodiscard]] std::string out() const { return read_file(out_); }
  [[nodiscard]] std::string err() const { return read_file(err_); }

 private:
  pid_t pid_ = -1;
  std::string out_, err_;
  std::vector<std::string> env_;
  bool exited_ = false;
  int code_ = -1;
};

std::unique_ptr<Child> serve(std::uint32_t d, const std::string& robots) {
  return std::make_unique<Child>(
      std::vector<std::string>{RCCX_EXE, "serve", "--cell", kCell, "--robots", robots, "--domain",
                               std::to_string(d), "--interface", "lo", "--detection",
                               std::to_string(kDetectionMs) + "ms", "--claim-wait", "200ms",
                               "--seconds", "120"},
      std::vector<std::string>{}, "serve_" + robots);
}

struct Printed {
  std::vector<std::string> events;  ///< every line but the times, in order
  std::vector<long> times_ms;       ///< "time N: T ms"
};

Printed parse(const std::string& out) {
  Printed p;
  std::istringstream in(out);
  const std::regex time(R"(^time \d+: (-?\d+) ms$)");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_match(line, m, time)) {
      p.times_ms.push_back(std::stol(m[1].str()));
    } else {
      p.events.push_back(line);
    }
  }
  return p;
}

std::string both(const Child& c) {
  return "stdout:\n" + c.out() + "stderr:\n" + c.err();
}

TEST(NetCCell, TheSameCProgramRunsInOneProcessAndAcrossTwoServeProcesses) {
  // One process: the cell as always (simulated time), no switch.
  Child local({C_CELL_REMOTE, "together"}, {"RCCX_CELL=" + kCell, "RCCX_CELL_REMOTE=0"}, "local");
  ASSERT_TRUE(local.started());
  ASSERT_EQ(local.wait_exit(120s), 0) << both(local);

  const std::uint32_t d = domain();
  auto puma = serve(d, "puma");
  auto microbo = serve(d, "microbo");
  ASSERT_TRUE(puma->started() && microbo->started());
  Child remote({C_CELL_REMOTE, "together"},
               {"RCCX_CELL=" + kCell, "RCCX_CELL_REMOTE=1", "RCCX_DOMAIN=" + std::to_string(d),
                "RCCX_DDS_INTERFACE=lo", "RCCX_DETECTION_MS=" + std::to_string(kDetectionMs)},
               "remote");
  ASSERT_TRUE(remote.started());
  const int code = remote.wait_exit(120s);
  if (code != 0 && remote.err().find("with overrun (10)") != std::string::npos) {
    // The serve processes run the cell's 7 ms period in real time; on a loaded machine (other
    // builds on 2 cores, sanitizers) a cycle can overrun and end control. The C layer then says
    // so (RTC_E_TERMINATED with the reason, checked here); the comparison cannot run.
    EXPECT_NE(remote.out().find("release: RTC_E_"), std::string::npos) << both(remote);
    GTEST_SKIP() << "a serve process overran its real-time period (machine too loaded to compare "
                    "the runs):\n"
                 << remote.err();
  }
  ASSERT_EQ(code, 0) << both(remote) << "\npuma serve:\n"
                     << puma->err() << "\nmicrobo serve:\n"
                     << microbo->err();

  Printed a = parse(local.out());
  Printed b = parse(remote.out());
  // The one difference the program is told of: a joint start does not cross processes.
  ASSERT_FALSE(a.events.empty());
  ASSERT_FALSE(b.events.empty());
  const auto together = [](std::vector<std::string>& events) {
    for (auto it = events.begin(); it != events.end(); ++it) {
      if (it->rfind("together: ", 0) == 0) {
        const std::string answer = it->substr(10);
        events.erase(it);
        return answer;
      }
    }
    return std::string("(not printed)");
  };
  EXPECT_EQ(together(a.events), "RTC_OK");
  EXPECT_EQ(together(b.events), "RTC_E_NOT_YET");
  EXPECT_NE(remote.err().find("rccl_together: a joint start across processes"), std::string::npos)
      << remote.err();
  EXPECT_EQ(a.events, b.events) << "one process:\n"
                                << local.out() << "across processes:\n"
                                << remote.out();
  ASSERT_EQ(a.times_ms.size(), 3U) << local.out();
  ASSERT_EQ(b.times_ms.size(), a.times_ms.size()) << remote.out();
  for (std::size_t i = 0; i < a.times_ms.size(); ++i) {
    // Real time adds each request's round trip, the states' period and the program's polling;
    // a loaded 2-core machine stretches them: 250 ms or a fifth of the phase.
    const double tolerance_ms = std::max(250.0, 0.2 * static_cast<double>(a.times_ms[i]));
    EXPECT_GT(a.times_ms[i], 0) << "phase " << i + 1;
    EXPECT_NEAR(static_cast<double>(b.times_ms[i]), static_cast<double>(a.times_ms[i]),
                tolerance_ms)
        << "phase " << i + 1 << " took " << a.times_ms[i] << " ms in one process and "
        << b.times_ms[i] << " ms across processes";
    std::printf("phase %zu: %ld ms in one process, %ld ms across processes\n", i + 1, a.times_ms[i],
                b.times_ms[i]);
  }
}

TEST(NetCCell, WithoutServeProcessesTheOpenFailsWithTheServeCommandToStart) {
  Child remote({C_CELL_REMOTE},
               {"RCCX_CELL=" + kCell, "RCCX_CELL_REMOTE=1",
                "RCCX_DOMAIN=" + std::to_string(domain() + 40), "RCCX_DDS_INTERFACE=lo"},
               "none");
  ASSERT_TRUE(remote.started());
  ASSERT_EQ(remote.wait_exit(60s), 1) << both(remote);
  EXPECT_NE(remote.out().find("open: RTC_E_OPEN"), std::string::npos) << both(remote);
  EXPECT_NE(remote.err().find("rccx serve --cell"), std::string::npos) << both(remote);
}

TEST(NetCCell, ABadSwitchValueIsRefusedAndSaysWhatItTakes) {
  Child c({C_CELL_REMOTE}, {"RCCX_CELL=" + kCell, "RCCX_CELL_REMOTE=yes"}, "badswitch");
  ASSERT_TRUE(c.started());
  ASSERT_EQ(c.wait_exit(60s), 1) << both(c);
  EXPECT_NE(c.out().find("open: RTC_E_ARGUMENT"), std::string::npos) << both(c);
  EXPECT_NE(c.err().find("RCCX_CELL_REMOTE is \"yes\""), std::string::npos) << both(c);
}

}  // namespace
