// rccx's network layer across processes on loopback, with its own types and net::Participant
// (make bench-net; scripts/bench-net puts these beside Cyclone's ddsperf ping/pong):
//
//   BM_NetRequestAckRoundtrip   a MotionRequest written, its MotionAck taken: p50/p99/max over
//                               100,000 round trips. The responder is a STAND-IN (a child of
//                               this program acknowledging each request at once): rccx's types
//                               and QoS without the serve's work.
//   BM_ServeRequestAckWire      the same against a real `rccx serve` (kind attach: answered
//                               without moving the robot), this process heartbeating as a program;
//                               the ack taken from a waitset (ddsperf -W's way).
//   BM_ServeRequestAckWireListener  the same, the ack taken and the next request written by a
//                               listener in Cyclone's receive thread (ddsperf's default way).
//   BM_ServeRequestAckApi       RemoteArm::attach() through net::RemoteCell against the serve:
//                               the round trip a program's call sees.
//   BM_ServeStateOneWay         the serve's state of its robot (the PUMA at the cell's rate,
//                               1 kHz in the script): written_ns to this reader's take,
//                               100,000 states.
//   BM_NetStateOneWay           one robot's state (a ServeStates of one) from another process
//                               at 10 kHz: written_ns (CLOCK_REALTIME) to take, p50/p99/max over
//                               those of 110,000 written that the reader saw (keep last 1: it
//                               may miss some).
//   BM_NetStateFleet/N          N robots' states written every 1 ms by another process for a few
//                               seconds as a serve writes them (net::StateBatch: one ServeStates
//                               sample a period, a part per 256 robots); the reader takes them
//                               in a listener (Cyclone's receive thread, as ddsperf's) and
//                               counts each robot's missing samples. The state topic is best
//                               effort, keep last 1 by design: "lost" is a sample the reader
//                               never saw (dropped, or overwritten before taken).
//
// Each case runs once (its own timing inside); the figures are user counters (us). The children
// are this program again (--net-role ...), so each side is a process of its own.
// Environment: RCCX_BENCH_DOMAIN (else 150 + pid % 50), RCCX_BENCH_FLEET_SECONDS (3),
// RCCX_BENCH_ROUNDTRIPS (100000), RCCX_BENCH_STATE_SAMPLES (100000), RCCX_BENCH_RCCX and
// RCCX_BENCH_CELL (the rccx executable and a cell file: the Serve cases skip without them),
// RCCX_BENCH_STATE_CELL (the cell file of BM_ServeStateOneWay, else RCCX_BENCH_CELL: the script
// gives it one with a 1 ms period, the round trips the cell as shipped),
// RCCX_BENCH_READER_DEPTH (the fleet reader's keep-last depth, 1: see fleet_reader),
// RCCX_BENCH_SECURE_DIR (DDS Security's files of rccx certs init, identities "program" here and
// "puma" in the child and the serve), RCCX_BENCH_SERVE_OPTIONS (more options for the serve, a
// diagnosis: "--no-ros2").
// Diagnoses: RCCX_BENCH_LISTENER=1 (the responder answers from a listener, in Cyclone's receive
// thread), RCCX_BENCH_KEEP_LAST=1 (request and ack reliable keep last 1, as ddsperf's ping/pong;
// 2: the readers only, 3: the writers only), RCCX_BENCH_DUMP=FILE (BM_ServeRequestAckWireListener
// writes each measured round trip there, "start_ns round_trip_ns" a line, start on
// CLOCK_MONOTONIC as the serve's ticks: scripts/roundtrip-phases finds which of them were slow),
// RCCX_BENCH_WIRE_STANDIN=1 (the wire cases against the stand-in responder, not the serve: with
// RCCX_BENCH_LISTENER=1 as well, what the serve adds to a listener's round trip).
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "rccx/cell/cell_model.hpp"
#include "rccx/net/dds.hpp"
#include "rccx/net/remote_cell.hpp"
#include "rccx/net/states.hpp"

extern char** environ;

using namespace rccx;
using namespace std::chrono_literals;

namespace {

long env_long(const char* name, long fallback) {
  const char* v = std::getenv(name);
  return (v != nullptr && *v != '\0') ? std::strtol(v, nullptr, 10) : fallback;
}

std::uint32_t bench_domain() {
  return static_cast<std::uint32_t>(env_long("RCCX_BENCH_DOMAIN", 150 + getpid() % 50));
}

net::NetOptions options(std::uint32_t domain, const char* identity) {
  net::NetOptions o;
  o.domain = domain;
  o.interface = "lo";
  if (const char* dir = std::getenv("RCCX_BENCH_SECURE_DIR"); dir != nullptr && *dir != '\0') {
    o.secure_dir = dir;
    o.secure_identity = identity;
  }
  return o;
}

/// This program run again as `--net-role ARGS...`, its stdout read back through a pipe.
class Child {
 public:
  explicit Child(const std::vector<std::string>& args) {
    std::vector<std::string> all{"/proc/self/exe", "--net-role"};
    all.insert(all.end(), args.begin(), args.end());
    spawn(all);
  }
  /// Another program: argv[0] is its path.
  struct Program {};
  Child(Program, const std::vector<std::string>& argv) { spawn(argv); }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() { finish(0ms); }

