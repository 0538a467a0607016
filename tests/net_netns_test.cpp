// Test hosts (issue 29, "Hosts"; docs/NETWORK.md): network namespaces joined through a wire
// namespace that adds 2 ms each way and drops 1 % of frames (rccx_l2_relay here, where the
// kernel has no netem). UDP across it takes the delay twice per round trip and loses about 1 %
// each way; a cut link passes nothing; rccx's own DDS participants find each other across it,
// answer within the delay, and see the cut as a lost peer. Root only: skipped, saying why,
// elsewhere.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "netns_fixture.hpp"

using namespace rccx;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {

constexpr std::uint16_t kPort = 47700;

/// A UDP socket bound to `address`:kPort, made inside the host's namespace.
int udp_socket(netns::Hosts& hosts, int host) {
  const std::string address = hosts.address(host);
  return hosts.in(host, [&] {
    const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0) throw std::runtime_error(std::string("socket: ") + std::strerror(errno));
    sockaddr_in at{};
    at.sin_family = AF_INET;
    at.sin_port = htons(kPort);
    inet_pton(AF_INET, address.c_str(), &at.sin_addr);
    if (bind(fd, reinterpret_cast<sockaddr*>(&at), sizeof at) != 0) {
      throw std::runtime_error("bind " + address + ": " + std::strerror(errno));
    }
    return fd;
  });
}

sockaddr_in peer(const std::string& address) {
  sockaddr_in at{};
  at.sin_family = AF_INET;
  at.sin_port = htons(kPort);
  inet_pton(AF_INET, address.c_str(), &at.sin_addr);
  return at;
}

struct Probe {
  std::uint32_t seq;
  std::int64_t sent_ns;
};

/// Echoes every datagram on `fd` back to its sender and marks its seq, until `stop`.
class Echo {
 public:
  Echo(int fd, std::size_t count) : fd_(fd), seen_(count, 0) {
    thread_ = std::thread([this] {
      while (!stop_) {
        pollfd p{fd_, POLLIN, 0};
        if (poll(&p, 1, 20) <= 0) continue;
        Probe probe{};
        sockaddr_in from{};
        socklen_t len = sizeof from;
        const ssize_t n =
            recvfrom(fd_, &probe, sizeof probe, 0, reinterpret_cast<sockaddr*>(&from), &len);
        if (n != static_cast<ssize_t>(sizeof probe)) continue;
        if (probe.seq < seen_.size()) seen_[probe.seq] = 1;
        ++received_;
        sendto(fd_, &probe, sizeof probe, 0, reinterpret_cast<sockaddr*>(&from), len);
      }
    });
  }
  ~Echo() {
    stop_ = true;
    thread_.join();
  }
  Echo(const Echo&) = delete;
  Echo& operator=(const Echo&) = delete;
  [[nodiscard]] std::size_t received() const { return received_; }
  [[nodiscard]] std::size_t seen_in(std::uint32_t from, std::uint32_t to) const {
    return static_cast<std::size_t>(std::count(
        seen_.begin() + from, seen_.begin() + std::min<std::size_t>(to, seen_.size()), 1));
  }

 private:
  int fd_;
  std::vector<char> seen_;
  std::atomic<std::size_t> received_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

struct Sent {
  std::size_t answered = 0;
  std::vector<double> rtt_ms;  ///< sorted
};

/// Sends probes first .. first + count - 1 to `to` every `period`, collecting the echoes
/// (waiting `linger` after the last for stragglers).
Sent send_probes(int fd, const sockaddr_in& to, std::uint32_t first, std::uint32_t count,
                 std::chrono::microseconds period, std::chrono::milliseconds linger = 200ms) {
  Sent s;
  const auto start = Clock::now();
  auto next = start;
  std::uint32_t seq = first;
  auto now_ns = [] {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
        .count();
  };
  auto last = Clock::time_point::max();
  while (Clock::now() < last) {
    if (seq < first + count && Clock::now() >= next) {
      const Probe p{seq++, now_ns()};
      sendto(fd, &p, sizeof p, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
      next += period;
      if (seq == first + count) last = Clock::now() + linger;
    }
    pollfd pf{fd, POLLIN, 0};
    if (poll(&pf, 1, 0) <= 0) {
      std::this_thread::sleep_for(100us);
      continue;
    }
    Probe back{};
    if (recv(fd, &back, sizeof back, 0) != static_cast<ssize_t>(sizeof back)) continue;
    if (back.seq < first || back.seq >= first + count) continue;  // an earlier phase's
    ++s.answered;
    s.rtt_ms.push_back(static_cast<double>(now_ns() - back.sent_ns) / 1e6);
  }
  std::sort(s.rtt_ms.begin(), s.rtt_ms.end());
  return s;
}

double percentile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0;
  return sorted[std::min(sorted.size() - 1,
                         static_cast<std::size_t>(q * static_cast<double>(sorted.size())))];
}

/// Sends a probe every 20 ms until one comes back (ARP resolved across the lossy link), <= 5 s.
bool warm_up(int fd, const sockaddr_in& to) {
  for (std::uint32_t i = 0; i < 250; ++i) {
    if (send_probes(fd, to, 1'000'000 + i, 1, 1ms, 20ms).answered > 0) return true;
  }
  return false;
}

}  // namespace

