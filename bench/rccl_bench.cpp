// RCCL setpoint benchmarks: one sample of the trajectory generator
// (rccl::TrajectoryGenerator::step), what the thesis timed in 1986 as the CPU time per cycle of
// RCCL's control function: 18.0 ms in joint mode, 25.5 ms in Cartesian mode, 33.5 ms in Cartesian
// mode with two functional transforms on the 286/287 driving the Microbo (section 4.5.3), and
// 12.0 / 15.5 / 20.0 ms on a VAX-750 driving a Puma-260 ([Lloyd 85], quoted in section 4.4.1).
// Here for the Microbo and the PUMA 560, with a modern peer for the PUMA's Cartesian sample done
// with Orocos KDL.
//
// Every timed iteration is one sample in the straight part of a long motion, never in a
// transition: each robot moves between the same two poses (a line of 0.27 m for the Microbo,
// 0.38 m for the PUMA, turning 20 deg about the tool's approach on the way, at 50 mm/s, 1 ms
// samples; `measured` is the previous setpoint, as from an ideal arm, so that a Cartesian sample
// also runs the FK of the path report: one IK and one FK per sample, as RCCL's Cartesian mode
// did). A validation pass, run once before timing, steps a whole motion and finds the samples of
// its straight part (Cartesian: those the generator's path report counts as straight; joint:
// those whose joint values have a zero second difference, the linear interpolation outside
// Paul's transitions); the timed window is that part less 50 samples at each end. When the
// window is used up, timing is paused, the generator is reset to the start, the motion queued
// again and stepped to the window (5,000 to 7,000 timed samples per restart), and timing
// resumes. After each window the benchmark checks, untimed, that nothing failed, that every
// timed sample belonged to the motion and (Cartesian) that the path report counted each of them
// as straight; SkipWithError otherwise.
//
// The position is T6 = CONV OBJ GRASP. In joint and Cartesian mode the three are constants
// (multiplied into one when the equation is made); in the "2 functional" case CONV (a conveyor,
// 2 mm/s along y) and OBJ (an object on it, rising 1 mm/s) are rccl::functional transforms whose
// translations are computed from ctx.t_s, re-evaluated every sample.
#include <benchmark/benchmark.h>

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/chainiksolverpos_nr_jl.hpp>
#include <kdl/chainiksolvervel_pinv.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/math/transform.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/force_control.hpp"
#include "rccx/rccl/position.hpp"
#include "rccx/rccl/trajectory.hpp"
#include "rccx/rccl/transforms.hpp"
#include "rccx/rtc/types.hpp"

namespace rccx::bench {
std::pair<rccl::TransformPtr, rccl::TransformPtr> c_moving_transforms(const math::Vec3& obj);
}

