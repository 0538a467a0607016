// rccx_l2_relay: a transparent Ethernet relay with delay and loss, for kernels without netem.
// It sits in a "wire" network namespace holding the far ends of the test hosts' veth pairs and
// forwards every frame that enters one of them out of the others (a learning hub), each frame
// held --delay-ms and dropped with probability --loss, in both directions. SIGUSR1 toggles
// "cut" (nothing passes, as with a cable pulled); SIGUSR2 writes the counters now; SIGTERM or
// SIGINT writes them and ends. tests/net/netns_fixture.cpp starts it; docs/NETWORK.md
// ("Test hosts") gives its figures.
//
//   ip netns exec rccx-123-w rccx_l2_relay --if w-a --if w-b --delay-ms 2 --loss 0.01 --seed 1
//        --json /tmp/relay.json --ready /tmp/relay.ready
//
// Frames are read and written with their virtio-net header (PACKET_VNET_HDR), so a frame whose
// checksum the sender left to offload, or a TCP segment the sender left to GSO, is passed on as
// the kernel gave it instead of arriving with a wrong checksum. Times are the kernel's receive
// stamps (SO_TIMESTAMPNS, CLOCK_REALTIME): the achieved delay includes the relay's own wake-up
// latency, which is the jitter the tests see.
#include <arpa/inet.h>
#include <fcntl.h>
#include <linux/if_packet.h>
#include <net/ethernet.h>
#include <net/if.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <vector>

namespace {

// struct virtio_net_hdr's size (<linux/virtio_net.h> is not C++: a member is named `class`).
constexpr std::size_t kVnetHeader = 10;
constexpr std::size_t kMaxFrame = 65536 + kVnetHeader;  // a GSO frame's largest
constexpr std::int64_t kHistogramUs = 200'000;          // delays counted up to 200 ms

struct Options {
  std::vector<std::string> interfaces;
  double delay_ms = 2.0;
  double loss = 0.01;
  std::uint64_t seed = 1;
  std::size_t queue_frames = 4096;
  std::size_t queue_bytes = 16u << 20;
  double cut_after_s = -1.0;  ///< < 0: never
  std::string json_path;
  std::string ready_path;
  int rt_priority = 0;  ///< SCHED_FIFO priority; 0: the normal scheduler
};

struct Port {
  std::string name;
  int fd = -1;
  int ifindex = 0;
  // Counted on the way in (received) and on the way out (the rest), per port.
  std::uint64_t received = 0;
  std::uint64_t forwarded = 0;
  std::uint64_t lost = 0;      ///< dropped by --loss
  std::uint64_t cut = 0;       ///< dropped while cut
  std::uint64_t overflow = 0;  ///< dropped: the queue was full
  std::uint64_t send_errors = 0;
};

struct Held {
  std::int64_t due_ns = 0;
  std::int64_t arrival_ns = 0;
  int out = 0;
  std::vector<unsigned char> bytes;  ///< virtio-net header, then the frame
};

[[noreturn]] void usage_error(const std::string& what) {
  std::fprintf(stderr,
               "rccx_l2_relay: %s\n"
               "usage: rccx_l2_relay --if NAME --if NAME [--if NAME...] [--delay-ms 2] "
               "[--loss 0.01]\n"
               "       [--seed 1] [--queue-frames 4096] [--queue-bytes 16777216] "
               "[--cut-after S]\n"
               "       [--json PATH] [--ready PATH] [--rt-priority 0..99]\n",
               what.c_str());
  std::exit(2);
}

double parse_number(const std::string& option, const char* text, double lo, double hi) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text, &end);
  if (errno != 0 || end == text || *end != '\0' || !std::isfinite(v) || v < lo || v > hi) {
    char range[96];
    std::snprintf(range, sizeof range, " wants a number in %g .. %g, not '", lo, hi);
    usage_error(option + range + text + "'");
  }
  return v;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") usage_error("a layer-2 relay with delay and loss");
    if (i + 1 >= argc) usage_error(a + " wants a value (or is unknown)");
    const char* v = argv[++i];
    if (a == "--if") {
      if (std::strlen(v) == 0 || std::strlen(v) >= IFNAMSIZ) usage_error("bad interface name");
      o.interfaces.emplace_back(v);
    } else if (a == "--delay-ms") {
      o.delay_ms = parse_number(a, v, 0.0, 10'000.0);
    } else if (a == "--loss") {
      o.loss = parse_number(a, v, 0.0, 1.0);
    } else if (a == "--seed") {
      o.seed = static_cast<std::uint64_t>(parse_number(a, v, 0.0, 9.0e15));
    } else if (a == "--queue-frames") {
      o.queue_frames = static_cast<std::size_t>(parse_number(a, v, 1.0, 1.0e6));
    } else if (a == "--queue-bytes") {
      o.queue_bytes = static_cast<std::size_t>(parse_number(a, v, 65536.0, 1.0e9));
    } else if (a == "--cut-after") {
      o.cut_after_s = parse_number(a, v, 0.0, 1.0e6);
    } else if (a == "--json") {
      o.json_path = v;
    } else if (a == "--ready") {
      o.ready_path = v;
    } else if (a == "--rt-priority") {
      o.rt_priority = static_cast<int>(parse_number(a, v, 0.0, 99.0));
    } else {
      usage_error("unknown option " + a);
    }
  }
  if (o.interfaces.size() < 2) usage_error("give at least two interfaces (--if NAME --if NAME)");
  return o;
}

