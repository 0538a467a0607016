// `rccx kin ...`: forward and inverse kinematics of the shipped robots from the command line.
#pragma once

#include <CLI/CLI.hpp>

namespace rccx::tools {

/// Exit codes shared by the rccx subcommands.
enum ExitCode : int { kOk = 0, kFailure = 1, kBadArguments = 2, kUnreachable = 3 };

/// Adds the `kin` subcommand to `app`; `exit_code` receives the result when it runs.
void add_kin_command(CLI::App& app, int& exit_code);

}  // namespace rccx::tools
