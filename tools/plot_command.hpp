// `rccx plot`: the standard plots of a recorded run (a --log CSV) as an SVG, without a browser.
#pragma once

#include "cli_common.hpp"
#include "rccx/view/run_log.hpp"

namespace rccx::tools {

void add_plot_command(CLI::App& app, int& exit_code);

/// True when the user gave --robot or --robot-file to `cmd`.
inline bool robot_given(const CLI::App& cmd) {
  return cmd.count("--robot") + cmd.count("--robot-file") > 0;
}

/// The robot a recorded run is drawn as (rccx plot, rccx view --log): the one its header names;
/// `robot` only when `given` (and then it must be the header's): view::log_robot, its refusals
/// as bad arguments (exit 2).
inline kin::RobotModel robot_of_log(const view::RunLog& log, const RobotChoice& robot, bool given) {
  std::optional<kin::RobotModel> model;
  if (given) model = robot.model();
  const std::string as = robot.file.empty() ? fmt::format("--robot {}", robot.name)
                                            : fmt::format("--robot-file {}", robot.file);
  try {
    return view::log_robot(log, model ? &*model : nullptr, as);
  } catch (const view::RunLogError& e) {
    throw BadArgument{e.what()};
  }
}

}  // namespace rccx::tools
