#include "cli_tree.hpp"

#include <fmt/format.h>

#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>

#include "cell_command.hpp"
#include "certs_command.hpp"
#include "cli_common.hpp"
#include "db_command.hpp"
#include "kin_command.hpp"
#include "plot_command.hpp"
#include "rccx/io/spelling.hpp"
#include "rcu_command.hpp"
#include "rtc_commands.hpp"
#include "serve_command.hpp"
#include "teach_command.hpp"
#include "view_command.hpp"

namespace rccx::tools {

namespace {

std::vector<const CLI::App*> subcommands(const CLI::App* app) {
  // Option groups are unnamed subcommands in CLI11: not words a user types.
  return app->get_subcommands([](const CLI::App* s) { return !s->get_name().empty(); });
}

const CLI::App* subcommand(const CLI::App* app, const std::string& word) {
  for (const CLI::App* s : subcommands(app)) {
    if (s->get_name() == word) return s;
  }
  return nullptr;
}

std::vector<std::string> subcommand_names(const CLI::App* app) {
  std::vector<std::string> names;
  for (const CLI::App* s : subcommands(app)) names.push_back(s->get_name());
  return names;
}

bool has_positionals(const CLI::App* app) {
  return !app->get_options([](const CLI::Option* o) { return !o->nonpositional(); }).empty();
}

/// The apps whose options `app` takes: itself, and its parents while it falls through.
std::vector<const CLI::App*> option_scope(const CLI::App* app) {
  std::vector<const CLI::App*> scope{app};
  while (scope.back()->get_fallthrough() && scope.back()->get_parent() != nullptr) {
    scope.push_back(scope.back()->get_parent());
  }
  return scope;
}

const CLI::Option* find_option(const CLI::App* app, const std::string& name) {
  for (const CLI::App* a : option_scope(app)) {
    if (const CLI::Option* o = a->get_option_no_throw(name)) return o;
  }
  return nullptr;
}

/// Every name an option of `app` can be written with ("--seconds", "-o").
std::vector<std::string> option_names(const CLI::App* app) {
  std::vector<std::string> names;
  for (const CLI::App* a : option_scope(app)) {
    for (const CLI::Option* o : a->get_options()) {
      for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
      for (const std::string& s : o->get_snames()) names.push_back("-" + s);
    }
  }
  return names;
}

bool takes_value(const CLI::Option* o) {
  return o->get_items_expected_max() > 0;
}

/// "-x", "--x": an option, where "-0.5" and "-" are not.
bool option_word(const std::string& w) {
  if (w.size() < 2 || w[0] != '-') return false;
  return !(std::isdigit(static_cast<unsigned char>(w[1])) || w[1] == '.');
}

std::string joined(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

std::string unknown_command(const CLI::App* app, const std::string& word) {
  const std::vector<std::string> names = subcommand_names(app);
  const std::string near = nearest(word, names);
  const std::string path = command_path(app);
  return fmt::format("unknown command '{}'; {}\nRun `{} --help` for the commands.", word,
                     near.empty() ? fmt::format("the commands of `{}` are {}", path, joined(names))
                                  : fmt::format("did you mean '{}'?", near),
                     path);
}

std::string unknown_option(const CLI::App* app, const std::string& word) {
  const std::string near = nearest(word, option_names(app));
  const std::string path = command_path(app);
  return fmt::format("unknown option '{}' for `{}`{}\nRun `{} --help` for its options.", word, path,
                     near.empty() ? "" : fmt::format("; did you mean '{}'?", near), path);
}

/// The first later word naming a verb of `app`: an option before it may be that verb's.
const CLI::App* coming_verb(const CLI::App* app, const std::vector<std::string>& args,
                            std::size_t from) {
  for (std::size_t i = from; i < args.size() && args[i] != "--"; ++i) {
    if (const CLI::App* s = subcommand(app, args[i])) return s;
  }
  return nullptr;
}

std::string empty_value(const CLI::Option* o, const CLI::App* app) {
  return fmt::format("{}: \"\" is empty; give a value (see `{} --help`)", o->get_name(),
                     command_path(app));
}

/// Reads an option word at args[i] and its values into `out`; advances i past them. Returns an
/// error, or "".
std::string take_option(const CLI::Option* o, const CLI::App* app,
                        const std::vector<std::string>& args, std::size_t& i,
                        std::vector<std::string>& out) {
  const std::string& word = args[i];
  out.push_back(word);
  if (!takes_value(o)) return "";
  const std::size_t eq = word.find('=');
  const bool attached_short = word[1] != '-' && word.size() > 2;
  if (eq != std::string::npos || attached_short) {
    const bool empty = attached_short ? false : eq + 1 == word.size();
    return empty ? empty_value(o, app) : "";
  }
  // Its values: one, or as many as follow for a repeatable option (CLI11 reads them so).
  for (std::size_t taken = 0; i + 1 < args.size(); ++taken) {
    const std::string& next = args[i + 1];
    if (taken > 0 && (!o->get_allow_extra_args() || option_word(next) || next == "--" ||
                      subcommand(app, next) != nullptr)) {
      break;
    }
    if (next.empty()) return empty_value(o, app);
    out.push_back(next);
    ++i;
  }
  return "";
}

/// The option's name as written: "--seconds" of "--seconds=2", "-o" of "-ofile".
std::string option_name(const std::string& word) {
  if (word[1] != '-') return word.substr(0, 2);
  return word.substr(0, word.find('='));
}

bool asks_for_help(const std::vector<std::string>& args) {
  return std::any_of(args.begin(), args.end(), [](const std::string& a) {
    return a == "-h" || a == "--help" || a == "--version";
  });
}

}  // namespace

std::string command_path(const CLI::App* app) {
  std::string path;
  for (const CLI::App* a = app; a != nullptr; a = a->get_parent()) {
    path = a->get_name() + (path.empty() ? "" : " ") + path;
  }
  return path;
}

Words check_words(const CLI::App& root, const std::vector<std::string>& args) {
  Words w;
  w.deepest = &root;
  std::vector<std::string> deferred;  // options of the coming verb, given before it
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& word = args[i];
    if (word == "--") {
      w.args.insert(w.args.end(), args.begin() + static_cast<std::ptrdiff_t>(i), args.end());
      break;
    }
    if (option_word(word)) {
      const std::string name = option_name(word);
      const CLI::Option* o = find_option(w.deepest, name);
      std::vector<std::string>* into = &w.args;
      const CLI::App* owner = w.deepest;
      if (o == nullptr) {
        const CLI::App* verb = coming_verb(w.deepest, args, i + 1);
        if (verb == nullptr || (o = find_option(verb, name)) == nullptr) {
          w.error = unknown_option(w.deepest, name);
          return w;
        }
        into = &deferred;
        owner = verb;
      }
      if (std::string e = take_option(o, owner, args, i, *into); !e.empty()) {
        w.error = std::move(e);
        return w;
      }
      continue;
    }
    if (const CLI::App* sub = subcommand(w.deepest, word)) {
      w.args.push_back(word);
      w.args.insert(w.args.end(), deferred.begin(), deferred.end());
      deferred.clear();
      w.deepest = sub;
      continue;
    }
    if (!subcommands(w.deepest).empty() && !has_positionals(w.deepest)) {
      w.error = unknown_command(w.deepest, word);
      return w;
    }
    w.args.push_back(word);
  }
  const std::vector<std::string> verbs = subcommand_names(w.deepest);
  if (w.deepest->get_require_subcommand_min() > 0 && !asks_for_help(args)) {
    w.error = fmt::format("`{}` needs a command: {}\nRun `{} --help` for the commands.",
                          command_path(w.deepest), joined(verbs), command_path(w.deepest));
  }
  return w;
}

std::string nearest(std::string_view word, const std::vector<std::string>& known) {
  const std::string_view bare = word.substr(std::min(word.find_first_not_of('-'), word.size()));
  // A typo of a short word is one letter; of a longer one, up to a third of its letters.
  const std::size_t allowed = bare.size() <= 2 ? 1 : std::max<std::size_t>(2, bare.size() / 3);
  std::string best;
  std::size_t best_distance = allowed + 1;
  for (const std::string& k : known) {
    std::size_t d = io::edit_distance(word, k);
    if (bare.size() >= 2 && k.starts_with(word)) d = std::min<std::size_t>(d, 1);  // "--sec"
    if (d < best_distance) {
      best = k;
      best_distance = d;
    }
  }
  return best;
}

namespace {

std::map<const CLI::Option*, std::vector<std::string>>& completions() {
  static std::map<const CLI::Option*, std::vector<std::string>> words;
  return words;
}

}  // namespace

void complete_with(const CLI::Option* option, std::vector<std::string> words) {
  completions()[option] = std::move(words);
}

namespace {

/// "rccx kin fk": the key of a command in the completion's tables.
void completion_tables(const CLI::App* app, std::string& out) {
  const std::string key = command_path(app);
  std::vector<std::string> values;
  for (const CLI::App* a : option_scope(app)) {
    for (const CLI::Option* o :
         a->get_options([](const CLI::Option* x) { return x->nonpositional(); })) {
      std::vector<std::string> names;
      for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
      for (const std::string& s : o->get_snames()) names.push_back("-" + s);
      if (!takes_value(o)) continue;
      values.insert(values.end(), names.begin(), names.end());
      const auto known = completions().find(o);
      if (known == completions().end()) continue;
      for (const std::string& n : names) {
        out +=
            fmt::format("_rccx_choices[\"{}|{}\"]=\"{}\"\n", key, n, fmt::join(known->second, " "));
      }
    }
  }
  out += fmt::format("_rccx_subs[\"{}\"]=\"{}\"\n", key, fmt::join(subcommand_names(app), " "));
  out += fmt::format("_rccx_opts[\"{}\"]=\"{}\"\n", key, fmt::join(option_names(app), " "));
  out += fmt::format("_rccx_values[\"{}\"]=\"{}\"\n", key, fmt::join(values, " "));
  for (const CLI::App* s : subcommands(app)) completion_tables(s, out);
}

/// The function the tables feed: the command reached so far, then its verbs, options or an
/// option's values; nothing offered falls back to file names (-o default).
constexpr const char* kCompletionFunction = R"(_rccx() {
  local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]} path=rccx w i skip=0
  for ((i = 1; i < COMP_CWORD; i++)); do
    w=${COMP_WORDS[i]}
    if ((skip)); then skip=0; continue; fi
    if [[ " ${_rccx_values[$path]} " == *" $w "* ]]; then skip=1; continue; fi
    if [[ " ${_rccx_subs[$path]} " == *" $w "* ]]; then path="$path $w"; fi
  done
  COMPREPLY=()
  if ((COMP_CWORD > 1)) && [[ " ${_rccx_values[$path]} " == *" $prev "* ]]; then
    local choices=${_rccx_choices["$path|$prev"]}
    [[ -n $choices ]] && COMPREPLY=($(compgen -W "$choices" -- "$cur"))
    return 0
  fi
  if [[ $cur == -* ]]; then
    COMPREPLY=($(compgen -W "${_rccx_opts[$path]}" -- "$cur"))
  else
    COMPREPLY=($(compgen -W "${_rccx_subs[$path]}" -- "$cur"))
  fi
}
complete -o bashdefault -o default -F _rccx rccx
)";

