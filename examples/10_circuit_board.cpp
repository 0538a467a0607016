// Example 10: two robots inspect and repair a circuit board (thesis 4.5, figure 4.8), on the
// CVaRL cell (cells/cvarl.json), each on its own simulated plant: the PUMA 260's PID servos on
// its dynamics, the Microbo's emulated RCU. The program runs as the thesis ran it, or in one:
//
//   - one process (default, `make demo-cell`): a cell::Cell runs both robots on one clock, in
//     simulated time;
//   - across processes (--remote, `make demo-distributed`): two `rccx serve` processes run the
//     PUMA and the Microbo in real time, each on its own clock, and this program commands them
//     over DDS through a net::RemoteCell (docs/NETWORK.md), as the thesis's two controllers
//     were synchronised over a serial link.
//
// The lesson: the program is written once, against cell::Workcell& and rccl::Arm&
// (run_program below). What differs is only how it watches the robots (class Watch): in one
// process it reads both sessions at the same sample; across processes it pairs the robots'
// published states by the host clock's time.
//
// The PUMA picks the board off the x-y stage and presents it to the Microbo. From the grasp on,
// the board is wherever the PUMA's tool is:
//
//     board (world) = PUMA_TOOL GRASP             PUMA_TOOL = cell.tool_frame("puma")
//
// so each test pad the Microbo probes is a position equation through the other robot's frame,
//
//     T6 TOOL = BASE_INV(microbo) PUMA_TOOL GRASP PAD DOWN     (DOWN: the probe onto the pad)
//
// a functional transform the Microbo's generator evaluates every sample: its goals stay on the
// pads while the PUMA moves the board. Across processes PUMA_TOOL is sent by name ("frame:puma")
// and the Microbo's serve process reads it from the PUMA's published states. The PUMA's own
// goals are written for the board frame (T6 TOOL GRASP = BASE_INV(puma) BOARD, the board the
// tool), so it carries the board on straight lines.
//
// The sequence, synchronised by events (the PUMA's motion ends, the Microbo's): a motion of one
// arm queued with cell.after(other, m.end()) starts at its first sample after
// the other's event, without the program waiting in between:
//   1. The Microbo backs off; the PUMA goes above the board, descends, closes its hand, lifts the
//      board off the stage and presents it nearer the Microbo.
//   2. When the presentation has ended, the Microbo probes the pads one by one: above, down to
//      touch, a dwell on the pad, up.
//   3. When the Microbo has touched pad TP3, the PUMA starts a slow translation of the board
//      (--moving-speed, mm/s): the next pads are probed on a moving board.
//   4. One pad is repaired: a longer dwell with the Microbo's hand closed.
//   5. The Microbo backs off; the PUMA puts the board back on the stage and parks.
//
// What it measures, per pad, at every Microbo sample of the dwell: the distance between the
// Microbo's measured probe tip (forward kinematics of the joints its RCU reports, through its
// base and tool) and where the pad really is at that instant (from the joints the PUMA reports:
// base FK(q) TOOL GRASP PAD), its max, mean and value at the dwell's end, and the pad's measured
// speed. It exits 1 when a motion failed, the collision check stopped the arms, or a probe
// missed its pad by more than kPadRadius; 2 for a bad option.
// Run: ./build/release/examples/10_circuit_board [--moving-speed 5] [--csv pads.csv]
//      ./build/release/examples/10_circuit_board --remote --domain 7 --interface lo
//      (with `rccx serve --cell cells/cvarl.json --robots puma` and `... --robots microbo` on
//      that domain: scripts/demo-distributed starts them)
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/cell/cell.hpp"
#include "rccx/cell/workcell.hpp"
#include "rccx/io/data_files.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/math/units.hpp"
#include "rccx/net/remote_cell.hpp"

using namespace rccx;
using namespace rccx::math::literals;
using namespace std::chrono_literals;

