// What the rccx subcommands share: exit codes, the bad-argument error, duration options, the
// robot options.
#pragma once

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <string>

#include "cli_tree.hpp"
#include "rccx/io/console.hpp"
#include "rccx/io/file.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/urdf.hpp"
#include "rccx/rtc/session.hpp"

namespace rccx::tools {

/// Exit codes shared by the rccx subcommands (docs/RELIABILITY.md). A command ended by SIGINT
/// or SIGTERM exits with 128 + the signal's number (130, 143), as a shell reports it.
enum ExitCode : int { kOk = 0, kFailure = 1, kBadArguments = 2, kUnreachable = 3 };

/// A bad argument found after parsing: its message goes to stderr and rccx exits with 2.
struct BadArgument {
  std::string message;
};

/// Refuses "" for an option: an empty value is a variable that was not set (`--log "$LOG"`), not
/// a choice, and must not silently mean the default (no log, the default period, ./rccx.db).
inline CLI::Validator not_empty() {
  return CLI::Validator(
      [](const std::string& value) {
        return value.empty() ? std::string("\"\" is empty; give a value (see --help)")
                             : std::string();
      },
      "", "NOT_EMPTY");
}

/// A duration option's value. One rule for every command (docs/RELIABILITY.md): a number and its
/// unit, ns, us, ms, s or min ("500ms", "2s", "1.5min"); a bare number is seconds, the SI unit.
struct Duration {
  std::string text;  ///< as given, or the default; "" when neither (the command decides)
  std::chrono::nanoseconds value{};

  [[nodiscard]] bool given() const { return !text.empty(); }
  [[nodiscard]] double seconds() const { return std::chrono::duration<double>(value).count(); }
};

/// Adds `name` as a duration within [lo, hi], read when the line is parsed: a bad value is
/// refused (exit 2) before anything runs, naming the option. `d.text` is its default.
inline CLI::Option* add_duration_option(CLI::App& cmd, const std::string& name, Duration& d,
                                        std::chrono::nanoseconds lo, std::chrono::nanoseconds hi,
                                        const std::string& help) {
  const auto read = [name, lo, hi](const std::string& text) {
    return io::parse_duration(text, name, io::BareUnit::seconds, lo, hi);
  };
  if (d.given()) d.value = read(d.text);  // the default, by the same rule
  CLI::Option* o = cmd.add_option_function<std::string>(
      name,
      [&d, read](const std::string& text) {
        try {
          d.value = read(text);
          d.text = text;
        } catch (const io::ParseError& e) {
          throw CLI::ValidationError(e.what());
        }
      },
      help + " (a duration: 500ms, 2s, 1.5min; a bare number is s)");
  o->type_name("DURATION");
  if (d.given()) o->default_str(d.text);
  return o;
}

/// --period: a sample period within what RTC serves (0.25 to 56 ms).
inline CLI::Option* add_period_option(CLI::App& cmd, Duration& d, const std::string& help) {
  return add_duration_option(cmd, "--period", d, rtc::kMinPeriod, rtc::kMaxPeriod, help);
}

/// --robot / --robot-file / --urdf (with --base-link, --tip-link).
struct RobotChoice {
  std::string name;
  std::string file;
  std::string urdf;
  kin::UrdfOptions urdf_links;

  explicit RobotChoice(std::string default_name) : name(std::move(default_name)) {}

  [[nodiscard]] kin::RobotModel model() const {
    try {
      if (!urdf.empty()) return kin::load_urdf(urdf, urdf_links);
      if (!urdf_links.base_link.empty() || !urdf_links.tip_link.empty()) {
        throw BadArgument{
            "--base-link and --tip-link choose the chain of a --urdf robot: give "
            "--urdf FILE"};
      }
      return file.empty() ? kin::builtin_robot(name) : kin::load_robot_file(file);
    } catch (const kin::RobotFileError& e) {
      throw BadArgument{e.what()};
    }
  }
  [[nodiscard]] std::unique_ptr<kin::Kinematics> load() const {
    try {
      return kin::make_kinematics(model());
    } catch (const kin::RobotFileError& e) {
      throw BadArgument{e.what()};
    }
  }
};

inline void add_robot_options(CLI::App& cmd, RobotChoice& robot) {
  cmd.add_option("--robot", robot.name,
                 "Shipped robot to use (see `rccx kin robots`): microbo, puma560, puma260, "
                 "stanford")
      ->capture_default_str();
  complete_with(cmd.get_option("--robot"), kin::builtin_robot_names());
  cmd.add_option("--robot-file", robot.file,
                 "Robot description file (JSON, see robots/README.md); overrides --robot")
      ->check(CLI::ExistingFile);
  cmd.add_option("--urdf", robot.urdf,
                 "A robot from a URDF file (robots/ur5e.urdf, robots/panda.urdf; a xacro file "
                 "needs `xacro` first); overrides --robot and --robot-file")
      ->check(CLI::ExistingFile)
      ->excludes("--robot-file");
  cmd.add_option("--base-link", robot.urdf_links.base_link,
                 "--urdf: the link whose frame is the base (default: the tree's root)");
  cmd.add_option("--tip-link", robot.urdf_links.tip_link,
                 "--urdf: the link whose frame is T6 (default: the only leaf; needed when the "
                 "tree branches)");
}

/// The position database file: `given`, else $RCCX_DB, else ./rccx.db (one file per cell).
inline std::string database_file(const std::string& given) {
  if (!given.empty()) return given;
  if (const char* env = std::getenv("RCCX_DB"); env != nullptr && *env != '\0') return env;
  return "rccx.db";
}

/// Runs a subcommand: bad input (BadArgument, io::ParseError) gives its message and exit code
/// 2, a file that cannot be read or written exit code 1.
template <typename F>
void guarded(int& exit_code, F&& run) {
  try {
    exit_code = run();
  } catch (const BadArgument& e) {
    io::eprint("error: {}\n", e.message);
    exit_code = kBadArguments;
  } catch (const io::ParseError& e) {
    io::eprint("error: {}\n", e.what());
    exit_code = kBadArguments;
  } catch (const io::FileError& e) {
    io::eprint("error: {}\n", e.what());
    exit_code = kFailure;
  }
}

}  // namespace rccx::tools
