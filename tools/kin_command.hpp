// `rccx kin ...`: forward and inverse kinematics of the shipped robots from the command line.
#pragma once

#include "cli_common.hpp"

namespace rccx::tools {

/// Adds the `kin` subcommand to `app`; `exit_code` receives the result when it runs.
void add_kin_command(CLI::App& app, int& exit_code);

}  // namespace rccx::tools
