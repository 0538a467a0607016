// Property test of the cell's collision stop (issue 13): many random two-robot programs in the
// CVaRL cell (cells/cvarl.json), both arms moving at once in simulated time, and on every tick
// of every program the two robots' setpoint capsules are never closer than the cell's margin
// and no joint setpoint leaves its limits. The capsules of the measured arms (each session's
// How, lagging the setpoints through the servo) are tracked and reported too, and every stop
// message must name both robots and links.
//
// Each program starts the arms from random poses outside the margin, then gives each robot a
// start delay and 1 .. 4 moves (random joint goals within the limits, or random world goals
// around the board, where the arms' workspaces overlap), in joint or Cartesian mode, at random
// speeds, with random dwells; some stopped programs go on with more moves from where the arms
// stand. Three scenarios (see Scenario) bring out stops from speed, stops at a crawl close to
// the margin and programs that run to their end. A good share of programs must end in a
// collision stop, or the generator tests nothing.
//
//   RCCX_PROPERTY_SEED=n       another seed (the one used is printed)
//   RCCX_PROPERTY_PROGRAMS=n   how many programs (default 500)
//   RCCX_PROPERTY_PROGRAM=i    only program i of the seed, its plan and its stops printed
//   RCCX_PROPERTY_REAL_EVERY=k every k-th program on the real plants (default 10; 1: all)
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "rccx/cell/cell.hpp"
#include "rccx/cell/collision.hpp"
#include "rccx/cell/robot_capsules.hpp"
#include "rccx/math/units.hpp"

using namespace rccx;
using namespace std::chrono_literals;

namespace {

const char* const kCvarl = RCCX_CVARL_CELL;
constexpr std::uint64_t kDefaultSeed = 20261123;
constexpr std::size_t kDefaultPrograms = 500;
constexpr double kInf = std::numeric_limits<double>::infinity();
/// Every k-th program runs on the real plants (the PUMA's PID on its dynamics, the Microbo's
/// RCU); the others on ideal servos, which cost a third of the time per tick (the PUMA's
/// dynamics dominate a tick in the sanitizer build).
constexpr std::size_t kRealPlantsEvery = 10;
/// The share of programs stopped by the check that go on with more moves from where they
/// stand.
constexpr double kResume = 0.2;
/// Programs start with the arms' capsules at least this far outside the margin, m; a crawl
/// within kCrawlStart_m of each other (inside the zone where an approach is stopped even from
/// rest: the Microbo's 28 ms period makes its allowance about 10 mm standing).
constexpr double kStartOutside_m = 0.0005;
constexpr double kCrawlStart_m = 0.03;
/// The Microbo's d3 at its shortest, m (robots/microbo.json).
constexpr double kMicroboShortestD3_m = 0.15;

std::uint64_t env_or(const char* name, std::uint64_t fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  return std::strtoull(v, nullptr, 0);
}

/// The equation T6 TOOL = BASE_INV(robot) WORLD_GOAL for a world pose.
rccl::PositionPtr world_position(cell::Cell& c, const std::string& robot, const std::string& name,
                                 const math::Transform& world_goal) {
  const auto t6 = rccl::t6();
  const auto tool = rccl::constant(robot + "_tool", c.model().find_robot(robot)->tool.value());
  const auto goal = c.in_base_of(robot, rccl::constant(name, world_goal));
  return rccl::Position::make(name, {t6, tool}, {goal}, tool);
}

/// One robot's random program, drawn and queued at once (so that the plan can be printed).
struct Plan {
  std::string text;          ///< what was queued, for a failure's report
  std::size_t moves = 0;     ///< moves queued
  std::size_t rejected = 0;  ///< goals move() refused (out of reach), drawn again
};

/// What kind of program: each brings out another side of the check.
enum class Scenario : std::uint8_t {
  /// Both arms over the whole board at ordinary speeds: stops, mostly far out (a fast arm's
  /// braking allowance is large).
  course,
  /// Both arms start near each other and creep over the whole board: the smallest braking
  /// allowances, the stops closest to the margin.
  crawl,
  /// Each arm on its own side of the board, the Microbo's arm drawn in: programs that run to
  /// their end (unless a fast arm's allowance reaches across).
  apart,
};

std::string_view to_string(Scenario s) {
  switch (s) {
    case Scenario::course:
      return "collision course";
    case Scenario::crawl:
      return "crawl";
    case Scenario::apart:
      return "own sides";
  }
  return "?";
}

/// A program runs at most this long in simulated time before both arms are halted: long
/// enough for four moves on their own sides, shorter for a crawl (which stops within a
/// second or two when it meets the other arm, or creeps on, away from it).
constexpr std::chrono::nanoseconds budget(Scenario s) {
  return s == Scenario::crawl ? std::chrono::nanoseconds(2s) : std::chrono::nanoseconds(5s);
}

class Generator {
 public:
  explicit Generator(std::uint64_t seed) : rng_(seed) {}