namespace {

/// A test pad on the board: board frame (the top face's centre, x towards the Microbo), mm.
struct Pad {
  const char* name;
  double x_mm;
  double y_mm;
};
// The Microbo probes from the +x side; the PUMA holds the board's -x edge (GRASP), so the pads
// stay at x >= -5 mm: the probe then keeps more than the collision check's margin and braking
// allowance from the PUMA's gripper, 45 mm away in x (see the closest approach the program
// prints).
constexpr std::array kPads{Pad{"TP1", -5, -25}, Pad{"TP2", 10, -30}, Pad{"TP3", 30, -25},
                           Pad{"TP4", 35, 0},   Pad{"TP5", 30, 25},  Pad{"TP6", 10, 30},
                           Pad{"TP7", -5, 25},  Pad{"U1", 10, 0}};
/// Touching this pad starts the PUMA's slow move: the next ones are probed on a moving board.
constexpr std::size_t kStartMovingAfter = 2;  // TP3
/// The pad repaired (a longer dwell with the hand closed): U1, a component's lead.
constexpr std::size_t kRepairPad = kPads.size() - 1;

/// How far a probe may land from a pad's centre and still touch it: we take the pads to be 4 mm
/// across (the thesis gives no size), m.
constexpr double kPadRadius = 2_mm;

constexpr double kDwellS = 0.5;        ///< on each pad, s
constexpr double kRepairS = 1.5;       ///< on the repaired pad, hand closed, s
constexpr double kProbeAbove = 30_mm;  ///< where the probe waits above a pad, m
constexpr double kTravel = 40_mm;      ///< the board's slow move, along the world's y, m

/// The Microbo's measurements on one pad.
struct PadResult {
  double touched_s = 0.0;  ///< when the descent ended, s since the cell started
  double max_error_m = 0.0;
  double sum_error_m = 0.0;
  double last_error_m = 0.0;  ///< at the dwell's end: settled, without the landing's lag
  int samples = 0;
  double board_speed_m_per_s = 0.0;  ///< of the pad, measured over the dwell
  bool hand_closed = false;          ///< the Microbo's hand was closed during the dwell
};

/// The tool pointing down (approach -z) at a point of a frame whose z is up: the probe's pose.
math::Transform down_at(double x_m, double y_m, double z_m) {
  return {math::Rot3::rot_x(math::kPi), {x_m, y_m, z_m}};
}

bool reached(rccl::WaitResult w) {
  return w == rccl::WaitResult::reached;
}

/// GRASP's inverse, board <- PUMA tool: the PUMA's fingers on the middle of the board's -x edge
/// (5 mm in), the approach tilted 45 deg from the vertical towards +x, turned 30 deg towards +y
/// (Rot_y 135 deg, then Rot_z 30 deg): the wrist stays 116 mm above the edge and 100 mm behind
/// it, 58 mm to the side, away from the Microbo reaching over the board from +x (its capsules
/// keep more than 40 mm from the PUMA's), and far enough from the PUMA's own shoulder axis: with
/// the approach straight along x, lifting the board took theta3 past its -235 deg limit.
/// board = PUMA_TOOL GRASP.
math::Transform tool_in_board() {
  return math::Transform::translation(-45_mm, 0, 0) *
         math::Transform{math::Rot3::rot_z(30_deg) * math::Rot3::rot_y(135_deg), {}};
}

/// Where the probe's tip and a pad are, from each arm's measured joints (m, world).
struct Geometry {
  const cell::CellRobot& puma;
  const cell::CellRobot& microbo;
  const kin::Kinematics& puma_kin;
  const kin::Kinematics& microbo_kin;
  math::Transform grasp;  ///< PUMA tool <- board

  [[nodiscard]] math::Vec3 pad(const kin::JointVector& puma_q, const Pad& p) const {
    return puma.base * puma_kin.forward(puma_q) * puma.tool.value_or(math::Transform{}) * grasp *
           math::Vec3{p.x_mm * 1e-3, p.y_mm * 1e-3, 0.0};
  }
  [[nodiscard]] math::Vec3 tip(const kin::JointVector& microbo_q) const {
    return (microbo.base * microbo_kin.forward(microbo_q) *
            microbo.tool.value_or(math::Transform{}))
        .p;
  }
};

/// One pad's figures from readings of the probe's tip and the pad at the same instants.
class PadMeter {
 public:
  explicit PadMeter(PadResult& r) : r_(r) {}
  void add(double t_s, const math::Vec3& tip, const math::Vec3& pad) {
    const double e = (tip - pad).norm();
    r_.max_error_m = std::max(r_.max_error_m, e);
    r_.sum_error_m += e;
    r_.last_error_m = e;
    ++r_.samples;
    if (first_s_ < 0.0) {
      first_s_ = t_s;
      first_ = pad;
    }
    last_s_ = t_s;
    last_ = pad;
  }
  /// The pad's speed over the readings.
  void finish() {
    if (last_s_ > first_s_) r_.board_speed_m_per_s = (last_ - first_).norm() / (last_s_ - first_s_);
  }

 private:
  PadResult& r_;
  double first_s_ = -1.0, last_s_ = -1.0;
  math::Vec3 first_, last_;
};

/// How the program watches the robots beyond their motion API: what differs between one
/// process (both sessions on one simulated clock) and several (each robot's published state,
/// on the host's wall clock). Times are s since the cell started.
class Watch {
 public:
  virtual ~Watch() = default;
  /// Lets `seconds` pass, measuring the Microbo's tip against `pad` whenever both arms' measured
  /// joints are known for the same instant. `hand_closed`: what the program asked of the hand.
  virtual void measure(const Pad& pad, double seconds, bool hand_closed, PadResult& r) = 0;
  /// When motion `m` of `robot` ended (it has ended).
  virtual double ended_s(std::string_view robot, const rccl::Motion& m) = 0;
  virtual double now_s() = 0;
  /// Both robots still under control.
  virtual bool controlling() = 0;
  /// The closest the arms' capsules came, m; none where it is not measured.
  [[nodiscard]] virtual std::optional<double> closest_m() const = 0;
  /// Times the collision check stopped the arms; none where it is not counted.
  [[nodiscard]] virtual std::optional<std::uint64_t> collision_stops() const = 0;
  /// "simulated time" or "real time".
  [[nodiscard]] virtual const char* clock() const = 0;
  /// What the table means differently here, for a footnote ("" for nothing).
  [[nodiscard]] virtual std::string note() const = 0;
  /// Closes what it kept (the sample logs); false when something was lost (said on stderr).
  virtual bool finish() = 0;
};

/// One process: both robots' sessions on the cell's one clock. The PUMA's How and the Microbo's
/// come from the same tick only every fourth tick (the Microbo's period), and either may be
/// published a tick late (the pipeline): the PUMA's recent readings are kept by sample time.
class LocalWatch final : public Watch {
 public:
  /// Before c.start(): the closest approach is read from every tick's collision world.
  /// The closest approach is shared with the observer: the cell (destroyed after the watch)
  /// may still run ticks while it stops.
  LocalWatch(cell::Cell& c, const Geometry& g) : c_(c), g_(g) {
    c_.set_cycle_observer([&c, closest = closest_m_](std::uint32_t) {
      *closest = std::min(*closest, c.collision_world().min_distance(0, 1).distance_m);
    });
  }

