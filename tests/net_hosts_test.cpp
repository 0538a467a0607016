// The cell across hosts (issue 29, "Hosts"; docs/NETWORK.md, "Across hosts: delay, loss and a
// cut link"): the PUMA's `rccx serve` in host a, the Microbo's in host b and the program in
// host c, three network namespaces on one segment through the test's relay (2 ms each way, 1 %
// of frames lost each way; tests/net/netns_fixture.hpp). With that link the program's motions
// all reach their ends and the Microbo tracks the PUMA's tool within a bound, and the thesis's
// circuit-board demonstration (examples/10_circuit_board --remote in host c, as
// scripts/demo-distributed runs it on loopback) probes every pad within its error bound; with
// the link cut, each serve stops its robot smoothly within the detection time and says why, and
// the program sees its motions fail with the reason. Root only: skipped, saying why, elsewhere.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <initializer_list>
#include <map>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "net_attempts.hpp"
#include "net_path_checks.hpp"
#include "netns_fixture.hpp"
#include "rccx/cell/cell_model.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/net/dds.hpp"
#include "rccx/rccl/trajectory.hpp"

using namespace rccx;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {

const std::string kCell = std::string(RCCX_CELLS_DIR) + "/cvarl.json";

/// The serves' and the program's detection time. Heartbeats go every detection / 4 = 25 ms, so
/// a peer counts as lost only when 4 in a row are lost or late: at 1 % loss, 1e-8 a window. Each
/// crossing adds 2 ms (4 ms a round trip) and the relay's and this loaded 2-core machine's
/// scheduling add tens of ms now and then; the 20 ms default would stop the robots for a stall
/// of the test machine rather than of the link. 100 ms is UR's RTDE watchdog at its lowest rate.
constexpr int kDetectionMs = 100;
/// The PUMA's period in cvarl.json (7 ms) and the Microbo's (4 x 7 ms), s.
constexpr double kPumaPeriodS = 0.007, kMicroboPeriodS = 0.028;
/// What a loaded machine may add to any of the times measured here (scheduling of five
/// processes and the relay on 2 cores shared with other builds): one more detection time.
constexpr double kSlackMs = kDetectionMs;

/// A domain of this test process's own (the namespaces are private, this only keeps runs of the
/// test that overlap apart).
std::string domain() {
  return std::to_string(100 + getpid() % 100);
}

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

/// Starts `argv` in host `host` under SCHED_FIFO at priority 1 (`chrt -f 1`), as a controller
/// would run it: rccx's middleware threads raise themselves to that, but Cyclone's receive and
/// timed-event threads are made in the process's class, and on this 2-core machine under a load
/// of 6 (other builds and tests) normal threads were starved for over 100 ms now and then, which
/// the serves and the program rightly took for a lost link. The control tasks stay above it.
netns::Child spawn_rt(netns::Hosts& hosts, int host, std::vector<std::string> argv) {
  argv.insert(argv.begin(), {"chrt", "-f", "1"});
  return hosts.spawn(host, argv);
}

/// `rccx serve` of `robots` in host `host`, on the host's interface.
netns::Child serve(netns::Hosts& hosts, int host, const std::string& robots, const std::string& d) {
  return spawn_rt(hosts, host,
                  {RCCX_EXE, "serve", "--cell", kCell, "--robots", robots, "--domain", d,
                   "--interface", netns::Hosts::kInterface, "--detection",
                   std::to_string(kDetectionMs) + "ms", "--claim-wait", "1s", "--seconds", "170"});
}

/// Waits for both serves to serve; the message says what they printed when one did not.
::testing::AssertionResult serving(const netns::Child& a, const netns::Child& b) {
  for (const netns::Child* c : {&a, &b}) {
    if (!c->wait_for_output("rccx serve: serving", 30s)) {
      return ::testing::AssertionFailure() << "a serve did not start in 30 s:\nhost a:\n"
                                           << a.output() << "\nhost b:\n"
                                           << b.output();
    }
  }
  return ::testing::AssertionSuccess();
}

std::string read_file(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// A file deleted when this goes (after a failed assertion too).
struct RemovedAtEnd {
  std::string path;
  ~RemovedAtEnd() { std::remove(path.c_str()); }
};

/// One RobotState as a recorder in the serve's own host received it.
struct Sample {
  std::uint64_t sample = 0;
  std::int64_t stamp_ns = 0;     ///< CLOCK_REALTIME the setpoint is for
  std::int64_t received_ns = 0;  ///< steady clock
  double period_s = 0;
  std::vector<double> q;
};

std::vector<Sample> samples_of(const std::string& file, const std::string& robot) {
  std::vector<Sample> v;
  std::istringstream in(read_file(file));
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream l(line);
    std::string name;
    Sample s;
    unsigned status = 0;
    l >> name >> s.sample >> s.stamp_ns >> s.received_ns >> s.period_s >> status;
    if (!l || name != robot) continue;
    double q = 0;
    while (l >> q) s.q.push_back(q);
    if (v.empty() || s.sample > v.back().sample) v.push_back(std::move(s));
  }
  return v;
}

/// The generator's acceleration bounds for a robot of the cell (rad/s^2), as its serve has them.
kin::JointVector acceleration_bounds(const std::string& robot) {
  const cell::CellModel m = cell::load_cell_file(kCell);
  const cell::CellRobot* r = m.find_robot(robot);
  const auto k = kin::make_kinematics(r->model);
  rccl::GeneratorOptions o;
  o.period_s =
      std::chrono::duration<double>(m.period(static_cast<std::size_t>(r - m.robots.data())))
          .count();
  const rccl::TrajectoryGenerator g(*k, o);
  return g.options().max_acceleration;
}

double step(const std::vector<Sample>& v, std::size_t i) {
  double s = 0;
  for (std::size_t j = 0; j < v[i].q.size(); ++j) s += std::pow(v[i].q[j] - v[i - 1].q[j], 2);
  return std::sqrt(s);
}

/// How a serve stopped its robot after the cut, from the samples recorded in its host.
struct Stop {
  double slowing_ms = -1;  ///< cut -> the first setpoint slower than before the cut (stamp)
  double rest_ms = -1;     ///< cut -> the first setpoint equal to the one before
  double accel_ratio = 0;  ///< worst |acceleration| / the generator's bound around the stop
  std::size_t samples = 0;
};

Stop stop_of(const std::vector<Sample>& v, std::int64_t cut_wall_ns, const std::string& robot) {
  Stop s;
  s.samples = v.size();
  std::size_t cut = 0;
  while (cut < v.size() && v[cut].stamp_ns < cut_wall_ns) ++cut;
  if (cut < 12 || cut + 2 >= v.size()) return s;
  // The joint step per sample while cruising: the median of the 10 before the cut.
  std::vector<double> before;
  for (std::size_t i = cut - 10; i < cut; ++i) before.push_back(step(v, i));
  std::sort(before.begin(), before.end());
  const double cruise = before[before.size() / 2];
  for (std::size_t i = cut; i < v.size(); ++i) {
    const double d = step(v, i);
    const double at_ms = static_cast<double>(v[i].stamp_ns - cut_wall_ns) * 1e-6;
    if (s.slowing_ms < 0 && d < 0.8 * cruise) s.slowing_ms = at_ms;
    if (d < 1e-12) {
      s.rest_ms = at_ms;
      break;
    }
  }
  s.accel_ratio = rccx::test::worst_acceleration_ratio(v, cut - 3, acceleration_bounds(robot));
  return s;
}

double number_after(const std::string& text, const std::string& pattern) {
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(pattern))) return -1;
  return std::stod(m[1].str());
}