  double uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  bool chance(double p) { return uniform(0.0, 1.0) < p; }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  double log_uniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }

  Scenario scenario() {
    const double u = uniform(0.0, 1.0);
    return u < 0.45 ? Scenario::course : (u < 0.88 ? Scenario::crawl : Scenario::apart);
  }

  /// The cell with the robots' start poses for one program (the simulated arms start at their
  /// model's ready pose): turned a little about their first axes, outside the margin (`world`
  /// measures it). At the CVaRL ready poses the Microbo's arm reaches to within 64 mm of the
  /// PUMA's wrist; on their own sides it starts drawn in (d3 short), for a crawl stretched out.
  cell::CellModel start_poses(const cell::CellModel& cvarl, Scenario s,
                              cell::CollisionWorld& world) {
    for (;;) {
      cell::CellModel m = cvarl;
      kin::RobotModel& microbo = m.robots[1].model;
      if (s == Scenario::apart) microbo.joints[2].ready = uniform(0.16, 0.2);
      if (s == Scenario::crawl) microbo.joints[2].ready = uniform(0.3, 0.38);
      microbo.joints[0].ready = uniform(-0.2, 0.2);
      m.robots[0].model.joints[0].ready = uniform(-0.3, 0.3);
      world.set_configuration(0, m.robots[0].model.ready());
      world.set_configuration(1, microbo.ready());
      const double d = world.min_distance(0, 1).distance_m;
      // A crawl starts close, so that it meets the other arm soon.
      if (d >= world.margin_m() + kStartOutside_m && (s != Scenario::crawl || d < kCrawlStart_m)) {
        return m;
      }
    }
  }

  /// A world goal around the board where both arms reach: tool down, turned about the
  /// vertical, tilted a little; x within [x_lo, x_hi] (the PUMA stands at -x, the Microbo at +x).
  math::Transform world_goal(double x_lo, double x_hi) {
    const math::Vec3 p{uniform(x_lo, x_hi), uniform(-0.12, 0.12), uniform(0.09, 0.21)};
    const math::Rot3 R = math::Rot3::rot_z(uniform(-0.8, 0.8)) * math::Rot3::rot_x(math::kPi) *
                         math::Rot3::rot_x(uniform(-0.25, 0.25)) *
                         math::Rot3::rot_y(uniform(-0.25, 0.25));
    return {R, p};
  }

  /// Joint values within the limits, within `spread` of each joint's span around the start
  /// pose (1: anywhere). On their own sides the Microbo's arm stays drawn in.
  kin::JointVector joint_goal(const kin::RobotModel& m, bool puma, Scenario s) {
    kin::JointVector q = m.ready();
    const double spread = s == Scenario::course && chance(0.3) ? 1.0 : 0.1;
    for (std::size_t j = 0; j < m.dof(); ++j) {
      const kin::Joint& k = m.joints[j];
      const double half = spread * (k.upper - k.lower);
      q[j] = uniform(std::max(k.lower, k.ready - half), std::min(k.upper, k.ready + half));
    }
    if (s == Scenario::apart && !puma) q[2] = uniform(kMicroboShortestD3_m, 0.2);
    return q;
  }

