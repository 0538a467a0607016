// The sample loop's last defence: a setpoint is never out of a joint's limits, never faster
// than its top speed, never a jump of velocity (a path through a singularity, an IK solution
// changing branch, a goal that leapt) - the loop stops the arm instead, with a message that
// names the cause. Planned motions stay well inside these bounds; the guard is what catches the
// unplanned. Then every setpoint is clamped to the limits.
//
//   GuardTrip trip;
//   if (guard_trips(model, q, last_q, prev_q, trip)) {
//     const Failure f = describe(trip, model, goals, present_segment, t);  // then fail, halt
//   }
//   clamp_to_limits(model, q);
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "rccx/rccl/trajectory/failure.hpp"
#include "rccx/rccl/trajectory/model.hpp"
#include "rccx/rccl/trajectory/segment.hpp"

namespace rccx::rccl::trajectory {

/// The sample loop stops the arm rather than command a joint acceleration above this multiple
/// of its bound: planned motions stay within the bound; only a singularity or a jump passes it.
inline constexpr double kAccelerationGuard = 2.0;

/// The joint that tripped the guard and how.
struct GuardTrip {
  std::size_t joint = 0;  ///< 0-based
  double speed = 0.0;     ///< rad/s or m/s
  double accel = 0.0;     ///< rad/s^2 or m/s^2
  bool out = false;       ///< out of its limits
  bool fast = false;      ///< above its top speed (else: accelerating past the guard)
};

/// Whether setpoint q (after last_q and prev_q, a period apart) trips the guard; `trip`: the
/// first joint that does.
inline bool guard_trips(const GeneratorModel& m, const JointVector& q, const JointVector& last_q,
                        const JointVector& prev_q, GuardTrip& trip) noexcept {
  const double P = m.options.period_s;
  for (std::size_t j = 0; j < q.size(); ++j) {
    const double speed = std::abs(q[j] - last_q[j]) / P;
    const double accel = std::abs((q[j] - last_q[j]) - (last_q[j] - prev_q[j])) / (P * P);
    const bool out =
        !(q[j] >= m.lower[j] - kin::kLimitTolerance && q[j] <= m.upper[j] + kin::kLimitTolerance);
    const bool fast = !(speed <= m.options.max_velocity[j] * (1.0 + 1e-6));
    const bool jerky = !(accel <= kAccelerationGuard * m.options.max_acceleration[j]);
    if (out || fast || jerky) {
      trip = GuardTrip{j, speed, accel, out, fast};
      return true;
    }
  }
  return false;
}

/// Why the guard stopped the arm at time t (s) on segment `present`: its goal jumped (as
/// `goals` saw it), else the joint's limit, speed or acceleration.
[[nodiscard]] Failure describe(const GuardTrip& trip, const GeneratorModel& m,
                               const GoalTrack& goals, const Segment& present, double t) noexcept;

/// Every joint of q within its limits.
inline void clamp_to_limits(const GeneratorModel& m, JointVector& q) noexcept {
  for (std::size_t j = 0; j < q.size(); ++j) q[j] = std::clamp(q[j], m.lower[j], m.upper[j]);
}

}  // namespace rccx::rccl::trajectory
