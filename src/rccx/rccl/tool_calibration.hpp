// The tool-load calibration of a wrist force sensor (thesis 4.4.2's gravity compensation, from
// the arm itself): turn the wrist to a handful of orientations about the present pose, let the
// arm come to rest at each, average the sensor's readings, and fit the sensor's bias and the
// tool's mass and centre of mass (force::estimate_tool_load). Nothing may touch the tool
// meanwhile. The result feeds force::external_wrench.
//
//   rccl::Manipulator arm(session);
//   arm.start();
//   force::LoadFit fit;
//   const force::ToolLoad tool = rccl::calibrate_tool_load(arm, {}, &fit);
//
// Planning level only (it moves the arm and waits); uses only the Manipulator's and the
// session's public calls.
#pragma once

#include <chrono>
#include <stdexcept>
#include <vector>

#include "rccx/force/tool_load.hpp"
#include "rccx/rccl/manipulator.hpp"

namespace rccx::rccl {

/// The calibration could not be done: no sensor, a motion failed, the arm did not come to rest,
/// the sensor saturated or froze. Says what to do.
class ToolCalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ToolCalibrationOptions {
  /// How far the last three joints turn from the present pose, rad (each pose turns one, two or
  /// all three of them by this much, either way; a turn that would leave a joint's limits goes
  /// the other way, or as far as the limit allows).
  double wrist_turn_rad = 0.7;
  /// Readings averaged at each orientation (distinct readings of the sensor).
  int readings_per_pose = 40;
  /// The arm counts as at rest once every joint's measured speed is below this, rad/s or m/s...
  double rest_speed = 1e-3;
  /// ... and it has stayed still this long after that.
  std::chrono::nanoseconds settle{std::chrono::milliseconds(300)};
  /// The longest wait for a motion, for rest, or for the readings of one pose.
  std::chrono::nanoseconds timeout{std::chrono::seconds(30)};
  /// The robot base's orientation in the world (gravity along world -z).
  math::Rot3 world_from_base = math::Rot3::identity();
  /// Move back to the joints the arm started from when done.
  bool return_to_start = true;
};

/// The readings the calibration took, one a pose (for a report, or to refit).
struct ToolCalibrationReadings {
  std::vector<kin::JointVector> joints;    ///< where each was taken (measured), rad or m
  std::vector<force::LoadSample> samples;  ///< orientation and averaged reading
};

/// Calibrates the tool load of `arm`'s wrist sensor (see the file comment). The manipulator
/// must be started (start()) and at rest with nothing queued. At least 6 orientations, about
/// two or more axes. Throws ToolCalibrationError when the robot has no wrist sensor
/// (How::force.present is false), has fewer than 3 joints, a motion fails or the arm does not
/// settle, or the sensor saturates or freezes; MotionError from the moves (e.g. not started);
/// std::invalid_argument from the estimator when the orientations reached do not determine the
/// load. `fit` receives the residuals, `readings` what was measured.
force::ToolLoad calibrate_tool_load(Manipulator& arm, const ToolCalibrationOptions& options = {},
                                    force::LoadFit* fit = nullptr,
                                    ToolCalibrationReadings* readings = nullptr);

}  // namespace rccx::rccl