  /// SIGTERM (a serve's clean stop), then what finish() does.
  std::string terminate(std::chrono::milliseconds grace) {
    if (pid_ > 0) kill(pid_, SIGTERM);
    return finish(grace);
  }

 private:
  void spawn(std::vector<std::string> all) {
    int fds[2];
    if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, fds[1], STDOUT_FILENO);
    posix_spawn_file_actions_addclose(&fa, fds[0]);
    const int rc = posix_spawn(&pid_, all[0].c_str(), &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    close(fds[1]);
    out_ = fds[0];
    if (rc != 0) throw std::runtime_error("posix_spawn of " + all[0] + " failed");
  }

 public:
  /// Waits up to `grace` for the child to end, then kills it; returns what it printed.
  std::string finish(std::chrono::milliseconds grace) {
    if (pid_ > 0) {
      const auto until = std::chrono::steady_clock::now() + grace;
      int status = 0;
      while (waitpid(pid_, &status, WNOHANG) == 0) {
        if (std::chrono::steady_clock::now() >= until) {
          kill(pid_, SIGKILL);
          waitpid(pid_, &status, 0);
          break;
        }
        std::this_thread::sleep_for(5ms);
      }
      pid_ = 0;
    }
    std::string text;
    if (out_ >= 0) {
      char buf[512];
      ssize_t n = 0;
      while ((n = read(out_, buf, sizeof buf)) > 0) text.append(buf, static_cast<std::size_t>(n));
      close(out_);
      out_ = -1;
    }
    return text;
  }

 private:
  pid_t pid_ = 0;
  int out_ = -1;
};

/// A waitset with one read condition on `reader`: wait() until it has data or `timeout`.
class DataWait {
 public:
  DataWait(const net::Participant& p, dds_entity_t reader)
      : ws_(net::check(dds_create_waitset(p.get()), "waitset")),
        cond_(net::check(dds_create_readcondition(reader, DDS_ANY_STATE), "read condition")) {
    net::check(dds_waitset_attach(ws_.get(), cond_.get(), 0), "waitset attach");
  }
  bool wait(dds_duration_t timeout) const {
    return dds_waitset_wait(ws_.get(), nullptr, 0, timeout) > 0;
  }

 private:
  net::Entity ws_;
  net::Entity cond_;
};

bool wait_for(auto&& ready, std::chrono::seconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (!ready()) {
    if (std::chrono::steady_clock::now() >= until) return false;
    std::this_thread::sleep_for(2ms);
  }
  return true;
}

std::uint32_t writer_matches(dds_entity_t w) {
  dds_publication_matched_status_t st{};
  return dds_get_publication_matched_status(w, &st) >= 0 ? st.current_count : 0;
}
std::uint32_t reader_matches(dds_entity_t r) {
  dds_subscription_matched_status_t st{};
  return dds_get_subscription_matched_status(r, &st) >= 0 ? st.current_count : 0;
}

/// p50, p99, max of `ns` in us, set as the case's counters.
void set_latency_counters(benchmark::State& state, std::vector<std::int64_t>& ns) {
  if (ns.empty()) return;
  std::sort(ns.begin(), ns.end());
  const auto at = [&](double q) {
    const auto i = static_cast<std::size_t>(q * static_cast<double>(ns.size() - 1));
    return static_cast<double>(ns[i]) / 1e3;
  };
  state.counters["p50_us"] = at(0.50);
  state.counters["p90_us"] = at(0.90);
  state.counters["p99_us"] = at(0.99);
  state.counters["max_us"] = static_cast<double>(ns.back()) / 1e3;
  state.counters["samples"] = static_cast<double>(ns.size());
}

/// A writer of `t` reliable keep last 1, as ddsperf's ping/pong.
net::Entity keep_last_1_writer(const net::Participant& p, net::Topic t) {
  const net::Qos qos;
  dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, 1);
  return net::Entity(
      net::check(dds_create_writer(p.get(), p.topic(t), qos.get(), nullptr), "bench writer"));
}

/// A reader / writer of `t` with the topic's QoS, or, with RCCX_BENCH_KEEP_LAST=1 (a diagnosis:
/// what keep-all costs), reliable keep last 1 as ddsperf's ping/pong (2: the readers only, 3:
/// the writers only).
net::Entity endpoint(const net::Participant& p, net::Topic t, bool writer) {
  const long keep_last = env_long("RCCX_BENCH_KEEP_LAST", 0);
  const bool mine =
      writer ? (keep_last == 1 || keep_last == 3) : (keep_last == 1 || keep_last == 2);
  if (!mine) return writer ? p.writer(t) : p.reader(t);
  if (writer) return keep_last_1_writer(p, t);
  const net::Qos qos;
  dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, 1);
  return net::Entity(
      net::check(dds_create_reader(p.get(), p.topic(t), qos.get(), nullptr), "bench endpoint"));
}

// ---- the children ----------------------------------------------------------------------------

/// Takes the requests there are and acknowledges each at once (accepted, motion = request id).
struct Acknowledger {
  dds_entity_t requests;
  dds_entity_t acks;
  rccx_net_MotionAck ack{};
  void operator()() {
    void* buf[16] = {};
    dds_sample_info_t info[16];
    const dds_return_t n = dds_take(requests, buf, info, 16, 16);
    for (dds_return_t i = 0; i < n; ++i) {
      if (!info[i].valid_data) continue;
      const auto* req = static_cast<const rccx_net_MotionRequest*>(buf[i]);
      std::memcpy(ack.robot, req->robot, sizeof ack.robot);
      std::memcpy(ack.program, req->program, sizeof ack.program);
      ack.request = req->request;
      ack.result = static_cast<std::uint8_t>(net::AckResult::accepted);
      ack.motion = req->request;
      dds_write(acks, &ack);
    }
    if (n > 0) dds_return_loan(requests, buf, n);
  }
};