/// Nobody took a peer for lost on the way: not the serves, not the program (their outputs).
void expect_no_peer_lost(std::initializer_list<const std::string*> outputs) {
  for (const std::string* text : outputs) {
    EXPECT_FALSE(contains(*text, "was lost (no heartbeat")) << *text;
    EXPECT_FALSE(contains(*text, "is silent for")) << *text;
  }
}

/// What the program and both serves printed, for a failure's message.
std::string said(const std::string& program, const netns::Child& a, const netns::Child& b) {
  return program + "\nhost a:\n" + a.output() + "\nhost b:\n" + b.output();
}

/// Prints what the relay forwarded and lost between `before` and `after`, and checks that it
/// lost frames meanwhile: the test is of a lossy link.
void report_relay(const netns::RelayStats& before, const netns::RelayStats& after) {
  if (!after.valid) return;
  const std::uint64_t forwarded = after.forwarded - before.forwarded;
  const std::uint64_t lost = after.lost - before.lost;
  std::printf(
      "[ figures  ] relay: %llu frames forwarded, %llu lost (%.2f %%), held p50 %.3f p99 %.3f "
      "max %.3f ms\n",
      static_cast<unsigned long long>(forwarded), static_cast<unsigned long long>(lost),
      100.0 * static_cast<double>(lost) /
          static_cast<double>(std::max<std::uint64_t>(1, forwarded + lost)),
      after.delay_p50_ms, after.delay_p99_ms, after.delay_max_ms);
  EXPECT_GT(after.lost, before.lost);
}

