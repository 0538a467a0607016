// Kinematics benchmarks: our closed forms (Microbo, PUMA 560), our generic DH chain solver, and
// Orocos KDL as the peer (recursive FK, Levenberg-Marquardt IK) on the same PUMA 560 DH table.
//
// Every benchmark cycles through a fixed pool of inputs drawn once with a fixed seed, so that
// runs are comparable. IK pools hold only poses our closed form solves away from singularities
// (|sin theta5|, |sin(theta3 + phi)| >= 1e-3 and wrist-centre reach >= 1 mm), so every timed call
// is a normal solve. Each benchmark checks its answers once (the check is cached) and reports
// SkipWithError when they are wrong. Run with `make bench`; docs/PERFORMANCE.md has the results.
#include <benchmark/benchmark.h>

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "rccx/kinematics/dh_kinematics.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/urdf.hpp"
#include "rccx/math/transform.hpp"

namespace {

using rccx::kin::IkOptions;
using rccx::kin::IkResult;
using rccx::kin::JointVector;
using rccx::kin::Kinematics;
using rccx::kin::RobotModel;
using rccx::math::Transform;

constexpr std::size_t kPoolSize = 1024;           // samples per pool
constexpr std::uint64_t kDrawSeed = 19860101;     // joint vectors
constexpr std::uint64_t kPerturbSeed = 19860102;  // seeds of the numeric solvers
constexpr double kPerturbation = 0.05;            // rad, +- per joint around the true q
constexpr double kNearSingular = 1e-3;            // |sin| (or m) below which a sample is skipped
constexpr double kIkTolerance = 1e-9;             // FK(IK(pose)) vs pose, closed form and DH
constexpr double kFkTolerance = 1e-12;            // our FK vs the DH chain / KDL
constexpr double kKdlPositionTolerance = 2e-5;    // m; see check_kdl_ik
constexpr double kKdlRotationTolerance = 2e-3;    // rotation matrix element

// ---- robots -------------------------------------------------------------------------------

const Kinematics& microbo() {
  static const auto k = rccx::kin::make_kinematics(rccx::kin::builtin_robot("microbo"));
  return *k;
}
const Kinematics& puma() {
  static const auto k = rccx::kin::make_kinematics(rccx::kin::builtin_robot("puma560"));
  return *k;
}
/// The UR5e from robots/ur5e.urdf: its closed form (recognised on the URDF's DH table), the
/// numeric solver forced on it, and KDL's chain of the same URDF.
const Kinematics& ur5e() {
  static const auto k =
      rccx::kin::make_kinematics(rccx::kin::load_urdf(RCCX_ROBOTS_DIR "/ur5e.urdf"));
  return *k;
}
/// The Panda from robots/panda.urdf: the 7-axis closed form given q7 (SevenAxisKinematics).
const Kinematics& panda() {
  static const std::unique_ptr<Kinematics> k =
      rccx::kin::make_kinematics(rccx::kin::load_urdf(RCCX_ROBOTS_DIR "/panda.urdf"));
  return *k;
}
const rccx::kin::DhKinematics& numeric_ur5e() {
  static const rccx::kin::DhKinematics k(ur5e().model());
  return k;
}
const rccx::kin::DhKinematics& dh_puma() {
  static const rccx::kin::DhKinematics dh(rccx::kin::builtin_robot("puma560"));
  return dh;
}

KDL::Frame to_kdl(const Transform& t) {
  const auto& R = t.R;
  return KDL::Frame(KDL::Rotation(R.n.x, R.o.x, R.a.x, R.n.y, R.o.y, R.a.y, R.n.z, R.o.z, R.a.z),
                    KDL::Vector(t.p.x, t.p.y, t.p.z));
}
Transform from_kdl(const KDL::Frame& f) {
  return Transform::from_rows({f.M(0, 0), f.M(0, 1), f.M(0, 2), f.p.x(), f.M(1, 0), f.M(1, 1),
                               f.M(1, 2), f.p.y(), f.M(2, 0), f.M(2, 1), f.M(2, 2), f.p.z()});
}
KDL::JntArray to_kdl(const JointVector& q) {
  KDL::JntArray a(static_cast<unsigned>(q.size()));
  for (std::size_t i = 0; i < q.size(); ++i) a(static_cast<unsigned>(i)) = q[i];
  return a;
}
JointVector from_kdl(const KDL::JntArray& a) {
  JointVector q(a.rows());
  for (std::size_t i = 0; i < q.size(); ++i) q[i] = a(static_cast<unsigned>(i));
  return q;
}

/// The KDL peer, its chain built from the same DH table as our model, or from the same
/// general chain (a URDF's: each joint about its axis at its origin, as kdl_parser builds it).
/// Not movable: the solvers keep a reference to the chain.
struct KdlPuma {
  KDL::Chain chain;
  std::unique_ptr<KDL::ChainFkSolverPos_recursive> fk;
  std::unique_ptr<KDL::ChainIkSolverPos_LMA> ik;

