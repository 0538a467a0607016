#include "certs_command.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "rccx/io/console.hpp"
#include "rccx/net/certs.hpp"

namespace rccx::tools {

namespace {

namespace fs = std::filesystem;

struct CertsArgs {
  std::string dir;
  std::vector<std::string> participants;  ///< init: --participants a,b,c
  std::vector<std::string> programs;      ///< --program NAME: a program whatever its name
  std::string participant;                ///< add: --participant NAME
  bool program = false;                   ///< add: --program (flag)
  int days = 365;
  bool force = false;
  net::Protection protection = net::Protection::full;  ///< init: --protection
};

void check_name(const std::string& name) {
  try {
    net::check_participant_name(name);
  } catch (const net::NetError& e) {
    throw BadArgument{e.what()};
  }
  if (name == "private") {
    throw BadArgument{"participant name 'private' is taken (DIR/private/ holds the CAs' keys)"};
  }
}

bool has_ca(const fs::path& dir) {
  return fs::exists(dir / "identity_ca.pem") || fs::exists(dir / "private");
}

/// Issues `name` and says which files it got.
void issue(const fs::path& dir, const std::string& name, bool program, int days) {
  net::ParticipantOptions o;
  o.days = days;
  if (program) o.role = net::Role::program;
  net::issue_participant(dir, name, o);
  const net::Role role = o.role.value_or(net::role_of(name));
  fmt::print("{}: {}/cert.pem, key.pem (0600), permissions.p7s ({}, valid {} days)\n", name,
             (dir / name).string(), role == net::Role::program ? "program" : "serve process", days);
}

int run_init(const CertsArgs& a) {
  const fs::path dir(a.dir);
  // Everything checked before anything is written: bad input changes nothing.
  std::vector<std::string> names;
  std::set<std::string> seen;
  for (const std::string& n : a.participants) {
    check_name(n);
    if (!seen.insert(n).second) throw BadArgument{fmt::format("--participants: {} twice", n)};
    names.push_back(n);
  }
  for (const std::string& n : a.programs) {
    check_name(n);
    if (seen.insert(n).second) names.push_back(n);  // a program not listed is issued too
  }
  if (names.empty()) throw BadArgument{"--participants: give at least one name"};
  if (has_ca(dir) && !a.force) {
    throw BadArgument{fmt::format(
        "{} has a CA already: give --force to replace it (participants of the old CA not issued "
        "again stop authenticating), or `rccx certs add {} --participant NAME` to add one",
        dir.string(), dir.string())};
  }
  if (fs::exists(dir) && !fs::is_directory(dir)) {
    throw BadArgument{fmt::format("{} is not a directory", dir.string())};
  }
  net::make_ca(dir, {.days = std::max(a.days, 3650), .force = a.force, .protection = a.protection});
  fmt::print(
      "{}: identity_ca.pem, permissions_ca.pem, governance.p7s ({} protection); the CAs' keys in "
      "{} (0700)\n",
      dir.string(), a.protection == net::Protection::full ? "full" : "payload",
      (dir / "private").string());
  const std::set<std::string> programs(a.programs.begin(), a.programs.end());
  for (const std::string& n : names) issue(dir, n, programs.count(n) > 0, a.days);
  fmt::print(
      "Use it: rccx serve --secure {} --identity NAME; a program's NetOptions::secure_dir / "
      "secure_identity (docs/NETWORK.md, \"Security\")\n",
      dir.string());
  return kOk;
}

int run_add(const CertsArgs& a) {
  const fs::path dir(a.dir);
  check_name(a.participant);
  if (!fs::exists(dir / "private" / "identity_ca_key.pem")) {
    throw BadArgument{fmt::format("{} has no CA: run `rccx certs init {} --participants {}` first",
                                  dir.string(), dir.string(), a.participant)};
  }
  if (fs::exists(dir / a.participant / "cert.pem") && !a.force) {
    throw BadArgument{fmt::format("{} has participant {} already: give --force to issue it again",
                                  dir.string(), a.participant)};
  }
  issue(dir, a.participant, a.program, a.days);
  return kOk;
}

int run(const std::string& what, const CertsArgs& a) {
  try {
    return what == "init" ? run_init(a) : run_add(a);
  } catch (const BadArgument& e) {
    io::eprint("error: {}; nothing written\n", e.message);
    return kBadArguments;
  } catch (const net::NetError& e) {  // OpenSSL or a file failed
    io::eprint("error: {}\n", e.what());
    return kFailure;
  } catch (const fs::filesystem_error& e) {
    io::eprint("error: {}\n", e.what());
    return kFailure;
  }
}

}  // namespace

void add_certs_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<CertsArgs>();
  CLI::App* certs = app.add_subcommand(
      "certs",
      "DDS Security's files for `rccx serve --secure DIR --identity NAME` and secure programs: an "
      "identity CA and a permissions CA (EC P-256), each participant's key, certificate "
      "(CN=NAME) and permissions, and the governance (every rccx topic authenticated, "
      "access-controlled and encrypted; docs/NETWORK.md, \"Security\"). A participant named "
      "program* (or given by --program) may send requests and frames and read state; the others "
      "are serve processes. Exit codes: 0 done, 1 OpenSSL or a file failed, 2 bad input "
      "(nothing written).");
  certs->require_subcommand(1);
  CLI::App* init =
      certs->add_subcommand("init", "Makes DIR's CAs, its governance and the participants' files");
  init->add_option("dir", args->dir, "The directory (made if missing)")->required();
  init->add_option("--participants", args->participants,
                   "The participants' names, comma-separated (1 to 32 letters, digits, _ -)")
      ->delimiter(',')
      ->required();
  init->add_option("--program", args->programs,
                   "A participant with the program's grants whatever its name (repeat for more)")
      ->type_name("NAME")
      ->allow_extra_args(false);
  init->add_flag("--force", args->force,
                 "Replace DIR's CA (participants not issued again stop authenticating)");
  init->add_option("--protection", args->protection,
                   "full: every message, submessage and payload encrypted (ROS 2's sros2 "
                   "default); payload: the payloads only, the headers clear (who talks to whom is "
                   "seen, no data is read or forged), about half full's cost a round trip. Both "
                   "authenticate and control access (docs/NETWORK.md, \"Security\")")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, net::Protection>{{"full", net::Protection::full},
                                                 {"payload", net::Protection::payload}},
          CLI::ignore_case))
      ->default_str("full");
  CLI::App* add = certs->add_subcommand(
      "add", "Issues one more participant of DIR's CA (DIR/private/ holds the CAs' keys)");
  add->add_option("dir", args->dir, "The directory of rccx certs init")->required();
  add->add_option("--participant", args->participant, "Its name (1 to 32 letters, digits, _ -)")
      ->required();
  add->add_flag("--program", args->program, "Give it the program's grants whatever its name");
  add->add_flag("--force", args->force, "Issue it again if it exists");
  for (CLI::App* c : {init, add}) {
    c->add_option("--days", args->days, "How long its certificates and permissions hold")
        ->check(CLI::Range(1, 36500))
        ->capture_default_str();
    const std::string what = c->get_name();
    c->callback([args, what, &exit_code] { exit_code = run(what, *args); });
  }
}

}  // namespace rccx::tools