  void measure(const Pad& pad, double seconds, bool /*hand_closed*/, PadResult& r) override {
    rtc::Session& puma = c_.session("puma");
    rtc::Session& microbo = c_.session("microbo");
    PadMeter meter(r);
    const double until_s = microbo.how().time_s + seconds;
    while (microbo.how().time_s < until_s && microbo.controlling()) {
      c_.wait_for(c_.model().base_period);  // one tick
      const rtc::How hp = puma.how();
      if (hp.time_s != recent_[(next_ + recent_.size() - 1) % recent_.size()].t_s) {
        recent_[next_] = {hp.time_s, hp.q()};
        next_ = (next_ + 1) % recent_.size();
      }
      const rtc::How hm = microbo.how();
      if (hm.time_s == microbo_last_s_) continue;
      microbo_last_s_ = hm.time_s;
      r.hand_closed = r.hand_closed || hm.hand_closed;  // as the RCU reports it
      const auto same = std::find_if(recent_.begin(), recent_.end(),
                                     [&](const Reading& x) { return x.t_s == hm.time_s; });
      if (same == recent_.end()) continue;
      meter.add(hm.time_s, g_.tip(hm.q()), g_.pad(same->q, pad));
    }
    meter.finish();
  }
  double ended_s(std::string_view robot, const rccl::Motion& m) override {
    return c_.robot(robot).report(m).end_s;
  }
  double now_s() override { return c_.session("puma").how().time_s; }
  bool controlling() override {
    return c_.session("puma").controlling() && c_.session("microbo").controlling();
  }
  [[nodiscard]] std::optional<double> closest_m() const override { return *closest_m_; }
  [[nodiscard]] std::optional<std::uint64_t> collision_stops() const override {
    return c_.collision_stops();
  }
  [[nodiscard]] const char* clock() const override { return "simulated time"; }
  [[nodiscard]] std::string note() const override { return ""; }
  bool finish() override {
    // RCCX_LOG's logs, one a robot (run-puma.csv, run-microbo.csv): put in place, whole or said.
    bool logged = true;
    for (const char* name : {"puma", "microbo"}) {
      rtc::Session& s = c_.session(name);
      s.close();
      if (!s.log_problem().empty()) {
        fmt::print(stderr, "10_circuit_board: {}'s sample log is lost: {}\n", s.name(),
                   s.log_problem());
        logged = false;
      }
    }
    return logged;
  }

 private:
  struct Reading {
    double t_s = -1.0;
    kin::JointVector q;
  };
  cell::Cell& c_;
  Geometry g_;
  std::shared_ptr<double> closest_m_ =
      std::make_shared<double>(std::numeric_limits<double>::infinity());
  std::array<Reading, 16> recent_{};
  std::size_t next_ = 0;
  double microbo_last_s_ = -1.0;
};

/// Across processes: each robot's state as its serve process publishes it (RemoteArm::state()),
/// its measured joints stamped with the host's CLOCK_REALTIME. The two robots are sampled by
/// different processes at different periods (PUMA 7 ms, Microbo 28 ms), so no two samples share
/// an instant: the Microbo's measured tip is paired with the PUMA's measured joints
/// interpolated to the same wall time (one host's clock; several hosts need synchronised
/// clocks, docs/NETWORK.md).
class RemoteWatch final : public Watch {
 public:
  RemoteWatch(net::RemoteCell& c, const Geometry& g)
      : c_(c),
        g_(g),
        puma_(c.robot("puma")),
        microbo_(c.robot("microbo")),
        puma_period_(period_of(c.model(), "puma")),
        microbo_period_(period_of(c.model(), "microbo")),
        t0_ns_(net::wall_ns()) {}