  explicit KdlPuma(const RobotModel& model) {
    for (const auto& j : model.joints) {
      const bool prismatic = j.type == rccx::kin::JointType::prismatic;
      if (model.geometry == rccx::kin::Geometry::chain) {
        const KDL::Frame origin = to_kdl(j.chain.origin);
        const KDL::Vector axis =
            origin.M * KDL::Vector(j.chain.axis.x, j.chain.axis.y, j.chain.axis.z);
        chain.addSegment(KDL::Segment(
            KDL::Joint(origin.p, axis, prismatic ? KDL::Joint::TransAxis : KDL::Joint::RotAxis),
            origin));
        continue;
      }
      chain.addSegment(
          KDL::Segment(KDL::Joint(prismatic ? KDL::Joint::TransZ : KDL::Joint::RotZ),
                       KDL::Frame::DH(j.dh.a_m, j.dh.alpha_rad, j.dh.d_m, j.dh.theta_rad)));
    }
    if (model.geometry == rccx::kin::Geometry::chain) {  // the flange
      chain.addSegment(
          KDL::Segment(KDL::Joint(KDL::Joint::Fixed), to_kdl(model.joints.back().chain.after)));
    }
    fk = std::make_unique<KDL::ChainFkSolverPos_recursive>(chain);
    ik = std::make_unique<KDL::ChainIkSolverPos_LMA>(chain);  // KDL's defaults: eps 1e-5, 500 it.
  }
  KdlPuma(const KdlPuma&) = delete;
  KdlPuma& operator=(const KdlPuma&) = delete;
};
KdlPuma& kdl_puma() {
  static KdlPuma k(puma().model());
  return k;
}
KdlPuma& kdl_panda() {
  static KdlPuma k(panda().model());
  return k;
}
KdlPuma& kdl_ur5e() {
  static KdlPuma k(ur5e().model());
  return k;
}

// ---- input pools --------------------------------------------------------------------------

JointVector random_q(const RobotModel& model, std::mt19937_64& rng) {
  JointVector q(model.dof());
  for (std::size_t i = 0; i < model.dof(); ++i) {
    std::uniform_real_distribution<double> u(model.joints[i].lower, model.joints[i].upper);
    q[i] = u(rng);
  }
  return q;
}

struct FkPool {
  std::vector<JointVector> q;
  std::vector<KDL::JntArray> kdl_q;
};

FkPool make_fk_pool(const RobotModel& model) {
  FkPool pool;
  std::mt19937_64 rng(kDrawSeed);
  for (std::size_t s = 0; s < kPoolSize; ++s) {
    pool.q.push_back(random_q(model, rng));
    pool.kdl_q.push_back(to_kdl(pool.q.back()));
  }
  return pool;
}

struct IkPool {
  std::vector<Transform> pose;
  std::vector<JointVector> q;        // the joint vector that produced the pose
  std::vector<IkOptions> one;        // .configuration = configuration_of(q)
  std::vector<IkOptions> seeded;     // .near = q + perturbation, clamped to the limits
  std::vector<KDL::Frame> kdl_pose;  // the same poses and seeds for KDL
  std::vector<KDL::JntArray> kdl_seed;
  std::size_t drawn = 0;
  std::size_t skipped_unsolved = 0;
  std::size_t skipped_singular = 0;
  std::string error;  // non-empty when the pool could not be built
};

/// Near a singularity of the PUMA (wrist, elbow or shoulder) or of the Microbo (wrist).
bool near_singular(const Kinematics& k, const JointVector& q) {
  if (k.dof() == 7) return false;  // the Panda's solver fills free joints from `near`
  if (std::abs(std::sin(q[4])) < kNearSingular) return true;
  if (k.model().solver != rccx::kin::SolverKind::puma) return false;
  const auto& j = k.model().joints;
  const double a2 = j[1].dh.a_m, a3 = j[2].dh.a_m, d4 = j[3].dh.d_m;
  const double phi = std::atan2(d4, a3);
  const double reach =
      a2 * std::cos(q[1]) + a3 * std::cos(q[1] + q[2]) - d4 * std::sin(q[1] + q[2]);
  return std::abs(std::sin(q[2] + phi)) < kNearSingular || std::abs(reach) < kNearSingular;
}

IkPool make_ik_pool(const Kinematics& k) {
  IkPool pool;
  const RobotModel& model = k.model();
  std::mt19937_64 rng(kDrawSeed);
  std::mt19937_64 perturb_rng(kPerturbSeed);
  std::uniform_real_distribution<double> perturb(-kPerturbation, kPerturbation);
  while (pool.pose.size() < kPoolSize) {
    if (pool.drawn > 100 * kPoolSize) {
      pool.error = "could not draw enough solvable, non-singular samples";
      return pool;
    }
    ++pool.drawn;
    const JointVector q = random_q(model, rng);
    JointVector seed(model.dof());
    for (std::size_t i = 0; i < model.dof(); ++i) {
      seed[i] =
          std::clamp(q[i] + perturb(perturb_rng), model.joints[i].lower, model.joints[i].upper);
    }
    if (near_singular(k, q)) {
      ++pool.skipped_singular;
      continue;
    }
    const Transform pose = k.forward(q);
    IkOptions one;
    one.configuration = k.configuration_of(q);
    if (k.dof() == 7) one.redundant = q[6];  // the closed form given q7
    if (!k.inverse(pose, one)) {
      ++pool.skipped_unsolved;
      continue;
    }
    IkOptions seeded;
    seeded.near = seed;
    pool.pose.push_back(pose);
    pool.q.push_back(q);
    pool.one.push_back(one);
    pool.seeded.push_back(seeded);
    pool.kdl_pose.push_back(to_kdl(pose));
    pool.kdl_seed.push_back(to_kdl(seed));
  }
  return pool;
}

const FkPool& microbo_fk_pool() {
  static const FkPool pool = make_fk_pool(microbo().model());
  return pool;
}
const FkPool& puma_fk_pool() {
  static const FkPool pool = make_fk_pool(puma().model());
  return pool;
}
const IkPool& microbo_ik_pool() {
  static const IkPool pool = make_ik_pool(microbo());
  return pool;
}
const IkPool& puma_ik_pool() {
  static const IkPool pool = make_ik_pool(puma());
  return pool;
}
const IkPool& panda_ik_pool() {
  static const IkPool pool = make_ik_pool(panda());
  return pool;
}
const IkPool& ur5e_ik_pool() {
  static const IkPool pool = make_ik_pool(ur5e());
  return pool;
}
/// The same poses with every seed the ready pose: a solve with no idea where the arm is.
const IkPool& ur5e_ik_pool_from_ready() {
  static const IkPool pool = [] {
    IkPool p = ur5e_ik_pool();
    const JointVector ready = ur5e().model().ready();
    for (std::size_t s = 0; s < p.pose.size(); ++s) {
      p.seeded[s].near = ready;
      p.kdl_seed[s] = to_kdl(ready);
    }
    return p;
  }();
  return pool;
}

// ---- sanity checks (each computed once, then cached) --------------------------------------

double max_diff(const Transform& a, const Transform& b) {
  return rccx::math::max_abs_difference(a, b);
}

/// Our FK against the generic DH chain product of the same model (and, for the PUMA, KDL).
std::string check_fk(const Kinematics& k, const FkPool& pool, bool with_kdl) {
  const rccx::kin::DhKinematics chain(k.model());
  for (std::size_t s = 0; s < pool.q.size(); ++s) {
    const Transform ours = k.forward(pool.q[s]);
    if (max_diff(ours, chain.forward(pool.q[s])) > kFkTolerance) {
      return "FK differs from the DH chain product";
    }
    if (with_kdl) {
      KDL::Frame f;
      if (kdl_puma().fk->JntToCart(pool.kdl_q[s], f) < 0) return "KDL FK failed";
      if (max_diff(ours, from_kdl(f)) > kFkTolerance) return "KDL FK differs from ours";
    }
  }
  return {};
}

/// One configuration: FK of the answer is the pose and the configuration is the one asked for.
std::string check_ik_one(const Kinematics& k, const IkPool& pool) {
  if (!pool.error.empty()) return pool.error;
  for (std::size_t s = 0; s < pool.pose.size(); ++s) {
    const IkResult r = k.inverse(pool.pose[s], pool.one[s]);
    if (!r) return "closed-form IK failed on a pool sample";
    if (max_diff(k.forward(r.q), pool.pose[s]) > kIkTolerance) return "FK(IK(pose)) != pose";
    if (k.configuration_of(r.q) != *pool.one[s].configuration) return "wrong configuration";
  }
  return {};
}

/// All configurations: every answer round-trips, and the sample's own configuration is there.
std::string check_ik_all(const Kinematics& k, const IkPool& pool) {
  if (!pool.error.empty()) return pool.error;
  for (std::size_t s = 0; s < pool.pose.size(); ++s) {
    const auto all = k.inverse_all(pool.pose[s]);
    bool found = false;
    for (const IkResult& r : all.solutions()) {
      if (max_diff(k.forward(r.q), pool.pose[s]) > kIkTolerance) {
        return "FK(IK(pose)) != pose for one of inverse_all's answers";
      }
      found = found || r.configuration == *pool.one[s].configuration;
    }
    if (!found) return "inverse_all misses the sample's own configuration";
  }
  return {};
}

struct NumericCheck {
  std::string error;
  double ok_rate = 0.0;
  double max_error = 0.0;  // over the successful answers: max |FK(q) - pose| element
  /// KDL's LMA knows no joint limits: the share of the poses its answer (revolute joints moved
  /// by whole turns where that helps) lies within them.
  double within_limits_rate = -1.0;
};

/// q within the model's limits once each revolute joint is moved by whole turns towards them.
bool within_limits_up_to_turns(const RobotModel& model, JointVector q) {
  constexpr double kTurn = 2.0 * std::numbers::pi;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const rccx::kin::Joint& j = model.joints[i];
    if (j.type == rccx::kin::JointType::revolute && std::isfinite(j.lower)) {
      while (q[i] < j.lower - 1e-9) q[i] += kTurn;
      while (q[i] > j.upper + 1e-9) q[i] -= kTurn;
    }
  }
  return model.within_limits(q, 1e-9);
}

