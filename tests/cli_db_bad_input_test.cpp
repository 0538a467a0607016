// `rccx db` fed bad input, one row each: the arguments (and the files or the lock prepared
// for it), the exit code, a piece of the one-line message, and that the database is as it was
// (a bad name must not even create the file). Exit codes: 1 the database or a file failed,
// 2 bad input.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "rccx/math/transform.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/position_db.hpp"
#include "rccx/rccl/position_export.hpp"

#include "shell_run.hpp"

namespace {

namespace fs = std::filesystem;
using namespace rccx;

using CliRun = rccx::test::ShellRun;  // stdout and stderr

/// Runs `rccx ARGUMENTS` through bash (so `ARGUMENTS` may redirect and write bytes as $'\xff').
CliRun rccx_cli(const std::string& arguments) {
  // timeout: a command that hangs fails its row (exit 124) rather than the whole run.
  const std::string command =
      "exec timeout -k 5 60 " + std::string(RCCX_CLI) + " 2>&1 " + arguments;
  ::setenv("RCCX_TEST_COMMAND", command.c_str(), 1);  // no quoting of the command itself
  const rccx::test::ShellRun r = rccx::test::run_shell("exec bash -c \"$RCCX_TEST_COMMAND\"");
  return r;
}

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void write(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

/// What the database holds, to compare before and after ("<none>": no file).
std::string snapshot(const fs::path& db) {
  if (!fs::exists(db)) return "<none>";
  rccl::PositionDb d(db, rccl::PositionDb::Open::existing);
  return rccl::position_export_json(d.list());
}

/// A second connection holding the write lock until destroyed.
struct Lock {
  explicit Lock(const fs::path& db) {
    sqlite3_open(db.c_str(), &raw);
    sqlite3_exec(raw, "BEGIN IMMEDIATE", nullptr, nullptr, nullptr);
    sqlite3_exec(raw, "DELETE FROM transforms WHERE name = 'none'", nullptr, nullptr, nullptr);
  }
  ~Lock() {
    sqlite3_exec(raw, "ROLLBACK", nullptr, nullptr, nullptr);
    sqlite3_close(raw);
  }
  Lock(const Lock&) = delete;
  Lock& operator=(const Lock&) = delete;
  sqlite3* raw = nullptr;
};

constexpr const char* kT = "1,0,0,0.3,0,1,0,0.1,0,0,1,0.2";
constexpr const char* kRows = "[1,0,0,0.1, 0,1,0,0.2, 0,0,1,0.3]";

std::string export_with(const std::string& transforms) {
  return std::string(R"({"rccx_position_database": 1, "transforms": )") + transforms + "}";
}
std::string entry(const std::string& robot, const std::string& name, const std::string& extra = "",
                  const std::string& rows = kRows) {
  return fmt::format(R"({{"robot": "{}", "name": "{}", "T_rows_m": {}{}}})", robot, name, rows,
                     extra);
}

/// One row. In `args`, {db} is the database (which holds microbo/KEEP), {dir} a scratch folder;
/// `prepare` may write files there and return something that lives during the run (a lock).
using Prepare = std::function<std::shared_ptr<void>(const fs::path& dir, const fs::path& db)>;

struct Case {
  Case(std::string args_, int exit_code_, std::string message_, Prepare prepare_ = {},
       bool fresh_db_ = false, bool db_unchanged_ = true, bool skip_as_root_ = false)
      : args(std::move(args_)),
        exit_code(exit_code_),
        message(std::move(message_)),
        prepare(std::move(prepare_)),
        fresh_db(fresh_db_),
        db_unchanged(db_unchanged_),
        skip_as_root(skip_as_root_) {}
  std::string args;
  int exit_code;
  std::string message;  // a piece of the output
  Prepare prepare;
  bool fresh_db;      // no database file at all before the run
  bool db_unchanged;  // false: the run is meant to store something
  bool skip_as_root;  // file permissions do not stop root
};

std::shared_ptr<void> file_in(const fs::path& dir, const std::string& name,
                              const std::string& text) {
  write(dir / name, text);
  return nullptr;
}

auto with_file(std::string name, std::string text) {
  return [name, text](const fs::path& dir, const fs::path&) { return file_in(dir, name, text); };
}

class CliDbBadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("rccx_cli_db_bad_{}", ::getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_ / "ro", fs::perms::owner_all, ec);
    fs::remove_all(dir_, ec);
  }