  void measure(const Pad& pad, double seconds, bool hand_closed, PadResult& r) override {
    PadMeter meter(r);
    r.hand_closed = hand_closed;  // as asked (and acknowledged): the state has no hand reading
    const std::int64_t until_ns = net::wall_ns() + static_cast<std::int64_t>(seconds * 1e9);
    pending_count_ = 0;
    // The dwell, then up to 200 ms for the PUMA's states that bracket the last Microbo readings.
    while (controlling()) {
      const std::int64_t now = net::wall_ns();
      if (now >= until_ns + 200'000'000 || (now >= until_ns && pending_count_ == 0)) break;
      c_.wait_for(1ms);  // both robots publish every sample; the newest is kept per robot
      const net::RemoteState sp = puma_.state();
      if (sp.sample != puma_sample_) {
        puma_sample_ = sp.sample;
        puma_recent_[puma_next_] = {measured_ns(sp, puma_period_), sp.q_measured};
        puma_next_ = (puma_next_ + 1) % puma_recent_.size();
      }
      const net::RemoteState sm = microbo_.state();
      if (sm.sample != microbo_sample_) {
        microbo_sample_ = sm.sample;
        const std::int64_t at = measured_ns(sm, microbo_period_);
        if (at <= until_ns && pending_count_ < pending_.size()) {
          pending_[pending_count_++] = {at, sm.q_measured};
        }
      }
      // Each Microbo reading the PUMA's states bracket: paired, measured, taken off.
      std::size_t kept = 0;
      for (std::size_t i = 0; i < pending_count_; ++i) {
        kin::JointVector q;
        switch (puma_at(pending_[i].ns, q)) {
          case Bracket::inside:
            meter.add(static_cast<double>(pending_[i].ns - t0_ns_) * 1e-9, g_.tip(pending_[i].q),
                      g_.pad(q, pad));
            break;
          case Bracket::later:
            pending_[kept++] = pending_[i];
            break;
          case Bracket::gone:
            break;  // older than the PUMA's readings kept
        }
      }
      pending_count_ = kept;
    }
    meter.finish();
  }
  double ended_s(std::string_view robot, const rccl::Motion& m) override {
    // The event's time is on the robot's serve clock; the robot's newest state maps that clock
    // to the host's (stamp_ns is the wall time its t_s stands for).
    net::RemoteArm& arm = c_.robot(robot);
    // The wait that saw the end answers from the robot's state; the end time comes with the end
    // event, which a frame lost on the way delays by a retransmission (up to 2 s here).
    double end_s = arm.report(m).end_s;
    for (int i = 0; end_s <= 0.0 && i < 2000 && controlling(); ++i) {
      c_.wait_for(1ms);
      end_s = arm.report(m).end_s;
    }
    const net::RemoteState s = arm.state();
    const double wall_ns = static_cast<double>(s.stamp_ns) - (s.t_s - end_s) * 1e9;
    return (wall_ns - static_cast<double>(t0_ns_)) * 1e-9;
  }
  double now_s() override { return static_cast<double>(net::wall_ns() - t0_ns_) * 1e-9; }
  bool controlling() override {
    try {
      return !puma_.state().control_ended && !microbo_.state().control_ended;
    } catch (const rccl::MotionError&) {  // no state yet
      return false;
    }
  }
  // Each serve process checks its robot against the other's published state, in its own
  // process: the figures are not gathered into this one (a stop fails a motion: see failures).
  [[nodiscard]] std::optional<double> closest_m() const override { return std::nullopt; }
  [[nodiscard]] std::optional<std::uint64_t> collision_stops() const override {
    return std::nullopt;
  }
  [[nodiscard]] const char* clock() const override { return "real time"; }
  [[nodiscard]] std::string note() const override {
    return "across processes: errors pair the Microbo's measured tip with the PUMA's measured "
           "joints interpolated to the same wall time; hand: as commanded and acknowledged "
           "(the robot's state carries no hand reading)";
  }
  bool finish() override { return true; }  // the serve processes keep their own logs

 private:
  struct Reading {
    std::int64_t ns = 0;  ///< CLOCK_REALTIME the joints were read at
    kin::JointVector q;
  };
  enum class Bracket : std::uint8_t { inside, later, gone };

  static std::chrono::nanoseconds period_of(const cell::CellModel& m, std::string_view robot) {
    for (std::size_t i = 0; i < m.robots.size(); ++i) {
      if (m.robots[i].name == robot) return m.period(i);
    }
    return m.base_period;
  }

  /// When a state's measured joints were read, ns: its setpoint (stamp_ns) stands two periods
  /// after the sample that read them (the generator's pipeline).
  [[nodiscard]] static std::int64_t measured_ns(const net::RemoteState& s,
                                                std::chrono::nanoseconds period) {
    return s.stamp_ns - 2 * period.count();
  }
  /// The PUMA's measured joints at `ns`, linear between the two readings around it.
  Bracket puma_at(std::int64_t ns, kin::JointVector& q) const {
    const Reading* before = nullptr;
    const Reading* after = nullptr;
    for (const Reading& x : puma_recent_) {
      if (x.q.empty()) continue;
      if (x.ns <= ns && (before == nullptr || x.ns > before->ns)) before = &x;
      if (x.ns >= ns && (after == nullptr || x.ns < after->ns)) after = &x;
    }
    if (after == nullptr) return Bracket::later;
    if (before == nullptr) return Bracket::gone;
    q = before->q;
    const double span = static_cast<double>(after->ns - before->ns);
    const double f = span > 0.0 ? static_cast<double>(ns - before->ns) / span : 0.0;
    for (std::size_t j = 0; j < q.size(); ++j) q[j] += f * (after->q[j] - before->q[j]);
    return Bracket::inside;
  }

