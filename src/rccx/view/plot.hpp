// `rccx plot`: the standard plots of a recorded run as one SVG, for reports and docs, without a
// browser: the joints (commanded and measured), the tool path in the plane it moves in most,
// the speed along the path, and the path error (the measured tool from the commanded path).
//
//   const view::RunLog log = view::load_run_log("run.csv");   // a session's CSV log
//   const std::string svg = view::plot_svg(log, kin::builtin_robot("puma560"), "run.csv");
//   io::write_file_atomically("run.svg", svg);                // about 1200 x 900 px
#pragma once

#include <cstddef>
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

/// One line of a plot: y against x, in the units of its panel's axes.
struct PlotSeries {
  std::vector<double> x, y;
  std::string colour;  ///< "#rrggbb"
  std::string label;   ///< for the legend; empty: none (a commanded joint, dashed beside its
                       ///< measured one)
  bool dashed = false;
  double width = 1.4;  ///< px
};

/// One panel of `rccx plot`: its title, axis labels (with units) and lines.
struct PlotPanel {
  std::string title, xlabel, ylabel;
  std::vector<PlotSeries> series;
  bool equal_axes = false;  ///< the same scale on both axes (a path in a plane)
};

/// What `rccx plot` draws, as numbers: the figures of its subtitle and its four panels in
/// order (joints deg or mm against t s; the tool path in mm in the plane it spans most; the
/// speed along the path, mm/s; the path error, mm). plot_svg draws exactly these; the Python
/// module (rccx.plot) draws them with Matplotlib. RunLogError when the log's joints are not the
/// robot's.
struct RunPlot {
  std::string robot_title;  ///< the model's title (its name when it has none)
  std::size_t samples = 0;
  double duration_s = 0.0;          ///< from the first sample to the last
  double worst_path_error_m = 0.0;  ///< the largest of path_errors_m
  std::vector<PlotPanel> panels;    ///< joints, tool path, speed, path error
};
RunPlot run_plot(const RunLog& log, const kin::RobotModel& model);

/// The SVG document (about 1200 x 900 px). `title` heads it. RunLogError when the log's joints
/// do not match the robot's.
std::string plot_svg(const RunLog& log, const kin::RobotModel& model, const std::string& title);

}  // namespace rccx::view