  void run_all(const std::vector<Case>& cases) {
    int n = 0;
    for (const Case& c : cases) {
      SCOPED_TRACE(fmt::format("row {}: rccx {}", n++, c.args));
      if (c.skip_as_root && ::geteuid() == 0) continue;
      const fs::path db = dir_ / "cell.db";
      for (const char* s : {"", "-wal", "-shm"}) fs::remove(db.string() + s);
      if (!c.fresh_db) {
        rccl::StoredTransform keep;
        keep.robot = "microbo";
        keep.name = "KEEP";
        rccl::PositionDb(db).put(keep);
      }
      std::shared_ptr<void> held;
      if (c.prepare) held = c.prepare(dir_, db);
      const std::string before = snapshot(db);
      std::string args = c.args;
      for (const auto& [key, value] :
           {std::pair<std::string, std::string>{"{db}", db.string()}, {"{dir}", dir_.string()}}) {
        for (std::size_t at; (at = args.find(key)) != std::string::npos;) {
          args.replace(at, key.size(), value);
        }
      }
      const CliRun run = rccx_cli(args);
      EXPECT_EQ(run.exit_code, c.exit_code) << run.out;
      EXPECT_NE(run.out.find(c.message), std::string::npos)
          << "expected \"" << c.message << "\" in:\n"
          << run.out;
      if (c.exit_code != 0) {
        // One clear line, and not a crash or an exception's name.
        EXPECT_EQ(run.out.rfind("error: ", 0), 0u) << run.out;
        EXPECT_EQ(run.out.find("terminate"), std::string::npos) << run.out;
      }
      if (c.db_unchanged) {
        EXPECT_EQ(snapshot(db), before);
      }
      held.reset();
    }
  }

  fs::path dir_;
};

TEST_F(CliDbBadInput, PutRefusesBadArgumentsBeforeTouchingTheDatabase) {
  const std::string put = "db --db {db} put --robot microbo P --T ";
  run_all({
      {put + "1,0,0,0.3,0,1,0,0.1,0,0,1", 2, "11 numbers given, 12 needed"},
      {put + kT + ",5", 2, "13 numbers given, 12 needed"},
      {put + "1,0,0,inf,0,1,0,0.1,0,0,1,0.2", 2, "\"inf\" is not a number"},
      {put + "1,0,0,nan,0,1,0,0.1,0,0,1,0.2", 2, "\"nan\" is not a number"},
      {put + "1,0,0,5abc,0,1,0,0.1,0,0,1,0.2", 2, "\"5abc\" is not a number"},
      {put + "1,0,0,1e400,0,1,0,0.1,0,0,1,0.2", 2, "too large"},
      {put + "1,0,0,,0,1,0,0.1,0,0,1,0.2", 2, "missing"},
      {put + "''", 2, "empty"},
      {put + "1,0,0,0.3,0,1,0,0.1,0,0,2,0.2", 2, "not a rotation matrix"},
      // Finite but absurd: within 100 m on each axis, so that mm and products stay finite.
      {put + "1,0,0,1e308,0,1,0,0.1,0,0,1,0.2", 2, "out of range; give a number from -100 to 100"},
      {put + "1,0,0,100.5,0,1,0,0.1,0,0,1,0.2", 2, "out of range"},
      {"db --db {db} put --robot microbo P --xyz 1e308,0,0 --rpy 0,0,0", 2, "out of range"},
      {"db --db {db} put --robot microbo P --xyz 0.3,0,0", 2, "--xyz requires --rpy"},
      {"db --db {db} put --robot microbo P --rpy 0,0,1e400deg --xyz 0,0,0", 2, "too large"},
      {"db --db {db} put --robot microbo P --xyz 0.3,0,0 --rpy 0,nan,0", 2, "not an angle"},
      {"db --db {db} put --robot microbo P", 2, "give --T (12 numbers), or --xyz and --rpy"},
      {"db --db {db} put --robot microbo 'TWO WORDS' --T " + std::string(kT), 2, "not a name"},
      {"db --db {db} put --robot microbo " + std::string(33, 'N') + " --T " + kT, 2, "at most 32"},
      {"db --db {db} put --robot microbo '' --T " + std::string(kT), 2, "empty"},
      {"db --db {db} put --robot '' P --T " + std::string(kT), 2, "empty"},
      {"db --db {db} put --robot $'micr\\xf6bo' P --T " + std::string(kT), 2, "not a name"},
      {"db --db {db} put --robot microbo $'P\\xff' --T " + std::string(kT), 2, "not a name"},
      {put + kT + " --note $'caf\\xe9'", 2, "not UTF-8"},
      {put + kT + " --note $'two\\nlines'", 2, "control character"},
      {put + kT + " --note $'bell\\x07'", 2, "control character"},
      {put + kT + " --note " + std::string(1001, 'n'), 2, "at most 1000"},
      {put + kT + " --config l1n", 2, "configuration"},
      {put + kT + " --config abcdefghi", 2, "configuration"},
      {"db --db {db} --wait soon put --robot microbo P --T " + std::string(kT), 2, "--wait"},
      {"db --db '' put --robot microbo P --T " + std::string(kT), 2, "empty"},
      {"db --db {dir} put --robot microbo P --T " + std::string(kT), 2, "is a directory"},
      // A misspelt robot is refused, with the known ones and how to declare a new one.
      {"db --db {db} put --robot pmua560 P --T " + std::string(kT), 2,
       "\"pmua560\" is not a known robot; did you mean puma560? (known: microbo, panda, "
       "puma260, puma560, stanford, ur5e); check the spelling, or declare a new robot with "
       "--new-robot pmua560"},
      // --new-robot takes the robot's name, as import's does; the old switch is refused.
      {"db --db {db} put --robot gantry P --new-robot --T " + std::string(kT), 2, "not expected"},
      {"db --db {db} put --robot microbo P --xyz '' --rpy 0,0,0", 2, "empty"},
      {"db --db {db} put --robot gantry --new-robot gantri P --T " + std::string(kT), 2,
       "--new-robot \"gantri\" is not --robot \"gantry\""},
      {"db --db {db} put --new-robot a --new-robot b P --T " + std::string(kT), 2,
       "give --new-robot once"},
      {"db --db {db} put --new-robot 'a b' P --T " + std::string(kT), 2, "not a name"},
      // A bad name does not create the file.
      {"db --db {db} put --robot microbo 'A B' --T " + std::string(kT), 2, "not a name", {}, true},
      {"db --db {db} put --robot pmua560 P --T " + std::string(kT),
       2,
       "not a known robot",
       {},
       true},
      // What may be stored is.
      {"db --db {db} put --new-robot gantry P --T " + std::string(kT), 0, "", {}, false, false},
      {put + kT + " --note 'über dem Tisch' --config lun", 0, "", {}, false, false},
  });
  // gantry is now known, so a second put needs no --new-robot.
  const fs::path db = dir_ / "cell.db";
  EXPECT_EQ(
      rccx_cli("db --db " + db.string() + " put --robot gantry --new-robot gantry P --T " + kT)
          .exit_code,
      0);
  EXPECT_EQ(rccx_cli("db --db " + db.string() + " put --robot gantry Q --T " + kT).exit_code, 0);
}