/// Stand-in for the serve process: acknowledges each MotionRequest at once, until the program's
/// request writer has gone. From an application thread woken by a waitset (as a serve's
/// middleware thread would), or with RCCX_BENCH_LISTENER=1 from Cyclone's receive thread (a
/// data-available listener: one thread hand-over less a message).
int run_responder(std::uint32_t domain) {
  const net::Participant p(options(domain, "puma"));
  const net::Entity requests = endpoint(p, net::Topic::request, false);
  const net::Entity acks = endpoint(p, net::Topic::ack, true);
  Acknowledger acknowledge{requests.get(), acks.get()};
  const bool by_listener = env_long("RCCX_BENCH_LISTENER", 0) != 0;
  if (by_listener) {
    dds_listener_t* l = dds_create_listener(&acknowledge);
    dds_lset_data_available(l,
                            [](dds_entity_t, void* arg) { (*static_cast<Acknowledger*>(arg))(); });
    net::check(dds_set_listener(requests.get(), l), "listener");
    dds_delete_listener(l);
  }
  const DataWait wait(p, requests.get());
  bool seen = false;
  const auto give_up = std::chrono::steady_clock::now() + 150s;
  while (std::chrono::steady_clock::now() < give_up) {
    if (by_listener || !wait.wait(DDS_MSECS(200))) {
      if (by_listener) std::this_thread::sleep_for(200ms);
      const bool matched = reader_matches(requests.get()) > 0;
      if (seen && !matched) break;  // the program is done
      seen = seen || matched;
      continue;
    }
    seen = true;
    acknowledge();
  }
  if (by_listener) dds_set_listener(requests.get(), nullptr);
  return 0;
}

/// Sleeps until `t` (CLOCK_MONOTONIC), then moves it on by `period_ns`.
void pace(timespec& t, long period_ns) {
  clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &t, nullptr);
  t.tv_nsec += period_ns;
  while (t.tv_nsec >= 1'000'000'000) {
    t.tv_nsec -= 1'000'000'000;
    ++t.tv_sec;
  }
}

/// One robot's state (a ServeStates of one, as a serve of one robot writes it), `count` times
/// at `rate_hz`, once a reader has matched; its written_ns is CLOCK_REALTIME just before writing.
int run_state_writer(std::uint32_t domain, long count, long rate_hz) {
  const net::Participant p(options(domain, "puma"));
  const net::Entity w = p.writer(net::Topic::state);
  if (!wait_for([&] { return writer_matches(w.get()) > 0; }, 30s)) return 2;
  std::this_thread::sleep_for(300ms);  // the reader's side of discovery settles too
  net::StateBatch batch("serve/bench", 1, 1);
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  for (long i = 1; i <= count; ++i) {
    pace(t, 1'000'000'000 / rate_hz);
    rccx_net_RobotState& s = batch.add();
    net::copy_to(s.robot, "puma");
    s.dof = 6;
    s.sample = static_cast<std::uint64_t>(i);
    s.written_ns = net::wall_ns();
    (void)batch.write(w.get());
  }
  std::this_thread::sleep_for(300ms);
  return 0;
}

/// `robots` robots' states every 1 ms for `seconds`, written as a serve writes them
/// (net::StateBatch: one ServeStates sample a period for all of them, a part per 256); prints
/// "periods=P late=L write_us=W" (W: mean time filling and writing a period, us).
int run_fleet_writer(std::uint32_t domain, int robots, long seconds) {
  const net::Participant p(options(domain, "puma"));
  const net::Entity w = p.writer(net::Topic::state);
  if (!wait_for([&] { return writer_matches(w.get()) > 0; }, 30s)) return 2;
  std::this_thread::sleep_for(300ms);
  net::StateBatch batch("serve/bench", 1, static_cast<std::size_t>(robots));
  std::vector<std::array<char, 16>> names(static_cast<std::size_t>(robots));
  for (int k = 0; k < robots; ++k) {
    std::snprintf(names[static_cast<std::size_t>(k)].data(), 16, "r%d", k);
  }
  long periods = 0;
  long late = 0;
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  std::int64_t write_ns = 0;  // time spent filling and writing, all periods
  // seconds * 1000 periods, or fewer when writing overruns the period: stop at `seconds`.
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  for (long i = 1; i <= seconds * 1000 && std::chrono::steady_clock::now() < end; ++i) {
    periods = i;
    pace(t, 1'000'000);
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& name : names) {
      rccx_net_RobotState& s = batch.add();
      net::copy_to(s.robot, name.data());
      s.dof = 6;
      s.sample = static_cast<std::uint64_t>(i);
    }
    (void)batch.write(w.get());
    write_ns += (std::chrono::steady_clock::now() - t0).count();
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    if (now.tv_sec > t.tv_sec || (now.tv_sec == t.tv_sec && now.tv_nsec > t.tv_nsec)) ++late;
  }
  std::this_thread::sleep_for(300ms);
  std::printf("periods=%ld late=%ld write_us=%.1f\n", periods, late,
              static_cast<double>(write_ns) / 1e3 / static_cast<double>(std::max(periods, 1L)));
  std::fflush(stdout);
  return 0;
}

