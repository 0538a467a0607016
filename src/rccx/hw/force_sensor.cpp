#include "rccx/hw/force_sensor.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rccx::hw {

ForceSensor::ForceSensor(const SimulatedArm& arm, const ForceSensorSpec& spec)
    : arm_(arm), spec_(spec), random_(spec.seed) {
  math::Wrench probe;
  if (!arm.wrist_wrench(probe)) {
    throw std::invalid_argument("the simulated " + arm.model().name +
                                " has no wrist force sensor: choose the MuJoCo plant "
                                "(\"plant\": \"mujoco\" in its robot file)");
  }
  const bool usable = spec.range_N > 0.0 && spec.range_N_m > 0.0 && spec.noise_N >= 0.0 &&
                      spec.noise_N_m >= 0.0 && std::isfinite(spec.range_N) &&
                      std::isfinite(spec.range_N_m) && std::isfinite(spec.noise_N) &&
                      std::isfinite(spec.noise_N_m);
  if (!usable) {
    throw std::invalid_argument(
        "force sensor: its ranges must be > 0 and its noise >= 0 (N, N m), all finite");
  }
}

ForceReading ForceSensor::read() noexcept {
  if (frozen_) return last_;
  math::Wrench load;
  (void)arm_.wrist_wrench(load);
  std::array<double, 6> w = (load + spec_.bias).to_array();
  bool saturated = false;
  for (std::size_t i = 0; i < 6; ++i) {
    const double range = i < 3 ? spec_.range_N : spec_.range_N_m;
    const double noise = i < 3 ? spec_.noise_N : spec_.noise_N_m;
    w[i] += noise * unit_noise_(random_);
    if (!(std::abs(w[i]) < range)) {  // a NaN saturates too
      saturated = true;
      w[i] = std::isnan(w[i]) ? range : std::clamp(w[i], -range, range);
    }
  }
  last_.wrench = math::Wrench::from_array(w);
  last_.saturated = saturated;
  ++last_.sequence;
  return last_;
}

}  // namespace rccx::hw
