// A six-axis wrist force/torque sensor below the wire (thesis 4.4.2's "intelligent" sensor: it
// reports the load in a frame at the wrist, here T6): the true load an arm with a contact model
// reports (SimulatedArm::wrist_wrench), plus what a real sensor adds - a bias (offset drift),
// white noise, saturation at its measuring range - and a fault where the readings freeze (a
// stalled sensor board, a cut cable: the last value repeats and the reading counter stops).
//
//   hw::ForceSensor sensor(*arm, {.noise_N = 0.0});  // arm: one with contact (MujocoArm)
//   const hw::ForceReading r = sensor.read();        // N, N m about T6; r.saturated, sequence
//   sensor.set_bias({{0.5, 0, 0}, {0, 0, 0}});       // the offset drifts, N and N m
//   sensor.set_frozen(true);                         // the fault: the readings stop
//
// ServoDriver makes one for an arm that has a wrist (ServoDriver::force_sensor()). The default
// spec is a small strain-gauge sensor of the ATI Mini45 class (SI-290-10: 290 N, 10 N m).
// Read by the communication task every sample: noexcept and allocation-free after
// construction.
#pragma once

#include <cstdint>
#include <random>

#include "rccx/hw/simulated_arm.hpp"
#include "rccx/math/wrench.hpp"

namespace rccx::hw {

struct ForceSensorSpec {
  double range_N = 290.0;    ///< measuring range of each force axis, +-N
  double range_N_m = 10.0;   ///< ... of each torque axis, +-N m
  double noise_N = 0.06;     ///< standard deviation of each force axis's noise, N
  double noise_N_m = 0.002;  ///< ... of each torque axis's, N m
  math::Wrench bias;         ///< added to every reading (N, N m)
  std::uint64_t seed = 1;    ///< of the noise: the same seed gives the same readings
};

struct ForceReading {
  math::Wrench wrench;         ///< about T6's origin in T6's axes, N and N m
  std::uint32_t sequence = 0;  ///< advances with every new reading
  bool saturated = false;      ///< an axis stood at its range (the value is clipped there)
};

class ForceSensor {
 public:
  /// The sensor on `arm`'s wrist; `arm` must outlive it. Throws std::invalid_argument when the
  /// arm has no wrist sensor (its plant has no contact model) or the spec is not usable.
  ForceSensor(const SimulatedArm& arm, const ForceSensorSpec& spec = {});

  /// One reading of the load on the wrist now (the arm's present state).
  ForceReading read() noexcept;

  /// The frozen-reading fault: from now on read() repeats the last reading and its counter.
  void set_frozen(bool frozen) noexcept { frozen_ = frozen; }
  [[nodiscard]] bool frozen() const noexcept { return frozen_; }
  /// A new bias (the offset drifts with temperature on real sensors), N and N m.
  void set_bias(const math::Wrench& bias) noexcept { spec_.bias = bias; }
  [[nodiscard]] const ForceSensorSpec& spec() const noexcept { return spec_; }

 private:
  const SimulatedArm& arm_;
  ForceSensorSpec spec_;
  std::mt19937_64 random_;
  std::normal_distribution<double> unit_noise_{0.0, 1.0};
  ForceReading last_;
  bool frozen_ = false;
};

}  // namespace rccx::hw
