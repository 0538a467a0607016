// Test hosts in network namespaces (netns_fixture.hpp): built with `ip` and `tc`, the relay
// started with `ip netns exec` in the wire namespace.
#include "netns_fixture.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace rccx::netns {
namespace {

using namespace std::chrono_literals;

struct Run {
  int code = -1;
  std::string out;
};

/// `argv` run to its end (no shell), its output and error together.
Run run(const std::vector<std::string>& argv) {
  int pipe_fds[2];
  if (pipe2(pipe_fds, O_CLOEXEC) != 0) return {-1, std::strerror(errno)};
  const pid_t pid = fork();
  if (pid < 0) return {-1, std::strerror(errno)};
  if (pid == 0) {
    dup2(pipe_fds[1], 1);
    dup2(pipe_fds[1], 2);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    std::fprintf(stderr, "cannot run %s: %s\n", args[0], std::strerror(errno));
    _exit(127);
  }
  close(pipe_fds[1]);
  Run r;
  char buffer[4096];
  ssize_t n = 0;
  while ((n = read(pipe_fds[0], buffer, sizeof buffer)) > 0 || (n < 0 && errno == EINTR)) {
    if (n > 0) r.out.append(buffer, static_cast<std::size_t>(n));
  }
  close(pipe_fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

std::string joined(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& a : argv) s += (s.empty() ? "" : " ") + a;
  return s;
}

/// `argv`, or std::runtime_error naming it and what it said.
void must(const std::vector<std::string>& argv) {
  const Run r = run(argv);
  if (r.code != 0) {
    throw std::runtime_error("`" + joined(argv) + "` failed (" + std::to_string(r.code) +
                             "): " + r.out);
  }
}

std::string number(double v) {
  char s[64];
  std::snprintf(s, sizeof s, "%.6g", v);
  return s;
}

/// Writes `value` to a /proc/sys file as a thread inside the namespace sees it.
void sysctl_in(int netns_fd, const std::string& path, const std::string& value) {
  run_in_namespace(netns_fd, [&] {
    std::ofstream f(path);
    f << value;
  });
}

}  // namespace

// ---- Child ----------------------------------------------------------------------------------

Child::~Child() {
  reap();
}

void Child::reap() noexcept {
  if (pid_ > 0 && !exit_) {
    kill(pid_, SIGKILL);
    int status = 0;
    waitpid(pid_, &status, 0);
  }
  pid_ = -1;
}

Child::Child(Child&& o) noexcept : pid_(o.pid_), output_(std::move(o.output_)), exit_(o.exit_) {
  o.pid_ = -1;
}

Child& Child::operator=(Child&& o) noexcept {
  if (this != &o) {
    reap();
    pid_ = o.pid_;
    output_ = std::move(o.output_);
    exit_ = o.exit_;
    o.pid_ = -1;
  }
  return *this;
}

void Child::signal(int sig) const noexcept {
  if (pid_ > 0 && !exit_) kill(pid_, sig);
}

std::optional<int> Child::wait(std::chrono::milliseconds limit) {
  if (exit_ || pid_ <= 0) return exit_;
  const auto until = std::chrono::steady_clock::now() + limit;
  for (;;) {
    int status = 0;
    const pid_t r = waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      exit_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      return exit_;
    }
    if (r < 0 && errno != EINTR) return std::nullopt;
    if (std::chrono::steady_clock::now() >= until) return std::nullopt;
    std::this_thread::sleep_for(2ms);
  }
}

int Child::stop() {
  if (exit_) return *exit_;
  signal(SIGTERM);
  if (auto code = wait(2000ms)) return *code;
  signal(SIGKILL);
  return wait(2000ms).value_or(-1);
}

