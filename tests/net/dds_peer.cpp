// rccx_netns_dds_peer: one rccx net::Participant exchanging heartbeats with another, for the
// test hosts (tests/net_netns_test.cpp): the two run in separate network namespaces, so every
// sample, discovery included, crosses the relay's delay and loss.
//
//   rccx_netns_dds_peer --role pong --domain 7 --interface veth0
//   rccx_netns_dds_peer --role ping --domain 7 --interface veth0 --count 200 --watch
//
// pong: answers each of ping's heartbeats with one of its own carrying the same seq.
// ping: beats every --period-ms; prints "discovered after X ms", then "rtt_ms n=.. sent=..
// p50=.. p99=.. max=.." once --count answers came back; with --watch it goes on beating and
// prints "lost after X ms" when pong's heartbeat writer loses its liveliness (the lease =
// --detection-ms), "back after X ms" when answers return. Ends on SIGTERM or after --seconds.
#include <unistd.h>
#include <csignal>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "rccx/net/dds.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

volatile sig_atomic_t g_stop = 0;
void on_signal(int /*sig*/) {
  g_stop = 1;
}

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

[[noreturn]] void usage(const char* what) {
  std::fprintf(stderr,
               "rccx_netns_dds_peer: %s\nusage: rccx_netns_dds_peer --role ping|pong --domain "
               "ID --interface NAME [--count N] [--period-ms 10] [--detection-ms 100] "
               "[--seconds 20] [--watch]\n",
               what);
  std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  std::string role;
  rccx::net::NetOptions options;
  int count = 200;
  int period_ms = 10;
  int detection_ms = 100;
  double seconds = 20;
  bool watch = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--watch") {
      watch = true;
      continue;
    }
    if (i + 1 >= argc) usage("an option wants a value");
    const char* v = argv[++i];
    if (a == "--role") {
      role = v;
    } else if (a == "--domain") {
      options.domain = static_cast<std::uint32_t>(std::atoi(v));
    } else if (a == "--interface") {
      options.interface = v;
    } else if (a == "--count") {
      count = std::max(1, std::atoi(v));
    } else if (a == "--period-ms") {
      period_ms = std::max(1, std::atoi(v));
    } else if (a == "--detection-ms") {
      detection_ms = std::max(1, std::atoi(v));
    } else if (a == "--seconds") {
      seconds = std::atof(v);
    } else {
      usage(("unknown option " + a).c_str());
    }
  }
  if (role != "ping" && role != "pong") usage("--role is ping or pong");
  std::signal(SIGTERM, on_signal);
  std::signal(SIGINT, on_signal);
  options.detection = std::chrono::milliseconds(detection_ms);
  options.heartbeat = std::chrono::milliseconds(period_ms);

  try {
    const rccx::net::Participant participant(options);
    const rccx::net::Entity writer = participant.writer(rccx::net::Topic::heartbeat);
    const rccx::net::Entity reader = participant.reader(rccx::net::Topic::heartbeat);
    const rccx::net::Entity waitset(dds_create_waitset(participant.get()));
    const dds_entity_t condition = dds_create_readcondition(reader.get(), DDS_ANY_STATE);
    rccx::net::check(condition, "a read condition");
    rccx::net::check(dds_waitset_attach(waitset.get(), condition, 0), "a waitset");
    dds_set_status_mask(reader.get(), DDS_LIVELINESS_CHANGED_STATUS);

    rccx_net_Heartbeat out{};
    rccx::net::copy_to(out.participant, role + "/" + rccx::net::host_and_pid());
    out.role = static_cast<std::uint8_t>(role == "ping" ? rccx::net::Role::program
                                                        : rccx::net::Role::serve);
    out.instance = static_cast<unsigned long long>(getpid());
    out.period_ns = static_cast<long long>(period_ms) * 1'000'000;
    out.detection_ns = static_cast<long long>(detection_ms) * 1'000'000;

    const auto start = Clock::now();
    const auto end = start + std::chrono::duration<double>(seconds);
    std::map<unsigned long long, Clock::time_point> sent;
    std::vector<double> rtts;
    auto next_beat = start;
    auto last_answer = start;
    bool discovered = false, reported = false, lost = false;
    std::uint32_t max_alive = 0;
    unsigned long long seq = 0;
    std::printf("%s on domain %u interface %s\n", role.c_str(), participant.domain(),
                options.interface.c_str());
    std::fflush(stdout);
    while (g_stop == 0 && Clock::now() < end) {
      if (role == "ping" && Clock::now() >= next_beat) {
        out.seq = ++seq;
        sent[seq] = Clock::now();
        if (sent.size() > 10'000) sent.erase(sent.begin());
        rccx::net::check(dds_write(writer.get(), &out), "writing a heartbeat");
        next_beat += std::chrono::milliseconds(period_ms);
      }
      const auto wait_ns =
          role == "ping"
              ? std::max<std::int64_t>(0, std::chrono::duration_cast<std::chrono::nanoseconds>(
                                              next_beat - Clock::now())
                                              .count())
              : DDS_MSECS(50);
      dds_waitset_wait(waitset.get(), nullptr, 0, wait_ns);
      for (;;) {
        rccx_net_Heartbeat in{};
        void* samples[1] = {&in};
        dds_sample_info_t info[1];
        if (dds_take(reader.get(), samples, info, 1, 1) != 1) break;
        if (!info[0].valid_data) continue;
        const std::string from = in.participant;
        if (role == "pong" && from.rfind("ping/", 0) == 0) {
          out.seq = in.seq;
          rccx::net::check(dds_write(writer.get(), &out), "answering a heartbeat");
        } else if (role == "ping" && from.rfind("pong/", 0) == 0) {
          const auto it = sent.find(in.seq);
          if (it == sent.end()) continue;
          if (!discovered) {
            std::printf("discovered after %.1f ms\n", ms_since(start));
            discovered = true;
          }
          if (lost) {
            std::printf("back after %.1f ms\n", ms_since(last_answer));
            lost = false;
          }
          last_answer = Clock::now();
          rtts.push_back(
              std::chrono::duration<double, std::milli>(last_answer - it->second).count());
          sent.erase(it);
        }
      }
      if (role == "ping" && !reported && static_cast<int>(rtts.size()) >= count) {
        std::vector<double> s = rtts;
        std::sort(s.begin(), s.end());
        auto at = [&](double q) {
          return s[std::min(s.size() - 1,
                            static_cast<std::size_t>(q * static_cast<double>(s.size())))];
        };
        std::printf("rtt_ms n=%zu sent=%llu p50=%.3f p99=%.3f max=%.3f\n", s.size(), seq, at(0.5),
                    at(0.99), s.back());
        reported = true;
        if (!watch) break;
        std::printf("watching\n");
      }
      if (role == "ping" && reported && !lost) {
        dds_liveliness_changed_status_t live{};
        dds_get_liveliness_changed_status(reader.get(), &live);
        // Our own writer matches our reader too: pong's loss shows as the count falling.
        max_alive = std::max(max_alive, live.alive_count);
        if (live.alive_count < max_alive && discovered) {
          std::printf("lost after %.1f ms\n", ms_since(last_answer));
          lost = true;
        }
      }
      std::fflush(stdout);
    }
    std::fflush(stdout);
    return role == "ping" && !reported ? 3 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rccx_netns_dds_peer: %s\n", e.what());
    return 1;
  }
}