/// KDL's LMA stops when |L .* twist error| < eps (1e-5) with weights L = (1, 1, 1, 0.01, 0.01,
/// 0.01): its answers are good to about 1e-5 m and 1e-3 rad, and are checked to that.
NumericCheck check_kdl_ik(const IkPool& pool, KdlPuma& kdl = kdl_puma(),
                          const Kinematics& ours = puma()) {
  NumericCheck c;
  if (!pool.error.empty()) {
    c.error = pool.error;
    return c;
  }
  KDL::JntArray q_out(kdl.chain.getNrOfJoints());
  std::size_t ok = 0, within = 0;
  double max_position = 0.0, max_rotation = 0.0;
  for (std::size_t s = 0; s < pool.pose.size(); ++s) {
    if (kdl.ik->CartToJnt(pool.kdl_seed[s], pool.kdl_pose[s], q_out) < 0) continue;
    ++ok;
    if (within_limits_up_to_turns(ours.model(), from_kdl(q_out))) ++within;
    const Transform t = ours.forward(from_kdl(q_out));
    max_position = std::max(max_position, (t.p - pool.pose[s].p).norm());
    Transform rotation_only = t;
    rotation_only.p = pool.pose[s].p;
    max_rotation = std::max(max_rotation, max_diff(rotation_only, pool.pose[s]));
    c.max_error = std::max(c.max_error, max_diff(t, pool.pose[s]));
  }
  c.ok_rate = static_cast<double>(ok) / static_cast<double>(pool.pose.size());
  c.within_limits_rate = static_cast<double>(within) / static_cast<double>(pool.pose.size());
  if (ok == 0) c.error = "KDL LMA solved no sample";
  if (max_position > kKdlPositionTolerance || max_rotation > kKdlRotationTolerance) {
    c.error = "KDL LMA: FK(IK(pose)) != pose, max position error " + std::to_string(max_position) +
              " m, rotation element " + std::to_string(max_rotation);
  }
  return c;
}

