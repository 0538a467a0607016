#include "db_command.hpp"

#include <fcntl.h>
#include <stdio_ext.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <set>
#include <system_error>

#include "rccx/io/console.hpp"
#include "rccx/io/file.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/io/signals.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/position_db.hpp"
#include "rccx/rccl/position_export.hpp"

namespace rccx::tools {
namespace {

using rccl::PositionDb;

struct DbArgs {
  std::string file;
  Duration wait{"5s"};  // for another process writing the database
  std::string robot;
  std::string name;
  std::string pattern = "*";
  std::string T;  // 12 comma-separated numbers, parsed strictly (CLI11 would take inf and nan)
  std::string configuration;
  std::string note;
  std::string path;                     // export / import file ("-": stdout / stdin)
  bool new_robot = false;               // put: --robot may be a robot not known yet
  std::vector<std::string> new_robots;  // import: robots the file may add
  /// The options given as "" (refused: an empty name or path is a lost variable, not a choice).
  std::vector<CLI::Option*> not_empty;
};

constexpr std::size_t kMaxPattern = 100;
constexpr std::size_t kMaxInput = 64u << 20;  // bytes of an import

/// Text from the database for a terminal: as it is when it is what put() stores, else quoted
/// with its odd bytes shown (a row written by another program).
std::string shown_text(const std::string& text) {
  try {
    io::check_text(text, "", rccl::kMaxNote);
    return text;
  } catch (const io::ParseError&) {
    return io::quoted(text);
  }
}

std::string shown_name(const std::string& name) {
  try {
    io::check_name(name, "", rccl::kMaxTransformName);
    return name;
  } catch (const io::ParseError&) {
    return io::quoted(name);
  }
}

std::string line(const rccl::StoredTransform& t) {
  const auto rpy = t.value.R.to_rpy();
  return fmt::format(
      "{} {}: x {:.3f} y {:.3f} z {:.3f} mm, roll {:.3f} pitch {:.3f} yaw {:.3f} deg{}{}\n",
      shown_name(t.robot), shown_name(t.name), t.value.p.x * 1e3, t.value.p.y * 1e3,
      t.value.p.z * 1e3, math::rad_to_deg(rpy[0]), math::rad_to_deg(rpy[1]),
      math::rad_to_deg(rpy[2]),
      t.configuration.empty() ? "" : ", configuration " + shown_text(t.configuration),
      t.note.empty() ? "" : " (" + shown_text(t.note) + ")");
}

/// Writes `text` to standard output and flushes it; throws FileError when any of it was lost
/// (a full disk, a closed pipe), since a partial listing or export must not look complete.
void write_stdout(std::string_view text) {
  const std::size_t n = std::fwrite(text.data(), 1, text.size(), stdout);
  std::string why;
  if (!io::flush_stdout(why) || n != text.size()) {
    // What is left in the buffer is lost all the same: dropped, so that the check of standard
    // output at exit does not say it a second time.
    __fpurge(stdout);
    std::clearerr(stdout);
    throw io::FileError(
        fmt::format("cannot write to standard output: {}; the output is "
                    "incomplete (write to a file with room, or a working pipe)",
                    why.empty() ? "a write failed" : why));
  }
}

/// Writes `text` to an existing file that is not a regular one (a device, a named pipe), which
/// an atomic replacement would turn into a regular file.
void write_device(const std::string& path, std::string_view text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    throw io::FileError(fmt::format("cannot write {}: {}", path, std::strerror(errno)));
  }
  const int e = io::write_all(fd, text.data(), text.size());
  const int c = ::close(fd) == 0 ? 0 : errno;
  if (e != 0 || c != 0) {
    throw io::FileError(fmt::format("cannot write {}: {}; the export is incomplete", path,
                                    std::strerror(e != 0 ? e : c)));
  }
}

void check_robot(const std::string& robot, std::string_view what) {
  try {
    io::check_name(robot, what, rccl::kMaxRobotName);
  } catch (const io::ParseError& e) {
    throw BadArgument{e.what()};
  }
}

void check_transform_name(const std::string& name) {
  try {
    PositionDb::check_name(name);
  } catch (const rccl::InvalidTransform& e) {
    throw BadArgument{e.what()};
  }
}

std::chrono::milliseconds busy_timeout(const DbArgs& a) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(a.wait.value);
}

