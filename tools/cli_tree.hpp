// The rccx command tree as a whole, once every subcommand has added itself: the rules every
// command shares without each saying it (docs/RELIABILITY.md, "Options"):
//
//   - a verb takes its parent's options too (`rccx db list --db x.db` = `rccx db --db x.db
//     list`), and a verb's option may come before the verb (`rccx db --robot puma560 list`);
//   - an option's value is never "" (an unset variable, not a choice);
//   - an unknown command or option is named with the nearest known one, and the help to read
//     is that of the command it was given to;
//   - bash completion is written from the same tree (`rccx completion bash`).
//
//   auto app = make_app(exit_code);               // every subcommand, the rules applied
//   if (const Words w = check_words(*app, args); !w.error.empty()) ...   // exit 2
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace rccx::tools {

/// The whole rccx command: every subcommand added, a verb's parent's options accepted after
/// the verb, and `completion`. Commands set `exit_code` when they run.
std::unique_ptr<CLI::App> make_app(int& exit_code);

/// What the words of a command line say before CLI11 reads them.
struct Words {
  const CLI::App* deepest = nullptr;  ///< the (sub)command the words reach
  std::string error;                  ///< empty, or what is wrong and which --help to read
  std::vector<std::string> args;      ///< the words to parse, verbs' options after their verb
};

/// Checks `args` (without the program name) against the tree: unknown commands and options,
/// empty values; moves an option of a verb given before the verb to after it.
Words check_words(const CLI::App& root, const std::vector<std::string>& args);

/// "rccx db list": how a user types the command `app`.
std::string command_path(const CLI::App* app);

/// The words a completion offers for an option's value (the robot names for --robot).
void complete_with(const CLI::Option* option, std::vector<std::string> words);

/// A bash completion script for the tree: its commands, options and their known values.
std::string bash_completion(const CLI::App& root);

/// The word of `known` nearest `word` when it is near enough to be a typo of it, else "".
std::string nearest(std::string_view word, const std::vector<std::string>& known);

}  // namespace rccx::tools
