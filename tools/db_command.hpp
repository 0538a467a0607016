// `rccx db`: the position database from the command line (list, show, put, rm, export, import).
#pragma once

#include "cli_common.hpp"

namespace rccx::tools {

void add_db_command(CLI::App& app, int& exit_code);

}  // namespace rccx::tools