/// The standard input, whole (an import from a pipe).
std::string read_stdin() {
  std::string out;
  char chunk[65536];
  for (;;) {
    const ssize_t n = ::read(STDIN_FILENO, chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      throw BadArgument{
          fmt::format("cannot read standard input: {}; nothing imported", std::strerror(errno))};
    }
    if (n == 0) break;
    out.append(chunk, static_cast<std::size_t>(n));
    if (out.size() > kMaxInput) {
      throw BadArgument{
          fmt::format("standard input: larger than {} MiB; nothing imported", kMaxInput >> 20)};
    }
  }
  return out;
}

/// The database, opened when it exists (a missing file is not created here), with the robots
/// a put or an import may use: the shipped ones, those already stored, and those declared new.
struct Known {
  std::unique_ptr<PositionDb> db;
  std::set<std::string> robots;
};

Known known_robots(const std::string& file, std::chrono::milliseconds wait,
                   const std::vector<std::string>& declared) {
  Known k;
  for (std::string& r : kin::builtin_robot_names()) k.robots.insert(std::move(r));
  k.robots.insert(declared.begin(), declared.end());
  std::error_code ec;
  if (std::filesystem::exists(file, ec)) {
    k.db = std::make_unique<PositionDb>(file, PositionDb::Open::existing, wait);
    for (std::string& r : k.db->robots()) k.robots.insert(std::move(r));
  }
  return k;
}

std::string joined(const std::set<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += fmt::format("{}{}", out.empty() ? "" : ", ", n);
  return out;
}