  net::RemoteCell& c_;
  Geometry g_;
  net::RemoteArm& puma_;
  net::RemoteArm& microbo_;
  std::chrono::nanoseconds puma_period_, microbo_period_;
  std::int64_t t0_ns_;                     ///< the cell's start on the host's clock
  std::array<Reading, 64> puma_recent_{};  ///< 64 PUMA samples: 0.45 s
  std::size_t puma_next_ = 0;
  std::uint64_t puma_sample_ = 0, microbo_sample_ = 0;
  std::array<Reading, 8> pending_{};  ///< Microbo readings waiting for the PUMA's
  std::size_t pending_count_ = 0;
};

struct Options {
  double moving_speed_mm_s = 5.0;
  std::string csv_path;
};

/// The demonstration: the same calls whether the robots run in this process or in others.
int run_program(cell::Workcell& c, Watch& watch, const Options& o) {
  const cell::CellRobot& puma_model = *c.model().find_robot("puma");
  const cell::CellRobot& microbo_model = *c.model().find_robot("microbo");
  const math::Transform puma_tool = puma_model.tool.value();
  const math::Transform microbo_tool = microbo_model.tool.value();

  // Where the board lies on the stage, and where the PUMA presents it: 60 mm nearer the Microbo
  // and 38 mm higher, so that every pad is mid-travel for the Microbo's d2 (200 .. 330 mm: the
  // probe's tip at 140 .. 170 mm puts it at 265 .. 295 mm) and d3 (245 .. 330 mm of 150 .. 450).
  const math::Transform board_home = c.model().find_frame("board_home")->pose;
  const math::Transform presented = math::Transform::translation(60_mm, 0, 140_mm);
  const math::Transform presented_end = math::Transform::translation(60_mm, kTravel, 140_mm);

  const math::Transform tool_on_board = tool_in_board();  // GRASP's inverse
  const math::Transform grasp_value = tool_on_board.inverse();

  // --- Reachability, before anything moves: every goal solved within both arms' limits -------
  const kin::Kinematics& puma_kin = c.robot("puma").kinematics();
  const kin::Kinematics& microbo_kin = c.robot("microbo").kinematics();
  const auto puma_t6 = [&](const math::Transform& board) {
    return c.world_to_base("puma", board * tool_on_board * puma_tool.inverse());
  };
  const auto microbo_t6 = [&](const math::Transform& board, const Pad& pad, double above_m) {
    return c.world_to_base("microbo", board * down_at(pad.x_mm * 1e-3, pad.y_mm * 1e-3, above_m) *
                                          microbo_tool.inverse());
  };
  const math::Transform lifted = board_home * math::Transform::translation(0, 0, 25_mm);
  const math::Transform over_home = board_home * math::Transform::translation(0, 0, 25_mm);
  int puma_goals = 0, microbo_goals = 0, unreachable = 0;
  const auto check = [&](const kin::Kinematics& k, const math::Transform& t6, int& goals,
                         const std::string& what) {
    ++goals;
    const kin::IkResult r = k.inverse(t6);
    if (!r) {
      ++unreachable;
      fmt::print(stderr, "{} cannot reach {}: {}\n", k.model().name, what, kin::describe(r.status));
    }
  };
  for (const math::Transform& b : {over_home, board_home, lifted, presented, presented_end}) {
    check(puma_kin, puma_t6(b), puma_goals,
          fmt::format("the board at ({:.0f}, {:.0f}, {:.0f}) mm", b.p.x * 1e3, b.p.y * 1e3,
                      b.p.z * 1e3));
  }
  for (const math::Transform& b : {presented, presented_end}) {
    for (const Pad& pad : kPads) {
      for (const double above : {0.0, kProbeAbove}) {
        check(microbo_kin, microbo_t6(b, pad, above), microbo_goals,
              fmt::format("{} {:.0f} mm above, board at y = {:.0f} mm", pad.name, above * 1e3,
                          b.p.y * 1e3));
      }
    }
  }
  fmt::print(
      "reach: {} PUMA goals (board on the stage, lifted, presented, moved) and {} Microbo "
      "goals (each pad and above it, board presented and moved): {} unreachable\n",
      puma_goals, microbo_goals, unreachable);
  if (unreachable > 0) return 1;

  c.start();  // one process: control starts; across processes: this program takes the robots
  rccl::Arm& puma = c.robot("puma");
  rccl::Arm& microbo = c.robot("microbo");

  // --- Equations --------------------------------------------------------------------------------
  const auto t6 = rccl::t6();
  const auto ptool = rccl::constant("PTOOL", puma_tool);
  const auto grasp = rccl::constant("GRASP", grasp_value);
  // T6 PTOOL GRASP = BASE_INV(puma) BOARD, tool GRASP: Cartesian moves carry the board straight.
  const auto board_at = [&](const char* name, const math::Transform& board) {
    return rccl::Position::make(name, {t6, ptool, grasp},
                                {c.in_base_of("puma", rccl::constant(name, board))});
  };
  const auto p_over = board_at("OVER_BOARD", over_home);
  const auto p_grip = board_at("ON_BOARD", board_home);
  const auto p_lift = board_at("LIFT", lifted);
  const auto p_present = board_at("PRESENT", presented);
  const auto p_moved = board_at("MOVED", presented_end);

  // T6 TOOL = BASE_INV(microbo) PUMA_TOOL GRASP PAD DOWN: on the pad wherever the PUMA holds it
  // (a goal in the world for the Microbo's tool: cell.world_goal, which keeps PUMA_TOOL a term
  // of its own, so that it can be sent by name to another process).
  const auto puma_frame = c.tool_frame("puma");
  const auto mgrasp = rccl::constant("GRASP", grasp_value);
  std::vector<rccl::PositionPtr> above, touch;
  for (const Pad& pad : kPads) {
    const auto probe = [&](const std::string& name, double z_m) {
      const auto at = rccl::constant(name, down_at(pad.x_mm * 1e-3, pad.y_mm * 1e-3, z_m));
      return c.world_goal("microbo", name, {puma_frame, mgrasp, at});
    };
    above.push_back(probe(std::string("ABOVE_") + pad.name, kProbeAbove));
    touch.push_back(probe(std::string("TOUCH_") + pad.name, 0.0));
  }
  // Where the Microbo waits, out of the PUMA's way: its arm drawn in (d3 200 mm), 300 mm up and
  // turned aside, clear of where the PUMA's hand swings down to the board; tool down as in its
  // ready pose.
  kin::JointVector wait_q = microbo_kin.model().ready();
  wait_q[0] = 0.8;  // turned 46 deg away from where the PUMA's hand comes down (world -y)
  wait_q[1] = 0.300;
  wait_q[2] = 0.200;
  const auto m_wait = rccl::Position::joints("MICROBO_WAIT", wait_q);
  // On the way there it lifts its arm, draws it in, and only then lowers it: its probe stands
  // over the board at the ready pose, and the collision check stops any motion that brings a
  // part closer to an object it may not touch.
  kin::JointVector up_q = microbo_kin.model().ready();
  up_q[1] = microbo_kin.model().joints[1].upper - 0.005;  // not at the stop: the RCU overshoots
  kin::JointVector drawn_q = up_q;
  drawn_q[2] = wait_q[2];
  const auto m_up = rccl::Position::joints("MICROBO_UP", up_q);
  const auto m_drawn = rccl::Position::joints("MICROBO_DRAWN_IN", drawn_q);
  fmt::print("{}\n{}\n", p_present->describe(), touch.front()->describe());

  // --- 1. Pick and present --------------------------------------------------------------------
  constexpr auto kTimeout = 60s;
  bool good = true;
  const auto wait = [&](rccl::Arm& m, const rccl::Event& e) {
    if (!good) return;
    const rccl::WaitResult w = m.waitfor(e, kTimeout);
    if (reached(w)) return;
    good = false;  // failures() says why a motion failed; a timeout or lost control, here
    fmt::print(stderr, "{}: waiting for motion {}: {}\n", &m == &puma ? "PUMA" : "Microbo", e.id,
               rccl::to_string(w));
  };
  puma.set_velocity(80_mm, 45_deg);  // joint moves, too, take their time from these
  microbo.set_velocity(80_mm, 45_deg);
  // The arms start 57 mm apart (both ready poses reach over the board): the Microbo backs off
  // first, and the PUMA sets off once that motion has ended.
  microbo.move(m_up);
  microbo.move(m_drawn);
  const rccl::Motion back_off = microbo.move(m_wait);
  // The PUMA's hand swings down past the waiting Microbo's arm: slowly, so that the collision
  // check's braking allowance (which grows with speed) leaves them room.
  // The gripper comes down over the board's edge, closes on it over the stage, and carries the
  // board (whose box stays where the cell file puts it): those motions may touch both.
  const rccl::StartWhen grip = c.touching({"board", "xy_stage"});
  const std::uint64_t board_and_stage = grip.touch;
  rccl::StartWhen after_back_off = c.after("microbo", back_off.end());
  after_back_off.touch = board_and_stage;
  puma.set_velocity(30_mm, 20_deg);
  puma.move(p_over, after_back_off);
  puma.set_mode(rccl::Mode::cartesian);
  puma.set_velocity(30_mm, 30_deg);
  const rccl::Motion descend = puma.move(p_grip, grip);
  wait(puma, descend.end());
  puma.set_hand(true);
  wait(puma, puma.dwell(0.5, grip).end());  // the fingers close on the board's edge
  puma.set_velocity(50_mm, 30_deg);
  puma.move(p_lift, grip);
  const rccl::Motion present = puma.move(p_present, grip);
  if (!good) {  // the pick failed: the Microbo's goals on the board would be nowhere
    // Across processes a failure's event (with its reason) may come after the state that said
    // the motion failed: a moment for it.
    c.wait_for(500ms);
    for (rccl::Arm* m : {&puma, &microbo}) {
      for (const rccl::MotionEvent& f : m->failures()) {
        if (!f.message().empty())
          fmt::print(stderr, "{}: {}\n", m == &puma ? "PUMA" : "Microbo", f.message());
      }
    }
    fmt::print(stderr, "the PUMA could not pick the board up; nothing is probed\n");
    return 1;
  }

  // --- 2-4. Probe, with the board moving for some pads, and repair one -------------------------
  std::array<PadResult, kPads.size()> results{};
  microbo.set_mode(rccl::Mode::cartesian);
  // Slowly among the PUMA's hand and the board: the collision check's braking allowance grows with
  // speed, and the Microbo's hand passes within 50 mm of the PUMA's flange.
  microbo.set_velocity(15_mm, 10_deg);
  // The Microbo starts only once the board stands still where it is presented.
  // The collision check keeps every part of both arms off the cell's objects, unless a motion
  // names what its tool may touch: the probe touches the board; the Microbo's arm and hand may
  // not.
  const rccl::StartWhen probe = c.touching({"board"});
  rccl::StartWhen after_present = c.after("puma", present.end());
  after_present.touch = probe.touch;
  // Queued once the board is there: move() checks a goal through the PUMA's frame for reach as
  // it is when queued, and with the board still on the stage or on its way (where it is at that
  // moment depends on the machine's load, across processes) a pad can be out of the Microbo's
  // limits.
  wait(puma, present.end());
  const rccl::Motion first_above = microbo.move(above[0], after_present);
  wait(microbo, first_above.start());
  const double presented_s = good ? watch.ended_s("puma", present) : 0.0;

  rccl::Motion slow{};
  for (std::size_t i = 0; i < kPads.size() && good; ++i) {
    if (i > 0) microbo.move(above[i], probe);
    const rccl::Motion down = microbo.move(touch[i], probe);
    if (i == kStartMovingAfter) {
      // Once the Microbo has touched TP3, the PUMA carries the board slowly along y.
      puma.set_velocity(o.moving_speed_mm_s * 1e-3, 10_deg);
      rccl::StartWhen after_touch = c.after("microbo", down.end());
      after_touch.touch = board_and_stage;
      slow = puma.move(p_moved, after_touch);
    }
    wait(microbo, down.end());
    if (!good) break;
    results[i].touched_s = watch.ended_s("microbo", down);
    // The dwell is time let pass, not microbo.dwell(): a queued dwell holds the joints, while a
    // motion to a moving goal that has ended keeps tracking it.
    if (i == kRepairPad) {
      microbo.set_hand(true);
      watch.measure(kPads[i], kRepairS, true, results[i]);
      microbo.set_hand(false);
    } else {
      watch.measure(kPads[i], kDwellS, false, results[i]);
    }
    microbo.move(above[i], probe);  // up
  }
  if (slow.id != 0) wait(puma, slow.end());
  // --- 5. Both back ----------------------------------------------------------------------------
  microbo.set_mode(rccl::Mode::joint);
  const rccl::Motion away = microbo.move(m_wait);
  puma.set_velocity(50_mm, 30_deg);
  rccl::StartWhen after_away = c.after("microbo", away.end());  // out of the PUMA's way first
  after_away.touch = board_and_stage;
  puma.move(p_lift, after_away);
  puma.set_velocity(30_mm, 30_deg);
  wait(puma, puma.move(p_grip, grip).end());
  puma.set_hand(false);
  wait(puma, puma.dwell(0.5, grip).end());
  puma.move(p_over, grip);
  puma.set_mode(rccl::Mode::joint);
  puma.set_velocity(80_mm, 45_deg);
  puma.move(puma.park(), grip);  // from over the board's edge, where it let go
  wait(puma, puma.completed());
  const double end_s = watch.now_s();

  // --- The table ---------------------------------------------------------------------------------
  fmt::print(
      "\nboard presented at {:.2f} s; the PUMA moves it {:.0f} mm along y at {:.1f} mm/s from the "
      "touch of {}\n\n",
      presented_s, kTravel * 1e3, o.moving_speed_mm_s, kPads[kStartMovingAfter].name);
  fmt::print(
      " pad   x mm   y mm  board     touched s  dwell s  samples  error mm max / mean / end  "
      "hand\n");
  double worst_m = 0.0;
  int moving_pads = 0;
  std::FILE* csv = o.csv_path.empty() ? nullptr : std::fopen(o.csv_path.c_str(), "w");
  if (!o.csv_path.empty() && csv == nullptr) {
    fmt::print(stderr, "cannot write {}\n", o.csv_path);
    good = false;
  }
  if (csv != nullptr) {
    fmt::print(csv,
               "pad,x_mm,y_mm,board_speed_mm_s,touched_s,samples,max_error_mm,"
               "mean_error_mm,end_error_mm,hand_closed\n");
  }
  for (std::size_t i = 0; i < kPads.size(); ++i) {
    const Pad& p = kPads[i];
    const PadResult& r = results[i];
    // Moving: the pad travelled faster than 0.5 mm/s while probed (the servos' drift is far less).
    const bool moving = r.board_speed_m_per_s > 0.5_mm;
    moving_pads += moving ? 1 : 0;
    const double mean_m = r.samples > 0 ? r.sum_error_m / r.samples : 0.0;
    worst_m = std::max(worst_m, r.max_error_m);
    good = good && r.samples > 0;
    fmt::print(
        "{:4} {:6.1f} {:6.1f}  {:<9} {:9.2f} {:8.2f} {:8}  {:8.3f} / {:5.3f} / {:5.3f}  {}\n",
        p.name, p.x_mm, p.y_mm,
        moving ? fmt::format("{:.1f} mm/s", r.board_speed_m_per_s * 1e3) : "still", r.touched_s,
        i == kRepairPad ? kRepairS : kDwellS, r.samples, r.max_error_m * 1e3, mean_m * 1e3,
        r.last_error_m * 1e3, r.hand_closed ? "closed" : "open");
    if (csv != nullptr) {
      fmt::print(csv, "{},{},{},{:.3f},{:.3f},{},{:.4f},{:.4f},{:.4f},{}\n", p.name, p.x_mm, p.y_mm,
                 r.board_speed_m_per_s * 1e3, r.touched_s, r.samples, r.max_error_m * 1e3,
                 mean_m * 1e3, r.last_error_m * 1e3, r.hand_closed ? 1 : 0);
    }
  }
  if (csv != nullptr && std::fclose(csv) != 0) {
    fmt::print(stderr, "cannot write {}\n", o.csv_path);
    good = false;
  }
  if (!watch.note().empty()) fmt::print("({})\n", watch.note());

  if (!good) c.wait_for(500ms);  // the failures' events, as above
  const std::size_t puma_failures = puma.failures().size();
  const std::size_t microbo_failures = microbo.failures().size();
  const std::optional<std::uint64_t> stops = watch.collision_stops();
  const std::optional<double> closest_m = watch.closest_m();
  fmt::print(
      "\n{} pads probed, {} on the moving board; worst error {:.3f} mm (bound {:.1f} mm)\n"
      "failures: PUMA {}, Microbo {}; collision stops {}; closest approach of the arms' capsules "
      "{} (margin {:.0f} mm); {} {:.1f} s\n",
      kPads.size(), moving_pads, worst_m * 1e3, kPadRadius * 1e3,
      puma_failures == 0 ? std::string("none") : std::to_string(puma_failures),
      microbo_failures == 0 ? std::string("none") : std::to_string(microbo_failures),
      stops ? std::to_string(*stops) : std::string("not counted across processes"),
      closest_m ? fmt::format("{:.1f} mm", *closest_m * 1e3)
                : std::string("not measured across processes"),
      c.model().collision_margin_m * 1e3, watch.clock(), end_s);

  std::fflush(stdout);  // the table before the messages on stderr
  for (rccl::Arm* m : {&puma, &microbo}) {
    for (const rccl::MotionEvent& f : m->failures()) {
      fmt::print(stderr, "{} motion {} {}: {}\n", m == &puma ? "puma" : "microbo", f.id,
                 rccl::to_string(f.kind), f.message());
    }
  }
  if (!good || puma_failures + microbo_failures > 0 || stops.value_or(0) > 0 ||
      !watch.controlling()) {
    fmt::print(stderr, "the demonstration did not run through\n");
    return 1;
  }
  if (worst_m > kPadRadius) {
    fmt::print(stderr, "a probe missed its pad by more than {:.1f} mm\n", kPadRadius * 1e3);
    return 1;
  }
  return watch.finish() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "The PUMA 260 presents a circuit board and the Microbo probes its test pads, some while "
      "the board moves (thesis 4.5, figure 4.8; CVaRL cell): in one process in simulated time, "
      "or with --remote on two `rccx serve` processes in real time."};
  Options o;
  std::string cell_path;  // empty: the shipped cells/cvarl.json (io::find_data_file)
  bool remote = false;
  long domain = -1;
  std::string interface;
  std::string detection = "20ms";
  app.add_option("--moving-speed", o.moving_speed_mm_s,
                 "speed of the board's slow move while the Microbo probes, mm/s")
      ->check(CLI::Range(1.0, 20.0))
      ->capture_default_str();
  app.add_option("--csv", o.csv_path, "also write the table to this CSV file (mm, s)");
  app.add_option("--cell", cell_path,
                 "the cell file (default: cells/cvarl.json under $RCCX_DATA_DIR, else the "
                 "installed share/rccx or the source tree)")
      ->check(CLI::ExistingFile);
  app.add_flag("--remote", remote,
               "command robots that `rccx serve` processes run (the PUMA and the Microbo), in "
               "real time, instead of running the cell here");
  app.add_option("--domain", domain,
                 "--remote: the DDS domain of the serve processes, 0 .. 232 (default: "
                 "$RCCX_DOMAIN, else 0)")
      ->check(CLI::Range(0, 232));
  app.add_option("--interface", interface,
                 "--remote: the network interface for DDS (lo, eth0, an address; default: "
                 "$RCCX_DDS_INTERFACE, else Cyclone's choice)");
  app.add_option("--detection", detection,
                 "--remote: a serve process silent this long is lost (2ms .. 10s)")
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help exits 0; bad input 2, as every rccx command (docs/RELIABILITY.md).
    return app.exit(e) == 0 ? 0 : 2;
  }
  net::NetOptions net;
  try {
    net.detection = io::parse_duration(detection, "--detection", io::BareUnit::seconds, 2ms, 10s);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "10_circuit_board: %s\n", e.what());
    return 2;
  }
  if (!remote && (domain >= 0 || !interface.empty() || app.count("--detection") > 0)) {
    std::fprintf(stderr,
                 "10_circuit_board: --domain, --interface and --detection go with --remote\n");
    return 2;
  }

  try {
    if (cell_path.empty()) cell_path = io::find_data_file("cells/cvarl.json").string();
  } catch (const io::DataFileError& e) {
    std::fprintf(stderr, "10_circuit_board: %s, or give --cell FILE\n", e.what());
    return 2;
  }

  if (!remote) {
    // The default options: collision checks on, each robot on its own plant (not ideal_servo).
    const std::unique_ptr<cell::Cell> c = cell::Cell::load(cell_path);
    const Geometry g{*c->model().find_robot("puma"), *c->model().find_robot("microbo"),
                     c->robot("puma").kinematics(), c->robot("microbo").kinematics(),
                     tool_in_board().inverse()};
    LocalWatch watch(*c, g);
    return run_program(*c, watch, o);
  }

  if (domain >= 0) net.domain = static_cast<std::uint32_t>(domain);
  net.interface = interface;
  net.heartbeat = std::max(net.detection / 4, std::chrono::nanoseconds(1ms));
  try {
    net::RemoteOptions ro;
    ro.wait_for_robots = 30s;  // serve processes still starting on a loaded machine
    net::RemoteCell c(cell::load_cell_file(cell_path), net, ro);
    fmt::print("across processes: the PUMA served by {}, the Microbo by {} (DDS domain {})\n",
               c.robot("puma").state().participant, c.robot("microbo").state().participant,
               net::domain_of(net));
    const Geometry g{*c.model().find_robot("puma"), *c.model().find_robot("microbo"),
                     c.robot("puma").kinematics(), c.robot("microbo").kinematics(),
                     tool_in_board().inverse()};
    RemoteWatch watch(c, g);
    return run_program(c, watch, o);
  } catch (const net::NetError& e) {
    std::fprintf(stderr, "10_circuit_board: %s\n", e.what());
    return 1;
  } catch (const rccl::MotionError& e) {  // a request refused, or a serve that did not answer
    std::fprintf(stderr, "10_circuit_board: %s\n", e.what());
    return 1;
  }
}