/// The three hosts at 2 ms and 1 % loss each way (the relay's losses drawn from `seed`), the
/// PUMA's serve in host a and the Microbo's in host b, on a domain of this test process's own.
struct ServedHosts {
  explicit ServedHosts(std::uint64_t seed)
      : hosts({.hosts = 3, .delay_ms = 2.0, .loss = 0.01, .seed = seed}),
        d(domain()),
        puma(serve(hosts, 0, "puma", d)),
        microbo(serve(hosts, 1, "microbo", d)) {}
  netns::Hosts hosts;
  std::string d;
  netns::Child puma;
  netns::Child microbo;
};

void track_once(int attempt, bool& again) {
  ServedHosts served(static_cast<std::uint64_t>(28 + attempt));
  netns::Hosts& hosts = served.hosts;
  const std::string& d = served.d;
  netns::Child& puma = served.puma;
  netns::Child& microbo = served.microbo;
  ASSERT_TRUE(serving(puma, microbo));
  const netns::RelayStats before = hosts.relay_stats();
  netns::Child program = spawn_rt(hosts, 2,
                                  {RCCX_HOSTS_PROGRAM, "track", kCell, d,
                                   std::to_string(kDetectionMs), netns::Hosts::kInterface});
  // The program prints its figures with its cell still open: the serves' words then, before
  // they take its end for its loss (a detection time on).
  for (const auto until = Clock::now() + 100s; Clock::now() < until &&
                                               !contains(program.output(), "tracking:") &&
                                               !program.wait(0ms).has_value();) {
    std::this_thread::sleep_for(5ms);
  }
  const std::string pa = puma.output(), mb = microbo.output();
  const std::optional<int> code = program.wait(30s);
  const netns::RelayStats after = hosts.relay_stats();
  const std::string out = program.output();
  RETRY_OR_SKIP_ON_OVERRUN(out);
  std::printf("[ program  ]\n%s", out.c_str());
  report_relay(before, after);
  ASSERT_TRUE(code.has_value()) << "the program did not end in 130 s:\n"
                                << said(out, puma, microbo);
  EXPECT_EQ(*code, 0) << "a motion did not reach its end:\n" << said(out, puma, microbo);
  const double reached = number_after(out, R"(reached (\d+) of)");
  const double total = number_after(out, R"(of (\d+) motions)");
  EXPECT_GE(total, 6.0) << out;
  EXPECT_EQ(reached, total) << out;
  // The Microbo's commanded tool against the PUMA's + 150 mm x at the same stamp (CLOCK_REALTIME,
  // one clock for all namespaces). The Microbo's serve extrapolates the PUMA's newest state by its
  // velocity over the state's age: 2 ms in transit, up to a 7 ms period, 7 ms more for each state
  // the link lost. Unextrapolated, that age at 20 mm/s would be 0.2 mm to 0.5 mm behind; the
  // extrapolation leaves only the PUMA's change of velocity over the age, during its speed-up and
  // slow-down. Measured here: 0.12 to 0.15 mm. The bound, 1 mm, is 50 ms of the PUMA's travel:
  // room for a burst of lost states and a loaded machine's stalls, and still five times tighter
  // than the 5 mm the loopback follow test allows.
  const double worst_mm = number_after(out, R"(tracking: worst ([0-9.]+) mm)");
  const double count = number_after(out, R"(over (\d+) samples)");
  std::printf(
      "[ figures  ] tracking across hosts (2 ms, 1 %% loss): worst %.3f mm over %.0f "
      "Microbo samples\n",
      worst_mm, count);
  EXPECT_GE(count, 50.0) << "too few samples matched: " << out;
  EXPECT_GE(worst_mm, 0.0) << out;
  EXPECT_LT(worst_mm, 1.0) << out;
  expect_no_peer_lost({&pa, &mb, &out});
  program.stop();
  puma.stop();
  microbo.stop();
}

