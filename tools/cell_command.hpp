// `rccx cell`: workcell files (cells/*.json): what a cell holds and where its robots' reaches
// meet.
#pragma once

#include "cli_common.hpp"

namespace rccx::tools {

void add_cell_command(CLI::App& app, int& exit_code);

}  // namespace rccx::tools