std::int64_t realtime_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

/// A raw socket on `name` that sees every frame entering it, with its virtio-net header and
/// receive stamp. Exits with the reason when the interface or the privilege is missing.
Port open_port(const std::string& name) {
  Port p;
  p.name = name;
  p.ifindex = static_cast<int>(if_nametoindex(name.c_str()));
  if (p.ifindex == 0) usage_error("no interface '" + name + "' in this network namespace");
  p.fd = socket(AF_PACKET, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, htons(ETH_P_ALL));
  if (p.fd < 0) {
    std::fprintf(stderr, "rccx_l2_relay: a packet socket: %s (run as root, or with CAP_NET_RAW)\n",
                 std::strerror(errno));
    std::exit(1);
  }
  const int on = 1;
  if (setsockopt(p.fd, SOL_PACKET, PACKET_VNET_HDR, &on, sizeof on) != 0 ||
      setsockopt(p.fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0) {
    std::fprintf(stderr, "rccx_l2_relay: socket options on %s: %s\n", name.c_str(),
                 std::strerror(errno));
    std::exit(1);
  }
  const int buffer = 4 << 20;
  (void)setsockopt(p.fd, SOL_SOCKET, SO_RCVBUFFORCE, &buffer, sizeof buffer);
  (void)setsockopt(p.fd, SOL_SOCKET, SO_SNDBUFFORCE, &buffer, sizeof buffer);
  sockaddr_ll at{};
  at.sll_family = AF_PACKET;
  at.sll_protocol = htons(ETH_P_ALL);
  at.sll_ifindex = p.ifindex;
  if (bind(p.fd, reinterpret_cast<sockaddr*>(&at), sizeof at) != 0) {
    std::fprintf(stderr, "rccx_l2_relay: bind to %s: %s\n", name.c_str(), std::strerror(errno));
    std::exit(1);
  }
  packet_mreq promisc{};
  promisc.mr_ifindex = p.ifindex;
  promisc.mr_type = PACKET_MR_PROMISC;
  if (setsockopt(p.fd, SOL_PACKET, PACKET_ADD_MEMBERSHIP, &promisc, sizeof promisc) != 0) {
    std::fprintf(stderr, "rccx_l2_relay: promiscuous %s: %s\n", name.c_str(), std::strerror(errno));
    std::exit(1);
  }
  return p;
}

class Relay {
 public:
  explicit Relay(Options o)
      : o_(std::move(o)),
        delay_ns_(static_cast<std::int64_t>(std::llround(o_.delay_ms * 1e6))),
        rng_(o_.seed),
        held_(o_.queue_frames),
        histogram_us_(static_cast<std::size_t>(kHistogramUs) + 1, 0),
        buffer_(kMaxFrame) {
    for (const auto& name : o_.interfaces) ports_.push_back(open_port(name));
    start_ns_ = realtime_ns();
  }

  int run(int signal_fd);

 private:
  void receive(int in);
  void route(int in, std::int64_t arrival_ns, std::size_t n);
  void hold(int in, int out, std::int64_t arrival_ns, std::size_t n);
  void send_due(std::int64_t now_ns);
  void learn(const unsigned char* mac, int port);
  [[nodiscard]] int port_of(const unsigned char* mac) const;
  /// The counters to --json, and with `say` to stderr too (at the end; not when asked).
  void write_counters(bool say = true) const;

  Options o_;
  std::int64_t delay_ns_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  std::vector<Port> ports_;
  // The frames on the wire, a ring in arrival order: with one delay for every frame that is
  // also the order they fall due, so no priority queue is needed.
  std::vector<Held> held_;
  std::size_t head_ = 0, count_ = 0, held_bytes_ = 0, max_count_ = 0;
  std::vector<std::pair<std::uint64_t, int>> macs_;  ///< learnt: source address -> port
  std::vector<std::uint64_t> histogram_us_;          ///< achieved delays, 1 us bins
  std::uint64_t delays_ = 0;
  std::int64_t max_delay_ns_ = 0, min_delay_ns_ = INT64_MAX;
  std::int64_t start_ns_ = 0;
  bool cut_ = false;
  std::vector<unsigned char> buffer_;
};

std::uint64_t mac_key(const unsigned char* mac) {
  std::uint64_t k = 0;
  for (int i = 0; i < 6; ++i) k = (k << 8) | mac[i];
  return k;
}

void Relay::learn(const unsigned char* mac, int port) {
  const std::uint64_t k = mac_key(mac);
  for (auto& [key, p] : macs_) {
    if (key == k) {
      p = port;
      return;
    }
  }
  if (macs_.size() < 1024) macs_.emplace_back(k, port);
}

int Relay::port_of(const unsigned char* mac) const {
  if ((mac[0] & 1) != 0) return -1;  // multicast or broadcast: every port
  const std::uint64_t k = mac_key(mac);
  for (const auto& [key, p] : macs_)
    if (key == k) return p;
  return -1;
}

void Relay::receive(int in) {
  Port& port = ports_[static_cast<std::size_t>(in)];
  for (;;) {
    sockaddr_ll from{};
    iovec iov{buffer_.data(), buffer_.size()};
    alignas(cmsghdr) std::array<char, 256> control{};
    msghdr msg{};
    msg.msg_name = &from;
    msg.msg_namelen = sizeof from;
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control.data();
    msg.msg_controllen = control.size();
    const ssize_t n = recvmsg(port.fd, &msg, MSG_TRUNC);
    if (n < 0) return;  // EAGAIN: drained
    // Our own sends out of this port come back as outgoing: never relay them again.
    if (from.sll_pkttype == PACKET_OUTGOING) continue;
    if (static_cast<std::size_t>(n) > buffer_.size() ||
        static_cast<std::size_t>(n) < kVnetHeader + sizeof(ether_header)) {
      ++port.overflow;
      continue;
    }
    std::int64_t arrival_ns = 0;
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
        timespec ts{};
        std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
        arrival_ns = static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
      }
    }
    if (arrival_ns == 0) arrival_ns = realtime_ns();
    ++port.received;
    route(in, arrival_ns, static_cast<std::size_t>(n));
  }
}

