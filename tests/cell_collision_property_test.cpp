// Property test of the cell's collision stop (issues 13 and 30): many random two-robot programs
// in the CVaRL cell (cells/cvarl.json), both arms moving at once in simulated time, and on every
// tick of every program no part of either arm - links, wrists, hands, tools - comes within the
// cell's margin of the other arm or of an object of the cell (table, stage, board; a robot's
// base may stand on the table), and no joint setpoint leaves its limits. The distances are the
// test's own (Oracle, below): the arms rebuilt from the cell file with Eigen's transforms, every
// part against every part, no broad phase, nothing of the code under test. The measured arms
// (each session's How, lagging the setpoints through the servo) are checked the same way, and
// every stop message must name both robots.
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

#include <Eigen/Geometry>

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

/// The arms as the test sees them: rebuilt from the cell file's data (DH table, base, link
/// radii, shapes, tool) with Eigen's transforms, a capsule along every DH offset, a sphere at
/// every joint, the shapes and the tool; distances by golden-section search of the point
/// distances, which are convex along an axis. Every pair, every tick.
class Oracle {
 public:
  struct Part {
    Eigen::Vector3d p0, p1;
    double radius = 0.0;
    std::string name;
    bool base_shape = false;  ///< fixed to the base frame: it stands on the table
    bool tool = false;        ///< beyond T6
  };
  struct Box {
    Eigen::Isometry3d inverse;
    Eigen::Vector3d half;
    Eigen::Vector3d centre;  ///< in the world
    std::string name;
  };

  explicit Oracle(const cell::CellModel& m) : model_(m) {
    for (const cell::CellObject& o : m.objects) {
      Box b;
      b.inverse = iso(o.pose).inverse();
      b.centre = vec(o.pose.p);
      b.half = Eigen::Vector3d(o.shape.size_m.x, o.shape.size_m.y, o.shape.size_m.z) / 2.0;
      b.name = o.name;
      boxes_.push_back(b);
    }
  }