/// Reports the check's error, if any; true when the benchmark may run.
bool checked(benchmark::State& state, const std::string& error) {
  if (error.empty()) return true;
  state.SkipWithError(error.c_str());
  return false;
}

void pool_counters(benchmark::State& state, const IkPool& pool) {
  state.counters["pool"] = static_cast<double>(pool.pose.size());
  state.counters["skipped"] = static_cast<double>(pool.skipped_singular + pool.skipped_unsolved) /
                              static_cast<double>(pool.drawn);
}

// ---- FK -----------------------------------------------------------------------------------

template <class Solver>
void run_fk(benchmark::State& state, const Solver& k, const FkPool& pool) {
  const std::size_t n = pool.q.size();
  std::size_t i = 0;
  for (auto _ : state) {
    const Transform t = k.forward(pool.q[i]);
    benchmark::DoNotOptimize(t);
    if (++i == n) i = 0;
  }
  state.counters["pool"] = static_cast<double>(n);
}

void BM_MicroboFK(benchmark::State& state) {
  static const std::string error = check_fk(microbo(), microbo_fk_pool(), false);
  if (!checked(state, error)) return;
  run_fk(state, microbo(), microbo_fk_pool());
}

void BM_Puma560FK(benchmark::State& state) {
  static const std::string error = check_fk(puma(), puma_fk_pool(), true);
  if (!checked(state, error)) return;
  run_fk(state, puma(), puma_fk_pool());
}

