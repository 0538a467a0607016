// Paul's quartic transition: continuity with the segments it joins, its acceleration against
// finite differences of its position, and the transition time that bounds the acceleration.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "rccx/rccl/paul_transition.hpp"

using rccx::rccl::paul_transition;
using rccx::rccl::paul_transition_peak_acceleration;
using rccx::rccl::paul_transition_time;

namespace {

struct Case {
  double B, v0, v1, tau, T;
  [[nodiscard]] double dB() const { return -v0 * tau; }  // A = B - v0 tau
  [[nodiscard]] double dC() const { return v1 * T; }     // C = B + v1 T
};

std::vector<Case> cases() {
  std::mt19937_64 rng(19811010);
  std::uniform_real_distribution<double> v(-2.0, 2.0), tau(0.02, 0.5), pos(-3.0, 3.0);
  std::vector<Case> out;
  for (int i = 0; i < 200; ++i) {
    Case c{pos(rng), v(rng), v(rng), tau(rng), 0.0};
    c.T = c.tau * (1.0 + 5.0 * std::abs(v(rng)));  // T >= tau
    out.push_back(c);
  }
  return out;
}

}  // namespace

TEST(PaulTransition, JoinsBothSegmentsWithContinuousPositionVelocityAndAcceleration) {
  for (const Case& c : cases()) {
    const auto start = paul_transition(c.B, c.dB(), c.dC(), c.tau, c.T, -c.tau);
    const auto end = paul_transition(c.B, c.dB(), c.dC(), c.tau, c.T, c.tau);
    // Where the straight segments stand at -tau and +tau, and their speeds.
    EXPECT_NEAR(start.q, c.B - c.v0 * c.tau, 1e-12);
    EXPECT_NEAR(start.qd, c.v0, 1e-12);
    EXPECT_NEAR(start.qdd, 0.0, 1e-12);
    EXPECT_NEAR(end.q, c.B + c.v1 * c.tau, 1e-12);
    EXPECT_NEAR(end.qd, c.v1, 1e-12);
    EXPECT_NEAR(end.qdd, 0.0, 1e-12);
  }
}

TEST(PaulTransition, VelocityAndAccelerationAreTheDerivativesOfPosition) {
  for (const Case& c : cases()) {
    const double dt = 1e-6 * c.tau;
    for (double f : {-0.9, -0.5, -0.1, 0.0, 0.3, 0.7, 0.95}) {
      const double t = f * c.tau;
      const auto at = [&](double s) { return paul_transition(c.B, c.dB(), c.dC(), c.tau, c.T, s); };
      const double qd = (at(t + dt).q - at(t - dt).q) / (2 * dt);
      const double qdd = (at(t + dt).qd - at(t - dt).qd) / (2 * dt);
      EXPECT_NEAR(at(t).qd, qd, 1e-6 * (1 + std::abs(qd)));
      EXPECT_NEAR(at(t).qdd, qdd, 1e-5 * (1 + std::abs(qdd)));
    }
  }
}

TEST(PaulTransition, PeakAccelerationIsInTheMiddleAndTheTransitionTimeBoundsIt) {
  for (const Case& c : cases()) {
    double largest = 0;
    for (int i = 0; i <= 2000; ++i) {
      const double t = -c.tau + 2 * c.tau * i / 2000.0;
      largest =
          std::max(largest, std::abs(paul_transition(c.B, c.dB(), c.dC(), c.tau, c.T, t).qdd));
    }
    const double peak = paul_transition_peak_acceleration(c.dB(), c.dC(), c.tau, c.T);
    EXPECT_NEAR(largest, peak, 1e-9 * (1 + peak));
    EXPECT_NEAR(std::abs(paul_transition(c.B, c.dB(), c.dC(), c.tau, c.T, 0.0).qdd), peak,
                1e-12 * (1 + peak));
    // The time that bounds the acceleration to a keeps it there, and a shorter one does not.
    const double a = 1.5;
    const double tau = paul_transition_time(c.v0, c.v1, a);
    if (tau <= 0) continue;
    EXPECT_NEAR(paul_transition_peak_acceleration(-c.v0 * tau, c.v1 * c.T, tau, c.T), a, 1e-9);
    EXPECT_GT(paul_transition_peak_acceleration(-c.v0 * 0.9 * tau, c.v1 * c.T, 0.9 * tau, c.T), a);
  }
}

TEST(PaulTransition, WithoutAChangeOfVelocityItIsTheStraightLine) {
  const double B = 0.7, v = 0.4, tau = 0.1, T = 1.0;
  for (double t = -tau; t <= tau; t += tau / 10) {
    const auto p = paul_transition(B, -v * tau, v * T, tau, T, t);
    EXPECT_NEAR(p.q, B + v * t, 1e-14);
    EXPECT_NEAR(p.qd, v, 1e-14);
    EXPECT_NEAR(p.qdd, 0.0, 1e-14);
  }
}