TEST(NetHosts, ThroughDelayAndLossEveryMotionEndsAndTheMicroboTracksThePumasTool) {
  NETNS_OR_SKIP();
  test::run_with_attempts(track_once);
}

void cut_once(int attempt, bool& again) {
  ServedHosts served(static_cast<std::uint64_t>(30 + attempt));
  netns::Hosts& hosts = served.hosts;
  const std::string& d = served.d;
  netns::Child& puma = served.puma;
  netns::Child& microbo = served.microbo;
  ASSERT_TRUE(serving(puma, microbo));
  // Recorders beside each serve: what it commands stays visible to them through the cut.
  const std::string file_a = ::testing::TempDir() + "rccx_hosts_a_" + d + ".txt";
  const std::string file_b = ::testing::TempDir() + "rccx_hosts_b_" + d + ".txt";
  const RemovedAtEnd remove_a{file_a}, remove_b{file_b};
  netns::Child rec_a = spawn_rt(hosts, 0,
                                {RCCX_HOSTS_PROGRAM, "record", d, std::to_string(kDetectionMs),
                                 netns::Hosts::kInterface, file_a});
  netns::Child rec_b = spawn_rt(hosts, 1,
                                {RCCX_HOSTS_PROGRAM, "record", d, std::to_string(kDetectionMs),
                                 netns::Hosts::kInterface, file_b});
  ASSERT_TRUE(rec_a.wait_for_output("recording", 30s)) << rec_a.output();
  ASSERT_TRUE(rec_b.wait_for_output("recording", 30s)) << rec_b.output();
  netns::Child program = spawn_rt(hosts, 2,
                                  {RCCX_HOSTS_PROGRAM, "long", kCell, d,
                                   std::to_string(kDetectionMs), netns::Hosts::kInterface});
  for (const auto until = Clock::now() + 90s; Clock::now() < until &&
                                              !contains(program.output(), "moving") &&
                                              !program.wait(0ms).has_value();) {
    std::this_thread::sleep_for(5ms);
  }
  const bool moving = contains(program.output(), "moving");
  if (!moving) RETRY_OR_SKIP_ON_OVERRUN(program.output());
  ASSERT_TRUE(moving) << "the long motion did not start:\n"
                      << program.output() << "\nhost a:\n"
                      << puma.output() << "\nhost b:\n"
                      << microbo.output();
  // The PUMA cruising at 10 mm/s (2 s of its motion left), the Microbo with it.
  std::this_thread::sleep_for(1000ms);

  const std::int64_t cut_steady = steady_ns();
  const std::int64_t cut_wall = net::wall_ns();
  hosts.cut(true);
  const double cut_took_ms = static_cast<double>(steady_ns() - cut_steady) * 1e-6;
  // When each serve said why (its output polled every 2 ms).
  std::map<std::string, double> said_ms;
  const std::string why = "was lost (no heartbeat for";
  while (steady_ns() - cut_steady < 5'000'000'000LL &&
         (said_ms.size() < 2 || !program.wait(0ms).has_value())) {
    for (const auto& [name, c] : {std::pair{"puma", &puma}, std::pair{"microbo", &microbo}}) {
      if (said_ms.count(name) == 0 && contains(c->output(), why)) {
        said_ms[name] = static_cast<double>(steady_ns() - cut_steady) * 1e-6;
      }
    }
    std::this_thread::sleep_for(2ms);
  }
  std::this_thread::sleep_for(1500ms);  // each robot at rest, recorded
  rec_a.stop();
  rec_b.stop();
  const std::optional<int> code = program.wait(10s);
  const std::string out = program.output(), pa = puma.output(), mb = microbo.output();
  RETRY_OR_SKIP_ON_OVERRUN(out);
  std::printf("[ program  ]\n%s[ host a   ]\n%s[ host b   ]\n%s", out.c_str(), pa.c_str(),
              mb.c_str());

  // The program: each robot's motion failed, the robot lost, within detection + slack.
  ASSERT_TRUE(code.has_value()) << out;
  EXPECT_EQ(*code, 0) << "a motion did not fail:\n" << out;
  const double bound_program_ms = kDetectionMs + kMicroboPeriodS * 1e3 + kSlackMs;
  for (const char* robot : {"puma", "microbo"}) {
    std::smatch m;
    const std::string pattern = std::string("failed ") + robot + R"( (\d+) ([^\n]*))";
    ASSERT_TRUE(std::regex_search(out, m, std::regex(pattern))) << out;
    const double ms = static_cast<double>(std::stoll(m[1].str()) - cut_steady) * 1e-6;
    std::printf("[ figures  ] the program saw %s's motion fail %.1f ms after the cut: %s\n", robot,
                ms, m[2].str().c_str());
    EXPECT_TRUE(contains(m[2].str(), std::string("robot ") + robot + " lost")) << m[2].str();
    EXPECT_GT(ms, 0.5 * kDetectionMs) << "failed before the detection time could pass";
    EXPECT_LE(ms, bound_program_ms);
  }

  // The serves: each said why and stopped its robot smoothly within the detection time.
  EXPECT_TRUE(contains(pa, "rccx serve: robot puma: the program ")) << pa;
  EXPECT_TRUE(contains(mb, "rccx serve: robot microbo: the program ")) << mb;
  const struct {
    const char* robot;
    const std::string& file;
    double period_s;
  } robots[] = {{"puma", file_a, kPumaPeriodS}, {"microbo", file_b, kMicroboPeriodS}};
  for (const auto& r : robots) {
    const std::string& text = std::string(r.robot) == "puma" ? pa : mb;
    const double serve_ms = number_after(text, R"(no heartbeat for ([0-9.]+) ms)");
    const Stop s = stop_of(samples_of(r.file, r.robot), cut_wall, r.robot);
    const double bound_ms = kDetectionMs + r.period_s * 1e3 + kSlackMs;
    std::printf(
        "[ figures  ] %s (period %.0f ms): its serve said why %.1f ms after the cut (its program "
        "silent %.0f ms by its own clock); setpoints slower from %.1f ms, at rest at %.1f ms; "
        "worst |accel| / bound %.3f over %zu samples (the cut took %.1f ms to apply)\n",
        r.robot, r.period_s * 1e3, said_ms.count(r.robot) ? said_ms[r.robot] : -1.0, serve_ms,
        s.slowing_ms, s.rest_ms, s.accel_ratio, s.samples, cut_took_ms);
    ASSERT_EQ(said_ms.count(r.robot), 1U) << r.robot << "'s serve did not say why:\n" << text;
    EXPECT_LE(said_ms[r.robot], bound_ms) << r.robot;
    EXPECT_GE(serve_ms, kDetectionMs) << text;
    ASSERT_GT(s.slowing_ms, 0.0) << r.robot << " did not slow down after the cut (" << s.samples
                                 << " samples in " << r.file << ")";
    EXPECT_GT(s.slowing_ms, 0.5 * kDetectionMs) << r.robot << " slowed before it could know";
    EXPECT_LE(s.slowing_ms, bound_ms) << r.robot;
    ASSERT_GT(s.rest_ms, 0.0) << r.robot << " did not come to rest";
    // At 10 mm/s the generator's stop takes a few samples; 1 s is a generous ceiling.
    EXPECT_LE(s.rest_ms, bound_ms + 1000.0) << r.robot;
    EXPECT_LE(s.accel_ratio, 1.0 + rccl::kAccelerationTolerance) << r.robot;
  }
  hosts.cut(false);
  program.stop();
  puma.stop();
  microbo.stop();
}