int run_db(const std::string& what, const DbArgs& a) {
  for (const CLI::Option* o : a.not_empty) {
    for (const std::string& value : o->results()) {
      if (value.empty()) {
        throw BadArgument{
            fmt::format("{}: \"\" is empty; give a value (see --help)", o->get_name())};
      }
    }
  }
  const std::string file = database_file(a.file);
  // Every argument is checked before the database is opened: bad input creates no file.
  if (!a.robot.empty() || what == "show" || what == "put" || what == "rm") {
    check_robot(a.robot, "--robot");
  }
  if (what == "show" || what == "put" || what == "rm") check_transform_name(a.name);
  const auto wait = busy_timeout(a);
  std::error_code ec;
  if (const auto type = std::filesystem::status(file, ec).type();
      type != std::filesystem::file_type::not_found &&
      type != std::filesystem::file_type::regular && !ec) {
    throw BadArgument{fmt::format(
        "position database {} is {}; name a database file with --db", io::quoted(file),
        type == std::filesystem::file_type::directory ? "a directory" : "not a regular file")};
  }

  if (what == "list") {
    if (a.pattern.empty()) {
      throw BadArgument{"pattern: \"\" is empty; give a name or a glob such as * or P*"};
    }
    io::check_text(a.pattern, "pattern", kMaxPattern);
    PositionDb db(file, PositionDb::Open::existing, wait);
    std::string out;
    for (const auto& t : db.list(a.robot, a.pattern)) out += line(t);
    write_stdout(out);
  } else if (what == "show") {
    PositionDb db(file, PositionDb::Open::existing, wait);
    const auto t = db.get(a.robot, a.name);
    if (!t) {
      throw BadArgument{fmt::format("{} has no {} for robot {} (`rccx db list` shows what it has)",
                                    file, a.name, a.robot)};
    }
    write_stdout(line(*t) + rccl::position_json(*t));
  } else if (what == "put") {
    rccl::StoredTransform t;
    t.robot = a.robot;
    t.name = a.name;
    const std::vector<double> v = io::parse_number_list(a.T, "--T", 12, {.unit = "m"});
    std::array<double, 12> rows{};
    std::copy(v.begin(), v.end(), rows.begin());
    t.value = math::Transform::from_rows(rows);
    t.configuration = a.configuration;
    t.note = a.note;
    PositionDb::check(t);  // InvalidTransform: exit 2, before any file is made
    Known k =
        known_robots(file, wait, a.new_robot ? std::vector{a.robot} : std::vector<std::string>{});
    if (k.robots.count(a.robot) == 0) {
      throw BadArgument{fmt::format(
          "--robot: {} is not a known robot (known: {}); check the spelling, or add --new-robot "
          "to store positions for a new robot",
          io::quoted(a.robot), joined(k.robots))};
    }
    if (!k.db) k.db = std::make_unique<PositionDb>(file, PositionDb::Open::create, wait);
    k.db->put(t);
  } else if (what == "rm") {
    PositionDb db(file, PositionDb::Open::existing, wait);
    if (!db.remove(a.robot, a.name)) {
      throw BadArgument{fmt::format("{} has no {} for robot {} (`rccx db list` shows what it has)",
                                    file, a.name, a.robot)};
    }
  } else if (what == "export") {
    const bool to_stdout = a.path.empty() || a.path == "-";
    if (!to_stdout && std::filesystem::is_directory(a.path, ec)) {
      throw BadArgument{fmt::format(
          "export: {} is a directory; name a file, or - for standard output", io::quoted(a.path))};
    }
    PositionDb db(file, PositionDb::Open::existing, wait);
    const std::string text = rccl::position_export_json(db.list(a.robot));
    if (to_stdout) {
      write_stdout(text);
    } else if (std::filesystem::exists(a.path, ec) &&
               !std::filesystem::is_regular_file(a.path, ec)) {
      write_device(a.path, text);  // /dev/stdout, a pipe: not to be replaced by a file
    } else {
      io::write_file_atomically(a.path, text);  // the old file, or the new one whole
    }
  } else if (what == "import") {
    for (const std::string& r : a.new_robots) check_robot(r, "--new-robot");
    const bool from_stdin = a.path == "-";
    std::string text;
    try {
      text = from_stdin ? read_stdin() : io::read_file(a.path, kMaxInput);
    } catch (const io::FileError& e) {
      throw BadArgument{fmt::format("{}; nothing imported", e.what())};
    }
    const std::vector<rccl::StoredTransform> all =
        rccl::parse_position_export(text, from_stdin ? "standard input" : a.path);
    Known k = known_robots(file, wait, a.new_robots);
    std::set<std::string> unknown;
    for (const auto& t : all) {
      if (k.robots.count(t.robot) == 0) unknown.insert(t.robot);
    }
    if (!unknown.empty()) {
      std::string names;
      for (const std::string& n : unknown) {
        names += fmt::format("{}{}", names.empty() ? "" : ", ", io::quoted(n));
      }
      throw BadArgument{fmt::format(
          "{}: robot {} not known (known: {}); check the file, or declare each new robot with "
          "--new-robot NAME; nothing imported",
          from_stdin ? "standard input" : a.path, names, joined(k.robots))};
    }
    if (!k.db) k.db = std::make_unique<PositionDb>(file, PositionDb::Open::create, wait);
    // All or nothing; a stop signal before the commit means nothing.
    k.db->put(all, [] { return io::stop_count() > 0; });
    io::eprint("imported {} transforms into {}\n", all.size(), file);
  }
  return kOk;
}

/// run_db with every error as one line on stderr and its exit code: bad input 2, a database
/// or a file that fails 1.
int run(const std::string& what, const DbArgs& a) {
  try {
    return run_db(what, a);
  } catch (const BadArgument& e) {
    io::eprint("error: {}\n", e.message);
    return kBadArguments;
  } catch (const io::ParseError& e) {  // also PositionExportError
    io::eprint("error: {}{}\n", e.what(), what == "import" ? "; nothing imported" : "");
    return kBadArguments;
  } catch (const rccl::InvalidTransform& e) {
    io::eprint("error: {}; nothing stored\n", e.what());
    return kBadArguments;
  } catch (const rccl::DatabaseError& e) {
    io::eprint("error: {}\n", e.what());
    return kFailure;
  } catch (const io::FileError& e) {
    io::eprint("error: {}\n", e.what());
    return kFailure;
  } catch (const std::system_error& e) {  // a stream that failed in a way not seen above
    io::eprint("error: {}\n", e.what());
    return kFailure;
  }
}

}  // namespace