void Relay::route(int in, std::int64_t arrival_ns, std::size_t n) {
  const unsigned char* frame = buffer_.data() + kVnetHeader;
  learn(frame + 6, in);
  const int to = port_of(frame);
  if (to == in) return;  // for a host on the port it came from
  for (int out = 0; out < static_cast<int>(ports_.size()); ++out) {
    if (out != in && (to < 0 || to == out)) hold(in, out, arrival_ns, n);
  }
}

void Relay::hold(int /*in*/, int out, std::int64_t arrival_ns, std::size_t n) {
  Port& port = ports_[static_cast<std::size_t>(out)];
  if (cut_) {
    ++port.cut;
    return;
  }
  if (uniform_(rng_) < o_.loss) {
    ++port.lost;
    return;
  }
  if (count_ == held_.size() || held_bytes_ + n > o_.queue_bytes) {
    ++port.overflow;
    return;
  }
  Held& h = held_[(head_ + count_) % held_.size()];
  h.due_ns = arrival_ns + delay_ns_;
  h.arrival_ns = arrival_ns;
  h.out = out;
  h.bytes.assign(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(n));
  ++count_;
  held_bytes_ += n;
  max_count_ = std::max(max_count_, count_);
}

void Relay::send_due(std::int64_t now_ns) {
  while (count_ > 0 && held_[head_].due_ns <= now_ns) {
    Held& h = held_[head_];
    Port& port = ports_[static_cast<std::size_t>(h.out)];
    if (cut_) {
      ++port.cut;  // in flight when the cable was pulled
    } else if (send(port.fd, h.bytes.data(), h.bytes.size(), MSG_DONTWAIT) < 0) {
      ++port.send_errors;
    } else {
      ++port.forwarded;
      const std::int64_t achieved = realtime_ns() - h.arrival_ns;
      const std::int64_t us = std::clamp<std::int64_t>(achieved / 1000, 0, kHistogramUs);
      ++histogram_us_[static_cast<std::size_t>(us)];
      ++delays_;
      max_delay_ns_ = std::max(max_delay_ns_, achieved);
      min_delay_ns_ = std::min(min_delay_ns_, achieved);
    }
    held_bytes_ -= h.bytes.size();
    // A GSO frame's buffer is given back rather than kept for every later 60-byte frame.
    if (h.bytes.capacity() > 16384) std::vector<unsigned char>().swap(h.bytes);
    head_ = (head_ + 1) % held_.size();
    --count_;
  }
}