void BM_DhFK(benchmark::State& state) {
  static const std::string error = check_fk(dh_puma(), puma_fk_pool(), true);
  if (!checked(state, error)) return;
  run_fk(state, dh_puma(), puma_fk_pool());
}

void BM_KdlPuma560FK(benchmark::State& state) {
  static const std::string error = check_fk(puma(), puma_fk_pool(), true);
  if (!checked(state, error)) return;
  const FkPool& pool = puma_fk_pool();
  KDL::ChainFkSolverPos_recursive& fk = *kdl_puma().fk;
  const std::size_t n = pool.kdl_q.size();
  std::size_t i = 0;
  KDL::Frame f;
  for (auto _ : state) {
    const int rc = fk.JntToCart(pool.kdl_q[i], f);
    benchmark::DoNotOptimize(rc);
    benchmark::DoNotOptimize(f);
    if (++i == n) i = 0;
  }
  state.counters["pool"] = static_cast<double>(n);
}

// ---- IK -----------------------------------------------------------------------------------

/// Closed form, one configuration (the one of the q that produced the pose).
void run_ik_one(benchmark::State& state, const Kinematics& k, const IkPool& pool) {
  const std::size_t n = pool.pose.size();
  std::size_t i = 0;
  for (auto _ : state) {
    const IkResult r = k.inverse(pool.pose[i], pool.one[i]);
    benchmark::DoNotOptimize(r);
    if (++i == n) i = 0;
  }
  pool_counters(state, pool);
}

void BM_MicroboIK(benchmark::State& state) {
  static const std::string error = check_ik_one(microbo(), microbo_ik_pool());
  if (!checked(state, error)) return;
  run_ik_one(state, microbo(), microbo_ik_pool());
}

void BM_Puma560IK(benchmark::State& state) {
  static const std::string error = check_ik_one(puma(), puma_ik_pool());
  if (!checked(state, error)) return;
  run_ik_one(state, puma(), puma_ik_pool());
}

/// inverse_all over a pool, after its check; counts the solutions.
void run_ik_all(benchmark::State& state, const Kinematics& k, const IkPool& pool,
                const std::string& error) {
  if (!checked(state, error)) return;
  const std::size_t n = pool.pose.size();
  std::size_t i = 0;
  std::int64_t solutions = 0;
  for (auto _ : state) {
    const auto all = k.inverse_all(pool.pose[i]);
    benchmark::DoNotOptimize(all);
    solutions += static_cast<std::int64_t>(all.count);
    if (++i == n) i = 0;
  }
  pool_counters(state, pool);
  state.counters["solutions"] =
      benchmark::Counter(static_cast<double>(solutions), benchmark::Counter::kAvgIterations);
}