TEST(NetHosts, WithTheLinkCutEachServeStopsItsRobotWithinTheDetectionTimeAndSaysWhy) {
  NETNS_OR_SKIP();
  test::run_with_attempts(cut_once);
}

/// The pads the example probes (kPads in examples/10_circuit_board.cpp), and the CSV's header.
constexpr int kPads = 8;
const char* const kCsvHeader =
    "pad,x_mm,y_mm,board_speed_mm_s,touched_s,samples,max_error_mm,mean_error_mm,end_error_mm,"
    "hand_closed";

/// One row of the example's --csv (mm, s).
struct PadRow {
  std::string pad;
  double board_speed_mm_s = 0;
  double touched_s = 0;  ///< since the program started
  long samples = 0;
  double max_error_mm = 0;
};

/// The CSV's rows; nullopt (and the reason in `why`) when its header is not the example's.
std::optional<std::vector<PadRow>> pad_rows(const std::string& text, std::string& why) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || line != kCsvHeader) {
    why = "the CSV's header is \"" + line + "\"";
    return std::nullopt;
  }
  std::vector<PadRow> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::istringstream l(line);
    for (std::string cell; std::getline(l, cell, ',');) f.push_back(cell);
    if (f.size() != 10) {
      why = "a CSV row without 10 fields: \"" + line + "\"";
      return std::nullopt;
    }
    rows.push_back({f[0], std::stod(f[3]), std::stod(f[4]), std::stol(f[5]), std::stod(f[6])});
  }
  return rows;
}