int Relay::run(int signal_fd) {
  std::vector<pollfd> fds;
  fds.push_back({signal_fd, POLLIN, 0});
  for (const auto& p : ports_) fds.push_back({p.fd, POLLIN, 0});
  if (!o_.ready_path.empty()) {
    // Written once every socket is bound: frames from now on are relayed.
    const std::string tmp = o_.ready_path + ".tmp";
    if (FILE* f = std::fopen(tmp.c_str(), "w")) {
      std::fprintf(f, "%d\n", static_cast<int>(getpid()));
      std::fclose(f);
      std::rename(tmp.c_str(), o_.ready_path.c_str());
    }
  }
  const std::int64_t cut_at_ns =
      o_.cut_after_s < 0 ? INT64_MAX : start_ns_ + static_cast<std::int64_t>(o_.cut_after_s * 1e9);
  for (;;) {
    std::int64_t now = realtime_ns();
    if (!cut_ && now >= cut_at_ns) cut_ = true;
    send_due(now);
    std::int64_t wait_ns = count_ > 0 ? held_[head_].due_ns - now : 1'000'000'000;
    if (cut_at_ns != INT64_MAX && !cut_) wait_ns = std::min(wait_ns, cut_at_ns - now);
    wait_ns = std::max<std::int64_t>(wait_ns, 0);
    const timespec timeout{static_cast<time_t>(wait_ns / 1'000'000'000),
                           static_cast<long>(wait_ns % 1'000'000'000)};
    if (ppoll(fds.data(), fds.size(), &timeout, nullptr) < 0 && errno != EINTR) {
      std::fprintf(stderr, "rccx_l2_relay: ppoll: %s\n", std::strerror(errno));
      write_counters();
      return 1;
    }
    // Signals first: a cut asked before a frame arrived applies to that frame.
    if ((fds[0].revents & POLLIN) != 0) {
      signalfd_siginfo si{};
      while (read(signal_fd, &si, sizeof si) == static_cast<ssize_t>(sizeof si)) {
        if (si.ssi_signo == SIGUSR1) {
          cut_ = !cut_;
        } else if (si.ssi_signo == SIGUSR2) {
          write_counters(false);
        } else {
          write_counters();
          return 0;
        }
      }
    }
    for (std::size_t i = 1; i < fds.size(); ++i) {
      if ((fds[i].revents & POLLIN) != 0) receive(static_cast<int>(i - 1));
    }
  }
}

void Relay::write_counters(bool say) const {
  auto percentile_us = [&](double q) -> std::int64_t {
    if (delays_ == 0) return 0;
    const auto rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(delays_)));
    std::uint64_t seen = 0;
    for (std::size_t us = 0; us < histogram_us_.size(); ++us) {
      seen += histogram_us_[us];
      if (seen >= std::max<std::uint64_t>(rank, 1)) return static_cast<std::int64_t>(us);
    }
    return kHistogramUs;
  };
  std::string ports;
  std::uint64_t forwarded = 0, lost = 0, cut = 0, overflow = 0;
  for (const auto& p : ports_) {
    char one[512];
    std::snprintf(
        one, sizeof one,
        "%s{\"interface\":\"%s\",\"received\":%llu,\"forwarded\":%llu,\"lost\":%llu,"
        "\"cut\":%llu,\"overflow\":%llu,\"send_errors\":%llu}",
        ports.empty() ? "" : ",", p.name.c_str(), static_cast<unsigned long long>(p.received),
        static_cast<unsigned long long>(p.forwarded), static_cast<unsigned long long>(p.lost),
        static_cast<unsigned long long>(p.cut), static_cast<unsigned long long>(p.overflow),
        static_cast<unsigned long long>(p.send_errors));
    ports += one;
    forwarded += p.forwarded;
    lost += p.lost;
    cut += p.cut;
    overflow += p.overflow;
  }
  const std::int64_t p50 = percentile_us(0.50), p99 = percentile_us(0.99);
  const double max_ms = static_cast<double>(max_delay_ns_) / 1e6;
  const double min_ms = delays_ == 0 ? 0.0 : static_cast<double>(min_delay_ns_) / 1e6;
  if (say) {
    std::fprintf(
        stderr,
        "rccx_l2_relay: forwarded %llu, lost %llu, cut %llu, overflow %llu, max queue %zu; "
        "delay (set %.3f ms) min %.3f p50 %.3f p99 %.3f max %.3f ms%s\n",
        static_cast<unsigned long long>(forwarded), static_cast<unsigned long long>(lost),
        static_cast<unsigned long long>(cut), static_cast<unsigned long long>(overflow), max_count_,
        o_.delay_ms, min_ms, static_cast<double>(p50) / 1e3, static_cast<double>(p99) / 1e3, max_ms,
        cut_ ? " (cut)" : "");
  }
  if (o_.json_path.empty()) return;
  const std::string tmp = o_.json_path + ".tmp";
  FILE* f = std::fopen(tmp.c_str(), "w");
  if (f == nullptr) {
    std::fprintf(stderr, "rccx_l2_relay: cannot write %s: %s\n", tmp.c_str(), std::strerror(errno));
    return;
  }
  std::fprintf(f,
               "{\"delay_ms\":%.6f,\"loss\":%.6f,\"seed\":%llu,\"cut\":%s,\"forwarded\":%llu,"
               "\"lost\":%llu,\"cut_dropped\":%llu,\"overflow\":%llu,\"max_queue\":%zu,"
               "\"delay_min_ms\":%.6f,\"delay_p50_ms\":%.6f,\"delay_p99_ms\":%.6f,"
               "\"delay_max_ms\":%.6f,\"ports\":[%s]}\n",
               o_.delay_ms, o_.loss, static_cast<unsigned long long>(o_.seed),
               cut_ ? "true" : "false", static_cast<unsigned long long>(forwarded),
               static_cast<unsigned long long>(lost), static_cast<unsigned long long>(cut),
               static_cast<unsigned long long>(overflow), max_count_, min_ms,
               static_cast<double>(p50) / 1e3, static_cast<double>(p99) / 1e3, max_ms,
               ports.c_str());
  std::fclose(f);
  std::rename(tmp.c_str(), o_.json_path.c_str());  // readers never see half a file
}

}  // namespace

int main(int argc, char** argv) {
  Options o = parse(argc, argv);
  sigset_t signals;
  sigemptyset(&signals);
  for (int s : {SIGTERM, SIGINT, SIGHUP, SIGUSR1, SIGUSR2}) sigaddset(&signals, s);
  // Blocked before anything else, so a signal sent early is queued, not fatal.
  sigprocmask(SIG_BLOCK, &signals, nullptr);
  const int signal_fd = signalfd(-1, &signals, SFD_NONBLOCK | SFD_CLOEXEC);
  if (signal_fd < 0) {
    std::fprintf(stderr, "rccx_l2_relay: signalfd: %s\n", std::strerror(errno));
    return 1;
  }
  // Timers to the nanosecond rather than the default 50 us slack: the delay is the product.
  (void)prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  if (o.rt_priority > 0) {
    sched_param sp{};
    sp.sched_priority = o.rt_priority;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0) {
      std::fprintf(stderr, "rccx_l2_relay: SCHED_FIFO %d refused (%s): normal scheduling\n",
                   o.rt_priority, std::strerror(errno));
    }
  }
  Relay relay(std::move(o));
  return relay.run(signal_fd);
}