void add_completion_command(CLI::App& app, int& exit_code) {
  CLI::App* cmd = app.add_subcommand(
      "completion", "Shell completion written from rccx's own commands and options");
  cmd->require_subcommand(1);
  auto out = std::make_shared<std::string>();
  CLI::App* bash = cmd->add_subcommand(
      "bash",
      "Prints a bash completion script: `source <(rccx completion bash)`, or install it as "
      "share/bash-completion/completions/rccx (cmake --install does)");
  bash->add_option("-o,--output", *out, "Write it to this file instead of standard output");
  bash->callback([&app, out, &exit_code] {
    const std::string script = bash_completion(app);
    if (out->empty()) {
      fmt::print("{}", script);
      exit_code = kOk;
      return;
    }
    std::ofstream file(*out, std::ios::binary | std::ios::trunc);
    file << script;
    file.close();
    exit_code = file ? kOk : kFailure;
    if (!file) io::eprint("error: cannot write {}\n", io::quoted(*out));
  });
}

/// A verb takes its parent's options too: `rccx db list --db x.db` as `rccx db --db x.db list`.
void verbs_take_parent_options(CLI::App* app, bool top) {
  for (CLI::App* s : app->get_subcommands([](CLI::App* x) { return !x->get_name().empty(); })) {
    if (!top) s->fallthrough();
    verbs_take_parent_options(s, false);
  }
}

}  // namespace

