// A measurement on the emulated Microbo: one joint driven along a ramp through the driver, as
// the communication task would drive it, with the joint's true speed sampled every millisecond
// of emulated time. It shows what the thesis showed (4.4.3): raw targets make the vendor's
// joint law decelerate at every target, the follow scheme tracks smoothly. Used by the tests,
// example 03 and docs/MICROBO.md.
//
//   const rtc::RampTrial trial{.scheme = rtc::TargetScheme::raw, .speed = 0.1};  // d3, 100 mm/s
//   const rtc::RampResult r = rtc::run_ramp_trial(kin::builtin_robot("microbo"), trial);
//   r.max_error_counts();                            // |Xd - Xm|, encoder counts
//   r.amplitude_at(1.0 / trial.period_s);            // m/s of ripple at the sample frequency
#pragma once

#include <cstddef>
#include <vector>

#include "rccx/rtc/microbo_driver.hpp"

namespace rccx::rtc {

struct RampTrial {
  TargetScheme scheme = TargetScheme::follow;
  std::size_t joint = 2;  ///< 0-based; joint 3 (d3) by default
  double speed = 0.050;   ///< rad/s or m/s; positive: up from near the lower limit
  double period_s = 0.028;
  double seconds = 2.5;   ///< cut short where the ramp would leave the joint's range
  double settle_s = 0.5;  ///< what comes before is not measured
};

struct RampResult {
  std::vector<double> error_counts;  ///< |Xd - Xm| at each sample instant, counts
  std::vector<double> speed;         ///< true joint speed, rad/s or m/s ...
  std::vector<double> speed_t;       ///< ... at these times, s: every 1 ms outside bus traffic
  double count = 0.0;                ///< the joint's encoder resolution, rad or m
  std::size_t exchanges_per_sample = 0;

  [[nodiscard]] double mean_error_counts() const noexcept;
  [[nodiscard]] double max_error_counts() const noexcept;
  /// Peak-to-peak of the speed.
  [[nodiscard]] double speed_ripple() const noexcept;
  /// Amplitude of the speed's component at `hz`, rad/s or m/s: a least-squares fit of a
  /// sinusoid and a constant to the samples, which leave gaps where the bus was busy.
  [[nodiscard]] double amplitude_at(double hz) const noexcept;
};

/// Runs the trial on a fresh emulated RCU of `model`, calibrated, in the ready pose but for the
/// ramp's joint, which starts 5 % of its range above its lower limit.
RampResult run_ramp_trial(const kin::RobotModel& model, const RampTrial& trial);

}  // namespace rccx::rtc
