// `rccx serve`: a process that owns some robots of a cell and serves them over Cyclone DDS to
// programs in other processes (docs/NETWORK.md).
#pragma once

#include "cli_common.hpp"

namespace rccx::tools {

void add_serve_command(CLI::App& app, int& exit_code);

}  // namespace rccx::tools