  /// Draws and queues one robot's program: a start delay, then 1 .. 4 moves to joint or world
  /// goals, in joint or Cartesian mode, each at its own speed, some followed by a dwell.
  Plan queue(cell::Cell& c, const std::string& robot, Scenario s) {
    rccl::Manipulator& m = c.robot(robot);
    const bool puma = robot == "puma";
    const kin::RobotModel& model = c.model().find_robot(robot)->model;
    Plan plan;
    const double delay = chance(0.5) ? uniform(0.0, 0.25) : 0.0;
    if (delay > 0.0) {
      m.dwell(delay);
      plan.text += fmt::format("dwell {:.3f}; ", delay);
    }
    // World goals in x: on their own sides, the PUMA's left of the Microbo's drawn-in arm and
    // the Microbo's right of the PUMA's reach; crawling, each on the other's side of the board.
    double x_lo = -0.15, x_hi = 0.15;
    if (s == Scenario::apart) {
      x_lo = puma ? -0.2 : 0.12;
      x_hi = puma ? -0.08 : 0.2;
    } else if (s == Scenario::crawl) {
      x_lo = puma ? 0.0 : -0.15;
      x_hi = puma ? 0.15 : 0.0;
    }
    const int moves = integer(1, 4);
    for (int i = 0; i < moves; ++i) {
      // Log-uniform speeds: as many slow moves as brisk ones.
      if (s == Scenario::crawl) {
        m.set_velocity(log_uniform(0.01, 0.05), uniform(0.2, 0.6));
      } else if (s == Scenario::apart) {
        m.set_velocity(log_uniform(0.15, 0.3), uniform(2.0, 3.0));
      } else {
        m.set_velocity(log_uniform(0.1, 0.5), uniform(2.0, 4.0));
      }
      m.set_transition_time(uniform(0.05, 0.4));
      const auto head = [&] {
        return fmt::format("{} {:.3f} m/s {:.2f} rad/s tr {:.2f}: ",
                           m.settings().mode == rccl::Mode::joint ? "joint" : "cartesian",
                           m.settings().translation_m_per_s, m.settings().rotation_rad_per_s,
                           m.settings().transition_time_s);
      };
      bool queued = false;
      if (chance(0.3)) {
        // In joint mode: a straight line to random joints mostly leaves the workspace.
        m.set_mode(rccl::Mode::joint);
        const kin::JointVector q = joint_goal(model, puma, s);
        try {
          m.move(rccl::Position::joints(fmt::format("J{}", i), q));
          plan.text +=
              head() + fmt::format("joints [{:.4f}]; ", fmt::join(q.begin(), q.end(), ", "));
          queued = true;
        } catch (const rccl::MotionError&) {
          ++plan.rejected;
        }
      }
      m.set_mode(chance(0.5) ? rccl::Mode::joint : rccl::Mode::cartesian);
      for (int attempt = 0; !queued && attempt < 20; ++attempt) {
        const math::Transform g = world_goal(x_lo, x_hi);
        try {
          m.move(world_position(c, robot, fmt::format("W{}", i), g));
          plan.text += head() + fmt::format(
                                    "world p [{:.4f}, {:.4f}, {:.4f}] n [{:.4f}, {:.4f}, {:.4f}] "
                                    "a [{:.4f}, {:.4f}, {:.4f}]; ",
                                    g.p.x, g.p.y, g.p.z, g.R.n.x, g.R.n.y, g.R.n.z, g.R.a.x,
                                    g.R.a.y, g.R.a.z);
          queued = true;
        } catch (const rccl::MotionError&) {
          ++plan.rejected;
        }
      }
      if (!queued) continue;
      ++plan.moves;
      if (chance(0.3)) {
        const double d = uniform(0.0, 0.15);
        m.dwell(d);
        plan.text += fmt::format("dwell {:.3f}; ", d);
      }
    }
    return plan;
  }

 private:
  std::mt19937_64 rng_;
};

/// What the cycle observer saw in one program.
struct Seen {
  double setpoint_min_m = kInf;
  double measured_min_m = kInf;
  cell::Contact setpoint_closest;  ///< where setpoint_min_m was taken
  cell::Contact measured_closest;
  double setpoint_min_t_s = 0.0;
  std::size_t ticks = 0;
  double first_m = kInf;         ///< at the first tick with both setpoints
  std::uint64_t stops = 0;       ///< the cell's count as last seen (RCCX_PROPERTY_PROGRAM only)
  std::size_t below_margin = 0;  ///< ticks with setpoint capsules within the margin
  std::size_t out_of_limits = 0;
  std::string first_violation;
};