std::string bash_completion(const CLI::App& root) {
  std::string out =
      "# bash completion for rccx, written by `rccx completion bash` from its own command "
      "definition\n"
      "declare -gA _rccx_subs _rccx_opts _rccx_values _rccx_choices\n";
  completion_tables(&root, out);
  return out + kCompletionFunction;
}

std::unique_ptr<CLI::App> make_app(int& exit_code) {
  auto app = std::make_unique<CLI::App>(
      "rccx - robot programming and real-time control in the manner of RCCL/RTC (1986).\n"
      "Units are SI (m, rad, s) unless an option says otherwise; a duration is a number and its "
      "unit (ns, us, ms, s, min), a bare number is seconds. Exit codes: 0 done, 1 failed while "
      "running, 2 bad input, 3 pose out of reach, 130 / 143 / 129 ended by SIGINT / SIGTERM / "
      "SIGHUP.",
      "rccx");
  app->set_version_flag("--version", "rccx 0.1.0");
  app->require_subcommand(1);
  add_kin_command(*app, exit_code);
  add_rtc_commands(*app, exit_code);
  add_rcu_command(*app, exit_code);
  add_db_command(*app, exit_code);
  add_teach_command(*app, exit_code);
  add_cell_command(*app, exit_code);
  add_view_command(*app, exit_code);
  add_plot_command(*app, exit_code);
  add_serve_command(*app, exit_code);  // issue 29: robots served over DDS
  add_certs_command(*app, exit_code);
  add_completion_command(*app, exit_code);
  verbs_take_parent_options(app.get(), true);
  return app;
}

}  // namespace rccx::tools
