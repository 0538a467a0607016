#include "db_command.hpp"

#include <fcntl.h>
#include <stdio_ext.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string_view>
#include <system_error>
#include <vector>

#include "pose_options.hpp"
#include "rccx/io/console.hpp"
#include "rccx/io/file.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/io/signals.hpp"
#include "rccx/io/spelling.hpp"
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
  PoseArgs pose;  // --T, or --xyz and --rpy, parsed strictly (CLI11 would take inf and nan)
  std::string configuration;
  std::string note;
  std::string path;                     // export / import file ("-": stdout / stdin)
  std::vector<std::string> new_robots;  // put, import: robots not known yet that may be added
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

/// Why a row read back cannot be shown ("" when it can): one another program wrote, or an older
/// rccx stored beyond today's bounds. Its numbers are not printed (no inf or nan).
std::string corrupt(const rccl::StoredTransform& t) {
  return PositionDb::value_problem(t.value);
}

std::string line(const rccl::StoredTransform& t) {
  const std::string who = fmt::format("{} {}", shown_name(t.robot), shown_name(t.name));
  if (const std::string problem = corrupt(t); !problem.empty()) {
    return fmt::format(
        "{}: the stored value is corrupt ({}); store it again with `rccx db put` "
        "or remove it with `rccx db rm`\n",
        who, problem);
  }
  // URDF's angles, as --rpy takes them: what is printed can be typed back.
  const auto rpy = t.value.R.to_urdf_rpy();
  return fmt::format(
      "{}: x {:.3f} y {:.3f} z {:.3f} mm, URDF rpy (about fixed x, y, z) {:.3f} {:.3f} {:.3f} "
      "deg{}{}\n",
      who, t.value.p.x * 1e3, t.value.p.y * 1e3, t.value.p.z * 1e3, math::rad_to_deg(rpy[0]),
      math::rad_to_deg(rpy[1]), math::rad_to_deg(rpy[2]),
      t.configuration.empty() ? "" : ", configuration " + shown_text(t.configuration),
      t.note.empty() ? "" : " (" + shown_text(t.note) + ")");
}

