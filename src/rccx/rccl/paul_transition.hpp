// Paul's quartic transition between two straight segments (R. P. Paul, "Robot Manipulators",
// MIT Press 1981, chapter 10; the transition RCCL's trajectory generator uses): around the via
// point B, over the interval -tau <= t <= tau, each coordinate leaves the previous segment at
// A = B + dB (where that segment stood tau before reaching B) and joins the next one at
// B + dC tau / T (where it stands tau after leaving B, T being its duration), with position,
// velocity and acceleration continuous at both ends. With h = (t + tau) / (2 tau):
//
//   q(h)   = ((dC tau / T + dB)(2 - h) h^2 - 2 dB) h + B + dB
//   q'(h)  = ((dC tau / T + dB)(1.5 - h) 2 h^2 - dB) / tau
//   q''(h) = (dC tau / T + dB)(1 - h) 3 h / tau^2
//
// The acceleration is zero at both ends and largest in the middle: 0.75 (dC tau / T + dB) /
// tau^2, i.e. 1.5 times the change of velocity spread evenly over the 2 tau: the transition time
// is what bounds it. The same formulas serve joint coordinates and the parameters of Paul's
// drive transform in Cartesian mode. Pure functions: constexpr, no state, no allocation.
#pragma once

namespace rccx::rccl {

struct TransitionPoint {
  double q = 0.0;    ///< position (the coordinate's unit)
  double qd = 0.0;   ///< velocity, unit/s
  double qdd = 0.0;  ///< acceleration, unit/s^2
};

/// One coordinate of the transition at time t in [-tau, tau] (s) around the via point B.
/// dB = A - B (A: where the previous segment stood tau before B); dC = C - B (C: the next
/// segment's end, reached T seconds after B; T >= tau > 0).
constexpr TransitionPoint paul_transition(double B, double dB, double dC, double tau, double T,
                                          double t) noexcept {
  const double h = (t + tau) / (2.0 * tau);
  const double k = dC * tau / T + dB;
  return {((k * (2.0 - h) * h * h) - 2.0 * dB) * h + B + dB,
          (k * (1.5 - h) * 2.0 * h * h - dB) / tau, k * (1.0 - h) * 3.0 * h / (tau * tau)};
}

/// The largest |acceleration| of that transition, unit/s^2 (at t = 0).
constexpr double paul_transition_peak_acceleration(double dB, double dC, double tau,
                                                   double T) noexcept {
  const double k = dC * tau / T + dB;
  return 0.75 * (k < 0 ? -k : k) / (tau * tau);
}

/// The transition time that keeps a change of velocity from v0 to v1 (unit/s) within an
/// acceleration bound a (unit/s^2): the smallest tau with peak acceleration <= a.
constexpr double paul_transition_time(double v0, double v1, double a) noexcept {
  const double dv = v1 > v0 ? v1 - v0 : v0 - v1;
  // dB = -v0 tau and dC tau / T = v1 tau, so the peak is 0.75 |v1 - v0| / tau.
  return 0.75 * dv / a;
}

}  // namespace rccx::rccl