/// True (and says so) before the last attempt when the demonstration failed on a state that
/// came late: a peer silent past the detection time, or a collision stop whose allowance the
/// remote robot's state's age widened (one of the link's 1 % lost states is enough where the
/// probe works beside the PUMA's gripper: 33 mm apart, 33 mm needed, seen once in a clean-clone
/// run). Real time on a shared machine and the lossy link, not the program
/// (tests/demo_distributed_test.cmake retries on the same words). The last attempt must pass.
bool late_state(const std::string& outputs, int attempt) {
  static const std::regex late(
      R"(another process's, its state [0-9]+ ms old|is silent for [0-9]+ ms)");
  if (attempt >= test::kAttempts || !std::regex_search(outputs, late)) return false;
  std::printf(
      "[ late     ] attempt %d: the demonstration failed on a late state (a loaded machine's "
      "scheduling, not the link's 2 ms); running it again:\n%s",
      attempt, outputs.c_str());
  return true;
}

void demo_once(int attempt, bool& again) {
  ServedHosts served(static_cast<std::uint64_t>(32 + attempt));
  netns::Hosts& hosts = served.hosts;
  const std::string& d = served.d;
  netns::Child& puma = served.puma;
  netns::Child& microbo = served.microbo;
  ASSERT_TRUE(serving(puma, microbo));
  const std::string csv = ::testing::TempDir() + "rccx_hosts_pads_" + d + ".csv";
  std::remove(csv.c_str());
  const RemovedAtEnd remove_csv{csv};
  const netns::RelayStats before = hosts.relay_stats();
  const auto started = Clock::now();
  netns::Child program = spawn_rt(
      hosts, 2,
      {RCCX_CIRCUIT_BOARD_EXE, "--remote", "--domain", d, "--interface", netns::Hosts::kInterface,
       "--detection", std::to_string(kDetectionMs) + "ms", "--csv", csv});
  // About 103 s of motion in real time. The example prints its summary with its cell still
  // open: the serves' words then, before they take its end for its loss (a detection time on).
  // The serves end on their own after 170 s (serve()): 160 s is as long as waiting can help.
  for (const auto until = Clock::now() + 160s; Clock::now() < until &&
                                               !contains(program.output(), "failures: PUMA") &&
                                               !program.wait(0ms).has_value();) {
    std::this_thread::sleep_for(5ms);
  }
  const std::string pa = puma.output(), mb = microbo.output();
  const std::optional<int> code = program.wait(30s);
  const double took_s = std::chrono::duration<double>(Clock::now() - started).count();
  const netns::RelayStats after = hosts.relay_stats();
  const std::string out = program.output();
  RETRY_OR_SKIP_ON_OVERRUN(out + pa + mb);
  if (late_state(out + pa + mb, attempt)) {
    again = true;
    return;
  }
  std::printf("[ program  ]\n%s", out.c_str());
  report_relay(before, after);
  ASSERT_TRUE(code.has_value()) << "the demonstration did not end in 190 s:\n"
                                << said(out, puma, microbo);
  EXPECT_EQ(*code, 0) << "the demonstration did not run through, or a probe missed its pad:\n"
                      << said(out, puma, microbo);
  // Its table, every pad probed, no motion failed.
  for (const char* text : {"across processes: the PUMA served by", " pad   x mm   y mm  board",
                           "failures: PUMA none, Microbo none"}) {
    EXPECT_TRUE(contains(out, text)) << "the demonstration did not print \"" << text << "\":\n"
                                     << out;
  }
  EXPECT_EQ(number_after(out, R"((\d+) pads probed)"), static_cast<double>(kPads)) << out;
  const double moving = number_after(out, R"((\d+) on the moving board)");
  EXPECT_GE(moving, 2.0) << "too few pads probed on the moving board:\n" << out;
  const double worst_mm = number_after(out, R"(worst error ([0-9.]+) mm)");
  const double bound_mm = number_after(out, R"(\(bound ([0-9.]+) mm\))");
  ASSERT_GT(bound_mm, 0.0) << "the demonstration did not print its worst error and bound:\n" << out;
  EXPECT_GE(worst_mm, 0.0) << out;
  EXPECT_LE(worst_mm, bound_mm) << out;
  // Every pad in the CSV: measured across hosts, and within the bound.
  std::string why;
  const std::optional<std::vector<PadRow>> rows = pad_rows(read_file(csv), why);
  ASSERT_TRUE(rows.has_value()) << "--csv " << csv << ": " << why;
  ASSERT_EQ(rows->size(), static_cast<std::size_t>(kPads)) << read_file(csv);
  int moving_rows = 0;
  double touched_before_s = 0;
  for (const PadRow& r : *rows) {
    EXPECT_GT(r.samples, 0) << "pad " << r.pad << ": no reading paired across hosts";
    // Pad after pad: a touch time from an end event not yet received would read 0 or less.
    EXPECT_GT(r.touched_s, touched_before_s) << "pad " << r.pad << "\n" << read_file(csv);
    touched_before_s = r.touched_s;
    EXPECT_LE(r.max_error_mm, bound_mm) << "pad " << r.pad;
    moving_rows += r.board_speed_mm_s > 0.5 ? 1 : 0;  // the example's own rule for "moving"
  }
  EXPECT_EQ(static_cast<double>(moving_rows), moving) << read_file(csv);
  std::printf(
      "[ figures  ] the demonstration across hosts (2 ms, 1 %% loss, detection %d ms): %d pads, "
      "%d on the moving board, worst error %.3f mm (bound %.1f mm); %.1f s from start to end\n",
      kDetectionMs, kPads, moving_rows, worst_mm, bound_mm, took_s);
  expect_no_peer_lost({&pa, &mb, &out});
  program.stop();
  puma.stop();
  microbo.stop();
}

TEST(NetHosts, TheCircuitBoardDemonstrationAcrossHostsMeetsItsErrorBound) {
  NETNS_OR_SKIP();
  test::run_with_attempts(demo_once);
}

}  // namespace