namespace {

using namespace rccx;
using namespace rccx::math::literals;
using kin::JointVector;
using math::Rot3;
using math::Transform;

constexpr double kPeriod = 1e-3;     // s
constexpr double kToolSpeed = 0.05;  // m/s along the line
// The goal moves with CONV and OBJ, and a motion from rest starts at once at the goal's speed
// (the start of the line rides on the goal): slow enough for the generator's acceleration guard
// at 1 ms samples.
constexpr double kConveyorSpeed = 0.002;  // m/s, CONV along y
constexpr double kObjectSpeed = 0.001;    // m/s, OBJ along z
constexpr std::size_t kMargin = 50;       // samples kept off each end of the straight part
constexpr std::size_t kMinWindow = 1000;  // timed samples per motion, at least
constexpr double kLinear = 1e-12;         // |second difference| of a linear joint segment

/// The line each robot's motion follows: from `start` (the arm at rest there) to `goal`.
struct Line {
  Transform start, goal;
};

/// Microbo: tool down over the washer's table (thesis 2.4.3: x 325 mm, y -150 .. 150 mm,
/// z 250 .. 300 mm), turning 20 deg about the approach on the way.
Line microbo_line() {
  return {{Rot3::rot_x(180_deg), {0.325, -0.15, 0.30}},
          {Rot3::rot_x(180_deg) * Rot3::rot_z(20_deg), {0.325, 0.12, 0.25}}};
}
/// PUMA 560 (base frame at the shoulder): tool down in front of the arm, 0.4 m across.
Line puma_line() {
  return {{Rot3::rot_x(180_deg), {0.45, -0.25, -0.15}},
          {Rot3::rot_x(180_deg) * Rot3::rot_z(20_deg), {0.45, 0.12, -0.25}}};
}
Line line_of(const std::string& robot) {
  return robot == "microbo" ? microbo_line() : puma_line();
}

enum class Case {
  joint,
  cartesian,
  cartesian_2_functional,
  cartesian_2_c_functional,
  cartesian_compliant,
};

/// One robot, its generator and the motion it repeats; steps it sample by sample.
class Rig {
 public:
  Rig(const std::string& robot, Case c)
      : model_(kin::builtin_robot(robot)),
        kin_(kin::make_kinematics(model_)),
        gen_(*kin_, rccl::GeneratorOptions{kPeriod, {}, {}}),
        case_(c) {
    const Line line = line_of(robot);
    kin::IkOptions o;
    o.near = model_.ready();
    const kin::IkResult r = kin_->inverse(line.start, o);
    if (!r) {
      error_ = "the line's start cannot be reached: " + std::string(kin::describe(r.status));
      return;
    }
    q_start_ = r.q;
    const auto t6 = rccl::t6();
    const Transform grasp{line.goal.R, {}};
    const math::Vec3 obj = line.goal.p;
    if (c == Case::cartesian_2_functional) {
      conv_ = rccl::functional("CONV", [](const rccl::SampleContext& ctx) {
        return Transform::translation(0.0, kConveyorSpeed * ctx.t_s, 0.0);
      });
      obj_ = rccl::functional("OBJ", [obj](const rccl::SampleContext& ctx) {
        return Transform::translation(obj.x, obj.y, obj.z + kObjectSpeed * ctx.t_s);
      });
    } else if (c == Case::cartesian_2_c_functional) {
      std::tie(conv_, obj_) = bench::c_moving_transforms(obj);
    } else {
      conv_ = rccl::constant("CONV", Transform::identity());
      obj_ = rccl::constant("OBJ", Transform::translation(obj));
    }
    grasp_ = rccl::constant("GRASP", grasp);
    position_ = rccl::Position::make("GOAL", {t6}, {conv_, obj_, grasp_}, t6);
    settings_.mode = c == Case::joint ? rccl::Mode::joint : rccl::Mode::cartesian;
    settings_.translation_m_per_s = kToolSpeed;
    if (c == Case::cartesian_compliant) {
      // The tool's x yields (a spring of 1000 N/m) to a steady 2 N push: every sample moves
      // the setpoint off the path (one FK and one IK more), as a compliant motion does.
      settings_.compliance.axes = 1U << 0;
      settings_.compliance.stiffness[0] = 1000.0;
      how_.force.present = true;
      how_.force.wrench.force_N = {-2.0, 0.0, 0.0};
      force_ = std::make_unique<rccl::ForceControl>(*kin_);
    }
    error_ = calibrate();
  }
  Rig(const Rig&) = delete;
  Rig& operator=(const Rig&) = delete;

  [[nodiscard]] const std::string& error() const noexcept { return error_; }
  [[nodiscard]] std::size_t window() const noexcept { return end_ - begin_; }
  [[nodiscard]] double duration_s() const noexcept { return duration_s_; }
  [[nodiscard]] const JointVector& q() const noexcept { return q_; }

  /// Untimed: the arm at rest at the start, the motion queued, stepped to the window's first
  /// sample.
  void restart() {
    start_motion();
    while (k_ < begin_) step();
    straight_at_window_ = gen_.report(id_).straight_samples;
  }

  /// One timed sample; true when the window is used up (restart() before the next).
  bool timed_step() {
    const std::uint64_t id = step();
    benchmark::DoNotOptimize(id);
    benchmark::DoNotOptimize(q_);
    wrong_id_ += id != id_ ? 1 : 0;
    return k_ == end_;
  }

