// `rccx certs ...`: the DDS Security files of a cell's participants (docs/NETWORK.md,
// "Security"): `init` makes the CAs and the first participants, `add` more participants later.
#pragma once

#include "cli_common.hpp"

namespace rccx::tools {

/// Adds the `certs` subcommand to `app`; `exit_code` receives the result when it runs.
void add_certs_command(CLI::App& app, int& exit_code);

}  // namespace rccx::tools
