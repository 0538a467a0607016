// `rccx teach`: the teach loop on a simulated robot, saving positions to the database.
#pragma once

#include "cli_common.hpp"

namespace rccx::tools {

void add_teach_command(CLI::App& app, int& exit_code);

}  // namespace rccx::tools