void BM_Puma560IKAll(benchmark::State& state) {
  static const std::string error = check_ik_all(puma(), puma_ik_pool());
  run_ik_all(state, puma(), puma_ik_pool(), error);
}

/// Any solver's inverse() from the pool's seeds (or, `from_ready`, with no seed): how many it
/// solves and its worst round-trip error.
NumericCheck check_seeded_ik(const Kinematics& k, const IkPool& pool, bool from_ready = false) {
  NumericCheck c;
  if (!pool.error.empty()) {
    c.error = pool.error;
    return c;
  }
  std::size_t ok = 0;
  for (std::size_t s = 0; s < pool.pose.size(); ++s) {
    const IkResult r = k.inverse(pool.pose[s], from_ready ? IkOptions{} : pool.seeded[s]);
    if (!r) continue;
    ++ok;
    c.max_error = std::max(c.max_error, max_diff(k.forward(r.q), pool.pose[s]));
  }
  c.ok_rate = static_cast<double>(ok) / static_cast<double>(pool.pose.size());
  if (ok == 0) c.error = "the solver solved no sample";
  if (c.max_error > kIkTolerance) {
    c.error = "FK(IK(pose)) != pose, max element error " + std::to_string(c.max_error);
  }
  return c;
}

void run_seeded_ik(benchmark::State& state, const Kinematics& k, const IkPool& pool,
                   const NumericCheck& check, bool from_ready = false) {
  if (!checked(state, check.error)) return;
  const std::size_t n = pool.pose.size();
  const IkOptions ready;
  std::size_t i = 0;
  std::int64_t ok = 0;
  for (auto _ : state) {
    const IkResult r = k.inverse(pool.pose[i], from_ready ? ready : pool.seeded[i]);
    benchmark::DoNotOptimize(r);
    ok += r ? 1 : 0;
    if (++i == n) i = 0;
  }
  pool_counters(state, pool);
  state.counters["ok_rate"] =
      benchmark::Counter(static_cast<double>(ok), benchmark::Counter::kAvgIterations);
  state.counters["max_err"] = check.max_error;
}

/// KDL's LMA over a pool from the same seeds, after its check.
void run_kdl_ik(benchmark::State& state, KdlPuma& kdl, const IkPool& pool,
                const NumericCheck& check) {
  if (!checked(state, check.error)) return;
  const std::size_t n = pool.pose.size();
  std::size_t i = 0;
  std::int64_t ok = 0, iterations = 0;
  KDL::JntArray q_out(kdl.chain.getNrOfJoints());
  for (auto _ : state) {
    const int rc = kdl.ik->CartToJnt(pool.kdl_seed[i], pool.kdl_pose[i], q_out);
    benchmark::DoNotOptimize(rc);
    benchmark::DoNotOptimize(q_out);
    ok += rc >= 0 ? 1 : 0;
    iterations += kdl.ik->lastNrOfIter;
    if (++i == n) i = 0;
  }
  pool_counters(state, pool);
  state.counters["ok_rate"] =
      benchmark::Counter(static_cast<double>(ok), benchmark::Counter::kAvgIterations);
  state.counters["lma_iters"] =
      benchmark::Counter(static_cast<double>(iterations), benchmark::Counter::kAvgIterations);
  state.counters["in_limits"] = check.within_limits_rate;
  state.counters["max_err"] = check.max_error;
}

void BM_DhIK(benchmark::State& state) {
  static const NumericCheck check = check_seeded_ik(dh_puma(), puma_ik_pool());
  run_seeded_ik(state, dh_puma(), puma_ik_pool(), check);
}

void BM_KdlPuma560IK(benchmark::State& state) {
  static const NumericCheck check = check_kdl_ik(puma_ik_pool());
  run_kdl_ik(state, kdl_puma(), puma_ik_pool(), check);
}

// ---- the UR5e from its URDF (issue 26): closed form, numeric, KDL on the same poses ---------