void add_db_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<DbArgs>();
  CLI::App* db = app.add_subcommand(
      "db",
      "The position database (SQLite): named transforms per robot, for programs and equations. "
      "The file is --db, else $RCCX_DB, else ./rccx.db. Export / import as JSON (m, rad) to "
      "keep positions in version control or edit them off-line. Names (of transforms and "
      "robots) are 1 to 32 letters, digits and _ - .; a note is UTF-8 text of up to 1000 bytes. "
      "Exit codes: 0 done, 1 the database or a file failed (or is busy), 2 bad input (nothing "
      "changed).");
  // Options that may not be given as "".
  const auto not_empty = [args](CLI::Option* o) {
    args->not_empty.push_back(o);
    return o;
  };
  not_empty(db->add_option("--db", args->file, "Database file"));
  add_duration_option(*db, "--wait", args->wait, std::chrono::nanoseconds(0), std::chrono::hours(1),
                      "How long to wait for another process writing the database");
  db->require_subcommand(1);
  const auto robot_name = [&](CLI::App* c) {
    not_empty(c->add_option("--robot", args->robot, "The robot the transform belongs to"))
        ->required();
    not_empty(c->add_option("name", args->name, "Transform name (1 to 32 letters, digits, _ - .)"))
        ->required();
  };
  CLI::App* list = db->add_subcommand("list", "Lists transforms (all robots unless --robot)");
  not_empty(list->add_option("--robot", args->robot, "Only this robot's"));
  not_empty(list->add_option("pattern", args->pattern, "Name pattern (glob: *, ?)"))
      ->capture_default_str();
  CLI::App* show = db->add_subcommand("show", "Prints one transform (mm, deg, and as JSON)");
  robot_name(show);
  CLI::App* put = db->add_subcommand(
      "put",
      "Stores a transform (replacing one of that name). --robot must be a shipped robot "
      "(microbo, puma560, puma260, stanford) or one the database already has; a new robot is "
      "declared with --new-robot, so that a misspelt name is refused rather than stored.");
  robot_name(put);
  not_empty(put->add_option(
                "--T", args->T,
                "r11,r12,r13,px,r21,r22,r23,py,r31,r32,r33,pz (m): 12 comma-separated numbers"))
      ->required();
  put->add_option("--config", args->configuration,
                  "The arm configuration it is for (up to 8 letters, e.g. lun)");
  put->add_option("--note", args->note, "A note (UTF-8, up to 1000 bytes, one line)");
  put->add_flag("--new-robot", args->new_robot, "--robot is a new robot: store it all the same");
  CLI::App* rm = db->add_subcommand("rm", "Removes a transform");
  robot_name(rm);
  CLI::App* exp = db->add_subcommand(
      "export", "Writes every transform as JSON (a file is replaced whole or not at all)");
  not_empty(exp->add_option("--robot", args->robot, "Only this robot's"));
  not_empty(exp->add_option("file", args->path, "Output file (default, or -: standard output)"));
  CLI::App* imp = db->add_subcommand(
      "import",
      "Reads a JSON export: all transforms or none. Its robots must be shipped robots or ones "
      "the database has; declare each new one with --new-robot NAME.");
  not_empty(imp->add_option("file", args->path, "Input file (- for standard input)"))->required();
  not_empty(imp->add_option("--new-robot", args->new_robots,
                            "A robot the file may add (repeat for several)"));
  for (CLI::App* c : {list, show, put, rm, exp, imp}) {
    const std::string what = c->get_name();
    c->callback([args, what, &exit_code] { exit_code = run(what, *args); });
  }
}

}  // namespace rccx::tools
