// Joint speeds from encoder positions: the difference over at least a window of time, so that
// one count of quantisation is a small speed even at a 0.25 ms period. Fixed size, no
// allocation: the communication task updates it every sample.
//
//   rtc::VelocityEstimator velocity;                 // a driver's, one for all joints
//   const kin::JointVector v = velocity.update(t_s, q);   // q rad / m read at t_s -> rad/s, m/s
//   velocity.restart(i, q[i]);                       // joint i's counts jumped (calibration)
#pragma once

#include <array>
#include <cstddef>

#include "rccx/kinematics/joint_vector.hpp"

namespace rccx::rtc {

class VelocityEstimator {
 public:
  static constexpr double kWindow_s = 0.010;
  static constexpr std::size_t kHistory = 64;  ///< 40 samples cover the window at 0.25 ms

  /// Adds the positions read at t_s (rad or m) and returns the speeds (rad/s or m/s).
  kin::JointVector update(double t_s, const kin::JointVector& q) noexcept;
  /// Forgets joint i's history (its counts jumped without motion, e.g. at calibration).
  void restart(std::size_t i, double q) noexcept;

 private:
  struct Sample {
    double t_s = 0.0;
    kin::JointVector q;
  };
  std::array<Sample, kHistory> history_{};
  std::size_t count_ = 0;
};

}  // namespace rccx::rtc