void BM_Ur5eIK(benchmark::State& state) {
  static const std::string error = check_ik_one(ur5e(), ur5e_ik_pool());
  if (!checked(state, error)) return;
  run_ik_one(state, ur5e(), ur5e_ik_pool());
}

void BM_Ur5eIKAll(benchmark::State& state) {
  static const std::string error = check_ik_all(ur5e(), ur5e_ik_pool());
  run_ik_all(state, ur5e(), ur5e_ik_pool(), error);
}

/// The numeric solver forced on the UR5e, from the seeds KDL gets (0.05 rad off each joint).
void BM_Ur5eNumericIK(benchmark::State& state) {
  static const NumericCheck check = check_seeded_ik(numeric_ur5e(), ur5e_ik_pool());
  run_seeded_ik(state, numeric_ur5e(), ur5e_ik_pool(), check);
}

/// Both numeric solvers from the ready pose: rccx's restarts from 16 seeds spread over the
/// ranges when its first start fails; KDL's LMA starts once.
void BM_Ur5eNumericIKFromReady(benchmark::State& state) {
  static const NumericCheck check = check_seeded_ik(numeric_ur5e(), ur5e_ik_pool_from_ready());
  run_seeded_ik(state, numeric_ur5e(), ur5e_ik_pool_from_ready(), check);
}

void BM_KdlUr5eIKFromReady(benchmark::State& state) {
  static const NumericCheck check = check_kdl_ik(ur5e_ik_pool_from_ready(), kdl_ur5e(), ur5e());
  run_kdl_ik(state, kdl_ur5e(), ur5e_ik_pool_from_ready(), check);
}

void BM_KdlUr5eIK(benchmark::State& state) {
  static const NumericCheck check = check_kdl_ik(ur5e_ik_pool(), kdl_ur5e(), ur5e());
  run_kdl_ik(state, kdl_ur5e(), ur5e_ik_pool(), check);
}

// ---- the Panda from its URDF (issue 26): 7-axis closed form, KDL on the same poses ----------

/// Given q7 and the configuration: the closed form alone.
void BM_PandaIK(benchmark::State& state) {
  static const std::string error = check_ik_one(panda(), panda_ik_pool());
  if (!checked(state, error)) return;
  run_ik_one(state, panda(), panda_ik_pool());
}

/// From the seeds KDL gets, q7 free: the solver starts at the seed's q7 and moves it only if it
/// must, as the generator calls it every sample. This is the one compared with KDL's LMA.
void BM_PandaIKSeeded(benchmark::State& state) {
  static const NumericCheck check = check_seeded_ik(panda(), panda_ik_pool());
  run_seeded_ik(state, panda(), panda_ik_pool(), check);
}

/// From the ready pose, q7 searched outward from ready's: the worst case of the search.
void BM_PandaIKFromReady(benchmark::State& state) {
  static const NumericCheck check = check_seeded_ik(panda(), panda_ik_pool(), true);
  run_seeded_ik(state, panda(), panda_ik_pool(), check, true);
}

void BM_KdlPandaIK(benchmark::State& state) {
  static const NumericCheck check = check_kdl_ik(panda_ik_pool(), kdl_panda(), panda());
  run_kdl_ik(state, kdl_panda(), panda_ik_pool(), check);
}

}  // namespace

BENCHMARK(BM_MicroboFK);
BENCHMARK(BM_MicroboIK);
BENCHMARK(BM_Puma560FK);
BENCHMARK(BM_Puma560IK);
BENCHMARK(BM_Puma560IKAll);
BENCHMARK(BM_DhFK);
BENCHMARK(BM_DhIK);
BENCHMARK(BM_KdlPuma560FK);
BENCHMARK(BM_KdlPuma560IK);
BENCHMARK(BM_Ur5eIK);
BENCHMARK(BM_Ur5eIKAll);
BENCHMARK(BM_Ur5eNumericIK);
BENCHMARK(BM_KdlUr5eIK);
BENCHMARK(BM_Ur5eNumericIKFromReady);
BENCHMARK(BM_KdlUr5eIKFromReady);
BENCHMARK(BM_PandaIK);
BENCHMARK(BM_PandaIKSeeded);
BENCHMARK(BM_PandaIKFromReady);
BENCHMARK(BM_KdlPandaIK);

BENCHMARK_MAIN();
