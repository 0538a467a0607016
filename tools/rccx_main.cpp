// rccx: one command for the robot programming environment; each layer adds a subcommand.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <exception>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "cli_common.hpp"
#include "cli_tree.hpp"
#include "rccx/io/console.hpp"
#include "rccx/io/signals.hpp"

namespace {

int run(int argc, char** argv) {
  int exit_code = rccx::tools::kOk;
  const std::unique_ptr<CLI::App> app = rccx::tools::make_app(exit_code);
  // The words first: an unknown one is named with the nearest known one, and a verb's option
  // given before the verb moves after it (cli_tree.hpp).
  const rccx::tools::Words words = rccx::tools::check_words(*app, {argv + 1, argv + argc});
  if (!words.error.empty()) {
    rccx::io::eprint("error: {}\n", words.error);
    return rccx::tools::kBadArguments;
  }
  std::vector<std::string> reversed(words.args.rbegin(), words.args.rend());  // CLI11's order
  try {
    app->parse(reversed);
  } catch (const CLI::CallForHelp& e) {
    return app->exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app->exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app->exit(e);
  } catch (const CLI::ParseError& e) {
    // One wording for every bad argument, CLI11's own included (docs/RELIABILITY.md); the help
    // to read is that of the command the words reached.
    rccx::io::eprint("error: {}\nRun `{} --help` for the options.\n", e.what(),
                     rccx::tools::command_path(words.deepest));
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