/// `db show`: the line, the same rotation as Paul's angles (RCCL's and the cell files'), and JSON.
std::string shown_transform(const rccl::StoredTransform& t, const std::string& file) {
  if (const std::string problem = corrupt(t); !problem.empty()) {
    throw rccl::DatabaseError(fmt::format(
        "position database {}: {} of robot {}: the stored value is corrupt ({}); store it "
        "again with `rccx db put` or remove it with `rccx db rm`",
        file, shown_name(t.name), shown_name(t.robot), problem));
  }
  const auto paul = t.value.R.to_rpy();
  return line(t) +
         fmt::format(
             "  Paul's RPY (RCCL, cell files: Rot(z, roll) Rot(y, pitch) Rot(x, yaw)): "
             "roll {:.3f} pitch {:.3f} yaw {:.3f} deg\n",
             math::rad_to_deg(paul[0]), math::rad_to_deg(paul[1]), math::rad_to_deg(paul[2])) +
         rccl::position_json(t);
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
/// known: the shipped ones, those already stored, and those declared new.
struct Known {
  std::unique_ptr<PositionDb> db;
  std::set<std::string> robots;
};

Known known_robots(const std::string& file, std::chrono::milliseconds wait,
                   const std::vector<std::string>& declared = {}) {
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

/// The database of `k`, opened now when it was missing (`mode` says whether to create it).
PositionDb& opened(Known& k, const std::string& file, std::chrono::milliseconds wait,
                   PositionDb::Open mode = PositionDb::Open::existing) {
  if (!k.db) k.db = std::make_unique<PositionDb>(file, mode, wait);
  return *k.db;
}

std::string joined(const std::set<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += fmt::format("{}{}", out.empty() ? "" : ", ", n);
  return out;
}

/// The edit distance of a and b, letters compared without case: how near a typo is to a name.
std::size_t distance(std::string_view a, std::string_view b) {
  const auto lower = [](std::string_view w) {
    std::string out(w);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
  };
  return io::edit_distance(lower(a), lower(b));
}

/// Throws BadArgument unless `robot` is known, naming the nearest known robot; `then` says what
/// else the user may do. A misspelt robot must not read as "nothing stored".
void require_known(const std::string& robot, const Known& k, std::string_view then) {
  if (k.robots.count(robot) != 0) return;
  const auto nearest = std::min_element(
      k.robots.begin(), k.robots.end(),
      [&](const auto& x, const auto& y) { return distance(robot, x) < distance(robot, y); });
  throw BadArgument{
      fmt::format("--robot: {} is not a known robot; did you mean {}? (known: {}); {}",
                  io::quoted(robot), *nearest, joined(k.robots), then)};
}

constexpr const char* kCheckSpelling = "check the spelling";

/// The robot a put stores for: --robot, or the one --new-robot declares.
std::string robot_to_put(const DbArgs& a) {
  if (a.new_robots.size() > 1) {
    throw BadArgument{"--new-robot: a put stores for one robot; give --new-robot once"};
  }
  if (a.robot.empty() && a.new_robots.empty()) {
    throw BadArgument{"--robot is required (or --new-robot NAME for a robot not known yet)"};
  }
  if (!a.robot.empty() && !a.new_robots.empty() && a.new_robots[0] != a.robot) {
    throw BadArgument{fmt::format(
        "--new-robot {} is not --robot {}; give the new robot's name once, as --new-robot NAME",
        io::quoted(a.new_robots[0]), io::quoted(a.robot))};
  }
  return a.robot.empty() ? a.new_robots[0] : a.robot;
}

void db_list(const std::string& file, std::chrono::milliseconds wait, const DbArgs& a) {
  if (a.pattern.empty()) {
    throw BadArgument{"pattern: \"\" is empty; give a name or a glob such as * or P*"};
  }
  io::check_text(a.pattern, "pattern", kMaxPattern);
  Known k = known_robots(file, wait);
  if (!a.robot.empty()) require_known(a.robot, k, kCheckSpelling);
  std::string out;
  std::size_t bad = 0;
  for (const auto& t : opened(k, file, wait).list(a.robot, a.pattern)) {
    out += line(t);
    bad += corrupt(t).empty() ? 0 : 1;
  }
  write_stdout(out);
  if (bad > 0) {
    throw rccl::DatabaseError(
        fmt::format("position database {}: {} stored value{} corrupt (said "
                    "above)",
                    file, bad, bad == 1 ? " is" : "s are"));
  }
}

BadArgument not_stored(const std::string& file, const DbArgs& a) {
  return BadArgument{fmt::format("{} has no {} for robot {} (`rccx db list` shows what it has)",
                                 file, a.name, a.robot)};
}

void db_show(const std::string& file, std::chrono::milliseconds wait, const DbArgs& a) {
  Known k = known_robots(file, wait);
  require_known(a.robot, k, kCheckSpelling);
  const auto t = opened(k, file, wait).get(a.robot, a.name);
  if (!t) throw not_stored(file, a);
  write_stdout(shown_transform(*t, file));
}

void db_rm(const std::string& file, std::chrono::milliseconds wait, const DbArgs& a) {
  Known k = known_robots(file, wait);
  require_known(a.robot, k, kCheckSpelling);
  if (!opened(k, file, wait).remove(a.robot, a.name)) throw not_stored(file, a);
}

void db_put(const std::string& file, std::chrono::milliseconds wait, const DbArgs& a) {
  rccl::StoredTransform t;
  t.robot = robot_to_put(a);
  t.name = a.name;
  t.value = pose_from(a.pose, rccl::kMaxPosition_m);
  t.configuration = a.configuration;
  t.note = a.note;
  PositionDb::check(t);  // InvalidTransform: exit 2, before any file is made
  Known k = known_robots(file, wait, a.new_robots);
  require_known(
      t.robot, k,
      fmt::format("check the spelling, or declare a new robot with --new-robot {}", t.robot));
  opened(k, file, wait, PositionDb::Open::create).put(t);
}

void db_export(const std::string& file, std::chrono::milliseconds wait, const DbArgs& a) {
  std::error_code ec;
  const bool to_stdout = a.path.empty() || a.path == "-";
  if (!to_stdout && std::filesystem::is_directory(a.path, ec)) {
    throw BadArgument{fmt::format(
        "export: {} is a directory; name a file, or - for standard output", io::quoted(a.path))};
  }
  Known k = known_robots(file, wait);
  if (!a.robot.empty()) require_known(a.robot, k, kCheckSpelling);
  const std::vector<rccl::StoredTransform> all = opened(k, file, wait).list(a.robot);
  for (const auto& t : all)
    (void)shown_transform(t, file);  // a corrupt value: said, nothing exported
  const std::string text = rccl::position_export_json(all);
  if (to_stdout) {
    write_stdout(text);
  } else if (std::filesystem::exists(a.path, ec) && !std::filesystem::is_regular_file(a.path, ec)) {
    write_device(a.path, text);  // /dev/stdout, a pipe: not to be replaced by a file
  } else {
    io::write_file_atomically(a.path, text);  // the old file, or the new one whole
  }
}

void db_import(const std::string& file, std::chrono::milliseconds wait, const DbArgs& a) {
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
  // All or nothing; a stop signal before the commit means nothing.
  opened(k, file, wait, PositionDb::Open::create).put(all, [] { return io::stop_count() > 0; });
  io::eprint("imported {} transforms into {}\n", all.size(), file);
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
  if (!a.robot.empty() || what == "show" || what == "rm") check_robot(a.robot, "--robot");
  for (const std::string& r : a.new_robots) check_robot(r, "--new-robot");
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
  if (what == "list") db_list(file, wait, a);
  if (what == "show") db_show(file, wait, a);
  if (what == "rm") db_rm(file, wait, a);
  if (what == "put") db_put(file, wait, a);
  if (what == "export") db_export(file, wait, a);
  if (what == "import") db_import(file, wait, a);
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
  // --new-robot NAME, the same for put and import: one name a time (repeat it for several).
  const auto new_robot = [&](CLI::App* c, const char* help) {
    not_empty(c->add_option("--new-robot", args->new_robots, help))
        ->type_name("NAME")
        ->allow_extra_args(false);
  };
  const auto robot_name = [&](CLI::App* c, bool robot_required) {
    CLI::Option* robot =
        not_empty(c->add_option("--robot", args->robot, "The robot the transform belongs to"));
    if (robot_required) robot->required();
    not_empty(c->add_option("name", args->name, "Transform name (1 to 32 letters, digits, _ - .)"))
        ->required();
  };
  // --robot of list, show, rm and export: a robot neither shipped nor stored is refused (exit 2),
  // naming the nearest known one, rather than listing nothing.
  CLI::App* list = db->add_subcommand("list", "Lists transforms (all robots unless --robot)");
  not_empty(list->add_option("--robot", args->robot, "Only this robot's"));
  not_empty(list->add_option("pattern", args->pattern, "Name pattern (glob: *, ?)"))
      ->capture_default_str();
  CLI::App* show = db->add_subcommand(
      "show",
      "Prints one transform: position in mm, rotation as URDF's roll-pitch-yaw (about the fixed "
      "x, y, z axes, as --rpy takes it) and as Paul's (RCCL's: roll about z), in deg; then JSON "
      "(m, rad)");
  robot_name(show, true);
  CLI::App* put = db->add_subcommand(
      "put",
      "Stores a transform (replacing one of that name), given as --T or as --xyz and --rpy. "
      "--robot must be a shipped robot (microbo, puma560, puma260, stanford) or one the database "
      "already has; a new robot is declared with --new-robot NAME (as for import), so that a "
      "misspelt name is refused rather than stored. The position is within 100 m of the origin "
      "on each axis, the rotation orthonormal and right-handed.");
  robot_name(put, false);
  add_pose_options(*put, args->pose, "The transform");
  put->add_option("--config", args->configuration,
                  "The arm configuration it is for (up to 8 letters, e.g. lun)");
  put->add_option("--note", args->note, "A note (UTF-8, up to 1000 bytes, one line)");
  new_robot(put, "A robot not known yet to store for (then --robot may be left out)");
  CLI::App* rm = db->add_subcommand("rm", "Removes a transform");
  robot_name(rm, true);
  CLI::App* exp = db->add_subcommand(
      "export", "Writes every transform as JSON (a file is replaced whole or not at all)");
  not_empty(exp->add_option("--robot", args->robot, "Only this robot's"));
  not_empty(exp->add_option("file", args->path, "Output file (default, or -: standard output)"));
  CLI::App* imp = db->add_subcommand(
      "import",
      "Reads a JSON export: all transforms or none. Its robots must be shipped robots or ones "
      "the database has; declare each new one with --new-robot NAME.");
  not_empty(imp->add_option("file", args->path, "Input file (- for standard input)"))->required();
  new_robot(imp, "A robot the file may add (repeat for several)");
  for (CLI::App* c : {list, show, put, rm, exp, imp}) {
    const std::string what = c->get_name();
    c->callback([args, what, &exit_code] { exit_code = run(what, *args); });
  }
}

}  // namespace rccx::tools
