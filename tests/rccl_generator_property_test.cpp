// Property test of the trajectory generator's slowing (issue 14): 1,000 random programs on each
// of the Microbo and the PUMA 560 - mixed joint and Cartesian segments queued back to back,
// random tool speeds (up to far more than the joints allow), random segment and transition
// times (down to one sample), goals reachable (made from joint values within the limits) - and
// on every commanded sample no joint passes its top speed or its acceleration bound (within the
// tolerance trajectory.hpp documents, kAccelerationTolerance). No motion may fail for a bound
// ("would move at", "would accelerate", "would leave its limits", a path that cannot be followed
// in the loop): the generator must have slowed down instead. A Cartesian line that cannot exist
// (one through a singularity where a joint must jump, one that leaves the workspace between its
// reachable ends, one that would turn a joint of several turns past its limit) may be refused
// before it starts, with that cause named; those are counted and
// must stay a minority.
//
// Cheap by construction: a long period (20 ms; 28 ms on the Microbo, its own) and an ideal arm
// (measured = commanded, tests/rccl_harness.hpp), with programs of 1 .. 4 short moves.
//
//   RCCX_PROPERTY_SEED=n       another seed (the one used is printed)
//   RCCX_PROPERTY_PROGRAMS=n   how many programs per robot (default 1000)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "rccl_harness.hpp"
#include "rccx/rccl/position.hpp"

