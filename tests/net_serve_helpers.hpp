// What the tests of `rccx serve` processes share (net_same_path_test, net_serve_ros2_test): a
// child process killed at the end, a serve spawned from the rccx executable on loopback, and a
// recorder of every RobotState of a domain. (net_serve_test.cpp uses the child and the serve;
// its own recorder keeps the fields its tests compare.)
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "rccx/net/codec.hpp"
#include "rccx/net/dds.hpp"
#include "rccx/net/states.hpp"

extern char** environ;

namespace rccx::test {

inline std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

inline std::string read_text(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// Loopback options on domain `d`; `detection` longer than the 20 ms default so that a loaded
/// machine's stalls of a normal-priority thread do not count as lost links.
inline net::NetOptions loopback(
    std::uint32_t d, std::chrono::milliseconds detection = std::chrono::milliseconds(50)) {
  net::NetOptions o;
  o.domain = d;
  o.interface = "lo";
  o.detection = detection;
  o.heartbeat = detection / 4;
  return o;
}

/// A child process, its stdout and stderr in files (under the test's temporary directory);
/// SIGTERM, then SIGKILL, at the end if still running.
class Child {
 public:
  /// `env` ("NAME=value") is added to this process's environment, replacing the same names.
  Child(const std::vector<std::string>& args, const std::string& tag,
        const std::vector<std::string>& env = {}) {
    const std::string base =
        std::string(P_tmpdir) + "/rccx_" + tag + "_" + std::to_string(getpid());
    out_ = base + ".out";
    err_ = base + ".err";
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
    if (posix_spawn(&pid_, argv[0], &fa, nullptr, argv.data(), envp.data()) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&fa);
  }
  ~Child() {
    if (pid_ <= 0 || exited_) return;
    kill(pid_, SIGTERM);
    if (wait_exit(std::chrono::seconds(5)) == -1) {
      kill(pid_, SIGKILL);
      (void)wait_exit(std::chrono::seconds(5));
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  [[nodiscard]] pid_t pid() const { return pid_; }
  [[nodiscard]] bool started() const { return pid_ > 0; }
  /// kill -9, and reaped.
  void kill9() {
    kill(pid_, SIGKILL);
    (void)wait_exit(std::chrono::seconds(5));
  }
  /// The exit code, 128 + signal, or -1 when still running after `timeout`.
  int wait_exit(std::chrono::nanoseconds timeout) {
    if (exited_) return code_;
    if (pid_ <= 0) return -1;
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return code_;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return -1;
  }
  [[nodiscard]] std::string out() const { return read_text(out_); }
  [[nodiscard]] std::string err() const { return read_text(err_); }
  /// Waits until stdout holds `text` (or timeout).
  bool wait_out(const std::string& text, std::chrono::nanoseconds timeout) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      if (out().find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

 private:
  pid_t pid_ = -1;
  std::string out_, err_;
  bool exited_ = false;
  int code_ = -1;
};

/// `rccx serve --cell cell --robots robots` on loopback domain `d`, plus `extra` arguments.
inline std::unique_ptr<Child> spawn_serve(const std::string& cell, std::uint32_t d,
                                          const std::string& robots, const std::string& tag,
                                          std::chrono::milliseconds detection,
                                          const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args{
      RCCX_EXE,       "serve", "--cell",      cell,
      "--robots",     robots,  "--domain",    std::to_string(d),
      "--interface",  "lo",    "--detection", std::to_string(detection.count()) + "ms",
      "--claim-wait", "200ms", "--seconds",   "120"};
  args.insert(args.end(), extra.begin(), extra.end());
  return std::make_unique<Child>(args, tag);
}

/// Every RobotState sample of a domain as it arrives, one per (robot, sample), each with the
/// steady time it was taken (ns).
class StateRecorder {
 public:
  struct Record {
    rccx_net_RobotState state{};
    std::int64_t received_ns = 0;
  };
  StateRecorder(std::uint32_t d, std::chrono::milliseconds detection)
      : participant_(loopback(d, detection)),
        reader_(participant_.reader(net::Topic::state, detection * 10)) {
    thread_ = std::thread([this] {
      net::StateInbox in;
      while (!stop_) {
        in.drain(reader_.get(), [&](const rccx_net_RobotState& s) {
          std::lock_guard lock(mutex_);
          auto& v = records_[std::string(net::text_of(s.robot))];
          if (v.empty() || v.back().state.sample != s.sample) v.push_back({s, now_ns()});
        });
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    });
  }
  ~StateRecorder() {
    stop_ = true;
    thread_.join();
  }
  StateRecorder(const StateRecorder&) = delete;
  StateRecorder& operator=(const StateRecorder&) = delete;
  [[nodiscard]] std::vector<Record> of(const std::string& robot) {
    std::lock_guard lock(mutex_);
    return records_[robot];
  }

 private:
  net::Participant participant_;
  net::Entity reader_;
  std::mutex mutex_;
  std::map<std::string, std::vector<Record>> records_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace rccx::test