  /// Robot r's parts at joints q.
  std::vector<Part> parts(std::size_t r, const kin::JointVector& q) const {
    const cell::CellRobot& cr = model_.robots[r];
    std::vector<Part> out;
    Eigen::Isometry3d T = iso(cr.base);
    const auto radius = [&](std::size_t i) { return cr.link_radius_m[i]; };
    std::vector<Eigen::Isometry3d> frames{T};
    for (std::size_t i = 0; i < cr.model.dof(); ++i) {
      const kin::DhParameters& dh = cr.model.joints[i].dh;
      const bool prismatic = cr.model.joints[i].type == kin::JointType::prismatic;
      const double theta = dh.theta_rad + (prismatic ? 0.0 : q[i]);
      const double d = dh.d_m + (prismatic ? q[i] : 0.0);
      const Eigen::Vector3d start = T.translation();
      // Rot(z, theta) Trans(z, d) Trans(x, a) Rot(x, alpha): the d part, then the a part.
      Eigen::Isometry3d after_d =
          T * Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()) * Eigen::Translation3d(0, 0, d);
      const Eigen::Vector3d mid = after_d.translation();
      T = after_d * Eigen::Translation3d(dh.a_m, 0, 0) *
          Eigen::AngleAxisd(dh.alpha_rad, Eigen::Vector3d::UnitX());
      const std::string link = fmt::format("link {}", i + 1);
      if (prismatic || dh.d_m != 0.0) out.push_back({start, mid, radius(i), link});
      if (dh.a_m != 0.0) out.push_back({mid, T.translation(), radius(i), link});
      out.push_back({T.translation(), T.translation(), radius(i), link});  // the joint
      frames.push_back(T);
    }
    bool tool_shape = false;
    for (const cell::RobotShape& s : cr.shapes) {
      const Eigen::Isometry3d& F = frames[s.frame];
      out.push_back({F * vec(s.from_m), F * vec(s.to_m), s.radius_m, s.name, s.frame == 0,
                     s.frame == cr.model.dof()});
      tool_shape = tool_shape || s.frame == cr.model.dof();
    }
    if (cr.tool && !tool_shape) {
      out.push_back(
          {T.translation(), T * vec(cr.tool->p), cr.link_radius_m.back(), "tool", false, true});
    }
    return out;
  }

  /// Distance between two segments' capsules: the closest pair is the interior critical point
  /// of |P(s) - Q(t)|^2 when it lies in [0, 1]^2, else on an edge of the square, where one end
  /// point meets the other segment.
  static double distance(const Part& a, const Part& b) {
    double best = std::min({point_segment(a.p0, b.p0, b.p1), point_segment(a.p1, b.p0, b.p1),
                            point_segment(b.p0, a.p0, a.p1), point_segment(b.p1, a.p0, a.p1)});
    const Eigen::Vector3d u = a.p1 - a.p0, v = b.p1 - b.p0, w = a.p0 - b.p0;
    const double uu = u.dot(u), uv = u.dot(v), vv = v.dot(v), uw = u.dot(w), vw = v.dot(w);
    const double det = uu * vv - uv * uv;
    if (det > 1e-12 * uu * vv && det > 0.0) {
      const double s = (uv * vw - vv * uw) / det, t = (uu * vw - uv * uw) / det;
      if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0) {
        best = std::min(best, (w + u * s - v * t).norm());
      }
    }
    return best - a.radius - b.radius;
  }
  /// Signed distance between a part and a box (negative inside); a part farther than
  /// `beyond_m` from the box's circumscribed sphere gives that bound instead.
  double distance(const Part& a, std::size_t box, double beyond_m = kInf) const {
    const Box& b = boxes_[box];
    const double bound = point_segment(b.centre, a.p0, a.p1) - b.half.norm() - a.radius;
    if (bound > beyond_m) return bound;
    const auto f = [&](double s) {
      const Eigen::Vector3d x = b.inverse * (a.p0 + (a.p1 - a.p0) * s);
      const Eigen::Vector3d q = x.cwiseAbs() - b.half;
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    };
    return minimise(f) - a.radius;
  }
  [[nodiscard]] std::size_t boxes() const { return boxes_.size(); }
  [[nodiscard]] const std::string& box_name(std::size_t k) const { return boxes_[k].name; }

 private:
  static Eigen::Isometry3d iso(const math::Transform& t) {
    Eigen::Matrix3d R;
    R << t.R.n.x, t.R.o.x, t.R.a.x, t.R.n.y, t.R.o.y, t.R.a.y, t.R.n.z, t.R.o.z, t.R.a.z;
    Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
    out.linear() = R;
    out.translation() = vec(t.p);
    return out;
  }
  static Eigen::Vector3d vec(const math::Vec3& v) { return {v.x, v.y, v.z}; }
  static double point_segment(const Eigen::Vector3d& x, const Eigen::Vector3d& q0,
                              const Eigen::Vector3d& q1) {
    const Eigen::Vector3d d = q1 - q0;
    const double dd = d.squaredNorm();
    const double t = dd > 0.0 ? std::clamp((x - q0).dot(d) / dd, 0.0, 1.0) : 0.0;
    return (x - (q0 + d * t)).norm();
  }
  /// Golden-section search of a convex function over [0, 1], the ends included.
  template <class F>
  static double minimise(const F& f) {
    double lo = 0.0, hi = 1.0;
    const double g = (std::sqrt(5.0) - 1.0) / 2.0;
    double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = f(x1), f2 = f(x2);
    for (int k = 0; k < 40; ++k) {
      if (f1 <= f2) {
        hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = f(x1);
      } else {
        lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = f(x2);
      }
    }
    return std::min({f1, f2, f(0.0), f(1.0)});
  }

  const cell::CellModel& model_;
  std::vector<Box> boxes_;
};

/// The closest approach in one configuration of both arms: arm to arm, and any part to any
/// object but a base shape to the table the robots are bolted to (and the bases' first links,
/// which stand on it: their parts from the base origin).
struct Clearance {
  double arms_m = kInf;
  double objects_m = kInf;
  std::string where;  ///< of the smaller of the two
};

Clearance clearance(const Oracle& o, const std::vector<Oracle::Part> (&parts)[2],
                    const Eigen::Vector3d (&base)[2], std::uint64_t touch[2]) {
  Clearance c;
  for (const Oracle::Part& a : parts[0]) {
    for (const Oracle::Part& b : parts[1]) {
      const double d = Oracle::distance(a, b);
      if (d < c.arms_m) {
        c.arms_m = d;
        if (d < c.objects_m) c.where = fmt::format("puma {} and microbo {}", a.name, b.name);
      }
    }
  }
  for (std::size_t r = 0; r < 2; ++r) {
    for (const Oracle::Part& a : parts[r]) {
      for (std::size_t k = 0; k < o.boxes(); ++k) {
        const bool on_table = o.box_name(k) == "table";
        const bool from_base = (a.p0 - base[r]).norm() < 1e-9 || (a.p1 - base[r]).norm() < 1e-9;
        if (on_table && (a.base_shape || from_base)) continue;
        if (a.tool && k < 64 && (touch[r] >> k & 1U)) continue;
        const double d = o.distance(a, k, 0.1);
        if (d < c.objects_m) {
          c.objects_m = d;
          if (d < c.arms_m)
            c.where =
                fmt::format("{} {} and {}", r == 0 ? "puma" : "microbo", a.name, o.box_name(k));
        }
      }
    }
  }
  return c;
}

