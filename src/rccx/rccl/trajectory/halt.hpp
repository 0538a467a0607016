// The halt: the arm stopped smoothly from wherever it is, every joint at its acceleration bound
// (one stopping time for all, so that the joint-space path stays straight; a joint that would
// pass its limit stops harder, at it). What a failure, a halt(), a nextmove or a cell's stop
// request lead to: the generator's halting phase.
//
//   Halt h;
//   h.start(model, last_q, prev_q, last_t);   // the velocity from the last two setpoints
//   while (h.value(t, q)) { /* q: the setpoint at t */ }
#pragma once

#include <algorithm>
#include <cmath>

#include "rccx/rccl/trajectory/model.hpp"

namespace rccx::rccl::trajectory {

struct Halt {
  double t0 = 0.0;                ///< when it began (the last setpoint's time), s
  JointVector q0, v0, stop_time;  ///< where, how fast (per s) and how long each joint stops

  /// Begins at the last setpoint last_q (for last_t, s), prev_q the one a period before.
  void start(const GeneratorModel& m, const JointVector& last_q, const JointVector& prev_q,
             double last_t) noexcept {
    const double P = m.options.period_s;
    t0 = last_t;
    q0 = last_q;
    v0 = last_q;
    stop_time = last_q;
    double Ts = 0.0;  // one time for all joints keeps the joint-space path straight
    for (std::size_t j = 0; j < last_q.size(); ++j) {
      v0[j] = (last_q[j] - prev_q[j]) / P;
      Ts = std::max(Ts, std::abs(v0[j]) / m.options.max_acceleration[j]);
    }
    for (std::size_t j = 0; j < last_q.size(); ++j) {
      const double v = v0[j];
      double stop = Ts;
      // Stopping distance v Ts / 2; a joint that would pass its limit stops harder, at it.
      const double room = v > 0 ? m.upper[j] - last_q[j] : last_q[j] - m.lower[j];
      if (std::abs(v) * Ts / 2.0 > room) stop = 2.0 * std::max(room, 0.0) / std::abs(v);
      stop_time[j] = stop;
    }
  }

  /// The setpoint at t (s) into q; false once every joint has stopped (q: where).
  bool value(double t, JointVector& q) const noexcept {
    q = q0;
    bool moving = false;
    for (std::size_t j = 0; j < q.size(); ++j) {
      const double Ts = stop_time[j];
      if (!(Ts > 0.0)) continue;
      const double dt = std::min(t - t0, Ts);
      q[j] += v0[j] * (dt - dt * dt / (2.0 * Ts));
      moving = moving || t - t0 < Ts;
    }
    return moving;
  }
};

}  // namespace rccx::rccl::trajectory