std::string Child::output() const {
  std::ifstream f(output_);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

bool Child::wait_for_output(const std::string& text, std::chrono::milliseconds limit) const {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (output().find(text) == std::string::npos) {
    if (std::chrono::steady_clock::now() >= until) return false;
    std::this_thread::sleep_for(5ms);
  }
  return true;
}

// ---- namespaces -----------------------------------------------------------------------------

void run_in_namespace(int netns_fd, const std::function<void()>& fn) {
  std::exception_ptr failure;
  // setns changes only the calling thread, so the test's own threads stay where they were.
  std::thread t([&] {
    if (setns(netns_fd, CLONE_NEWNET) != 0) {
      failure = std::make_exception_ptr(
          std::runtime_error(std::string("setns into a test namespace: ") + std::strerror(errno)));
      return;
    }
    try {
      fn();
    } catch (...) {
      failure = std::current_exception();
    }
  });
  t.join();
  close(netns_fd);
  if (failure) std::rethrow_exception(failure);
}

std::string Hosts::unavailable() {
  if (geteuid() != 0) {
    return "network namespaces need root (CAP_SYS_ADMIN and CAP_NET_ADMIN): run this test as "
           "root to check hosts with delay and loss between them";
  }
  if (run({"ip", "-V"}).code != 0) return "no `ip` command (install iproute2)";
  const std::string probe = "rccx-" + std::to_string(getpid()) + "-p";
  const Run add = run({"ip", "netns", "add", probe});
  if (add.code != 0) return "`ip netns add` refused here: " + add.out;
  run({"ip", "netns", "del", probe});
  if (access(RCCX_L2_RELAY, X_OK) != 0) {
    return std::string("the relay ") + RCCX_L2_RELAY + " is not built (build rccx_l2_relay)";
  }
  return {};
}

void Hosts::remove_stale() {
  static const std::regex ours(R"(rccx-([0-9]+)-[a-z])");
  DIR* d = opendir("/run/netns");
  if (d == nullptr) return;
  std::vector<std::string> stale;
  while (const dirent* e = readdir(d)) {
    std::cmatch m;
    if (!std::regex_match(e->d_name, m, ours)) continue;
    const auto pid = static_cast<pid_t>(std::stol(m[1].str()));
    if (kill(pid, 0) != 0 && errno == ESRCH) stale.emplace_back(e->d_name);
  }
  closedir(d);
  for (const auto& n : stale) run({"ip", "netns", "del", n});
}

Hosts::Hosts(LinkOptions options) : options_(options) {
  if (options_.hosts < 2 || options_.hosts > 3) {
    throw std::invalid_argument("netns::Hosts: 2 or 3 hosts, not " +
                                std::to_string(options_.hosts));
  }
  remove_stale();
  const pid_t pid = getpid();
  prefix_ = "rccx-" + std::to_string(pid) + "-";
  subnet_ = static_cast<int>(pid % 250) + 1;
  for (int i = 0; i < options_.hosts; ++i) names_.push_back(prefix_ + static_cast<char>('a' + i));
  wire_ = prefix_ + "w";
  char dir[] = "/tmp/rccx-netns-XXXXXX";
  if (mkdtemp(dir) == nullptr) throw std::runtime_error("mkdtemp: " + std::string(strerror(errno)));
  dir_ = dir;
  try {
    build();
  } catch (...) {
    teardown();
    throw;
  }
}

Hosts::~Hosts() {
  teardown();
}

std::string Hosts::address(int host) const {
  return "10.77." + std::to_string(subnet_) + "." + std::to_string(host + 1);
}

int Hosts::enter(int host) const {
  const std::string& ns = host < 0 ? wire_ : names_.at(static_cast<std::size_t>(host));
  const int fd = open(("/run/netns/" + ns).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("open /run/netns/" + ns + ": " + std::strerror(errno));
  return fd;
}

void Hosts::build() {
  // Left by an earlier Hosts of this process that did not get to its destructor.
  for (const auto& n : names_) run({"ip", "netns", "del", n});
  run({"ip", "netns", "del", wire_});
  must({"ip", "netns", "add", wire_});
  // No IPv6 on the segment: only what the test sends crosses it (and draws on the loss).
  sysctl_in(enter(-1), "/proc/sys/net/ipv6/conf/all/disable_ipv6", "1");
  sysctl_in(enter(-1), "/proc/sys/net/ipv6/conf/default/disable_ipv6", "1");
  for (int i = 0; i < options_.hosts; ++i) {
    const std::string& ns = names_[static_cast<std::size_t>(i)];
    const std::string port = std::string("w-") + static_cast<char>('a' + i);
    must({"ip", "netns", "add", ns});
    sysctl_in(enter(i), "/proc/sys/net/ipv6/conf/all/disable_ipv6", "1");
    sysctl_in(enter(i), "/proc/sys/net/ipv6/conf/default/disable_ipv6", "1");
    must({"ip", "-n", wire_, "link", "add", port, "type", "veth", "peer", "name", kInterface,
          "netns", ns});
    must({"ip", "-n", ns, "link", "set", "lo", "up"});
    must({"ip", "-n", ns, "addr", "add", address(i) + "/24", "dev", kInterface});
    must({"ip", "-n", ns, "link", "set", kInterface, "up"});
    must({"ip", "-n", wire_, "link", "set", port, "up"});
  }
  const char* force_relay = std::getenv("RCCX_NETNS_RELAY");
  const bool try_netem =
      options_.prefer_netem && !(force_relay != nullptr && std::string(force_relay) == "1");
  if (try_netem &&
      run({"ip", "netns", "exec", wire_, "tc", "qdisc", "add", "dev", "w-a", "root", "netem",
           "delay", number(options_.delay_ms) + "ms", "loss", number(options_.loss * 100.0) + "%"})
              .code == 0) {
    // netem: a bridge joins the ports; each port's netem delays and drops what leaves it toward
    // its host, so every frame crosses exactly one netem, as it crosses the relay once.
    netem_ = true;
    must({"ip", "-n", wire_, "link", "add", "br0", "type", "bridge"});
    for (int i = 0; i < options_.hosts; ++i) {
      const std::string port = std::string("w-") + static_cast<char>('a' + i);
      if (i > 0) {
        must({"ip", "netns", "exec", wire_, "tc", "qdisc", "add", "dev", port, "root", "netem",
              "delay", number(options_.delay_ms) + "ms", "loss",
              number(options_.loss * 100.0) + "%"});
      }
      must({"ip", "-n", wire_, "link", "set", port, "master", "br0"});
    }
    must({"ip", "-n", wire_, "link", "set", "br0", "up"});
    return;
  }
  start_relay();
}

void Hosts::start_relay() {
  std::vector<std::string> argv = {RCCX_L2_RELAY};
  for (int i = 0; i < options_.hosts; ++i) {
    argv.insert(argv.end(), {"--if", std::string("w-") + static_cast<char>('a' + i)});
  }
  const std::string ready = dir_ + "/relay.ready";
  argv.insert(argv.end(),
              {"--delay-ms", number(options_.delay_ms), "--loss", number(options_.loss), "--seed",
               std::to_string(options_.seed), "--json", dir_ + "/relay.json", "--ready", ready,
               "--rt-priority", std::to_string(options_.relay_rt_priority)});
  relay_ = spawn(-1, argv);
  const auto until = std::chrono::steady_clock::now() + 5s;
  while (access(ready.c_str(), F_OK) != 0) {
    if (relay_.wait(0ms) || std::chrono::steady_clock::now() >= until) {
      throw std::runtime_error("the relay did not start (`" + joined(argv) +
                               "`): " + relay_.output());
    }
    std::this_thread::sleep_for(2ms);
  }
}

Child Hosts::spawn(int host, const std::vector<std::string>& argv,
                   const std::vector<std::string>& env) {
  const std::string& ns = host < 0 ? wire_ : names_.at(static_cast<std::size_t>(host));
  static std::atomic<int> serial{0};
  const std::string output = dir_ + "/child-" + std::to_string(++serial) + ".out";
  std::vector<std::string> full = {"ip", "netns", "exec", ns};
  if (!env.empty()) {
    full.emplace_back("env");
    full.insert(full.end(), env.begin(), env.end());
  }
  full.insert(full.end(), argv.begin(), argv.end());
  std::vector<char*> args;
  for (auto& a : full) args.push_back(a.data());
  args.push_back(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    // Dies with the test process, so a crashed test leaves no relay or peer running.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(1);
    const int out = open(output.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int in = open("/dev/null", O_RDONLY);
    if (out >= 0) {
      dup2(out, 1);
      dup2(out, 2);
    }
    if (in >= 0) dup2(in, 0);
    // `ip netns exec` execs the command in place: this pid is the command's.
    execvp(args[0], args.data());
    std::fprintf(stderr, "cannot run ip: %s\n", std::strerror(errno));
    _exit(127);
  }
  return Child(pid, output);
}

void Hosts::cut(bool on) {
  if (netem_) {
    for (int i = 0; i < options_.hosts; ++i) {
      must({"ip", "netns", "exec", wire_, "tc", "qdisc", "change", "dev",
            std::string("w-") + static_cast<char>('a' + i), "root", "netem", "delay",
            number(options_.delay_ms) + "ms", "loss",
            on ? std::string("100%") : number(options_.loss * 100.0) + "%"});
    }
    cut_ = on;
    return;
  }
  if (on != cut_) relay_.signal(SIGUSR1);
  // SIGUSR1 is handled before the SIGUSR2 that asks for the counters: once they say so, it is.
  const auto until = std::chrono::steady_clock::now() + 5s;
  while (relay_stats().cut != on) {
    if (std::chrono::steady_clock::now() >= until) {
      throw std::runtime_error("the relay did not take the cut: " + relay_.output());
    }
  }
  cut_ = on;
}

RelayStats Hosts::relay_stats() {
  RelayStats s;
  if (netem_) return s;
  const std::string path = dir_ + "/relay.json";
  std::remove(path.c_str());
  relay_.signal(SIGUSR2);
  const auto until = std::chrono::steady_clock::now() + 5s;
  while (access(path.c_str(), F_OK) != 0) {
    if (std::chrono::steady_clock::now() >= until || relay_.wait(0ms)) return s;
    std::this_thread::sleep_for(1ms);
  }
  std::ifstream f(path);
  std::stringstream text;
  text << f.rdbuf();
  s.json = text.str();
  const auto j = nlohmann::json::parse(s.json, nullptr, false);
  if (j.is_discarded()) return s;
  s.valid = true;
  s.cut = j.value("cut", false);
  s.forwarded = j.value("forwarded", 0ULL);
  s.lost = j.value("lost", 0ULL);
  s.cut_dropped = j.value("cut_dropped", 0ULL);
  s.overflow = j.value("overflow", 0ULL);
  s.max_queue = j.value("max_queue", 0ULL);
  s.delay_min_ms = j.value("delay_min_ms", 0.0);
  s.delay_p50_ms = j.value("delay_p50_ms", 0.0);
  s.delay_p99_ms = j.value("delay_p99_ms", 0.0);
  s.delay_max_ms = j.value("delay_max_ms", 0.0);
  for (const auto& p : j.value("ports", nlohmann::json::array())) {
    s.port_forwarded.push_back(p.value("forwarded", 0ULL));
    s.port_lost.push_back(p.value("lost", 0ULL));
    s.port_received.push_back(p.value("received", 0ULL));
  }
  return s;
}

void Hosts::teardown() noexcept {
  if (relay_.pid() > 0) {
    relay_.stop();
    // The relay's own summary (counters, achieved delays) into the test's log.
    std::fprintf(stderr, "%s", relay_.output().c_str());
  }
  for (const auto& n : names_) run({"ip", "netns", "del", n});
  if (!wire_.empty()) run({"ip", "netns", "del", wire_});
  if (!dir_.empty()) {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
}

}  // namespace rccx::netns
