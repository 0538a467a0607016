// Test hosts: network namespaces on one Ethernet segment with delay and loss between them, made
// and removed by a test (docs/NETWORK.md, "Test hosts: namespaces, delay and loss").
//
//   if (auto why = netns::Hosts::unavailable(); !why.empty()) GTEST_SKIP() << why;
//   netns::Hosts hosts({.hosts = 2, .delay_ms = 2.0, .loss = 0.01});
//   int fd = hosts.in(0, [] { return socket(AF_INET, SOCK_DGRAM, 0); });  // a socket on host a
//   netns::Child pong = hosts.spawn(1, {"ddsperf", "pong"});              // a process on host b
//   hosts.cut(true);   // the cable pulled: nothing passes
//   hosts.cut(false);
//
// Topology: host i is the namespace rccx-<pid>-<a|b|c> with interface veth0 at 10.77.<k>.<i+1>/24;
// the far end of each veth pair, w-<a|b|c>, lies in the wire namespace rccx-<pid>-w. There
// rccx_l2_relay joins them (each frame held delay_ms, loss of them dropped, each way), or, where
// the kernel has the netem qdisc, a bridge with netem on each port's way out. Everything made is
// removed by ~Hosts, even after a failed assertion; namespaces left by a test process that was
// killed are removed by the next one (remove_stale).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

namespace rccx::netns {

struct LinkOptions {
  int hosts = 2;               ///< 2 or 3 (a, b, c)
  double delay_ms = 2.0;       ///< added one way, each direction
  double loss = 0.01;          ///< the fraction of frames dropped, each direction
  std::uint64_t seed = 1;      ///< the relay's loss draws
  bool prefer_netem = true;    ///< tc netem where the kernel has it ($RCCX_NETNS_RELAY=1: never)
  int relay_rt_priority = 20;  ///< the relay's SCHED_FIFO priority (0: normal): low jitter
};

/// What the relay counted and achieved (empty under netem, which counts nothing for us).
struct RelayStats {
  bool valid = false;
  bool cut = false;
  std::uint64_t forwarded = 0, lost = 0, cut_dropped = 0, overflow = 0, max_queue = 0;
  double delay_min_ms = 0, delay_p50_ms = 0, delay_p99_ms = 0, delay_max_ms = 0;
  /// Per wire port (w-a, w-b, ...): frames out of it toward its host, and those lost on the way.
  std::vector<std::uint64_t> port_forwarded, port_lost, port_received;
  std::string json;
};

/// A process started in a namespace: SIGKILLed when this goes unless it was waited for.
class Child {
 public:
  Child() = default;
  Child(pid_t pid, std::string output_path) : pid_(pid), output_(std::move(output_path)) {}
  ~Child();
  Child(Child&& o) noexcept;
  Child& operator=(Child&& o) noexcept;
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  [[nodiscard]] pid_t pid() const noexcept { return pid_; }
  void signal(int sig) const noexcept;
  /// Its exit code (128 + signal when one ended it), or nullopt when still running after `limit`.
  std::optional<int> wait(std::chrono::milliseconds limit);
  /// SIGTERM, up to 2 s, then SIGKILL; its exit code.
  int stop();
  /// Its standard output and error so far.
  [[nodiscard]] std::string output() const;
  /// Waits up to `limit` for `text` in its output; true when it came.
  bool wait_for_output(const std::string& text, std::chrono::milliseconds limit) const;

 private:
  void reap() noexcept;  ///< SIGKILL and wait, unless it ended and was waited for

  pid_t pid_ = -1;
  std::string output_;
  std::optional<int> exit_;
};

class Hosts {
 public:
  /// Why namespaces cannot be made here (not root, no `ip`, `ip netns add` refused), or "" when
  /// they can. Tests skip with this as the reason.
  static std::string unavailable();
  /// Deletes rccx-<pid>-* namespaces whose test process is gone.
  static void remove_stale();

  /// Makes the namespaces, links and relay. Throws std::runtime_error naming the command that
  /// failed and its output; what was made by then is removed.
  explicit Hosts(LinkOptions options = {});
  ~Hosts();
  Hosts(const Hosts&) = delete;
  Hosts& operator=(const Hosts&) = delete;

  [[nodiscard]] int count() const noexcept { return options_.hosts; }
  [[nodiscard]] const std::string& name(int host) const { return names_.at(host); }
  [[nodiscard]] const std::string& wire() const noexcept { return wire_; }
  /// Host `host`'s IPv4 address, "10.77.<k>.<host + 1>".
  [[nodiscard]] std::string address(int host) const;
  /// The interface of every host, in its own namespace.
  static constexpr const char* kInterface = "veth0";
  /// True when tc netem does the delay and loss (no relay).
  [[nodiscard]] bool netem() const noexcept { return netem_; }

  /// Runs `fn` on a thread that has entered host `host`'s network namespace and returns what it
  /// returns (rethrows what it throws): sockets made there stay in that namespace.
  template <class F>
  auto in(int host, F fn) -> decltype(fn());

  /// Starts `argv` in host `host`'s namespace (ip netns exec), with `env` ("NAME=value") added,
  /// its output to a file; host -1: the wire namespace. Call it from a thread that outlives the
  /// child (the test's own): the child is killed when the thread that started it ends.
  Child spawn(int host, const std::vector<std::string>& argv,
              const std::vector<std::string>& env = {});

  /// Cut (true) or mend (false) every link; returns once the relay (or netem) has it.
  void cut(bool on);
  /// The relay's counters now (valid = false under netem).
  RelayStats relay_stats();

 private:
  void build();
  void start_relay();
  void teardown() noexcept;
  [[nodiscard]] int enter(int host) const;  ///< an fd of the namespace's /var/run/netns file

  LinkOptions options_;
  std::string prefix_;
  std::vector<std::string> names_;
  std::string wire_;
  int subnet_ = 0;
  bool netem_ = false;
  bool cut_ = false;
  std::string dir_;  ///< a temporary directory for the relay's files and children's output
  Child relay_;
};

/// Runs `fn` on a thread inside `netns_fd`'s network namespace.
void run_in_namespace(int netns_fd, const std::function<void()>& fn);

template <class F>
auto Hosts::in(int host, F fn) -> decltype(fn()) {
  using R = decltype(fn());
  const int fd = enter(host);
  if constexpr (std::is_void_v<R>) {
    run_in_namespace(fd, [&] { fn(); });
  } else {
    std::optional<R> result;
    run_in_namespace(fd, [&] { result.emplace(fn()); });
    return std::move(*result);
  }
}

}  // namespace rccx::netns

/// In a GoogleTest test: skips it, saying why, where Hosts cannot be made (not root, no ip).
#define NETNS_OR_SKIP()                                                              \
  do {                                                                               \
    if (const std::string why = ::rccx::netns::Hosts::unavailable(); !why.empty()) { \
      GTEST_SKIP() << why;                                                           \
    }                                                                                \
  } while (false)