int run_role(int argc, char** argv) {
  const std::string_view role = argc > 2 ? argv[2] : "";
  const auto arg = [&](int i) { return argc > i ? std::strtol(argv[i], nullptr, 10) : 0L; };
  try {
    const auto domain = static_cast<std::uint32_t>(arg(3));
    if (role == "responder") return run_responder(domain);
    if (role == "state-writer") return run_state_writer(domain, arg(4), arg(5));
    if (role == "fleet-writer") {
      return run_fleet_writer(domain, static_cast<int>(arg(4)), arg(5));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "net_bench %s: %s\n", std::string(role).c_str(), e.what());
    return 1;
  }
  std::fprintf(stderr, "net_bench: unknown role '%s'\n", std::string(role).c_str());
  return 1;
}

// ---- the cases -------------------------------------------------------------------------------

void BM_NetRequestAckRoundtrip(benchmark::State& state) {
  const std::uint32_t domain = bench_domain();
  const long roundtrips = env_long("RCCX_BENCH_ROUNDTRIPS", 100'000);
  for (auto _ : state) {
    const net::Participant p(options(domain, "program"));
    const net::Entity requests = endpoint(p, net::Topic::request, true);
    const net::Entity acks = endpoint(p, net::Topic::ack, false);
    const DataWait wait(p, acks.get());
    Child responder({"responder", std::to_string(domain)});
    if (!wait_for(
            [&] { return writer_matches(requests.get()) > 0 && reader_matches(acks.get()) > 0; },
            30s)) {
      state.SkipWithError("the responder did not match in 30 s");
      return;
    }
    rccx_net_MotionRequest req{};
    net::copy_to(req.robot, "puma");
    net::copy_to(req.program, "bench");
    req.kind = static_cast<std::uint8_t>(net::RequestKind::move);
    std::vector<std::int64_t> ns;
    ns.reserve(static_cast<std::size_t>(roundtrips));
    const long warmup = 2000;
    for (long i = 1; i <= warmup + roundtrips; ++i) {
      req.request = static_cast<std::uint64_t>(i);
      const auto t0 = std::chrono::steady_clock::now();
      dds_write(requests.get(), &req);
      bool acked = false;
      while (!acked) {
        if (!wait.wait(DDS_SECS(2))) {
          state.SkipWithError("no acknowledgement in 2 s");
          return;
        }
        void* buf[4] = {};
        dds_sample_info_t info[4];
        const dds_return_t n = dds_take(acks.get(), buf, info, 4, 4);
        for (dds_return_t k = 0; k < n; ++k) {
          acked = acked || (info[k].valid_data &&
                            static_cast<const rccx_net_MotionAck*>(buf[k])->request == req.request);
        }
        if (n > 0) dds_return_loan(acks.get(), buf, n);
      }
      const auto t1 = std::chrono::steady_clock::now();
      if (i > warmup) ns.push_back((t1 - t0).count());
    }
    set_latency_counters(state, ns);
    state.counters["responder_is_stand_in"] = 1;
  }
}
BENCHMARK(BM_NetRequestAckRoundtrip)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_NetStateOneWay(benchmark::State& state) {
  const std::uint32_t domain = bench_domain();
  const long count = env_long("RCCX_BENCH_ROUNDTRIPS", 100'000) * 11 / 10;
  const long rate_hz = 10'000;
  for (auto _ : state) {
    const net::Participant p(options(domain, "program"));
    const net::Entity states = p.reader(net::Topic::state);
    const DataWait wait(p, states.get());
    Child writer(
        {"state-writer", std::to_string(domain), std::to_string(count), std::to_string(rate_hz)});
    std::vector<std::int64_t> ns;
    ns.reserve(static_cast<std::size_t>(count));
    std::uint64_t last = 0;
    long lost = 0;
    net::StateInbox in;
    const auto limit =
        std::chrono::steady_clock::now() + 30s + std::chrono::seconds(count / rate_hz);
    while (last < static_cast<std::uint64_t>(count) && std::chrono::steady_clock::now() < limit) {
      if (!wait.wait(DDS_MSECS(500))) {
        if (last > 0) break;  // the writer is done or gone
        continue;
      }
      const std::int64_t now = net::wall_ns();
      in.drain(states.get(), [&](const rccx_net_RobotState& s) {
        if (last > 0 && s.sample > last + 1) lost += static_cast<long>(s.sample - last - 1);
        last = s.sample;
        ns.push_back(now - s.written_ns);
      });
    }
    (void)writer.finish(5s);
    set_latency_counters(state, ns);
    state.counters["lost"] = static_cast<double>(lost);
    state.counters["rate_hz"] = static_cast<double>(rate_hz);
  }
}
BENCHMARK(BM_NetStateOneWay)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- against a real `rccx serve` -------------------------------------------------------------

/// `rccx serve` of `robots` (RCCX_BENCH_RCCX: the rccx executable; RCCX_BENCH_CELL: its cell
/// file), secured as "puma" when RCCX_BENCH_SECURE_DIR is set; nullptr (the case skips) when
/// either is unset.
std::unique_ptr<Child> start_serve(std::uint32_t domain, const char* robots,
                                   const char* cell_variable = "RCCX_BENCH_CELL") {
  const char* rccx_exe = std::getenv("RCCX_BENCH_RCCX");
  const char* cell = std::getenv(cell_variable);
  if (cell == nullptr || *cell == '\0') cell = std::getenv("RCCX_BENCH_CELL");
  if (rccx_exe == nullptr || cell == nullptr || *rccx_exe == '\0' || *cell == '\0') return nullptr;
  std::vector<std::string> argv{rccx_exe,      "serve", "--cell",       cell,
                                "--robots",    robots,  "--domain",     std::to_string(domain),
                                "--interface", "lo",    "--claim-wait", "100ms",
                                "--seconds",   "900"};
  if (const char* dir = std::getenv("RCCX_BENCH_SECURE_DIR"); dir != nullptr && *dir != '\0') {
    argv.insert(argv.end(), {"--secure", dir, "--identity", "puma"});
  }
  // A diagnosis: more options for the serve, space-separated (e.g. "--no-ros2").
  if (const char* extra = std::getenv("RCCX_BENCH_SERVE_OPTIONS"); extra != nullptr) {
    std::istringstream words(extra);
    for (std::string w; words >> w;) argv.push_back(w);
  }
  return std::make_unique<Child>(Child::Program{}, argv);
}

/// The serve's own count of how it answered (`rccx serve: N requests: A answered at once in the
/// listener, B by the middleware thread ...`, printed when it stops) as counters: the share of
/// requests that found the middleware thread in a pass and waited for its next one.
void serve_request_counters(benchmark::State& state, const std::string& serve_output) {
  const std::string key = "rccx serve: ";
  for (std::size_t at = serve_output.find(key); at != std::string::npos;
       at = serve_output.find(key, at + 1)) {
    unsigned long long total = 0, listener = 0, pass = 0;
    if (std::sscanf(serve_output.c_str() + at + key.size(),
                    "%llu requests: %llu answered at once in the listener, %llu by the middleware",
                    &total, &listener, &pass) == 3 &&
        total > 0) {
      state.counters["serve_answered_in_pass"] = static_cast<double>(pass);
      state.counters["serve_answered_in_pass_pct"] =
          100.0 * static_cast<double>(pass) / static_cast<double>(total);
      return;
    }
  }
}

constexpr const char* kNoServe =
    "set RCCX_BENCH_RCCX (the rccx executable) and RCCX_BENCH_CELL (a cell file) to run "
    "against rccx serve (scripts/bench-net does)";

/// What both wire cases share: this process as a program (a request writer, an ack reader, a
/// heartbeat every 5 ms outside the timed part so the serve keeps it attached) beside a real
/// `rccx serve` of the PUMA, matched; requests of kind attach (answered without moving the robot
/// at rest, through the serve's whole request path: the dedup table, Manipulator::last_queued,
/// the ack written).
struct WireProgram {
  net::Participant p;
  net::Entity requests;
  net::Entity acks;
  net::Entity beats;
  std::unique_ptr<Child> serve;
  rccx_net_Heartbeat hb{};
  rccx_net_MotionRequest req{};
  std::chrono::steady_clock::time_point beat_at = std::chrono::steady_clock::now();

  /// `keep_last_1`: the requests written reliable keep last 1 (ddsperf's ping QoS) instead of
  /// the topic's keep all; see BM_ServeRequestAckWireListener.
  WireProgram(std::uint32_t domain, bool keep_last_1)
      : p(options(domain, "program")),
        requests(keep_last_1 ? keep_last_1_writer(p, net::Topic::request)
                             : p.writer(net::Topic::request)),
        acks(p.reader(net::Topic::ack)),
        beats(p.writer(net::Topic::heartbeat)) {
    const std::string program = "program/bench-" + std::to_string(getpid());
    net::copy_to(hb.participant, program);
    hb.role = static_cast<std::uint8_t>(net::Role::program);
    hb.instance = 42;
    hb.period_ns = 5'000'000;
    hb.detection_ns = 20'000'000;
    net::copy_to(hb.robots, "puma");
    net::copy_to(req.robot, "puma");
    net::copy_to(req.program, program);
    req.program_instance = hb.instance;
    req.kind = static_cast<std::uint8_t>(net::RequestKind::attach);
  }
  /// Starts the serve and waits for it to match: "" when ready, else why the case skips.
  std::string start(std::uint32_t domain) {
    // A diagnosis: the stand-in responder instead of the serve (what the serve adds).
    if (env_long("RCCX_BENCH_WIRE_STANDIN", 0) != 0) {
      serve =
          std::make_unique<Child>(std::vector<std::string>{"responder", std::to_string(domain)});
    } else {
      serve = start_serve(domain, "puma");
    }
    if (!serve) return kNoServe;
    if (!wait_for(
            [&] { return writer_matches(requests.get()) > 0 && reader_matches(acks.get()) > 0; },
            30s)) {
      return "rccx serve did not match in 30 s (see its stderr)";
    }
    return "";
  }
  void beat_if_due() {
    if (std::chrono::steady_clock::now() < beat_at) return;
    ++hb.seq;
    dds_write(beats.get(), &hb);
    beat_at += 5ms;
  }
  /// Takes the acks there are: true when one answers request `id`.
  bool take_ack(std::uint64_t id) const {
    void* buf[4] = {};
    dds_sample_info_t info[4];
    const dds_return_t n = dds_take(acks.get(), buf, info, 4, 4);
    bool acked = false;
    for (dds_return_t k = 0; k < n; ++k) {
      acked = acked ||
              (info[k].valid_data && static_cast<const rccx_net_MotionAck*>(buf[k])->request == id);
    }
    if (n > 0) dds_return_loan(acks.get(), buf, n);
    return acked;
  }
};

/// The wire round trip against the real serve, its ack taken by this thread from a waitset (as
/// a program's middleware thread would): like ddsperf's ping/pong in waitset mode (-W).
void BM_ServeRequestAckWire(benchmark::State& state) {
  const std::uint32_t domain = bench_domain();
  const long roundtrips = env_long("RCCX_BENCH_ROUNDTRIPS", 100'000);
  for (auto _ : state) {
    WireProgram w(domain, false);
    const DataWait wait(w.p, w.acks.get());
    if (const std::string why = w.start(domain); !why.empty()) {
      state.SkipWithError(why.c_str());
      return;
    }
    std::vector<std::int64_t> ns;
    ns.reserve(static_cast<std::size_t>(roundtrips));
    const long warmup = 2000;
    for (long i = 1; i <= warmup + roundtrips; ++i) {
      w.beat_if_due();
      w.req.request = static_cast<std::uint64_t>(i);
      const auto t0 = std::chrono::steady_clock::now();
      dds_write(w.requests.get(), &w.req);
      bool acked = false;
      while (!acked) {
        // The first answers wait for the serve's cell to start.
        if (!wait.wait(i == 1 ? DDS_SECS(20) : DDS_SECS(2))) {
          state.SkipWithError("rccx serve sent no acknowledgement in 2 s");
          return;
        }
        acked = w.take_ack(w.req.request);
      }
      const auto t1 = std::chrono::steady_clock::now();
      if (i > warmup) ns.push_back((t1 - t0).count());
    }
    set_latency_counters(state, ns);
    serve_request_counters(state, w.serve->terminate(5s));
  }
}
BENCHMARK(BM_ServeRequestAckWire)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The same round trip with the ack taken, and the next request written, by a data-available
/// listener in Cyclone's receive thread: like ddsperf's ping/pong in its default (listener)
/// mode, one thread woken a message. This thread only heartbeats and watches progress. The
/// requests are written reliable keep last 1, as ddsperf's pings: a keep-all writer in the
/// receive thread is throttled once its unacknowledged data pass Cyclone's WhcHigh, waiting for
/// acknowledgements that only that thread reads (it stalled after 28 requests, then timed out).
/// The serve's side is rccx's own: its request reader and ack writer as shipped.
void BM_ServeRequestAckWireListener(benchmark::State& state) {
  const std::uint32_t domain = bench_domain();
  const long roundtrips = env_long("RCCX_BENCH_ROUNDTRIPS", 100'000);
  struct Pinger {
    WireProgram* w = nullptr;
    long total = 0;
    long warmup = 2000;
    std::vector<std::int64_t> ns, at;
    std::chrono::steady_clock::time_point t0;
    std::atomic<long> sent{0};  // the request in flight
    std::atomic<bool> done{false};
    // Who heartbeats: the main thread until the listener answers steadily, then the listener,
    // between round trips. Cleared by the main thread after its last beat, so that the two
    // never write one at once.
    std::atomic<bool> main_beats{true};
    void send() {
      const long i = sent.load() + 1;
      w->req.request = static_cast<std::uint64_t>(i);
      t0 = std::chrono::steady_clock::now();
      sent.store(i);
      dds_write(w->requests.get(), &w->req);
    }
    void on_acks() {  // Cyclone's receive thread
      const long i = sent.load();
      if (done.load() || !w->take_ack(static_cast<std::uint64_t>(i))) return;
      if (i > warmup) {
        ns.push_back((std::chrono::steady_clock::now() - t0).count());
        at.push_back(t0.time_since_epoch().count());
      }
      if (!main_beats.load(std::memory_order_acquire)) w->beat_if_due();
      if (i < total) {
        send();
      } else {
        done.store(true);
      }
    }
  };
  for (auto _ : state) {
    WireProgram w(domain, true);
    if (const std::string why = w.start(domain); !why.empty()) {
      state.SkipWithError(why.c_str());
      return;
    }
    Pinger ping;
    ping.w = &w;
    ping.total = ping.warmup + roundtrips;
    ping.ns.reserve(static_cast<std::size_t>(roundtrips));
    ping.at.reserve(static_cast<std::size_t>(roundtrips));
    dds_listener_t* l = dds_create_listener(&ping);
    dds_lset_data_available(l,
                            [](dds_entity_t, void* arg) { static_cast<Pinger*>(arg)->on_acks(); });
    net::check(dds_set_listener(w.acks.get(), l), "listener");
    dds_delete_listener(l);
    w.beat_if_due();
    ping.send();
    long seen = 0;
    auto progress_at = std::chrono::steady_clock::now();
    std::string failed;
    // Then this thread only watches progress, every 100 ms: its heartbeat writes and 1 ms
    // wake-ups, beside the receive threads on 2 cores, were inside the timed round trips
    // (ddsperf's main thread sleeps meanwhile too).
    while (!ping.done.load()) {
      const bool beating = ping.main_beats.load(std::memory_order_relaxed);
      std::this_thread::sleep_for(beating ? 1ms : 100ms);
      if (beating) {
        w.beat_if_due();
        if (ping.sent.load() > 2) ping.main_beats.store(false, std::memory_order_release);
      }
      const auto now = std::chrono::steady_clock::now();
      if (const long s = ping.sent.load(); s != seen) {
        seen = s;
        progress_at = now;
      } else if (now - progress_at > (seen <= 1 ? 20s : 2s)) {  // the first waits for the cell
        failed = "rccx serve sent no acknowledgement in 2 s";
        break;
      }
    }
    dds_set_listener(w.acks.get(), nullptr);  // waits for a callback under way
    if (!failed.empty()) {
      state.SkipWithError(failed.c_str());
      return;
    }
    if (const char* dump = std::getenv("RCCX_BENCH_DUMP"); dump != nullptr) {
      FILE* f = std::fopen(dump, "w");
      bool written = f != nullptr;
      for (std::size_t k = 0; written && k < ping.ns.size(); ++k) {
        written = std::fprintf(f, "%lld %lld\n", static_cast<long long>(ping.at[k]),
                               static_cast<long long>(ping.ns[k])) > 0;
      }
      if (f != nullptr) written = std::fclose(f) == 0 && written;
      if (!written) {
        const std::string why = std::string("RCCX_BENCH_DUMP: could not write ") + dump + ": " +
                                std::strerror(errno) + " (give a writable file)";
        state.SkipWithError(why.c_str());
        (void)w.serve->terminate(5s);
        return;
      }
    }
    set_latency_counters(state, ping.ns);
    serve_request_counters(state, w.serve->terminate(5s));
  }
}
BENCHMARK(BM_ServeRequestAckWireListener)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// What a program sees: RemoteArm::attach() through net::RemoteCell (its request written from
/// the calling thread, the ack taken by its middleware thread from a waitset and handed over
/// through a condition variable) against the real serve.
void BM_ServeRequestAckApi(benchmark::State& state) {
  const std::uint32_t domain = bench_domain();
  const long roundtrips = env_long("RCCX_BENCH_ROUNDTRIPS", 100'000);
  for (auto _ : state) {
    const std::unique_ptr<Child> serve = start_serve(domain, "puma");
    if (!serve) {
      state.SkipWithError(kNoServe);
      return;
    }
    try {
      net::RemoteOptions ro;
      ro.robots = {"puma"};
      ro.wait_for_robots = 30s;
      net::RemoteCell cell(cell::load_cell_file(std::getenv("RCCX_BENCH_CELL")),
                           options(domain, "program"), ro);
      net::RemoteArm& puma = cell.robot("puma");
      std::vector<std::int64_t> ns;
      ns.reserve(static_cast<std::size_t>(roundtrips));
      const long warmup = 2000;
      for (long i = 1; i <= warmup + roundtrips; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        puma.attach();
        const auto t1 = std::chrono::steady_clock::now();
        if (i > warmup) ns.push_back((t1 - t0).count());
      }
      set_latency_counters(state, ns);
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      return;
    }
    serve_request_counters(state, serve->terminate(5s));
  }
}
BENCHMARK(BM_ServeRequestAckApi)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The serve's RobotState one way: its written_ns (CLOCK_REALTIME, as the middleware thread
/// writes it) to this reader's take (same clock, same host), over RCCX_BENCH_STATE_SAMPLES
/// (100,000) states of the PUMA at its sample rate (the script's cell: 1 ms; the Microbo's
/// link needs 11.3 ms at least, so it is not served here).
/// Also counts the samples missed (gaps in each robot's sample numbers).
void BM_ServeStateOneWay(benchmark::State& state) {
  const std::uint32_t domain = bench_domain();
  const long want = env_long("RCCX_BENCH_STATE_SAMPLES", 100'000);
  for (auto _ : state) {
    const net::Participant p(options(domain, "program"));
    const net::Entity states = p.reader(net::Topic::state);
    const DataWait wait(p, states.get());
    const std::unique_ptr<Child> serve = start_serve(domain, "puma", "RCCX_BENCH_STATE_CELL");
    if (!serve) {
      state.SkipWithError(kNoServe);
      return;
    }
    std::vector<std::int64_t> ns;
    ns.reserve(static_cast<std::size_t>(want));
    std::uint64_t last = 0;
    long lost = 0;
    long warm = 0;  // the first 1,000 states (the cell starting) are left out
    std::uint64_t first_sample = 0;
    std::int64_t first_ns = 0;
    std::int64_t last_ns = 0;
    net::StateInbox in;
    const auto limit = std::chrono::steady_clock::now() + 60s + std::chrono::seconds(want / 500);
    // (want / 500 s: twice the time 1 kHz needs.)
    while (static_cast<long>(ns.size()) < want && std::chrono::steady_clock::now() < limit) {
      if (!wait.wait(DDS_MSECS(500))) continue;
      const std::int64_t now = net::wall_ns();
      in.drain(states.get(), [&](const rccx_net_RobotState& s) {
        if (s.sample == last) return;  // the heartbeat's repeat of the same state
        if (last > 0 && s.sample > last + 1 && warm >= 1000) {
          lost += static_cast<long>(s.sample - last - 1);
        }
        last = s.sample;
        if (++warm > 1000) {
          if (ns.empty()) {
            first_sample = s.sample;
            first_ns = now;
          }
          last_ns = now;
          ns.push_back(now - s.written_ns);
        }
      });
    }
    (void)serve->terminate(5s);
    set_latency_counters(state, ns);
    state.counters["lost"] = static_cast<double>(lost);
    // The serve's pace: its samples a second of the wall clock (below 1,000: it overran).
    state.counters["rate_hz"] = last_ns > first_ns
                                    ? static_cast<double>(last - first_sample) * 1e9 /
                                          static_cast<double>(last_ns - first_ns)
                                    : 0.0;
  }
}
BENCHMARK(BM_ServeStateOneWay)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The fleet's reader: the state topic's QoS, or with RCCX_BENCH_READER_DEPTH=N (a diagnosis)
/// keep last N per part, so that a sample overwritten before the listener took it is told
/// apart from one the transport lost.
net::Entity fleet_reader(const net::Participant& p) {
  const long depth = env_long("RCCX_BENCH_READER_DEPTH", 0);
  if (depth <= 1) return p.reader(net::Topic::state);
  const net::Qos qos;
  dds_qset_reliability(qos.get(), DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, static_cast<int32_t>(depth));
  return net::Entity(net::check(
      dds_create_reader(p.get(), p.topic(net::Topic::state), qos.get(), nullptr), "reader"));
}

/// What the fleet's reader counted: each robot's states seen and the gaps in its sample numbers.
/// Touched by the reader's listener only, until it is removed.
struct FleetCount {
  explicit FleetCount(int robots)
      : received(static_cast<std::size_t>(robots), 0), last(static_cast<std::size_t>(robots), 0) {}
  std::vector<long> received;
  std::vector<std::uint64_t> last;
  long gaps = 0;
  net::StateInbox in{8};
};

/// Data available on the fleet's reader: taken at once, in Cyclone's receive thread (ddsperf's
/// default way), so that no wake-up of another thread stands between a sample and its take.
void fleet_on_data(dds_entity_t reader, void* arg) {
  auto& c = *static_cast<FleetCount*>(arg);
  c.in.drain(reader, [&](const rccx_net_RobotState& s) {
    const long r = std::strtol(s.robot + 1, nullptr, 10);
    if (r < 0 || r >= static_cast<long>(c.received.size())) return;
    const auto i = static_cast<std::size_t>(r);
    if (c.last[i] > 0 && s.sample > c.last[i] + 1) {
      c.gaps += static_cast<long>(s.sample - c.last[i] - 1);
    }
    c.last[i] = s.sample;
    ++c.received[i];
  });
}

void BM_NetStateFleet(benchmark::State& state) {
  const std::uint32_t domain = bench_domain();
  const auto robots = static_cast<int>(state.range(0));
  const long seconds = env_long("RCCX_BENCH_FLEET_SECONDS", 3);
  for (auto _ : state) {
    const net::Participant p(options(domain, "program"));
    const net::Entity states = fleet_reader(p);
    FleetCount count(robots);
    dds_listener_t* l = dds_create_listener(&count);
    dds_lset_data_available(l, &fleet_on_data);
    net::check(dds_set_listener(states.get(), l), "listener");
    dds_delete_listener(l);
    Child writer(
        {"fleet-writer", std::to_string(domain), std::to_string(robots), std::to_string(seconds)});
    // The writer waits up to 30 s for the match, writes for `seconds`, then says what it did.
    const std::string said = writer.finish(40s + std::chrono::seconds(seconds));
    std::this_thread::sleep_for(100ms);       // the last samples in flight
    dds_set_listener(states.get(), nullptr);  // waits for a callback under way
    const std::vector<long>& received = count.received;
    const long gaps = count.gaps;
    long periods = 0;
    long late = 0;
    double write_us = 0.0;
    if (std::sscanf(said.c_str(), "periods=%ld late=%ld write_us=%lf", &periods, &late,
                    &write_us) != 3) {
      state.SkipWithError("the fleet writer did not finish (see its stderr)");
      return;
    }
    long lost = 0;
    long robots_with_loss = 0;
    for (const long got : received) {
      lost += periods - got;
      robots_with_loss += got < periods ? 1 : 0;
    }
    state.counters["robots"] = robots;
    state.counters["periods"] = static_cast<double>(periods);
    state.counters["periods_due"] = static_cast<double>(seconds * 1000);
    state.counters["late_periods"] = static_cast<double>(late);
    state.counters["write_us_per_period"] = write_us;
    state.counters["lost"] = static_cast<double>(lost);
    state.counters["gaps_seen"] = static_cast<double>(gaps);
    state.counters["robots_with_loss"] = static_cast<double>(robots_with_loss);
    // Every period's sample written (the writer kept 1 kHz: a period finished late on this VM's
    // scheduling, as one robot's is too, still has its sample) and every one read.
    state.counters["no_loss"] = lost == 0 && periods == seconds * 1000 ? 1 : 0;
  }
}
BENCHMARK(BM_NetStateFleet)
    ->Arg(1)
    ->Arg(64)
    ->Arg(256)
    ->Arg(512)
    ->Arg(1024)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && std::string_view(argv[1]) == "--net-role") return run_role(argc, argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