const Eigen::Vector3d (&bases_of(const cell::CellModel& m))[2] {
  static Eigen::Vector3d bases[2];
  for (std::size_t r = 0; r < 2; ++r) {
    bases[r] = {m.robots[r].base.p.x, m.robots[r].base.p.y, m.robots[r].base.p.z};
  }
  return bases;
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
  /// Each arm on its own side, creeping down onto the stage and the board, some goals inside
  /// them: the check against the objects, closest to its margin. In half of the programs a
  /// robot's motions name the board, which its tool may then touch (the stage and the table
  /// still not, nor the arm itself).
  descend,
};

std::string_view to_string(Scenario s) {
  switch (s) {
    case Scenario::course:
      return "collision course";
    case Scenario::crawl:
      return "crawl";
    case Scenario::apart:
      return "own sides";
    case Scenario::descend:
      return "onto the stage";
  }
  return "?";
}

/// A program runs at most this long in simulated time before both arms are halted: long
/// enough for four moves on their own sides, shorter for a crawl (which stops within a
/// second or two when it meets the other arm, or creeps on, away from it).
constexpr std::chrono::nanoseconds budget(Scenario s) {
  return s == Scenario::crawl     ? std::chrono::nanoseconds(2s)
         : s == Scenario::descend ? std::chrono::nanoseconds(6s)
                                  : std::chrono::nanoseconds(5s);
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
    return u < 0.4    ? Scenario::course
           : u < 0.76 ? Scenario::crawl
           : u < 0.88 ? Scenario::apart
                      : Scenario::descend;
  }

  /// The cell with the robots' start poses for one program (the simulated arms start at their
  /// model's ready pose): turned a little about their first axes, outside the margin (`world`
  /// measures it). At the CVaRL ready poses the Microbo's arm reaches to within 64 mm of the
  /// PUMA's wrist; on their own sides it starts drawn in (d3 short), for a crawl stretched out.
  cell::CellModel start_poses(const cell::CellModel& cvarl, Scenario s, const Oracle& oracle) {
    for (;;) {
      cell::CellModel m = cvarl;
      kin::RobotModel& microbo = m.robots[1].model;
      if (s == Scenario::apart || s == Scenario::descend) {
        microbo.joints[2].ready = uniform(0.16, 0.2);
      }
      if (s == Scenario::crawl) microbo.joints[2].ready = uniform(0.3, 0.38);
      microbo.joints[0].ready = uniform(-0.2, 0.2);
      m.robots[0].model.joints[0].ready = uniform(-0.3, 0.3);
      const std::vector<Oracle::Part> parts[2] = {oracle.parts(0, m.robots[0].model.ready()),
                                                  oracle.parts(1, microbo.ready())};
      std::uint64_t touch[2] = {0, 0};
      const Clearance c = clearance(oracle, parts, bases_of(cvarl), touch);
      const double margin = cvarl.collision_margin_m + kStartOutside_m;
      // A crawl starts close, so that it meets the other arm soon.
      if (c.arms_m >= margin && c.objects_m >= margin &&
          (s != Scenario::crawl || c.arms_m < kCrawlStart_m)) {
        return m;
      }
    }
  }

  /// A world goal around the board where both arms reach: tool down, turned about the
  /// vertical, tilted a little; x within [x_lo, x_hi] (the PUMA stands at -x, the Microbo at +x).
  math::Transform world_goal(double x_lo, double x_hi, double z_lo = 0.09, double z_hi = 0.21) {
    const math::Vec3 p{uniform(x_lo, x_hi), uniform(-0.12, 0.12), uniform(z_lo, z_hi)};
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
    double x_lo = -0.15, x_hi = 0.15, z_lo = 0.09, z_hi = 0.21;
    rccl::StartWhen when;  // descending: the board may be touched, in half the programs
    if (s == Scenario::descend) {
      x_lo = puma ? -0.09 : 0.03;
      x_hi = puma ? -0.03 : 0.09;
      z_lo = 0.06;
      z_hi = 0.13;
      if (chance(0.5)) {
        when = c.touching({"board"});
        plan.text += "touching the board: ";
      }
    } else if (s == Scenario::apart) {
      x_lo = puma ? -0.2 : 0.12;
      x_hi = puma ? -0.08 : 0.2;
    } else if (s == Scenario::crawl) {
      x_lo = puma ? 0.0 : -0.15;
      x_hi = puma ? 0.15 : 0.0;
    }
    const int moves = integer(1, 4);
    for (int i = 0; i < moves; ++i) {
      // Log-uniform speeds: as many slow moves as brisk ones.
      if (s == Scenario::crawl || s == Scenario::descend) {
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
      if (s != Scenario::descend && chance(0.3)) {
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
        const math::Transform g = world_goal(x_lo, x_hi, z_lo, z_hi);
        try {
          m.move(world_position(c, robot, fmt::format("W{}", i), g), when);
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
        m.dwell(d, when);
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
  double setpoint_min_m = kInf;  ///< arm to arm
  double measured_min_m = kInf;
  double setpoint_objects_min_m = kInf;  ///< any part to an object it may not touch
  double measured_objects_min_m = kInf;
  std::string measured_where;
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
  // The test's own model of both arms and the objects (not the code under test).
  const Oracle oracle(model);
  const Eigen::Vector3d(&bases)[2] = bases_of(model);
  // Closer than the margin by more than the oracle's search can err is a violation.
  constexpr double kOracleTolerance_m = 1e-9;

  // Outcomes per scenario, and in all (the last).
  struct Tally {
    std::size_t programs = 0, stopped = 0, completed = 0, failed = 0, cut = 0;
    double setpoint_min_m = kInf, measured_min_m = kInf;
    double setpoint_objects_min_m = kInf, measured_objects_min_m = kInf;
  };
  std::array<Tally, 5> tally{};  // per scenario, and all
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
    // Before the cell: its control task runs the observer, which writes these, until ~Cell.
    std::vector<Oracle::Part> set_parts[2], measured_parts[2];
    std::uint64_t touch[2] = {0, 0};
    Seen seen;
    const kin::JointVector lo[2] = {model.robots[0].model.lower(), model.robots[1].model.lower()};
    const kin::JointVector hi[2] = {model.robots[0].model.upper(), model.robots[1].model.upper()};
    const std::string names[2] = {"puma", "microbo"};
    const auto c = std::make_unique<cell::Cell>(gen.start_poses(model, scenario, oracle), options);
    for (std::size_t r = 0; r < 2; ++r) {
      measured_parts[r] = oracle.parts(r, c->model().robots[r].model.ready());
    }
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
        set_parts[r] = oracle.parts(r, q);
        const rccl::MotionSettings* settings = g.running_settings(g.last_motion());
        touch[r] = settings != nullptr ? settings->may_touch : 0;
        const kin::JointVector measured = c->session(names[r]).how().q();
        if (measured.size() == lo[r].size()) measured_parts[r] = oracle.parts(r, measured);
      }
      if (!both) return;
      const Clearance set = clearance(oracle, set_parts, bases, touch);
      const cell::Contact s = c->collision_world().min_distance(ip, im);
      if (seen.first_m == kInf) seen.first_m = set.arms_m;
      seen.setpoint_objects_min_m = std::min(seen.setpoint_objects_min_m, set.objects_m);
      if (set.arms_m < seen.setpoint_min_m) {
        seen.setpoint_min_m = set.arms_m;
        seen.setpoint_closest = s;
        seen.setpoint_min_t_s = c->robot("puma").generator().last_setpoint_time_s();
      }
      const double closest = std::min(set.arms_m, set.objects_m);
      if (closest < margin_m - kOracleTolerance_m && seen.below_margin++ == 0 &&
          seen.first_violation.empty()) {
        seen.first_violation =
            fmt::format("setpoints: {} {:.2f} mm apart at {:.3f} s", set.where, closest * 1e3,
                        c->robot("puma").generator().last_setpoint_time_s());
      }
      if (only && c->collision_stops() != seen.stops) {
        seen.stops = c->collision_stops();
        std::printf("  tick %u: stop %llu, setpoints %.3f mm apart, puma %s, microbo %s\n", tick,
                    static_cast<unsigned long long>(seen.stops), s.distance_m * 1e3,
                    c->robot("puma").generator().at_rest() ? "at rest" : "moving",
                    c->robot("microbo").generator().at_rest() ? "at rest" : "moving");
      }
      const Clearance m = clearance(oracle, measured_parts, bases, touch);
      seen.measured_objects_min_m = std::min(seen.measured_objects_min_m, m.objects_m);
      if (std::min(m.arms_m, m.objects_m) <
              std::min(seen.measured_min_m, seen.measured_objects_min_m) ||
          seen.measured_where.empty()) {
        seen.measured_where = m.where;
      }
      seen.measured_min_m = std::min(seen.measured_min_m, m.arms_m);
    });
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
          // Between the arms both are named; against an object, the robot and the object.
          const bool object = msg.find(" from object ") != std::string::npos;
          if (msg.find(m == &puma ? "puma " : "microbo ") == std::string::npos ||
              (!object && (msg.find("puma ") == std::string::npos ||
                           msg.find("microbo ") == std::string::npos))) {
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
    for (Tally* t : {&tally[static_cast<std::size_t>(scenario)], &tally[4]}) {
      ++t->programs;
      // One outcome per program, the first that applies.
      ++(collision ? t->stopped : others > 0 ? t->failed : cut ? t->cut : t->completed);
      t->setpoint_min_m = std::min(t->setpoint_min_m, seen.setpoint_min_m);
      t->measured_min_m = std::min(t->measured_min_m, seen.measured_min_m);
      t->setpoint_objects_min_m = std::min(t->setpoint_objects_min_m, seen.setpoint_objects_min_m);
      t->measured_objects_min_m = std::min(t->measured_objects_min_m, seen.measured_objects_min_m);
    }
    if (std::min(seen.measured_min_m, seen.measured_objects_min_m) <
        margin_m - kOracleTolerance_m) {
      ++measured_below;
      if (measured_report.size() < 2000) {
        measured_report += fmt::format(
            "  program {}: measured arms {:.2f} mm apart, {:.2f} mm from the objects ({}); "
            "setpoints at least {:.2f} mm\n",
            i, seen.measured_min_m * 1e3, seen.measured_objects_min_m * 1e3, seen.measured_where,
            std::min(seen.setpoint_min_m, seen.setpoint_objects_min_m) * 1e3);
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
  const Tally& all = tally[4];
  std::printf(
      "%zu programs, %zu moves (%zu goals out of reach drawn again); %zu on the real "
      "plants, %zu on ideal servos; %.1f s simulated in %.1f s\n",
      n, moves, rejected, real_plant_programs, n - real_plant_programs, simulated_s, wall_s);
  std::printf("%-17s %8s %14s %10s %8s %9s %15s %15s %15s %15s\n", "", "programs", "collision stop",
              "completed", "failed", "cut short", "arms setpts", "arms measured", "objects setpts",
              "objects measured");
  const auto row = [&](const char* name, const Tally& t) {
    std::printf("%-17s %8zu %8zu %4.0f%% %10zu %8zu %9zu %12.2f mm %12.2f mm %12.2f mm %12.2f mm\n",
                name, t.programs, t.stopped,
                100.0 * static_cast<double>(t.stopped) /
                    static_cast<double>(std::max<std::size_t>(t.programs, 1)),
                t.completed, t.failed, t.cut, t.setpoint_min_m * 1e3, t.measured_min_m * 1e3,
                t.setpoint_objects_min_m * 1e3, t.measured_objects_min_m * 1e3);
  };
  for (const Scenario sc :
       {Scenario::course, Scenario::crawl, Scenario::apart, Scenario::descend}) {
    row(std::string(to_string(sc)).c_str(), tally[static_cast<std::size_t>(sc)]);
  }
  row("all", all);
  std::printf(
      "(failed: a goal found unreachable on the way, e.g. a line through a singularity; cut "
      "short: halted after %.1f s, a crawl after %.1f s)\n"
      "margin %.1f mm (any part, tools included, of either arm to the other or to an object): "
      "programs with setpoints within it %zu, with measured arms within it %zu; joint setpoints "
      "out of limits %zu\n"
      "stop messages %zu, every one naming the robots: %s; programs whose stop "
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
  RecordProperty("closest_object_setpoint_mm", std::to_string(all.setpoint_objects_min_m * 1e3));

  EXPECT_EQ(violations, 0U);
  EXPECT_EQ(limit_violations, 0U);
  EXPECT_EQ(unnamed_stops, 0U);
  EXPECT_GE(all.setpoint_min_m, margin_m - kOracleTolerance_m);
  EXPECT_GE(all.setpoint_objects_min_m, margin_m - kOracleTolerance_m);
  // The measured arms too: the servos follow closely enough (their lag and overshoot stay
  // inside what the braking allowance leaves over).
  EXPECT_EQ(measured_below, 0U) << measured_report;
  EXPECT_GE(all.measured_min_m, margin_m - kOracleTolerance_m);
  EXPECT_GE(all.measured_objects_min_m, margin_m - kOracleTolerance_m);
  if (!only) {
    // A generator too timid to bring the arms together tests nothing.
    EXPECT_GE(static_cast<double>(all.stopped), 0.15 * static_cast<double>(n))
        << "too few programs ended in a collision stop";
  }
}
