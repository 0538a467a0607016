// `rccx rcu`: a register console to the emulated Microbo RCU, scriptable line by line.
#pragma once

#include "cli_common.hpp"

namespace rccx::tools {

void add_rcu_command(CLI::App& app, int& exit_code);

}  // namespace rccx::tools
