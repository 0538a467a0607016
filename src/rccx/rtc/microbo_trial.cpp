#include "rccx/rtc/microbo_trial.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "rccx/hw/rcu.hpp"

namespace rccx::rtc {

double RampResult::mean_error_counts() const noexcept {
  if (error_counts.empty()) return 0.0;
  return std::accumulate(error_counts.begin(), error_counts.end(), 0.0) /
         static_cast<double>(error_counts.size());
}

double RampResult::max_error_counts() const noexcept {
  return error_counts.empty() ? 0.0 : *std::max_element(error_counts.begin(), error_counts.end());
}

double RampResult::speed_ripple() const noexcept {
  if (speed.empty()) return 0.0;
  const auto [lo, hi] = std::minmax_element(speed.begin(), speed.end());
  return *hi - *lo;
}

double RampResult::amplitude_at(double hz) const noexcept {
  if (speed.size() < 3) return 0.0;
  // Normal equations of v = a cos(wt) + b sin(wt) + c.
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < speed.size(); ++i) {
    const double wt = 2.0 * std::numbers::pi * hz * speed_t[i];
    const Eigen::Vector3d basis(std::cos(wt), std::sin(wt), 1.0);
    m += basis * basis.transpose();
    r += basis * speed[i];
  }
  const Eigen::Vector3d x = m.ldlt().solve(r);
  return std::hypot(x[0], x[1]);
}

RampResult run_ramp_trial(const kin::RobotModel& model, const RampTrial& trial) {
  const kin::Joint& joint = model.joints[trial.joint];
  const double range = joint.upper - joint.lower;
  hw::SimulatedArmOptions start;
  start.initial = model.ready();
  start.initial[trial.joint] = joint.lower + 0.05 * range;
  const double seconds = std::min(trial.seconds, 0.9 * range / std::abs(trial.speed));
  hw::Rcu rcu(model, start);
  hw::RcuBus bus(rcu);
  MicroboDriverOptions options;
  options.scheme = trial.scheme;
  for (std::size_t j = 0; j < model.dof(); ++j) options.work_areas[j] = rcu.work_area(j);
  MicroboDriver driver(model, bus, rcu, options);

  RampResult result;
  result.count = model.joints[trial.joint].resolution_per_count;
  const auto period_us = std::llround(trial.period_s * 1e6);
  How how;
  driver.read(0.0, how);
  const double from = how.joint[trial.joint].q;
  const auto samples = static_cast<std::int64_t>(seconds / trial.period_s);
  for (std::int64_t k = 1; k <= samples; ++k) {
    const double t = static_cast<double>(k) * trial.period_s;
    const bool measured = t > trial.settle_s;
    const std::uint64_t before = bus.exchanges();
    driver.read(t, how);
    if (measured) {
      const double desired = from + trial.speed * t;
      result.error_counts.push_back(std::abs(desired - how.joint[trial.joint].q) / result.count);
    }
    JointCommands c{};
    // POSVEL: there at the end of the next period (rate 0: the driver takes it as one step).
    c[trial.joint] = {JointCommand::Kind::move, from + trial.speed * (t + trial.period_s), 0.0};
    driver.send(c);
    result.exchanges_per_sample = bus.exchanges() - before;
    // The rest of the period, a millisecond at a time (the bus has used some of it already).
    const std::int64_t end = (k + 1) * period_us;
    while (rcu.time_us() < end) {
      rcu.advance_us(std::min<std::int64_t>(1000, end - rcu.time_us()));
      if (measured) {
        result.speed.push_back(rcu.true_velocity()[trial.joint]);
        result.speed_t.push_back(static_cast<double>(rcu.time_us()) * 1e-6);
      }
    }
  }
  return result;
}

}  // namespace rccx::rtc