namespace {

using namespace rccx;
using rccl::EventKind;
using rccl::Mode;
using test::GeneratorRun;

std::uint64_t env_or(const char* name, std::uint64_t fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  return std::strtoull(v, nullptr, 0);
}

rccl::PositionPtr pose_position(const std::string& name, const math::Transform& t6) {
  const auto t6_ = rccl::t6();
  return rccl::Position::make(name, {t6_}, {rccl::constant(name, t6)}, t6_);
}

bool contains(std::string_view s, std::string_view what) {
  return s.find(what) != std::string_view::npos;
}

/// A failure the generator should have avoided by slowing down: one the sample loop's guards
/// raise.
bool bound_failure(std::string_view m) {
  return contains(m, "would move at") || contains(m, "would accelerate") ||
         contains(m, "would leave its limits") || contains(m, "cannot be followed");
}

struct Tally {
  std::size_t programs = 0, motions = 0, ended = 0, refused = 0, samples = 0;
  double worst_speed = 0.0, worst_acceleration = 0.0;
};

void run_programs(const char* robot, double period, std::uint64_t seed, std::size_t programs,
                  Tally& tally) {
  GeneratorRun run(robot, period);
  const rccl::GeneratorOptions& o = run.generator.options();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const std::size_t n = run.model.dof();
  const auto random_joints = [&](const kin::JointVector& around, double spread) {
    kin::JointVector g = around;
    for (std::size_t j = 0; j < n; ++j) {
      const kin::Joint& J = run.model.joints[j];
      const double m = 0.02 * (J.upper - J.lower);
      g[j] = std::clamp(g[j] + spread * (J.upper - J.lower) * (2.0 * u01(rng) - 1.0), J.lower + m,
                        J.upper - m);
    }
    return g;
  };
  for (std::size_t program = 0; program < programs; ++program) {
    const int moves = 1 + static_cast<int>(rng() % 4);
    kin::JointVector planned = run.q;  // where the queued moves leave the arm, roughly
    std::string plan;                  // printed when the program fails
    for (int m = 0; m < moves; ++m) {
      rccl::MotionSettings s;
      s.mode = rng() % 2 ? Mode::joint : Mode::cartesian;
      s.translation_m_per_s = 0.02 + 1.5 * u01(rng) * u01(rng);
      s.rotation_rad_per_s = 0.2 + 6.0 * u01(rng) * u01(rng);
      s.transition_time_s = rng() % 5 == 0 ? period : 0.01 + 0.5 * u01(rng);
      if (rng() % 6 == 0) s.segment_time_s = 0.02 + 0.5 * u01(rng);  // far too short, often
      // Cartesian goals near where the arm will be (the same configuration: a line can exist);
      // joint goals anywhere within the limits.
      // A Cartesian line keeps the configuration; a joint move is asked into the goal's.
      const kin::Configuration c = run.kinematics->configuration_of(planned);
      kin::JointVector g;
      do {
        g = random_joints(planned, s.mode == Mode::cartesian ? 0.12 : 0.6 * u01(rng));
      } while (s.mode == Mode::cartesian && !(run.kinematics->configuration_of(g) == c));
      if (s.mode == Mode::joint && !run.kinematics->configuration_names().empty()) {
        s.configuration = static_cast<std::int16_t>(run.kinematics->configuration_of(g).index);
      }
      if (s.mode == Mode::joint && rng() % 3 == 0) {
        run.move(rccl::Position::joints("Q", g), s);
      } else {
        run.move(pose_position("P", run.kinematics->forward(g)), s);
      }
      plan += fmt::format(
          "  motion {}: {} {} v {:.3f} m/s {:.3f} rad/s, segment {:.3f} s, "
          "transition {:.3f} s, to joints [{:.4f}]\n",
          run.next_id - 1, rccl::to_string(s.mode),
          run.keep.back()->in_joints() ? "(in joints)" : "(pose)", s.translation_m_per_s,
          s.rotation_rad_per_s, s.segment_time_s, s.transition_time_s, fmt::join(g, ", "));
      planned = g;
      ++tally.motions;
    }
    const std::size_t from = run.qs.size();
    if (!run.run_until_rest(600.0) && std::getenv("RCCX_PROPERTY_DEBUG")) {
      for (const auto& ev : run.events) {
        std::printf("%s %llu %.3f %s\n", std::string(rccl::to_string(ev.kind)).c_str(),
                    static_cast<unsigned long long>(ev.id), ev.t_s,
                    std::string(ev.message()).c_str());
      }
      for (std::size_t k = from; k < run.qs.size(); k += 500) {
        std::printf("t %.3f seg %llu q [%s]\n", run.t[k],
                    static_cast<unsigned long long>(run.segment[k]),
                    fmt::format("{:.4f}", fmt::join(run.qs[k], ", ")).c_str());
      }
    }
    ASSERT_TRUE(run.generator.at_rest()) << robot << " program " << program << " never rested\n"
                                         << plan;
    bool failed = false;
    for (const auto& e : run.events) {
      if (e.kind == EventKind::ended) ++tally.ended;
      if (e.kind != EventKind::failed) continue;
      failed = true;
      if (bound_failure(e.message()) && std::getenv("RCCX_PROPERTY_DEBUG")) {
        for (std::size_t k = from; k < run.qs.size(); ++k) {
          if (run.t[k] < e.t_s - 1.5 || run.t[k] > e.t_s + 0.1) continue;
          std::printf("t %.3f seg %llu q [%s]\n", run.t[k],
                      static_cast<unsigned long long>(run.segment[k]),
                      fmt::format("{:.4f}", fmt::join(run.qs[k], ", ")).c_str());
        }
        for (const auto& ev : run.events) {
          std::printf("%s %llu %.3f %s\n", std::string(rccl::to_string(ev.kind)).c_str(),
                      static_cast<unsigned long long>(ev.id), ev.t_s,
                      std::string(ev.message()).c_str());
        }
      }
      ASSERT_FALSE(bound_failure(e.message()))
          << robot << " program " << program << " (seed " << seed << "), motion " << e.id
          << " failed for a bound at t = " << e.t_s << ": " << e.message() << "\n"
          << plan;
      ASSERT_TRUE(contains(e.message(), "singularity") || contains(e.message(), "workspace") ||
                  contains(e.message(), "past its limit"))
          << robot << " program " << program << ": " << e.message();
      ++tally.refused;
    }
    // Every commanded sample of the program: speed and acceleration within the bounds.
    for (std::size_t k = std::max<std::size_t>(from, 2); k < run.qs.size(); ++k) {
      for (std::size_t j = 0; j < n; ++j) {
        const double v = std::abs(run.qs[k][j] - run.qs[k - 1][j]) / period / o.max_velocity[j];
        const double a = std::abs(run.qs[k][j] - 2.0 * run.qs[k - 1][j] + run.qs[k - 2][j]) /
                         (period * period) / o.max_acceleration[j];
        tally.worst_speed = std::max(tally.worst_speed, v);
        tally.worst_acceleration = std::max(tally.worst_acceleration, a);
        ASSERT_LE(v, 1.0 + 1e-6) << robot << " program " << program << " joint " << j + 1
                                 << " t = " << run.t[k];
        // A failure's stop may brake at up to the guard to stay inside a limit; otherwise the
        // bound holds.
        if (!failed && a > 1.0 + rccl::kAccelerationTolerance &&
            std::getenv("RCCX_PROPERTY_DEBUG")) {
          for (std::size_t i = from + 2; i < run.qs.size(); ++i) {
            if (run.t[i] < run.t[k] - 1.0 || run.t[i] > run.t[k] + 0.3) continue;
            std::printf("t %.3f seg %llu q%zu %.5f v %.3f a %.3f\n", run.t[i],
                        static_cast<unsigned long long>(run.segment[i]), j + 1, run.qs[i][j],
                        (run.qs[i][j] - run.qs[i - 1][j]) / period / o.max_velocity[j],
                        (run.qs[i][j] - 2.0 * run.qs[i - 1][j] + run.qs[i - 2][j]) /
                            (period * period) / o.max_acceleration[j]);
          }
          for (const auto& ev : run.events) {
            std::printf("%s %llu %.3f %s\n", std::string(rccl::to_string(ev.kind)).c_str(),
                        static_cast<unsigned long long>(ev.id), ev.t_s,
                        std::string(ev.message()).c_str());
          }
        }
        if (!failed) {
          ASSERT_LE(a, 1.0 + rccl::kAccelerationTolerance)
              << robot << " program " << program << " (seed " << seed << ") joint " << j + 1
              << " t = " << run.t[k] << " segment " << run.segment[k] << "\n"
              << plan;
        }
      }
    }
    tally.samples += run.qs.size() - from;
    ++tally.programs;
    // Keep memory flat: the next program starts where this one ended.
    run.qs.erase(run.qs.begin(), run.qs.end() - 2);
    run.t.erase(run.t.begin(), run.t.end() - 2);
    run.segment.erase(run.segment.begin(), run.segment.end() - 2);
    run.events.clear();
  }
}

TEST(RcclGeneratorProperty, RandomProgramsAreSlowedNeverFailedForABound) {
  const std::uint64_t seed = env_or("RCCX_PROPERTY_SEED", 14);
  const std::size_t programs = env_or("RCCX_PROPERTY_PROGRAMS", 1000);
  for (const auto& [robot, period] : {std::pair{"microbo", 0.028}, std::pair{"puma560", 0.02}}) {
    Tally t;
    run_programs(robot, period, seed, programs, t);
    if (HasFatalFailure()) return;
    std::printf(
        "%s (seed %llu): %zu programs, %zu motions, %zu ended, %zu refused (a line through a "
        "singularity, out of the workspace or past a limit), %zu samples; peak speed %.4f, peak "
        "acceleration "
        "%.4f of the bounds\n",
        robot, static_cast<unsigned long long>(seed), t.programs, t.motions, t.ended, t.refused,
        t.samples, t.worst_speed, t.worst_acceleration);
    EXPECT_EQ(t.programs, programs);
    EXPECT_LT(t.refused, t.motions / 4) << robot;
    EXPECT_GT(t.samples, 1000 * programs / 10);
  }
}

}  // namespace