TEST(NetnsHosts, UdpAcrossTheLinkTakesTheDelayEachWayAndLosesAboutOnePercentEachWay) {
  NETNS_OR_SKIP();
  netns::Hosts hosts({.hosts = 2, .delay_ms = 2.0, .loss = 0.01, .seed = 29});
  const int a = udp_socket(hosts, 0);
  const int b = udp_socket(hosts, 1);
  constexpr std::uint32_t kCount = 2000;
  {
    Echo echo(b, kCount);
    ASSERT_TRUE(warm_up(a, peer(hosts.address(1)))) << "nothing came back in 5 s";
    const netns::RelayStats before = hosts.relay_stats();
    const Sent sent = send_probes(a, peer(hosts.address(1)), 0, kCount, 1ms);
    const netns::RelayStats after = hosts.relay_stats();
    const std::size_t at_b = echo.seen_in(0, kCount);
    const double loss_ab = 1.0 - static_cast<double>(at_b) / kCount;
    const double loss_ba = 1.0 - static_cast<double>(sent.answered) / static_cast<double>(at_b);
    const double p50 = percentile(sent.rtt_ms, 0.5), p99 = percentile(sent.rtt_ms, 0.99);
    std::printf(
        "[ figures  ] %s; round trip over %u probes: p50 %.3f p99 %.3f max %.3f ms; "
        "lost a->b %.2f %%, b->a %.2f %%\n",
        hosts.netem() ? "tc netem" : "relay", kCount, p50, p99,
        sent.rtt_ms.empty() ? 0.0 : sent.rtt_ms.back(), loss_ab * 100, loss_ba * 100);
    if (after.valid) {
      std::printf(
          "[ figures  ] relay: held min %.3f p50 %.3f p99 %.3f max %.3f ms (set 2 ms), "
          "max queue %llu, overflow %llu, dropped %llu of %llu\n",
          after.delay_min_ms, after.delay_p50_ms, after.delay_p99_ms, after.delay_max_ms,
          static_cast<unsigned long long>(after.max_queue),
          static_cast<unsigned long long>(after.overflow),
          static_cast<unsigned long long>(after.lost - before.lost),
          static_cast<unsigned long long>(after.forwarded - before.forwarded + after.lost -
                                          before.lost));
      // The relay holds each frame at least the delay, and on this machine rarely much more.
      EXPECT_GE(after.delay_min_ms, 2.0);
      EXPECT_LT(after.delay_p50_ms, 3.0);
      EXPECT_EQ(after.overflow, 0U);
    }
    // Two crossings of 2 ms each, plus the hosts' own scheduling on a loaded machine.
    EXPECT_GE(p50, 3.5);
    EXPECT_LE(p50, 12.0);
    // 1 % of 2,000: 20 expected, 4 .. 50 holds with a margin of over 3.5 standard deviations.
    EXPECT_GE(loss_ab, 0.002);
    EXPECT_LE(loss_ab, 0.025);
    EXPECT_GE(loss_ba, 0.002);
    EXPECT_LE(loss_ba, 0.025);
  }
  close(a);
  close(b);
}

TEST(NetnsHosts, WithTheLinkCutNothingPassesAndMendedItPassesAgain) {
  NETNS_OR_SKIP();
  netns::Hosts hosts({.hosts = 2, .delay_ms = 2.0, .loss = 0.01, .seed = 7});
  const int a = udp_socket(hosts, 0);
  const int b = udp_socket(hosts, 1);
  {
    Echo echo(b, 400);
    const sockaddr_in to_b = peer(hosts.address(1));
    ASSERT_TRUE(warm_up(a, to_b)) << "nothing came back in 5 s";
    EXPECT_GE(send_probes(a, to_b, 0, 100, 2ms).answered, 90U) << "before the cut";
    hosts.cut(true);
    const Sent during = send_probes(a, to_b, 100, 100, 2ms, 300ms);
    EXPECT_EQ(during.answered, 0U);
    EXPECT_EQ(echo.seen_in(100, 200), 0U) << "frames reached b through a cut link";
    hosts.cut(false);
    EXPECT_GE(send_probes(a, to_b, 200, 100, 2ms).answered, 90U) << "after mending";
  }
  close(a);
  close(b);
}

TEST(NetnsHosts, ThreeHostsOnOneSegmentReachEachOther) {
  NETNS_OR_SKIP();
  netns::Hosts hosts({.hosts = 3, .delay_ms = 2.0, .loss = 0.01, .seed = 3});
  int fds[3];
  for (int i = 0; i < 3; ++i) fds[i] = udp_socket(hosts, i);
  for (int from = 0; from < 3; ++from) {
    const int to = (from + 1) % 3;
    Echo echo(fds[to], 100);
    ASSERT_TRUE(warm_up(fds[from], peer(hosts.address(to))))
        << "host " << from << " cannot reach host " << to;
    const Sent s = send_probes(fds[from], peer(hosts.address(to)), 0, 50, 2ms);
    EXPECT_GE(s.answered, 45U) << from << " -> " << to;
    EXPECT_GE(percentile(s.rtt_ms, 0.5), 3.5) << from << " -> " << to;
  }
  for (int fd : fds) close(fd);
}

