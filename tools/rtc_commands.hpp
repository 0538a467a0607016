// The RTC control programs of thesis 4.5.4.6 on a simulated robot: `rccx calib`, `limp`,
// `marsh`, `report`, `jointtest`, and `rccx codes` (what each terminate code means).
#pragma once

#include "cli_common.hpp"

namespace rccx::tools {

/// Adds the subcommands to `app`; `exit_code` receives the result of the one that runs.
void add_rtc_commands(CLI::App& app, int& exit_code);

}  // namespace rccx::tools
