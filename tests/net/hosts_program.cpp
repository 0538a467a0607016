// The program and the recorder of net_hosts_test (issue 29, "Hosts"), each run inside a network
// namespace of its own (tests/net/netns_fixture.hpp) on the interface given.
//
//   rccx_net_hosts_program track  CELL DOMAIN DETECTION_MS INTERFACE
//     Places the Microbo and then, gated on its end, the PUMA over the board 150 mm to -x; the
//     Microbo follows the PUMA's tool frame (other process) while the PUMA goes 30 mm along y and
//     back at 20 mm/s. Prints "reached <n> of <m> motions", the tracking error from the robots'
//     states matched by stamp ("tracking: worst W mm rms R mm over N samples"), and exits 0 when
//     every motion reached its end, 3 when one did not (its reason printed).
//   rccx_net_hosts_program long   CELL DOMAIN DETECTION_MS INTERFACE
//     Places them and starts the Microbo's tracking as above, then moves the PUMA 30 mm along y
//     at 10 mm/s (3 s), prints "moving <steady ns>" and then "failed <robot> <steady ns> <reason>"
//     when the PUMA's motion fails and when the Microbo's failures() report it (its motion,
//     tracking at rest, has ended); exits 0 when both did, 3 otherwise (30 s at most).
//   rccx_net_hosts_program record DOMAIN DETECTION_MS INTERFACE FILE
//     Writes every RobotState it receives to FILE, one line each, until SIGTERM:
//     "<robot> <sample> <stamp_ns> <received steady ns> <period_s> <status> <q1..qn>".
//
// steady ns is CLOCK_MONOTONIC, which network namespaces share with the test process.
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "rccx/cell/cell_model.hpp"
#include "rccx/net/codec.hpp"
#include "rccx/net/dds.hpp"
#include "rccx/net/remote_cell.hpp"
#include "rccx/net/states.hpp"

namespace {

using namespace rccx;
using namespace std::chrono_literals;

std::atomic<bool> g_stop{false};

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

net::NetOptions options(const char* domain, const char* detection_ms, const char* interface) {
  net::NetOptions o;
  o.domain = static_cast<std::uint32_t>(std::atoi(domain));
  o.interface = interface;
  o.detection = std::chrono::milliseconds(std::atoi(detection_ms));
  o.heartbeat = o.detection / 4;
  return o;
}

math::Transform tool_down(double x, double y, double z) {
  math::Transform t;
  t.R = math::Rot3::rot_x(M_PI);
  t.p = {x, y, z};
  return t;
}

/// The robots' states as received: by robot, stamp (CLOCK_REALTIME ns the setpoint is for) -> tool.
struct Track {
  std::mutex mutex;
  std::map<std::string, std::map<std::int64_t, math::Vec3>> tool;  ///< by robot, by stamp_ns
  std::map<std::string, std::uint64_t> samples, gaps;              ///< received, missed
  std::map<std::string, std::uint64_t> last_sample;
};

/// Reads every RobotState of the domain on a thread of its own into `track`.
class StateReader {
 public:
  StateReader(const net::NetOptions& o, Track& track)
      : participant_(o), reader_(participant_.reader(net::Topic::state, o.detection * 10)) {
    thread_ = std::thread([this, &track] {
      net::StateInbox in;
      while (!stop_) {
        in.drain(reader_.get(), [&](const rccx_net_RobotState& s) {
          const std::string robot(net::text_of(s.robot));
          std::lock_guard lock(track.mutex);
          auto& last = track.last_sample[robot];
          if (s.sample == last) return;  // the same state again (the serve's other robots' pass)
          if (last != 0 && s.sample > last + 1) track.gaps[robot] += s.sample - last - 1;
          last = std::max<std::uint64_t>(last, s.sample);
          ++track.samples[robot];
          track.tool[robot][s.stamp_ns] = net::from_pose(s.tool).p;
        });
        std::this_thread::sleep_for(1ms);
      }
    });
  }
  ~StateReader() {
    stop_ = true;
    thread_.join();
  }
  StateReader(const StateReader&) = delete;
  StateReader& operator=(const StateReader&) = delete;