TEST_F(CliDbBadInput, ShowListRmRefuseBadNamesAndReportMissingFiles) {
  run_all({
      {"db --db {db} show --robot microbo NOPE", 2, "has no NOPE for robot microbo"},
      {"db --db {db} show --robot microbo 'A B'", 2, "not a name"},
      {"db --db {db} rm --robot microbo NOPE", 2, "has no NOPE"},
      {"db --db {db} list ''", 2, "empty"},
      {"db --db {db} list --robot $'\\xff'", 2, "not a name"},
      {"db --db {db} list", 1, "does not exist", {}, true},
      {"db --db {dir}/not-a-db list", 1, "is it an rccx database?",
       with_file("not-a-db", std::string(8192, 'x'))},
  });
}

TEST_F(CliDbBadInput, AnUnknownRobotIsRefusedNamingTheNearest) {
  const auto stored_gantry = [](const fs::path&, const fs::path& db) {
    rccl::StoredTransform t;
    t.robot = "gantry";
    t.name = "HOME";
    rccl::PositionDb(db).put(t);
    return std::shared_ptr<void>();
  };
  const std::string nearest =
      "did you mean puma560? (known: microbo, panda, puma260, puma560, stanford, ur5e)";
  run_all({
      {"db --db {db} list --robot pmua560", 2, nearest},
      {"db --db {db} list --robot MICROBOO", 2, "did you mean microbo?"},
      {"db --db {db} show --robot pmua560 KEEP", 2, nearest},
      {"db --db {db} rm --robot pmua560 KEEP", 2, nearest},
      {"db --db {db} export --robot pmua560", 2, nearest},
      {"db --db {db} export --robot pmua560 {dir}/out.json", 2, nearest},
      // A robot of the database is known, and is the nearest of a typo of it.
      {"db --db {db} list --robot gantri", 2, "did you mean gantry?", stored_gantry},
      {"db --db {db} list --robot gantry", 0, "gantry HOME:", stored_gantry},
      // A shipped robot with nothing stored lists nothing, and that is no error.
      {"db --db {db} list --robot puma260", 0, ""},
  });
  EXPECT_FALSE(fs::exists(dir_ / "out.json"));
}

