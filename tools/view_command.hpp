// `rccx view`: a read-only web page of simulated robots at work, live, or of a recorded run.
#pragma once

#include "cli_common.hpp"

namespace rccx::tools {

void add_view_command(CLI::App& app, int& exit_code);

}  // namespace rccx::tools