std::uint64_t mix(std::uint64_t seed, std::uint64_t i) {
  // splitmix64 of seed + i: programs independent of each other, one reproducible alone.
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (i + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

TEST(CellCollisionProperty, ACollisionCourseStopsBothBeforeTheCapsulesMeet) {
  const std::uint64_t seed = env_or("RCCX_PROPERTY_SEED", kDefaultSeed);
  const std::size_t programs = env_or("RCCX_PROPERTY_PROGRAMS", kDefaultPrograms);
  const char* only_env = std::getenv("RCCX_PROPERTY_PROGRAM");
  const bool only = only_env != nullptr && *only_env != '\0';
  const std::size_t first = only ? std::strtoull(only_env, nullptr, 0) : 0;
  const std::size_t last = only ? first + 1 : programs;
  const std::size_t real_every =
      std::max<std::uint64_t>(env_or("RCCX_PROPERTY_REAL_EVERY", kRealPlantsEvery), 1);
  std::printf("seed %llu (RCCX_PROPERTY_SEED), %zu programs (RCCX_PROPERTY_PROGRAMS)\n",
              static_cast<unsigned long long>(seed), last - first);

  const cell::CellModel model = cell::load_cell_file(kCvarl);
  const double margin_m = model.collision_margin_m;
  const std::size_t ip = 0, im = 1;
  ASSERT_EQ(model.robots[ip].name, "puma");
  ASSERT_EQ(model.robots[im].name, "microbo");
  // The measured arms' capsules, in a world of their own.
  std::vector<cell::RobotCapsules> capsules;
  for (const cell::CellRobot& r : model.robots)
    capsules.emplace_back(r.model, r.link_radius_m, r.base);
  cell::CollisionWorld measured_world(std::move(capsules), margin_m);

  // Outcomes per scenario, and in all (the last).
  struct Tally {
    std::size_t programs = 0, stopped = 0, completed = 0, failed = 0, cut = 0;
    double setpoint_min_m = kInf, measured_min_m = kInf;
  };
  std::array<Tally, 4> tally{};
  std::size_t stops_without_message = 0, unnamed_stops = 0, stop_messages = 0, both_stopped = 0;
  std::string silent_stops;  ///< the first programs stopped with no message
  std::size_t violations = 0, limit_violations = 0, rejected = 0, moves = 0;
  std::size_t real_plant_programs = 0, resumed_programs = 0, resumed_stopped = 0;
  // On the real plants: the closest measured capsules, and how much closer than the closest
  // setpoints of the same program the measured arms came (the servos' lag and overshoot).
  double real_measured_min_m = kInf, real_measured_closer_m = -kInf;
  std::size_t measured_below = 0;  ///< programs whose measured arms came within the margin
  std::string measured_report;
  double simulated_s = 0.0;
  const auto wall0 = std::chrono::steady_clock::now();

  for (std::size_t i = first; i < last; ++i) {
    cell::CellOptions options;
    const bool real_plants = i % real_every == 0;
    options.ideal_servo = !real_plants;
    Generator gen(mix(seed, i));
    const Scenario scenario = gen.scenario();
    const auto c =
        std::make_unique<cell::Cell>(gen.start_poses(model, scenario, measured_world), options);
    Seen seen;
    const kin::JointVector lo[2] = {model.robots[0].model.lower(), model.robots[1].model.lower()};
    const kin::JointVector hi[2] = {model.robots[0].model.upper(), model.robots[1].model.upper()};
    const std::string names[2] = {"puma", "microbo"};
    c->set_cycle_observer([&](std::uint32_t tick) {
      ++seen.ticks;
      bool both = true;
      for (std::size_t r = 0; r < 2; ++r) {
        const rccl::TrajectoryGenerator& g = c->robot(names[r]).generator();
        const kin::JointVector& q = g.last_setpoint();
        if (q.size() != lo[r].size()) {
          both = false;
          continue;
        }
        for (std::size_t j = 0; j < q.size(); ++j) {
          if (!(q[j] >= lo[r][j] && q[j] <= hi[r][j])) {
            if (seen.out_of_limits++ == 0 && seen.first_violation.empty()) {
              seen.first_violation =
                  fmt::format("{} joint {} setpoint {} outside [{}, {}] at {:.3f} s", names[r],
                              j + 1, q[j], lo[r][j], hi[r][j], g.last_setpoint_time_s());
            }
          }
        }
        const kin::JointVector measured = c->session(names[r]).how().q();
        if (measured.size() == lo[r].size()) measured_world.set_configuration(r, measured);
      }
      if (!both) return;
      const cell::Contact s = c->collision_world().min_distance(ip, im);
      if (seen.first_m == kInf) seen.first_m = s.distance_m;
      if (s.distance_m < seen.setpoint_min_m) {
        seen.setpoint_min_m = s.distance_m;
        seen.setpoint_closest = s;
        seen.setpoint_min_t_s = c->robot("puma").generator().last_setpoint_time_s();
      }
      if (s.distance_m < margin_m && seen.below_margin++ == 0 && seen.first_violation.empty()) {
        seen.first_violation = fmt::format(
            "setpoints: puma link {} and microbo link {} {:.2f} mm apart at {:.3f} s", s.link_a + 1,
            s.link_b + 1, s.distance_m * 1e3, c->robot("puma").generator().last_setpoint_time_s());
      }
      if (only && c->collision_stops() != seen.stops) {
        seen.stops = c->collision_stops();
        std::printf("  tick %u: stop %llu, setpoints %.3f mm apart, puma %s, microbo %s\n", tick,
                    static_cast<unsigned long long>(seen.stops), s.distance_m * 1e3,
                    c->robot("puma").generator().at_rest() ? "at rest" : "moving",
                    c->robot("microbo").generator().at_rest() ? "at rest" : "moving");
      }
      const cell::Contact m = measured_world.min_distance(ip, im);
      if (m.distance_m < seen.measured_min_m) {
        seen.measured_min_m = m.distance_m;
        seen.measured_closest = m;
      }
    });
    // The measured world starts at the ready poses, as the arms do.
    measured_world.set_configuration(ip, c->model().robots[ip].model.ready());
    measured_world.set_configuration(im, c->model().robots[im].model.ready());
    c->start();

    Plan pp = gen.queue(*c, "puma", scenario);
    Plan pm = gen.queue(*c, "microbo", scenario);

    rccl::Manipulator& puma = c->robot("puma");
    rccl::Manipulator& microbo = c->robot("microbo");
    rccl::WaitResult wp = rccl::WaitResult::reached, wm = wp;
    bool cut = false;
    // Runs what is queued to its end, or halts both arms once the scenario's budget is spent.
    const auto run = [&] {
      const std::size_t from = seen.ticks;
      const auto left = [&] {
        const auto elapsed = std::chrono::duration_cast<std::chrono::nanoseconds>(
            model.base_period * static_cast<std::int64_t>(seen.ticks - from));
        return std::max(std::chrono::nanoseconds(budget(scenario) - elapsed),
                        std::chrono::nanoseconds(1ms));
      };
      wp = puma.waitfor(rccl::Manipulator::completed(), left());
      wm = microbo.waitfor(rccl::Manipulator::completed(), left());
      if (wp == rccl::WaitResult::timeout || wm == rccl::WaitResult::timeout) {
        // Too long a program (crawling moves): both stop smoothly, still checked every tick.
        cut = true;
        puma.halt();
        microbo.halt();
        wp = puma.waitfor(rccl::Manipulator::completed(), 5s);
        wm = microbo.waitfor(rccl::Manipulator::completed(), 5s);
      }
    };
    run();
    // Stopped, the arms stand inside each other's braking zone: some programs go on from there
    // (the check lets arms move apart, and must stop them coming closer from a standstill).
    const bool resumed = c->collision_stops() > 0 && !cut && gen.chance(kResume);
    if (resumed) {
      const std::uint64_t stops_before = c->collision_stops();
      const Plan more_p = gen.queue(*c, "puma", scenario);
      const Plan more_m = gen.queue(*c, "microbo", scenario);
      pp.text += "after the stop: " + more_p.text;
      pm.text += "after the stop: " + more_m.text;
      pp.moves += more_p.moves;
      pm.moves += more_m.moves;
      pp.rejected += more_p.rejected;
      pm.rejected += more_m.rejected;
      run();
      ++resumed_programs;
      if (c->collision_stops() > stops_before) ++resumed_stopped;
    }
    rejected += pp.rejected + pm.rejected;
    moves += pp.moves + pm.moves;
    if (only) {
      std::printf("program %zu (%s)\n  puma: %s\n  microbo: %s\n", i,
                  std::string(to_string(scenario)).c_str(), pp.text.c_str(), pm.text.c_str());
    }
    // Both stand; the measured arms settle (the servos' overshoot, if any, is seen here; an
    // ideal servo is two of the Microbo's periods behind: the pipeline).
    c->wait_for(real_plants ? 250ms : 60ms);
    simulated_s +=
        static_cast<double>(seen.ticks) * std::chrono::duration<double>(model.base_period).count();
    EXPECT_NE(wp, rccl::WaitResult::timeout) << "program " << i;
    EXPECT_NE(wm, rccl::WaitResult::timeout) << "program " << i;
    EXPECT_NE(wp, rccl::WaitResult::session_ended) << "program " << i;
    EXPECT_NE(wm, rccl::WaitResult::session_ended) << "program " << i;

    std::size_t collision_messages = 0, others = 0, stopped_robots = 0;
    for (rccl::Manipulator* m : {&puma, &microbo}) {
      bool this_stopped = false;
      for (const rccl::MotionEvent& e : m->failures()) {
        const std::string msg(e.message());
        if (msg.rfind("collision stop", 0) == 0) {
          ++collision_messages;
          if (!this_stopped) ++stopped_robots;
          this_stopped = true;
          if (only) std::printf("  %s: %s\n", m == &puma ? "puma" : "microbo", msg.c_str());
          if (msg.find("puma link ") == std::string::npos ||
              msg.find("microbo link ") == std::string::npos) {
            ++unnamed_stops;
            ADD_FAILURE() << "program " << i << ": a stop that does not name both: " << msg;
          }
        } else if (e.kind == rccl::EventKind::failed && !(cut && msg.rfind("halted", 0) == 0)) {
          // A goal the line or the configuration cannot reach, found on the way.
          ++others;
          if (only) std::printf("  %s failed: %s\n", m == &puma ? "puma" : "microbo", msg.c_str());
        }
      }
    }
    const bool collision = c->collision_stops() > 0;
    if (real_plants) {
      ++real_plant_programs;
      real_measured_min_m = std::min(real_measured_min_m, seen.measured_min_m);
      real_measured_closer_m =
          std::max(real_measured_closer_m, seen.setpoint_min_m - seen.measured_min_m);
    }
    if (collision && collision_messages == 0 && stops_without_message++ < 10) {
      silent_stops += fmt::format(" {}", i);
    }
    // Both generators take the stop unless one stood still (or was stopping) already.
    if (collision && stopped_robots == 2) ++both_stopped;
    stop_messages += collision_messages;
    for (Tally* t : {&tally[static_cast<std::size_t>(scenario)], &tally[3]}) {
      ++t->programs;
      // One outcome per program, the first that applies.
      ++(collision ? t->stopped : others > 0 ? t->failed : cut ? t->cut : t->completed);
      t->setpoint_min_m = std::min(t->setpoint_min_m, seen.setpoint_min_m);
      t->measured_min_m = std::min(t->measured_min_m, seen.measured_min_m);
    }
    if (seen.measured_min_m < margin_m) {
      ++measured_below;
      if (measured_report.size() < 2000) {
        measured_report += fmt::format(
            "  program {}: measured arms {:.2f} mm apart (puma link {}, microbo link {}); "
            "setpoints at least {:.2f} mm\n",
            i, seen.measured_min_m * 1e3, seen.measured_closest.link_a + 1,
            seen.measured_closest.link_b + 1, seen.setpoint_min_m * 1e3);
      }
    }
    if (seen.below_margin > 0) ++violations;
    if (seen.out_of_limits > 0) ++limit_violations;
    EXPECT_EQ(seen.below_margin, 0U)
        << "program " << i << " (RCCX_PROPERTY_SEED=" << seed << " RCCX_PROPERTY_PROGRAM=" << i
        << "): " << seen.first_violation << "\n  puma: " << pp.text << "\n  microbo: " << pm.text;
    EXPECT_EQ(seen.out_of_limits, 0U) << "program " << i << ": " << seen.first_violation;
    if (only) {
      std::printf("  %s, %s%s\n", std::string(rccl::to_string(wp)).c_str(),
                  std::string(rccl::to_string(wm)).c_str(), cut ? ", cut short" : "");
      std::printf(
          "  ticks %zu, collision stops %llu, messages %zu, other failures %zu, closest "
          "setpoints %.2f mm (puma link %zu, microbo link %zu at %.3f s), measured %.2f mm, at the "
          "start %.2f mm\n",
          seen.ticks, static_cast<unsigned long long>(c->collision_stops()), collision_messages,
          others, seen.setpoint_min_m * 1e3, seen.setpoint_closest.link_a + 1,
          seen.setpoint_closest.link_b + 1, seen.setpoint_min_t_s, seen.measured_min_m * 1e3,
          seen.first_m * 1e3);
    }
  }

  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const std::size_t n = last - first;
  const Tally& all = tally[3];
  std::printf(
      "%zu programs, %zu moves (%zu goals out of reach drawn again); %zu on the real "
      "plants, %zu on ideal servos; %.1f s simulated in %.1f s\n",
      n, moves, rejected, real_plant_programs, n - real_plant_programs, simulated_s, wall_s);
  std::printf("%-17s %8s %14s %10s %8s %9s %15s %15s\n", "", "programs", "collision stop",
              "completed", "failed", "cut short", "closest setpts", "closest measured");
  const auto row = [&](const char* name, const Tally& t) {
    std::printf("%-17s %8zu %8zu %4.0f%% %10zu %8zu %9zu %12.2f mm %12.2f mm\n", name, t.programs,
                t.stopped,
                100.0 * static_cast<double>(t.stopped) /
                    static_cast<double>(std::max<std::size_t>(t.programs, 1)),
                t.completed, t.failed, t.cut, t.setpoint_min_m * 1e3, t.measured_min_m * 1e3);
  };
  for (const Scenario sc : {Scenario::course, Scenario::crawl, Scenario::apart}) {
    row(std::string(to_string(sc)).c_str(), tally[static_cast<std::size_t>(sc)]);
  }
  row("all", all);
  std::printf(
      "(failed: a goal found unreachable on the way, e.g. a line through a singularity; cut "
      "short: halted after %.1f s, a crawl after %.1f s)\n"
      "margin %.1f mm: programs with setpoint capsules within it %zu, with measured capsules "
      "within it %zu; joint setpoints out of limits %zu\n"
      "stop messages %zu, every one naming both robots and links: %s; programs whose stop "
      "failed both robots' motions %zu, one robot's %zu (the other stood or was stopping "
      "already), neither's %zu%s\n"
      "programs going on after a stop %zu, stopped again %zu\n"
      "on the real plants: closest measured capsules %.2f mm, at most %.2f mm closer than the "
      "same program's closest setpoints\n",
      std::chrono::duration<double>(budget(Scenario::course)).count(),
      std::chrono::duration<double>(budget(Scenario::crawl)).count(), margin_m * 1e3, violations,
      measured_below, limit_violations, stop_messages, unnamed_stops == 0 ? "yes" : "NO",
      both_stopped, all.stopped - both_stopped - stops_without_message, stops_without_message,
      silent_stops.empty() ? "" : (" (programs" + silent_stops + ")").c_str(), resumed_programs,
      resumed_stopped, real_measured_min_m * 1e3, real_measured_closer_m * 1e3);
  if (!measured_report.empty()) std::printf("%s", measured_report.c_str());
  RecordProperty("programs", std::to_string(n));
  RecordProperty("collision_stops", std::to_string(all.stopped));
  RecordProperty("closest_setpoint_mm", std::to_string(all.setpoint_min_m * 1e3));
  RecordProperty("closest_measured_mm", std::to_string(all.measured_min_m * 1e3));

  EXPECT_EQ(violations, 0U);
  EXPECT_EQ(limit_violations, 0U);
  EXPECT_EQ(unnamed_stops, 0U);
  EXPECT_GE(all.setpoint_min_m, margin_m);
  // The measured arms too: the servos follow closely enough (their lag and overshoot stay
  // inside what the braking allowance leaves over).
  EXPECT_EQ(measured_below, 0U) << measured_report;
  EXPECT_GE(all.measured_min_m, margin_m);
  if (!only) {
    // A generator too timid to bring the arms together tests nothing.
    EXPECT_GE(static_cast<double>(all.stopped), 0.15 * static_cast<double>(n))
        << "too few programs ended in a collision stop";
  }
}