TEST_F(CliDbBadInput, ACorruptStoredValueIsSaidNeverPrintedAsInf) {
  // Rows another program (or an older rccx) wrote: a position of 1e308 m, an infinite one.
  const auto bad_rows = [](const fs::path&, const fs::path& db) {
    sqlite3* raw = nullptr;
    sqlite3_open(db.c_str(), &raw);
    sqlite3_exec(raw,
                 "INSERT INTO transforms VALUES ('microbo', 'FAR', 1,0,0, 0,1,0, 0,0,1, "
                 "1e308,0,0, 'm, rad', '', '', 5, 6);"
                 "INSERT INTO transforms VALUES ('microbo', 'INF', 1,0,0, 0,1,0, 0,0,1, "
                 "9e999,0,0, 'm, rad', '', '', 5, 6)",
                 nullptr, nullptr, nullptr);
    sqlite3_close(raw);
    return std::shared_ptr<void>();
  };
  // (list is below: its good lines come before the error.)
  for (const char* args : {"show --robot microbo FAR", "show --robot microbo INF", "export",
                           "export {dir}/out.json"}) {
    run_all({{std::string("db --db {db} ") + args, 1, "", bad_rows}});
  }
  const fs::path db = dir_ / "cell.db";
  const CliRun show = rccx_cli("db --db " + db.string() + " show --robot microbo FAR");
  EXPECT_NE(show.out.find("FAR of robot microbo: the stored value is corrupt (position (1e+308"),
            std::string::npos)
      << show.out;
  const CliRun list = rccx_cli("db --db " + db.string() + " list");
  EXPECT_EQ(list.exit_code, 1);
  EXPECT_NE(list.out.find("microbo INF: the stored value is corrupt (not a rigid transform"),
            std::string::npos)
      << list.out;
  EXPECT_NE(list.out.find("microbo KEEP: x 0.000"), std::string::npos) << list.out;
  EXPECT_NE(list.out.find("2 stored values are corrupt"), std::string::npos) << list.out;
  for (const CliRun& r : {show, list}) {
    EXPECT_EQ(r.out.find("inf"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("nan"), std::string::npos) << r.out;
  }
  EXPECT_FALSE(fs::exists(dir_ / "out.json"));
}

TEST_F(CliDbBadInput, XyzAndRpyStoreWhatTheMatrixDoesAndShowNamesItsAngles) {
  const fs::path db = dir_ / "cell.db";
  const std::string put = "db --db " + db.string() + " put --robot microbo ";
  // URDF's roll 10 deg about x, pitch 20 deg about y, yaw 30 deg about z.
  const math::Transform T{
      math::Rot3::from_urdf_rpy(math::deg_to_rad(10), math::deg_to_rad(20), math::deg_to_rad(30)),
      {0.325, -0.15, 0.25}};
  std::string rows;
  for (double v : T.rows()) rows += fmt::format("{}{}", rows.empty() ? "" : ",", v);
  ASSERT_EQ(rccx_cli(put + "BY_T --T " + rows).exit_code, 0);
  ASSERT_EQ(rccx_cli(put + "BY_M --xyz 0.325m,-0.15,0.25 --rpy 10deg,20deg,30deg").exit_code, 0);
  ASSERT_EQ(rccx_cli(put + "BY_MM --xyz 325mm,-150mm,250mm --rpy 0.17453292519943295rad,"
                           "0.3490658503988659,0.5235987755982988")
                .exit_code,
            0);
  const rccl::PositionDb d(db, rccl::PositionDb::Open::existing);
  const math::Transform by_t = d.get("microbo", "BY_T")->value;
  EXPECT_LT(math::max_abs_difference(by_t, T), 1e-15);
  for (const char* name : {"BY_M", "BY_MM"}) {
    EXPECT_LT(math::max_abs_difference(d.get("microbo", name)->value, by_t), 1e-15) << name;
  }
  // The angles printed are those typed, with their convention named; Paul's are the reverse.
  const CliRun show = rccx_cli("db --db " + db.string() + " show --robot microbo BY_M");
  ASSERT_EQ(show.exit_code, 0) << show.out;
  for (const char* piece :
       {"x 325.000 y -150.000 z 250.000 mm, URDF rpy (about fixed x, y, z) 10.000 20.000 30.000 "
        "deg",
        "Paul's RPY (RCCL, cell files: Rot(z, roll) Rot(y, pitch) Rot(x, yaw)): roll 30.000 "
        "pitch 20.000 yaw 10.000 deg"}) {
    EXPECT_NE(show.out.find(piece), std::string::npos) << piece << "\n" << show.out;
  }
  // The help says both forms and the convention.
  const CliRun help = rccx_cli("db put --help");
  for (const char* word :
       {"--T", "--xyz", "--rpy", "URDF", "roll about x", "--new-robot NAME", "100 m"}) {
    EXPECT_NE(help.out.find(word), std::string::npos) << word << "\n" << help.out;
  }
}

TEST_F(CliDbBadInput, ALockedDatabaseIsBusyNotDamaged) {
  const auto lock = [](const fs::path&, const fs::path& db) {
    return std::static_pointer_cast<void>(std::make_shared<Lock>(db));
  };
  run_all({
      {"db --db {db} --wait 0.2 put --robot microbo P --T " + std::string(kT), 1,
       "is busy: another process is writing it (waited 0.2 s); try again when it has finished",
       lock},
      {"db --db {db} --wait 0.2 rm --robot microbo KEEP", 1, "is busy", lock},
      {"db --db {db} --wait 0.2 import {dir}/in.json", 1, "is busy",
       [lock](const fs::path& dir, const fs::path& db) {
         file_in(dir, "in.json", export_with("[" + entry("microbo", "P") + "]"));
         return lock(dir, db);
       }},
  });
}

TEST_F(CliDbBadInput, ExportFailuresLeaveTheOldFileAndNoTemporary) {
  const std::string good = "{\"an\": \"old good export\"}\n";
  const auto old_file_in = [good](const std::string& sub) {
    return [good, sub](const fs::path& dir, const fs::path&) {
      fs::create_directories(dir / sub);
      write(dir / sub / "out.json", good);
      if (sub == "ro") fs::permissions(dir / sub, fs::perms::owner_read | fs::perms::owner_exec);
      return std::shared_ptr<void>();
    };
  };
  run_all({
      {"db --db {db} export > /dev/full", 1, "cannot write to standard output"},
      {"db --db {db} export {dir}", 2, "is a directory"},
      {"db --db {db} export {dir}/missing/out.json", 1, "cannot write"},
      {"db --db {db} export {dir}/ro/out.json", 1, "cannot write", old_file_in("ro"), false, true,
       true},
      {"db --db {db} export ''", 2, "empty"},
      {"db --db {db} export /dev/full", 1, "cannot write /dev/full: No space left on device"},
      {"db --db /dev/null list", 2, "not a regular file"},
      {"db --db {db} export {dir}/ok/out.json", 0, "", old_file_in("ok")},
  });
  if (::geteuid() != 0) {
    fs::permissions(dir_ / "ro", fs::perms::owner_all);
    EXPECT_EQ(read(dir_ / "ro" / "out.json"), good);  // byte for byte
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_ / "ro"), fs::directory_iterator()), 1);
  }
  EXPECT_NE(read(dir_ / "ok" / "out.json").find("KEEP"), std::string::npos);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_ / "ok"), fs::directory_iterator()), 1);
}