 private:
  net::Participant participant_;
  net::Entity reader_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

std::string reasons(net::RemoteArm& arm) {
  std::string s;
  for (const auto& e : arm.failures()) s += std::string(e.message()) + "; ";
  return s;
}

/// What is known of a motion that failed with no failure event: the robot's state and events.
std::string unexplained(net::RemoteArm& arm) {
  const net::RemoteState st = arm.state();
  std::string why =
      "no failure event in 3 s; its state: status " + std::to_string(static_cast<int>(st.status)) +
      ", control ended " + std::to_string(st.control_ended) + ", running " +
      std::to_string(st.running) + ", queued " + std::to_string(st.queued) + ", started up to " +
      std::to_string(st.started_upto) + ", ended up to " + std::to_string(st.ended_upto) +
      ", termination '" + st.termination + "'; events:";
  for (const auto& e : arm.take_events()) {
    why += " [" + std::to_string(e.id) + " kind " + std::to_string(static_cast<int>(e.kind)) + " " +
           std::string(e.message()) + "]";
  }
  return why;
}

/// Counts and names the motions that did not reach their end.
struct Tally {
  int reached = 0, total = 0;
  std::string why;
  void wait(net::RemoteArm& arm, const rccl::Motion& m, const char* what) {
    ++total;
    const rccl::WaitResult r = arm.waitfor(m.end(), 40s);
    if (r == rccl::WaitResult::reached) {
      ++reached;
      return;
    }
    // The failure's event (reliable, with its reason) may come after the state that told
    // the ledger.
    for (int i = 0; i < 300 && r == rccl::WaitResult::failed && arm.failures().empty(); ++i) {
      std::this_thread::sleep_for(10ms);
    }
    why += std::string(what) + " (motion " + std::to_string(m.id) +
           "): " + (r == rccl::WaitResult::timeout ? "timeout" : "failed: " + reasons(arm));
    if (arm.failures().empty()) why += unexplained(arm);
    why += "\n";
  }
};

/// The Microbo 150 mm to +x of the board's point; then, gated on its end, the PUMA over that
/// point pointing down (the geometry of net_serve_test's follow test).
void place(net::RemoteCell& cell, Tally& tally) {
  net::RemoteArm& puma = cell.robot("puma");
  net::RemoteArm& microbo = cell.robot("microbo");
  puma.set_mode(rccl::Mode::joint);
  puma.set_velocity(0.05, 0.5);
  microbo.set_mode(rccl::Mode::joint);
  microbo.set_velocity(0.05, 0.5);
  // The Microbo's ready pose is in the PUMA's way to the board: it moves aside first.
  const rccl::Motion m0 =
      microbo.move(cell.world_goal("microbo", "M0", tool_down(0.10, 0.0, 0.1516)));
  const rccl::Motion p1 = puma.move(cell.world_goal("puma", "OVER", tool_down(-0.05, 0.0, 0.1516)),
                                    cell.after("microbo", m0.end()));
  tally.wait(microbo, m0, "microbo M0");
  tally.wait(puma, p1, "puma OVER (after microbo M0)");
  std::this_thread::sleep_for(100ms);  // both at rest in each other's states
  const math::Vec3 a = puma.state().tool.pose.p, b = microbo.state().tool.pose.p;
  std::printf("placed: puma's tool at (%.4f, %.4f, %.4f) m, microbo's at (%.4f, %.4f, %.4f) m\n",
              a.x, a.y, a.z, b.x, b.y, b.z);
}

/// The Microbo onto the PUMA's tool frame + 150 mm x, then tracking it (Cartesian mode goes on
/// tracking its goal once there: net_serve_test's follow test).
void follow(net::RemoteCell& cell, Tally& tally) {
  net::RemoteArm& microbo = cell.robot("microbo");
  const auto offset = rccl::constant("BESIDE", math::Transform::translation(0.15, 0, 0));
  microbo.set_mode(rccl::Mode::joint);
  const rccl::Motion f1 =
      microbo.move(cell.world_goal("microbo", "FOLLOW", {cell.tool_frame("puma"), offset}));
  tally.wait(microbo, f1, "microbo FOLLOW (joint)");
  microbo.set_mode(rccl::Mode::cartesian);
  const rccl::Motion f2 =
      microbo.move(cell.world_goal("microbo", "FOLLOW", {cell.tool_frame("puma"), offset}));
  tally.wait(microbo, f2, "microbo FOLLOW (Cartesian)");
}

/// The largest and rms distance (m) of the Microbo's tool from the PUMA's + 150 mm x at the
/// Microbo's stamps in [from_ns, to_ns], the PUMA's interpolated between its two samples around
/// each stamp (none more than 3 of its periods apart).
struct Error {
  double worst_m = 0, rms_m = 0;
  std::size_t count = 0;
};
Error tracking_error(Track& track, std::int64_t from_ns, std::int64_t to_ns) {
  std::lock_guard lock(track.mutex);
  const auto& p = track.tool["puma"];
  const auto& m = track.tool["microbo"];
  Error e;
  double sum = 0;
  for (auto it = m.lower_bound(from_ns); it != m.end() && it->first <= to_ns; ++it) {
    const auto after = p.lower_bound(it->first);
    if (after == p.end() || after == p.begin()) continue;
    const auto before = std::prev(after);
    const double span = static_cast<double>(after->first - before->first);
    if (span > 3 * 7e6) continue;  // lost PUMA samples around it: not measured
    const double f = span > 0 ? static_cast<double>(it->first - before->first) / span : 0.0;
    const math::Vec3 leader = before->second + (after->second - before->second) * f;
    const double d = (it->second - (leader + math::Vec3{0.15, 0, 0})).norm();
    e.worst_m = std::max(e.worst_m, d);
    sum += d * d;
    ++e.count;
  }
  if (e.count > 0) e.rms_m = std::sqrt(sum / static_cast<double>(e.count));
  return e;
}

int track(char** argv) {
  const net::NetOptions o = options(argv[3], argv[4], argv[5]);
  Track track;
  StateReader reader(o, track);
  net::RemoteOptions ro;
  ro.wait_for_robots = 30s;  // discovery across a lossy, delayed link on a loaded machine
  net::RemoteCell cell(cell::load_cell_file(argv[2]), o, ro);
  net::RemoteArm& puma = cell.robot("puma");
  Tally tally;
  place(cell, tally);
  if (tally.reached != tally.total) {
    std::printf("placing failed:\n%s", tally.why.c_str());
    return 3;
  }
  follow(cell, tally);
  puma.set_mode(rccl::Mode::cartesian);
  puma.set_velocity(0.02, 0.3);
  const std::int64_t from = net::wall_ns();
  const rccl::Motion p2 =
      puma.move(cell.world_goal("puma", "ASIDE", tool_down(-0.05, 0.03, 0.1516)));
  const rccl::Motion p3 = puma.move(cell.world_goal("puma", "BACK", tool_down(-0.05, 0.0, 0.1516)));
  tally.wait(puma, p2, "puma ASIDE");
  tally.wait(puma, p3, "puma BACK");
  std::this_thread::sleep_for(300ms);  // the last states in
  const Error e = tracking_error(track, from, net::wall_ns());
  {
    std::lock_guard lock(track.mutex);
    std::printf("states received: puma %llu (%llu missed), microbo %llu (%llu missed)\n",
                static_cast<unsigned long long>(track.samples["puma"]),
                static_cast<unsigned long long>(track.gaps["puma"]),
                static_cast<unsigned long long>(track.samples["microbo"]),
                static_cast<unsigned long long>(track.gaps["microbo"]));
  }
  std::printf("reached %d of %d motions\n", tally.reached, tally.total);
  std::printf("tracking: worst %.3f mm rms %.3f mm over %zu samples\n", e.worst_m * 1e3,
              e.rms_m * 1e3, e.count);
  if (!tally.why.empty()) std::printf("not reached:\n%s", tally.why.c_str());
  std::fflush(stdout);
  return tally.reached == tally.total ? 0 : 3;
}

int long_motion(char** argv) {
  const net::NetOptions o = options(argv[3], argv[4], argv[5]);
  net::RemoteOptions ro;
  ro.wait_for_robots = 30s;
  net::RemoteCell cell(cell::load_cell_file(argv[2]), o, ro);
  net::RemoteArm& puma = cell.robot("puma");
  net::RemoteArm& microbo = cell.robot("microbo");
  Tally tally;
  place(cell, tally);
  if (tally.reached == tally.total) follow(cell, tally);
  if (tally.reached != tally.total) {
    std::printf("placing failed:\n%s", tally.why.c_str());
    return 3;
  }
  // The PUMA 30 mm along y at 10 mm/s (3 s) and the Microbo tracking it, 150 mm beside.
  puma.set_mode(rccl::Mode::cartesian);
  puma.set_velocity(0.01, 0.3);
  const rccl::Motion lp =
      puma.move(cell.world_goal("puma", "LONG", tool_down(-0.05, 0.03, 0.1516)));
  if (puma.waitfor(lp.start(), 10s) != rccl::WaitResult::reached) {
    std::printf("the long motion did not start: %s\n", reasons(puma).c_str());
    return 3;
  }
  std::printf("moving %lld\n", static_cast<long long>(steady_ns()));
  std::fflush(stdout);
  // The PUMA's motion fails; the Microbo's (ended, tracking at rest) is reported by the robot's
  // loss in failures().
  bool puma_done = false, microbo_done = false;
  int failed = 0;
  const auto until = std::chrono::steady_clock::now() + 30s;
  while (std::chrono::steady_clock::now() < until && !(puma_done && microbo_done)) {
    if (!puma_done) {
      const rccl::WaitResult r = puma.waitfor(lp.end(), 2ms);
      if (r != rccl::WaitResult::timeout) {
        puma_done = true;
        if (r == rccl::WaitResult::failed) {
          ++failed;
          std::printf("failed puma %lld %s\n", static_cast<long long>(steady_ns()),
                      reasons(puma).c_str());
          if (puma.failures().empty()) std::printf("(puma: %s)\n", unexplained(puma).c_str());
        } else {
          std::printf("reached puma %lld\n", static_cast<long long>(steady_ns()));
        }
        std::fflush(stdout);
      }
    }
    if (!microbo_done && !microbo.failures().empty()) {
      microbo_done = true;
      ++failed;
      std::printf("failed microbo %lld %s\n", static_cast<long long>(steady_ns()),
                  reasons(microbo).c_str());
      std::fflush(stdout);
    }
    std::this_thread::sleep_for(1ms);
  }
  return failed == 2 ? 0 : 3;
}

int record(char** argv) {
  const net::NetOptions o = options(argv[2], argv[3], argv[4]);
  std::FILE* out = std::fopen(argv[5], "w");
  if (out == nullptr) {
    std::fprintf(stderr, "cannot write %s\n", argv[5]);
    return 1;
  }
  net::Participant participant(o);
  const net::Entity reader = participant.reader(net::Topic::state, o.detection * 10);
  std::printf("recording\n");
  std::fflush(stdout);
  net::StateInbox in;
  std::map<std::string, std::uint64_t> last;  // by robot: its last sample written out
  while (!g_stop) {
    in.drain(reader.get(), [&](const rccx_net_RobotState& s) {
      std::uint64_t& seen = last[std::string(net::text_of(s.robot))];
      if (s.sample == seen) return;  // the same state again (with the serve's other robots')
      seen = s.sample;
      std::fprintf(out, "%s %llu %lld %lld %.9g %u", std::string(net::text_of(s.robot)).c_str(),
                   static_cast<unsigned long long>(s.sample), static_cast<long long>(s.stamp_ns),
                   static_cast<long long>(steady_ns()), s.period_s,
                   static_cast<unsigned>(s.status));
      for (std::size_t j = 0; j < s.dof; ++j) std::fprintf(out, " %.12g", s.q_commanded[j]);
      std::fprintf(out, "\n");
    });
    std::fflush(out);
    std::this_thread::sleep_for(1ms);
  }
  std::fclose(out);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  signal(SIGTERM, [](int) { g_stop = true; });
  signal(SIGINT, [](int) { g_stop = true; });
  try {
    if ((mode == "track" || mode == "long") && argc == 6) {
      return mode == "track" ? track(argv) : long_motion(argv);
    }
    if (mode == "record" && argc == 6) return record(argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rccx_net_hosts_program %s: %s\n", mode.c_str(), e.what());
    return 1;
  }
  std::fprintf(stderr,
               "usage: %s track|long CELL DOMAIN DETECTION_MS INTERFACE\n"
               "       %s record DOMAIN DETECTION_MS INTERFACE FILE\n",
               argv[0], argv[0]);
  return 2;
}
