// `rccx plot`: the standard plots of a recorded run as one SVG, for reports and docs, without a
// browser: the joints (commanded and measured), the tool path in the plane it moves in most,
// the speed along the path, and the path error (the measured tool from the commanded path).
//
//   const view::RunLog log = view::load_run_log("run.csv");   // a session's CSV log
//   const std::string svg = view::plot_svg(log, kin::builtin_robot("puma560"), "run.csv");
//   io::write_file_atomically("run.svg", svg);                // about 1200 x 900 px
#pragma once

#include <string>
#include <vector>

#include "rccx/kinematics/robot_model.hpp"
#include "rccx/view/run_log.hpp"

namespace rccx::view {

/// The path error of a run at each of its samples, m: how far the measured tool point is from
/// the commanded path (the nearest point of the commanded tool's polyline from 600 samples
/// before to 50 after: a lag along the path is not an error of the path). Every sample counts,
/// corner blends and joint motions too: the largest is what `rccx plot` calls the "worst path
/// error". RunLogError when the log's joints are not the robot's.
std::vector<double> path_errors_m(const RunLog& log, const kin::RobotModel& model);

/// The SVG document (about 1200 x 900 px). `title` heads it. RunLogError when the log's joints
/// do not match the robot's.
std::string plot_svg(const RunLog& log, const kin::RobotModel& model, const std::string& title);

}  // namespace rccx::view