TEST_F(CliDbBadInput, AFullStandardOutputIsSaidOnce) {
  const fs::path db = dir_ / "cell.db";
  rccl::StoredTransform keep;
  keep.robot = "microbo";
  keep.name = "KEEP";
  rccl::PositionDb(db).put(keep);
  const CliRun run = rccx_cli("db --db " + db.string() + " export > /dev/full");
  EXPECT_EQ(run.exit_code, 1) << run.out;
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1) << "one line:\n" << run.out;
}

TEST_F(CliDbBadInput, ImportIsStrictAndAllOrNothing) {
  const std::string imp = "db --db {db} import {dir}/in.json";
  const auto in = [](const std::string& text) { return with_file("in.json", text); };
  const std::string good = entry("microbo", "GOOD");
  run_all({
      {"db --db {db} import {dir}", 2, "is a directory; name a file"},
      {"db --db {db} import {dir}/missing.json", 2, "No such file"},
      // A named pipe nobody writes: refused at once, not waited on for ever.
      {"db --db {db} import {dir}/fifo", 2, "not a regular file",
       [](const fs::path& dir, const fs::path&) {
         fs::remove(dir / "fifo");
         ::mkfifo((dir / "fifo").c_str(), 0600);
         return std::shared_ptr<void>();
       }},
      {"db --db {db} import /dev/zero", 2, "not a regular file"},
      {"db --db {db} import ''", 2, "empty"},
      {imp, 2, "not JSON", in("")},
      {imp, 2, "not JSON", in("{\"rccx_position_database\": 1, ")},
      {imp, 2, "\"transforms\" is a null",
       in(R"({"rccx_position_database": 1, "transforms": null})")},
      {imp, 2, "written by a newer rccx",
       in(R"({"rccx_position_database": 99, "transforms": []})")},
      {imp, 2, "not a version", in(R"({"rccx_position_database": "1", "transforms": []})")},
      {imp, 2, "no \"rccx_position_database\"", in(R"({"transforms": []})")},
      {imp, 2, "transforms[1] (\"P\"), key \"T_rows_m\": 13 numbers",
       in(export_with("[" + good + "," +
                      entry("microbo", "P", "", "[1,0,0,0.1, 0,1,0,0.2, 0,0,1,0.3, 9]") + "]"))},
      {imp, 2, "key \"colour\"",
       in(export_with("[" + entry("microbo", "P", R"(, "colour": 1)") + "]"))},
      {imp, 2, "not JSON",
       in(export_with("[" + entry("microbo", "P", "", "[1,0,0,1e400, 0,1,0,0.2, 0,0,1,0.3]") +
                      "]"))},
      {imp, 2, "control character",
       in(export_with("[" + good + "," + entry("microbo", "P", R"(, "note": "a\u0000b")") + "]"))},
      {imp, 2, "not JSON",
       in(export_with("[" + entry("microbo", "P", ", \"note\": \"\xff\"") + "]"))},
      {imp, 2, "key \"name\"", in(export_with("[" + entry("microbo", "A B") + "]"))},
      {imp, 2, "rigid",
       in(export_with("[" + entry("microbo", "P", "", "[1,0,0,0, 0,1,0,0, 0,0,3,0]") + "]"))},
      {imp, 2, "give each (robot, name) once", in(export_with("[" + good + "," + good + "]"))},
      {imp, 2, "key \"created_unix_s\"",
       in(export_with("[" + entry("microbo", "P", R"(, "created_unix_s": -1)") + "]"))},
      {imp, 2,
       "robot \"gantry\", \"pmua560\" not known (known: microbo, panda, puma260, puma560, "
       "stanford, ur5e); check the file, or declare each new robot with --new-robot NAME",
       in(export_with("[" + good + "," + entry("pmua560", "P") + "," + entry("gantry", "P") +
                      "]"))},
      {imp + " --new-robot gantry", 2, "robot \"pmua560\" not known",
       in(export_with("[" + entry("pmua560", "P") + "," + entry("gantry", "P") + "]"))},
      {imp, 2, "not known", in(export_with("[" + entry("gantry", "P") + "]")), true},
      // What is good is imported, from a file or from standard input.
      {imp + " --new-robot gantry", 0, "imported 2 transforms",
       in(export_with("[" + good + "," + entry("gantry", "P") + "]")), false, false},
      {"db --db {db} import - < {dir}/in.json", 0, "imported 1 transforms",
       in(export_with("[" + good + "]")), false, false},
  });
}

TEST_F(CliDbBadInput, OddBytesInAnOldFileDoNotStopShowListOrExport) {
  const auto odd_row = [](const fs::path&, const fs::path& db) {
    sqlite3* raw = nullptr;
    sqlite3_open(db.c_str(), &raw);
    sqlite3_exec(raw,
                 "INSERT INTO transforms VALUES ('microbo', 'ODD', 1,0,0, 0,1,0, 0,0,1, "
                 "0.1,0.2,0.3, 'm, rad', CAST(X'6cff' AS TEXT), CAST(X'410042ff0a1b' AS TEXT), "
                 "5, 6)",
                 nullptr, nullptr, nullptr);
    sqlite3_close(raw);
    return std::shared_ptr<void>();
  };
  run_all({
      {"db --db {db} show --robot microbo ODD", 0, "\"A\\x00B\\xff\\x0a\\x1b\"", odd_row},
      {"db --db {db} list", 0, "microbo ODD", odd_row},
      {"db --db {db} export", 0, "\"ODD\"", odd_row},
  });
}

}  // namespace
