// rccx: one command for the robot programming environment; each layer adds a subcommand.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <exception>
#include <system_error>

#include "cell_command.hpp"
#include "cli_common.hpp"
#include "db_command.hpp"
#include "kin_command.hpp"
#include "plot_command.hpp"
#include "rccx/io/console.hpp"
#include "rccx/io/signals.hpp"
#include "rcu_command.hpp"
#include "rtc_commands.hpp"
#include "teach_command.hpp"
#include "view_command.hpp"

namespace {

int run(int argc, char** argv) {
  CLI::App app{
      "rccx - robot programming and real-time control in the manner of RCCL/RTC (1986).\n"
      "Units are SI (m, rad, s) unless an option says otherwise. Exit codes: 0 done, 1 failed "
      "while running, 2 bad input, 3 pose out of reach, 130 / 143 / 129 ended by SIGINT / "
      "SIGTERM / SIGHUP.",
      "rccx"};
  app.set_version_flag("--version", "rccx 0.1.0");
  app.require_subcommand(1);
  // One wording for every bad argument, CLI11's own included (docs/RELIABILITY.md).
  app.failure_message([](const CLI::App* from, const CLI::Error& e) {
    std::string path;
    for (const CLI::App* a = from; a != nullptr; a = a->get_parent()) {
      path = a->get_name() + (path.empty() ? "" : " ") + path;
    }
    return fmt::format("error: {}\nRun `{} --help` for the options.\n", e.what(), path);
  });
  int exit_code = rccx::tools::kOk;
  rccx::tools::add_kin_command(app, exit_code);
  rccx::tools::add_rtc_commands(app, exit_code);
  rccx::tools::add_rcu_command(app, exit_code);
  rccx::tools::add_db_command(app, exit_code);
  rccx::tools::add_teach_command(app, exit_code);
  rccx::tools::add_cell_command(app, exit_code);
  rccx::tools::add_view_command(app, exit_code);
  rccx::tools::add_plot_command(app, exit_code);
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

}  // namespace

int main(int argc, char** argv) {
  using namespace rccx;
  // SIGINT and SIGTERM only ask to stop: control ends cleanly, logs close on a row boundary,
  // files being replaced stay as they were (docs/RELIABILITY.md).
  io::install_stop_handlers();
  int code = tools::kFailure;
  try {
    code = run(argc, argv);
  } catch (const std::system_error& e) {  // fmt: standard output could not be written
    if (io::stop_count() == 0)
      io::eprint("rccx: cannot write the output: {}\n", e.code().message());
    code = tools::kFailure;
  } catch (const std::exception& e) {
    io::eprint("rccx: internal error: {} (please report it)\n", e.what());
    code = tools::kFailure;
  }
  // What went to standard output but failed at the last flush (a full disk, a closed pipe).
  if (std::string why; !io::flush_stdout(why)) {
    io::eprint("rccx: cannot write the output: {}\n", why);
    if (code == tools::kOk) code = tools::kFailure;
  }
  if (io::stop_count() > 0 && code != tools::kBadArguments) {
    code = io::stop_exit_code();
    io::eprint("rccx: stopped by {}\n",
               code == 143 ? "SIGTERM" : (code == 129 ? "SIGHUP" : "SIGINT"));
  }
  return code;
}
