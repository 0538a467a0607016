// A wrist sensor's reading turned into what contacts put on the tool (thesis 4.4.2:
// "compensation would have to be made, of course, for gravity loading due to changes in the
// configuration of the wrist"), the calibration of that compensation from readings at a few
// wrist orientations, and the force transform from the sensor (T6) to the tool.
//
//   std::vector<force::LoadSample> rest;           // 3+ wrist orientations, nothing touching
//   rest.push_back({world_from_t6.R, how.force.wrench});   // N, N m, in T6
//   const force::ToolLoad load = force::estimate_tool_load(rest);   // bias, kg, com in m
//   const math::Wrench contact = force::external_wrench(load, world_from_t6.R, how.force.wrench);
//   const math::Wrench at_tip = force::at_tool(t6_from_tool, contact);   // about the tool frame
//
// Signs: a sensor reading is the wrench the tool side exerts on the arm, about T6's origin in
// T6's axes (rtc::ForceHow). A hanging tool of mass m reads its weight, force = R^T (0, 0, -m g)
// with R = world_from_sensor, and a contact that pushes the tool with F reads +F: the reading is
// bias + weight + contacts, and external_wrench() gives back the contacts.
//
// external_wrench and at_tool are noexcept and allocate nothing (the sample loop may call
// them); estimate_tool_load is set-up work (Eigen, heap) and throws on data that cannot
// determine the load.
#pragma once

#include <cstddef>
#include <span>

#include "rccx/math/transform.hpp"
#include "rccx/math/wrench.hpp"

namespace rccx::force {

/// Standard gravity, m/s^2, along world -z (as hw::kGravity_m_per_s2).
inline constexpr double kGravity_m_per_s2 = 9.81;

/// What a wrist sensor reads with nothing touching the tool: its bias and the tool's weight.
struct ToolLoad {
  math::Wrench bias;   ///< the sensor's offset, N and N m, in the sensor (T6) frame
  double mass_kg = 0;  ///< the tool's mass (everything outboard of the sensor), kg
  /// The tool's centre of mass in the sensor (T6) frame, m. Only mass_kg x com_m is well
  /// determined for a light tool; com_m is 0 when mass_kg is 0.
  math::Vec3 com_m;
};

/// Gravity compensation: the wrench contacts put on the tool, about T6's origin in T6's axes
/// (N, N m), from a sensor `reading` taken with the sensor at `world_from_sensor` (its
/// orientation in a world whose gravity points along -z): reading - bias - the tool's weight.
[[nodiscard]] math::Wrench external_wrench(const ToolLoad& load,
                                           const math::Rot3& world_from_sensor,
                                           const math::Wrench& reading) noexcept;

/// One calibration reading: the sensor's orientation in the world and what it read (averaged
/// over a few dozen samples at rest, nothing touching the tool).
struct LoadSample {
  math::Rot3 world_from_sensor;
  math::Wrench reading;  ///< N, N m, sensor frame
};

/// How well a ToolLoad fits its samples.
struct LoadFit {
  std::size_t samples = 0;
  double rms_force_N = 0.0;     ///< RMS of the force residuals, over every axis of every sample
  double rms_torque_N_m = 0.0;  ///< ... of the torque residuals
  /// Smallest over largest singular value of the (scaled) least-squares matrix, in (0, 1]:
  /// near 0 when the orientations hardly differ (the estimate then follows the noise).
  double conditioning = 0.0;
};

/// The estimate is refused when LoadFit::conditioning would fall below this.
inline constexpr double kMinLoadConditioning = 1e-3;

/// The bias, mass and centre of mass that explain `samples` best (linear least squares over
/// force = b_f + m g_s, torque = b_t + (m c) x g_s, g_s = R^T (0, 0, -g): ten unknowns, six
/// equations a sample). Gravity must point in at least three different directions in the sensor
/// frame: throws std::invalid_argument, saying to take readings at three or more orientations
/// that differ about two axes, for fewer than three samples or samples that do not determine
/// the load (conditioning below kMinLoadConditioning), and for non-finite samples. `fit`, when
/// given, receives the residuals.
[[nodiscard]] ToolLoad estimate_tool_load(std::span<const LoadSample> samples,
                                          LoadFit* fit = nullptr);

/// The force transform to the tool (thesis 4.4.2's F_{4,6} in general form): `at_t6`, a wrench
/// about T6's origin in T6's axes, expressed about the tool frame's origin in the tool's axes,
/// where `t6_from_tool` is the tool frame in T6 (RCCL's TOOL transform).
[[nodiscard]] math::Wrench at_tool(const math::Transform& t6_from_tool,
                                   const math::Wrench& at_t6) noexcept;

}  // namespace rccx::force