  /// Untimed, after a window: an error message if a timed sample was not a straight sample of
  /// the motion.
  std::string check_window() {
    if (wrong_id_ != 0) return "a timed setpoint did not belong to the motion";
    if (force_failures_ != 0) return "the compliance stopped the motion";
    if (force_ && force_->offset()[0] == 0.0) return "the compliance did not move the setpoint";
    while (auto e = gen_.next_event()) {
      if (e->kind != rccl::EventKind::started) {
        return "motion " + std::to_string(e->id) + " " + std::string(rccl::to_string(e->kind)) +
               " in the timed window: " + std::string(e->message());
      }
    }
    if (case_ != Case::joint &&
        gen_.report(id_).straight_samples - straight_at_window_ != k_ - begin_) {
      return "a timed sample was not on the straight part (the path report did not count it)";
    }
    return {};
  }

 private:
  void start_motion() {
    gen_.reset(q_start_, 0.0);
    if (force_) force_->reset();
    while (gen_.next_event()) {
    }
    q_ = measured_ = q_start_;
    k_ = 0;
    wrong_id_ = 0;
    rccl::MotionRequest r;
    r.id = ++last_id_;
    r.position = position_.get();
    r.settings = settings_;
    gen_.submit(r);
    id_ = r.id;
  }

  std::uint64_t step() {
    ctx_.t_s = static_cast<double>(k_) * kPeriod;
    ctx_.sample = ++sample_;
    // The loop's How, as a session gives it (a C transform's function runs only in the loop).
    how_.time_s = ctx_.t_s;
    how_.sample = ctx_.sample;
    ctx_.how = &how_;
    const std::uint64_t id = gen_.step(ctx_, &measured_, q_);
    if (force_) {
      // The push stays along T6's x (the sensor turns with it); the force side reads q here.
      for (std::size_t j = 0; j < measured_.size(); ++j) how_.joint[j].q = measured_[j];
      how_.dof = static_cast<std::uint8_t>(measured_.size());
      if (force_->step(how_, id, gen_.running_settings(id), kPeriod, q_) !=
          rccl::ForceControl::Outcome::none) {
        ++force_failures_;
      }
    }
    measured_ = q_;  // an ideal arm: where it was told to be
    ++k_;
    return id;
  }

  /// Steps one whole motion and finds its straight part: [begin_, end_) is that part less
  /// kMargin samples at each end (sample indices since the motion was queued).
  std::string calibrate() {
    start_motion();
    std::vector<JointVector> qs;
    std::vector<bool> mine, straight;  // a sample of the motion; on its straight part
    const std::size_t limit = 200'000;
    while (gen_.ended_upto() < id_ && k_ < limit) {
      const std::uint32_t before = gen_.report(id_).straight_samples;
      const std::uint64_t id = step();
      qs.push_back(q_);
      mine.push_back(id == id_);
      straight.push_back(mine.back() && gen_.report(id_).straight_samples == before + 1);
      while (auto e = gen_.next_event()) {
        if (e->kind == rccl::EventKind::failed || e->kind == rccl::EventKind::cancelled) {
          return "the motion failed: " + std::string(e->message());
        }
      }
    }
    if (gen_.ended_upto() < id_) return "the motion did not end";
    duration_s_ = gen_.report(id_).duration_s;
    if (case_ == Case::joint) {
      for (std::size_t i = 0; i < qs.size(); ++i) {
        bool linear = i > 0 && i + 1 < qs.size();
        for (std::size_t j = 0; linear && j < qs[i].size(); ++j) {
          linear = std::abs(qs[i + 1][j] - 2.0 * qs[i][j] + qs[i - 1][j]) <= kLinear;
        }
        straight[i] = mine[i] && linear;
      }
    }
    const auto first = std::find(straight.begin(), straight.end(), true);
    if (first == straight.end()) return "the motion has no straight part";
    const auto last = std::find(first, straight.end(), false);
    if (std::find(last, straight.end(), true) != straight.end()) {
      return "the straight part is not one run of samples";
    }
    if (static_cast<std::size_t>(last - first) < 2 * kMargin + kMinWindow) {
      return "the straight part is too short to time";
    }
    begin_ = static_cast<std::size_t>(first - straight.begin()) + kMargin;
    end_ = static_cast<std::size_t>(last - straight.begin()) - kMargin;
    return {};
  }

