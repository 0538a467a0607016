// `rccx plot`: the standard plots of a recorded run (a --log CSV) as an SVG, without a browser.
#pragma once

#include "cli_common.hpp"

namespace rccx::tools {

void add_plot_command(CLI::App& app, int& exit_code);

}  // namespace rccx::tools
