// rccx: one command for the robot programming environment; each layer adds a subcommand.
#include <fmt/format.h>

#include <CLI/CLI.hpp>

#include "db_command.hpp"
#include "kin_command.hpp"
#include "rcu_command.hpp"
#include "rtc_commands.hpp"
#include "teach_command.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "rccx - robot programming and real-time control in the manner of RCCL/RTC (1986).\n"
      "Units are SI (m, rad, s) unless an option says otherwise."};
  app.set_version_flag("--version", "rccx 0.1.0");
  app.require_subcommand(1);
  int exit_code = rccx::tools::kOk;
  rccx::tools::add_kin_command(app, exit_code);
  rccx::tools::add_rtc_commands(app, exit_code);
  rccx::tools::add_rcu_command(app, exit_code);
  rccx::tools::add_db_command(app, exit_code);
  rccx::tools::add_teach_command(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);  // prints the message and the usage hint
    return rccx::tools::kBadArguments;
  }
  return exit_code;
}