  kin::RobotModel model_;
  std::unique_ptr<kin::Kinematics> kin_;
  rccl::TrajectoryGenerator gen_;
  Case case_;
  rccl::TransformPtr conv_, obj_, grasp_;
  rccl::PositionPtr position_;
  rccl::MotionSettings settings_;
  std::unique_ptr<rccl::ForceControl> force_;  ///< cartesian_compliant only
  std::size_t force_failures_ = 0;
  JointVector q_start_, q_, measured_;
  rccl::SampleContext ctx_;
  rtc::How how_;
  std::uint64_t sample_ = 0, last_id_ = 0, id_ = 0;
  std::size_t k_ = 0, begin_ = 0, end_ = 0, wrong_id_ = 0;
  std::uint32_t straight_at_window_ = 0;
  double duration_s_ = 0.0;
  std::string error_;
};

Rig& rig(const std::string& robot, Case c) {
  // One rig per robot and case, made on first use (the generator is neither copied nor moved).
  static std::vector<std::pair<std::string, std::unique_ptr<Rig>>> rigs;
  const std::string key = robot + "/" + std::to_string(static_cast<int>(c));
  for (auto& [name, r] : rigs) {
    if (name == key) return *r;
  }
  rigs.emplace_back(key, std::make_unique<Rig>(robot, c));
  return *rigs.back().second;
}

void run_setpoint(benchmark::State& state, const std::string& robot, Case c) {
  Rig& r = rig(robot, c);
  if (!r.error().empty()) {
    state.SkipWithError(r.error().c_str());
    return;
  }
  std::string error;
  std::int64_t motions = 1;
  r.restart();
  for (auto _ : state) {
    if (r.timed_step()) {
      state.PauseTiming();
      error = r.check_window();
      if (!error.empty()) {
        state.SkipWithError(error.c_str());
        break;
      }
      r.restart();
      ++motions;
      state.ResumeTiming();
    }
  }
  if (!error.empty()) return;
  error = r.check_window();
  if (!error.empty()) {
    state.SkipWithError(error.c_str());
    return;
  }
  state.counters["window"] = static_cast<double>(r.window());
  state.counters["motions"] = static_cast<double>(motions);
}

void BM_SetpointJoint(benchmark::State& state, const std::string& robot) {
  run_setpoint(state, robot, Case::joint);
}
void BM_SetpointCartesian(benchmark::State& state, const std::string& robot) {
  run_setpoint(state, robot, Case::cartesian);
}
void BM_SetpointCartesian2Functional(benchmark::State& state, const std::string& robot) {
  run_setpoint(state, robot, Case::cartesian_2_functional);
}
/// The same sample with CONV and OBJ written in C over compat/rccl.h (bench/compat_bench.cpp):
/// the price of the C calling convention and of mm in a TRSF.
void BM_SetpointCartesian2CFunctional(benchmark::State& state, const std::string& robot) {
  run_setpoint(state, robot, Case::cartesian_2_c_functional);
}
/// The Cartesian sample with compliance on along the tool's x (issue 15): the generator's step
/// and the force side's (gravity compensation, force transform, admittance, the offset
/// setpoint's FK and IK), beside BM_SetpointCartesian.
void BM_SetpointCartesianCompliant(benchmark::State& state, const std::string& robot) {
  run_setpoint(state, robot, Case::cartesian_compliant);
}

// ---- the peer: one Cartesian sample with Orocos KDL, PUMA 560 -----------------------------

KDL::Frame to_kdl(const Transform& t) {
  const auto& R = t.R;
  return KDL::Frame(KDL::Rotation(R.n.x, R.o.x, R.a.x, R.n.y, R.o.y, R.a.y, R.n.z, R.o.z, R.a.z),
                    KDL::Vector(t.p.x, t.p.y, t.p.z));
}
KDL::JntArray to_kdl(const JointVector& q) {
  KDL::JntArray a(static_cast<unsigned>(q.size()));
  for (std::size_t i = 0; i < q.size(); ++i) a(static_cast<unsigned>(i)) = q[i];
  return a;
}

/// What one Cartesian sample needs, done with KDL on the same line, period, duration and window
/// as BM_SetpointCartesian/puma560: the tool frame at fraction r of the line (position
/// interpolated, rotation about the fixed axis of start⁻¹ goal), KDL's IK seeded with the
/// previous sample's answer, and the FK of the measured joints (= the previous answer), as our
/// generator's path report does. Two IK solvers, each with KDL's defaults: Levenberg-Marquardt
/// (ChainIkSolverPos_LMA: weighted error < 1e-5, rotation weight 0.01) and Newton-Raphson within
/// joint limits (ChainIkSolverPos_NR_JL over ChainIkSolverVel_pinv: every twist component
/// < 1e-6). The chain is built from the same DH table as our model.
struct KdlPeer {
  KDL::Chain chain;
  std::unique_ptr<KDL::ChainFkSolverPos_recursive> fk;
  std::unique_ptr<KDL::ChainIkSolverPos_LMA> lma;
  std::unique_ptr<KDL::ChainIkSolverVel_pinv> velocity;
  std::unique_ptr<KDL::ChainIkSolverPos_NR_JL> nr_jl;
  KDL::Vector p0, dp, axis;
  KDL::Rotation R0;
  double angle = 0.0;
  double r_begin = 0.0, dr = 0.0;  // r at the window's first sample, r per sample
  std::size_t window = 0;
  KDL::JntArray q_begin;  // our setpoint just before the window
  std::string error;