TEST(NetnsHosts, RccxParticipantsFindEachOtherAcrossTheLinkAndSeeItsCut) {
  NETNS_OR_SKIP();
  netns::Hosts hosts({.hosts = 2, .delay_ms = 2.0, .loss = 0.01, .seed = 11});
  const std::string domain = std::to_string(100 + getpid() % 100);
  netns::Child pong = hosts.spawn(1, {RCCX_NETNS_DDS_PEER, "--role", "pong", "--domain", domain,
                                      "--interface", netns::Hosts::kInterface, "--seconds", "25"});
  netns::Child ping =
      hosts.spawn(0, {RCCX_NETNS_DDS_PEER, "--role", "ping", "--domain", domain, "--interface",
                      netns::Hosts::kInterface, "--count", "300", "--period-ms", "10",
                      "--detection-ms", "100", "--seconds", "25", "--watch"});
  ASSERT_TRUE(ping.wait_for_output("watching", 15s)) << "no round trips in 15 s.\nping:\n"
                                                     << ping.output() << "\npong:\n"
                                                     << pong.output();
  const std::string out = ping.output();
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"(p50=([0-9.]+) p99=([0-9.]+))"))) << out;
  const double p50 = std::stod(m[1].str());
  std::printf("[ figures  ] rccx heartbeats across the link: %s", out.c_str());
  // Two crossings of 2 ms, DDS's own cost and the scheduling of two processes on a loaded host.
  EXPECT_GE(p50, 3.5) << out;
  EXPECT_LE(p50, 15.0) << out;

  const auto cut_at = Clock::now();
  hosts.cut(true);
  ASSERT_TRUE(ping.wait_for_output("lost after", 5s)) << "the cut was not seen:\n" << ping.output();
  const double seen_ms = std::chrono::duration<double, std::milli>(Clock::now() - cut_at).count();
  std::printf("[ figures  ] the cut seen by ping within %.0f ms (detection 100 ms)\n", seen_ms);
  // The lease is 100 ms; the margin is for the processes' scheduling and our 5 ms polling.
  EXPECT_LE(seen_ms, 1000.0);
  hosts.cut(false);
  EXPECT_TRUE(ping.wait_for_output("back after", 10s)) << "not back after mending:\n"
                                                       << ping.output();
  ping.stop();
  pong.stop();
}

TEST(NetnsHosts, DdsperfPingPongAcrossTheLinkTakesTheDelayEachWay) {
  NETNS_OR_SKIP();
  if (access("/usr/bin/ddsperf", X_OK) != 0) GTEST_SKIP() << "no ddsperf (cyclonedds-tools)";
  netns::Hosts hosts({.hosts = 2, .delay_ms = 2.0, .loss = 0.01, .seed = 5});
  const std::string domain = std::to_string(100 + getpid() % 100);
  const std::string uri = std::string(
                              "CYCLONEDDS_URI=<CycloneDDS><Domain id=\"any\"><General>"
                              "<Interfaces><NetworkInterface name=\"") +
                          netns::Hosts::kInterface +
                          "\"/></Interfaces></General></Domain></CycloneDDS>";
  netns::Child pong = hosts.spawn(1, {"ddsperf", "-i", domain, "-D", "8", "pong"}, {uri});
  netns::Child ping = hosts.spawn(0, {"ddsperf", "-i", domain, "-D", "5", "ping", "100Hz"}, {uri});
  const auto code = ping.wait(15s);
  pong.stop();
  ASSERT_TRUE(code.has_value()) << "ddsperf ping did not end:\n" << ping.output();
  const std::string out = ping.output();
  std::printf("[ figures  ] ddsperf ping across the link:\n%s", out.c_str());
  // ddsperf prints half the round trip (its minimum here is just over the 2 ms one way, which a
  // round trip through two 2 ms crossings cannot be): each second's median.
  const std::regex median(R"(50% ([0-9.]+)us)");
  std::vector<double> half_rtt_ms;
  for (auto it = std::sregex_iterator(out.begin(), out.end(), median); it != std::sregex_iterator();
       ++it) {
    half_rtt_ms.push_back(std::stod((*it)[1].str()) / 1e3);
  }
  ASSERT_GE(half_rtt_ms.size(), 2U) << "ddsperf reported no round trips:\n" << out;
  std::sort(half_rtt_ms.begin(), half_rtt_ms.end());
  const double p50 = half_rtt_ms[half_rtt_ms.size() / 2];
  EXPECT_GE(p50, 1.75) << out;
  EXPECT_LE(p50, 7.5) << out;
}