  KdlPeer() {
    const kin::RobotModel model = kin::builtin_robot("puma560");
    for (const auto& j : model.joints) {
      chain.addSegment(KDL::Segment(
          KDL::Joint(j.type == kin::JointType::prismatic ? KDL::Joint::TransZ : KDL::Joint::RotZ),
          KDL::Frame::DH(j.dh.a_m, j.dh.alpha_rad, j.dh.d_m, j.dh.theta_rad)));
    }
    fk = std::make_unique<KDL::ChainFkSolverPos_recursive>(chain);
    lma = std::make_unique<KDL::ChainIkSolverPos_LMA>(chain);
    velocity = std::make_unique<KDL::ChainIkSolverVel_pinv>(chain);
    nr_jl = std::make_unique<KDL::ChainIkSolverPos_NR_JL>(chain, to_kdl(model.lower()),
                                                          to_kdl(model.upper()), *fk, *velocity);
    Rig& ours = rig("puma560", Case::cartesian);
    if (!ours.error().empty()) {
      error = ours.error();
      return;
    }
    const Line line = puma_line();
    const KDL::Frame f0 = to_kdl(line.start), f1 = to_kdl(line.goal);
    p0 = f0.p;
    dp = f1.p - f0.p;
    R0 = f0.M;
    axis = (f0.M.Inverse() * f1.M).GetRot();
    angle = axis.Normalize();
    // The same samples as our window: r = (t - ts) / T runs over the straight part.
    dr = kPeriod / ours.duration_s();
    window = ours.window();
    // Our first timed sample follows the one restart() stops after: start from that sample's
    // setpoint (the seed and the measured arm) and its r (the tool point is on the line, at
    // fraction r of it, since the drive's translation is linear in r).
    ours.restart();
    const auto kin = kin::make_kinematics(model);
    const Transform previous = kin->forward(ours.q());
    r_begin = (previous.p - line.start.p).norm() / (line.goal.p - line.start.p).norm() + dr;
    q_begin = to_kdl(ours.q());
    error = check(*kin, *lma);
    if (error.empty()) error = check(*kin, *nr_jl);
  }

  [[nodiscard]] KDL::Frame frame(double r) const {
    return {R0 * KDL::Rotation::Rot2(axis, angle * r), p0 + dp * r};
  }
  [[nodiscard]] Transform from_r(double r) const {
    const KDL::Frame f = frame(r);
    return Transform::from_rows({f.M(0, 0), f.M(0, 1), f.M(0, 2), f.p.x(), f.M(1, 0), f.M(1, 1),
                                 f.M(1, 2), f.p.y(), f.M(2, 0), f.M(2, 1), f.M(2, 2), f.p.z()});
  }

  /// One pass over the window: every answer is on the line within LMA's tolerance (2e-5 m,
  /// 2e-3 per rotation element, as in the kinematics benchmarks).
  std::string check(const kin::Kinematics& k, KDL::ChainIkSolverPos& ik) const {
    KDL::JntArray q = q_begin, out(chain.getNrOfJoints());
    for (std::size_t i = 0; i < window; ++i) {
      const double r = r_begin + dr * static_cast<double>(i);
      if (ik.CartToJnt(q, frame(r), out) < 0) return "KDL's IK failed on the line";
      JointVector qv(out.rows());
      for (std::size_t j = 0; j < qv.size(); ++j) qv[j] = out(static_cast<unsigned>(j));
      const Transform t = k.forward(qv), want = from_r(r);
      Transform rotation_only = t;
      rotation_only.p = want.p;
      if ((t.p - want.p).norm() > 2e-5 || math::max_abs_difference(rotation_only, want) > 2e-3) {
        return "KDL's IK answer is off the line";
      }
      q = out;
    }
    return {};
  }
};

enum class KdlIk { lma, nr_jl };

void BM_PeerKdlCartesianSample(benchmark::State& state, KdlIk which) {
  static KdlPeer peer;
  if (!peer.error.empty()) {
    state.SkipWithError(peer.error.c_str());
    return;
  }
  const unsigned n = peer.chain.getNrOfJoints();
  KDL::JntArray q = peer.q_begin, out(n);
  KDL::Frame measured_frame;
  KDL::ChainIkSolverPos& ik =
      which == KdlIk::lma ? static_cast<KDL::ChainIkSolverPos&>(*peer.lma) : *peer.nr_jl;
  std::size_t i = 0;
  std::int64_t iterations = 0, failed = 0;
  for (auto _ : state) {
    const double r = peer.r_begin + peer.dr * static_cast<double>(i);
    const KDL::Frame f = peer.frame(r);
    const int rc = ik.CartToJnt(q, f, out);
    const int fk_rc = peer.fk->JntToCart(q, measured_frame);  // the measured arm's tool frame
    benchmark::DoNotOptimize(measured_frame);
    benchmark::DoNotOptimize(out);
    failed += (rc < 0 || fk_rc < 0) ? 1 : 0;
    if (which == KdlIk::lma) iterations += peer.lma->lastNrOfIter;
    q = out;
    if (++i == peer.window) {  // back to the start of the window: a 6-double copy
      i = 0;
      q = peer.q_begin;
    }
  }
  if (failed != 0) state.SkipWithError("KDL's IK failed in the timed loop");
  if (which == KdlIk::lma) {
    state.counters["lma_iters"] =
        benchmark::Counter(static_cast<double>(iterations), benchmark::Counter::kAvgIterations);
  }
  state.counters["window"] = static_cast<double>(peer.window);
}

}  // namespace

BENCHMARK_CAPTURE(BM_SetpointJoint, microbo, std::string("microbo"));
BENCHMARK_CAPTURE(BM_SetpointCartesian, microbo, std::string("microbo"));
BENCHMARK_CAPTURE(BM_SetpointCartesian2Functional, microbo, std::string("microbo"));
BENCHMARK_CAPTURE(BM_SetpointCartesian2CFunctional, microbo, std::string("microbo"));
BENCHMARK_CAPTURE(BM_SetpointCartesianCompliant, microbo, std::string("microbo"));
BENCHMARK_CAPTURE(BM_SetpointJoint, puma560, std::string("puma560"));
BENCHMARK_CAPTURE(BM_SetpointCartesian, puma560, std::string("puma560"));
BENCHMARK_CAPTURE(BM_SetpointCartesian2Functional, puma560, std::string("puma560"));
BENCHMARK_CAPTURE(BM_SetpointCartesian2CFunctional, puma560, std::string("puma560"));
BENCHMARK_CAPTURE(BM_SetpointCartesianCompliant, puma560, std::string("puma560"));
BENCHMARK_CAPTURE(BM_PeerKdlCartesianSample, lma, KdlIk::lma);
BENCHMARK_CAPTURE(BM_PeerKdlCartesianSample, nr_jl, KdlIk::nr_jl);
