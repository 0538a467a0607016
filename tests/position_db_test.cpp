// The position database on SQLite: exact round trips, lookups by robot and pattern, clear
// errors that change nothing (bad names, a transform that is not rigid, a missing, foreign or
// newer file), two connections at once, and a writer killed with SIGKILL mid-transaction
// leaving an intact file with every committed row; several processes creating one new file at
// once; a locked file reported as busy; rows with odd bytes written by other programs.
#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "rccx/math/units.hpp"
#include "rccx/rccl/position_db.hpp"
#include "rccx/rccl/position_export.hpp"
#include "temp_db.hpp"

namespace {

using namespace rccx;
using namespace rccx::math::literals;
using rccl::DatabaseError;
using rccl::PositionDb;
using rccl::StoredTransform;

using test::TempDb;

StoredTransform sample(const std::string& robot, const std::string& name, double x) {
  StoredTransform t;
  t.robot = robot;
  t.name = name;
  t.value = {math::Rot3::rot_x(180_deg) * math::Rot3::rot_z(0.3), {x, -0.15, 0.3}};
  t.configuration = "n";
  t.note = "taught by hand";
  return t;
}

template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const DatabaseError& e) {
    return e.what();
  }
  return "";
}

TEST(PositionDb, RoundTripsExactlyAndListsByRobotAndPattern) {
  TempDb file;
  PositionDb db(file.path);
  EXPECT_EQ(db.schema_version(), PositionDb::kSchemaVersion);
  const StoredTransform pick = sample("microbo", "PICK", 0.325);
  db.put(pick);
  db.put(sample("microbo", "PLACE", 0.35));
  db.put(sample("puma560", "PICK", 0.4));
  const auto got = db.get("microbo", "PICK");
  ASSERT_TRUE(got);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) EXPECT_EQ((*got).value(r, c), pick.value(r, c));  // bit for bit
  }
  EXPECT_EQ(got->configuration, "n");
  EXPECT_EQ(got->note, "taught by hand");
  EXPECT_GT(got->created_unix_s, 0);
  EXPECT_EQ(db.list("microbo").size(), 2u);
  EXPECT_EQ(db.list("", "PICK").size(), 2u);
  EXPECT_EQ(db.list("microbo", "PL*").size(), 1u);
  EXPECT_FALSE(db.get("puma560", "PLACE"));
  // Replacing keeps the created time.
  StoredTransform moved = sample("microbo", "PICK", 0.3);
  db.put(moved);
  EXPECT_EQ(db.get("microbo", "PICK")->value.p.x, 0.3);
  EXPECT_EQ(db.get("microbo", "PICK")->created_unix_s, got->created_unix_s);
  EXPECT_TRUE(db.remove("microbo", "PICK"));
  EXPECT_FALSE(db.remove("microbo", "PICK"));
  EXPECT_EQ(db.list().size(), 2u);
  // As transforms of equations.
  EXPECT_EQ(db.constant("microbo", "PLACE")->value().p.x, 0.35);
  EXPECT_EQ(db.hold("puma560", "PICK")->kind(), rccl::TransformKind::hold);
  EXPECT_NE(error_of([&] { (void)db.constant("microbo", "NOPE"); }).find("NOPE"),
            std::string::npos);
}

TEST(PositionDb, BadNamesAndNonRigidTransformsAreRefusedAndChangeNothing) {
  TempDb file;
  PositionDb db(file.path);
  db.put(sample("microbo", "KEEP", 0.3));
  EXPECT_NE(error_of([&] { db.put(sample("microbo", "", 0.3)); }).find("empty"), std::string::npos);
  const std::string long_name(33, 'N');
  EXPECT_NE(error_of([&] { db.put(sample("microbo", long_name, 0.3)); }).find("at most 32"),
            std::string::npos);
  EXPECT_NO_THROW(db.put(sample("microbo", std::string(32, 'N'), 0.3)));  // 32 is allowed
  EXPECT_NE(error_of([&] { db.put(sample("microbo", "TWO WORDS", 0.3)); }), "");
  StoredTransform skew = sample("microbo", "SKEW", 0.3);
  skew.value.R.n = skew.value.R.n * 1.01;
  EXPECT_NE(error_of([&] { db.put(skew); }).find("rigid"), std::string::npos);
  StoredTransform bad = sample("microbo", "NAN", 0.3);
  bad.value.p.x = NAN;
  EXPECT_NE(error_of([&] { db.put(bad); }), "");
  // Finite but absurd: 1e308 m overflows in mm and in any product of transforms.
  StoredTransform far = sample("microbo", "FAR", 0.3);
  far.value.p.y = 1e308;
  EXPECT_NE(error_of([&] { db.put(far); }).find("beyond 100 m"), std::string::npos);
  far.value.p.y = -(rccl::kMaxPosition_m + 1e-9);
  EXPECT_NE(error_of([&] { db.put(far); }).find("beyond"), std::string::npos);
  far.value.p.y = -rccl::kMaxPosition_m;  // the bound itself is stored
  EXPECT_NO_THROW(db.put(far));
  EXPECT_EQ(PositionDb::value_problem(far.value), "");
  EXPECT_EQ(db.list().size(), 3u);  // KEEP, the 32-character one and FAR at the bound
}

TEST(PositionDb, MissingForeignAndNewerFilesGiveClearErrors) {
  TempDb missing;
  EXPECT_NE(error_of([&] {
              PositionDb db(missing.path, PositionDb::Open::existing);
            }).find("does not exist"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(missing.path));  // not created

  TempDb foreign;
  {
    std::ofstream out(foreign.path);
    out << "this is a text file, not a database\n" << std::string(4096, 'x');
  }
  const auto size = std::filesystem::file_size(foreign.path);
  const std::string message = error_of([&] { PositionDb db(foreign.path); });
  EXPECT_NE(message.find("not a database"), std::string::npos) << message;
  EXPECT_EQ(std::filesystem::file_size(foreign.path), size);  // untouched

  // SQLite would open these and put a -wal file beside them.
  EXPECT_NE(error_of([&] {
              PositionDb db(std::filesystem::temp_directory_path());
            }).find("is a directory"),
            std::string::npos);
  EXPECT_NE(error_of([&] { PositionDb db("/dev/null"); }).find("not a regular file"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists("/dev/null-wal"));

  TempDb newer;
  { PositionDb db(newer.path); }
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(newer.path.c_str(), &raw), SQLITE_OK);
  sqlite3_exec(raw, "PRAGMA user_version = 99", nullptr, nullptr, nullptr);
  sqlite3_close(raw);
  EXPECT_NE(error_of([&] { PositionDb db(newer.path); }).find("newer rccx"), std::string::npos);
}

TEST(PositionDb, TwoConnectionsReadAndWriteAtOnce) {
  TempDb file;
  PositionDb a(file.path);
  PositionDb b(file.path);
  a.put(sample("microbo", "A", 0.3));
  b.put(sample("microbo", "B", 0.31));
  EXPECT_TRUE(b.get("microbo", "A"));
  EXPECT_TRUE(a.get("microbo", "B"));
}

std::string integrity(const std::filesystem::path& file) {
  sqlite3* raw = nullptr;
  sqlite3_open(file.c_str(), &raw);
  sqlite3_stmt* s = nullptr;
  sqlite3_prepare_v2(raw, "PRAGMA integrity_check", -1, &s, nullptr);
  std::string result = sqlite3_step(s) == SQLITE_ROW
                           ? reinterpret_cast<const char*>(sqlite3_column_text(s, 0))
                           : "no answer";
  sqlite3_finalize(s);
  sqlite3_close(raw);
  return result;
}

// A child process puts rows N0, N1, ... as fast as it can and tells the parent, through a pipe,
// each one it has committed; the parent kills it with SIGKILL at a random moment. The file must
// pass PRAGMA integrity_check and hold every row reported committed (and at most one more).
TEST(PositionDb, WriterKilledMidTransactionLeavesAnIntactFile) {
  std::mt19937 rng(4);
  for (int round = 0; round < 5; ++round) {
    TempDb file;
    { PositionDb create(file.path); }
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(fds[0]);
      try {
        PositionDb db(file.path);
        for (std::uint32_t i = 0;; ++i) {
          db.put(sample("microbo", "N" + std::to_string(i), 0.3 + 1e-6 * i));
          if (::write(fds[1], &i, sizeof i) != sizeof i) ::_exit(3);
        }
      } catch (...) {
        ::_exit(2);
      }
    }
    ::close(fds[1]);
    std::this_thread::sleep_for(std::chrono::milliseconds(20 + rng() % 200));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the writer ended by itself: " << status;
    std::int64_t last = -1;
    std::uint32_t i = 0;
    while (::read(fds[0], &i, sizeof i) == sizeof i) last = i;
    ::close(fds[0]);

    EXPECT_EQ(integrity(file.path), "ok");
    PositionDb db(file.path, PositionDb::Open::existing);
    const auto rows = db.list("microbo");
    EXPECT_GE(static_cast<std::int64_t>(rows.size()), last + 1);
    EXPECT_LE(static_cast<std::int64_t>(rows.size()), last + 2);
    for (std::int64_t k = 0; k <= last; ++k) {
      const auto r = db.get("microbo", "N" + std::to_string(k));
      ASSERT_TRUE(r) << "committed row N" << k << " is missing";
      EXPECT_EQ(r->value.p.x, 0.3 + 1e-6 * static_cast<double>(k));
    }
  }
}

// Several processes create the same new file at the same instant (a pipe closing is their
// start signal) and each puts a row: every one succeeds ("table already exists" and a failing
// journal-mode change were the failures), every row is there, the file is intact.
TEST(PositionDb, ProcessesCreatingOneNewFileAtOnceAllSucceed) {
  for (const int processes : {3, 8}) {
    TempDb file;
    int start[2];
    ASSERT_EQ(::pipe(start), 0);
    std::vector<pid_t> children;
    for (int i = 0; i < processes; ++i) {
      const pid_t child = ::fork();
      ASSERT_GE(child, 0);
      if (child == 0) {
        ::close(start[1]);
        char c = 0;
        (void)::read(start[0], &c, 1);  // returns when the parent closes its end
        try {
          PositionDb db(file.path);
          db.put(sample("microbo", "P" + std::to_string(i), 0.3));
        } catch (const std::exception& e) {
          (void)::write(2, e.what(), std::strlen(e.what()));
          ::_exit(1);
        }
        ::_exit(0);
      }
      children.push_back(child);
    }
    ::close(start[0]);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // all waiting on the pipe
    ::close(start[1]);
    for (const pid_t child : children) {
      int status = 0;
      ::waitpid(child, &status, 0);
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
          << "a creating process failed: " << status;
    }
    EXPECT_EQ(integrity(file.path), "ok");
    PositionDb db(file.path, PositionDb::Open::existing);
    EXPECT_EQ(db.list("microbo").size(), static_cast<std::size_t>(processes));
  }
}

/// A second connection holding the write lock (BEGIN IMMEDIATE), or the whole file
/// (exclusive locking mode), until destroyed.
struct Holder {
  Holder(const std::filesystem::path& file, bool exclusive) {
    sqlite3_open(file.c_str(), &raw);
    if (exclusive) sqlite3_exec(raw, "PRAGMA locking_mode=EXCLUSIVE", nullptr, nullptr, nullptr);
    sqlite3_exec(raw, "BEGIN IMMEDIATE", nullptr, nullptr, nullptr);
    sqlite3_exec(raw, "DELETE FROM transforms WHERE name = 'none'", nullptr, nullptr, nullptr);
    if (exclusive) sqlite3_exec(raw, "COMMIT", nullptr, nullptr, nullptr);  // keeps the lock
  }
  ~Holder() {
    sqlite3_exec(raw, "ROLLBACK", nullptr, nullptr, nullptr);
    sqlite3_close(raw);
  }
  Holder(const Holder&) = delete;
  Holder& operator=(const Holder&) = delete;
  sqlite3* raw = nullptr;
};

template <class F>
std::string busy_error_of(F f) {
  try {
    f();
  } catch (const rccl::DatabaseBusy& e) {
    return e.what();
  } catch (const DatabaseError& e) {
    return std::string("not DatabaseBusy: ") + e.what();
  }
  return "no error";
}

TEST(PositionDb, ALockedFileIsReportedAsBusyNotAsDamaged) {
  TempDb file;
  { PositionDb(file.path).put(sample("microbo", "KEEP", 0.3)); }
  const auto wait = std::chrono::milliseconds(100);
  {
    const Holder writer(file.path, false);
    PositionDb db(file.path, PositionDb::Open::existing, wait);  // readers go on in WAL mode
    EXPECT_TRUE(db.get("microbo", "KEEP"));
    const std::string put = busy_error_of([&] { db.put(sample("microbo", "NEW", 0.3)); });
    EXPECT_NE(put.find("is busy: another process is writing it (waited 0.1 s); try again"),
              std::string::npos)
        << put;
    EXPECT_EQ(put.find("damaged"), std::string::npos) << put;
    EXPECT_NE(busy_error_of([&] { db.remove("microbo", "KEEP"); }).find("busy"), std::string::npos);
  }
  {
    const Holder whole(file.path, true);  // even opening (the journal-mode pragma) waits
    const auto t0 = std::chrono::steady_clock::now();
    const std::string open =
        busy_error_of([&] { PositionDb db(file.path, PositionDb::Open::existing, wait); });
    EXPECT_NE(open.find("is busy"), std::string::npos) << open;
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(3));  // no hang
  }
  PositionDb db(file.path, PositionDb::Open::existing, wait);  // free again
  EXPECT_EQ(db.list().size(), 1u);
  db.put(sample("microbo", "NEW", 0.3));
}

TEST(PositionDb, RobotNotesAndConfigurationsAreCheckedAsUtf8WithALength) {
  TempDb file;
  PositionDb db(file.path);
  db.put(sample("microbo", "KEEP", 0.3));
  const auto refused = [&](StoredTransform t, const std::string& expected) {
    std::string message;
    try {
      db.put(t);
    } catch (const rccl::InvalidTransform& e) {
      message = e.what();
    }
    EXPECT_NE(message.find(expected), std::string::npos)
        << "expected \"" << expected << "\" in \"" << message << "\"";
  };
  StoredTransform t = sample("", "A", 0.3);
  refused(t, "robot name");
  t.robot = "puma 560";
  refused(t, "not a name");
  t.robot =
      "micr\xc3"
      "bo";  // not UTF-8, not ASCII
  refused(t, "not a name");
  t.robot = std::string(33, 'r');
  refused(t, "at most 32");
  t = sample("microbo", "N\xff", 0.3);
  refused(t, "not a name");
  t = sample("microbo", "A", 0.3);
  t.note = std::string("before\0after", 12);  // a NUL would cut the note in C and SQLite
  refused(t, "control character");
  t.note = "caf\xe9";  // Latin-1, not UTF-8
  refused(t, "not UTF-8");
  t.note = "line\nbreak";
  refused(t, "control character");
  t.note = std::string(rccl::kMaxNote + 1, 'n');
  refused(t, "at most 1000");
  t.note = std::string(rccl::kMaxNote, 'n');
  t.configuration = "l1n";
  refused(t, "configuration");
  t.configuration = "abcdefghi";
  refused(t, "configuration");
  t.configuration = "lun";
  t.created_unix_s = -1;
  refused(t, "times");
  t.created_unix_s = 0;
  EXPECT_NO_THROW(db.put(t));  // the limits themselves are allowed
  t = sample("microbo", "B", 0.3);
  t.note = "über den Tisch, 30° gedreht\t";  // UTF-8 and a tab are fine
  EXPECT_NO_THROW(db.put(t));
  EXPECT_EQ(db.get("microbo", "B")->note, t.note);
  EXPECT_EQ(db.list().size(), 3u);  // KEEP, A, B
  EXPECT_EQ(db.robots(), std::vector<std::string>{"microbo"});
}

// A file written by another program (or an older rccx) may hold any bytes: reading, listing
// and exporting it must not throw or cut it at a NUL.
TEST(PositionDb, RowsWithOddBytesFromOtherProgramsCanBeReadAndExported) {
  TempDb file;
  { PositionDb(file.path).put(sample("microbo", "KEEP", 0.3)); }
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(file.path.c_str(), &raw), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(raw,
                         "INSERT INTO transforms VALUES (CAST(X'6dff' AS TEXT), "
                         "CAST(X'5000ff' AS TEXT), 1,0,0, 0,1,0, 0,0,1, 0.1,0.2,0.3, 'm, rad', "
                         "CAST(X'0aff' AS TEXT), CAST(X'41fe0042' AS TEXT), 5, 6)",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(raw);
  PositionDb db(file.path, PositionDb::Open::existing);
  const auto all = db.list();
  ASSERT_EQ(all.size(), 2u);
  const auto odd = db.get("m\xff", std::string("P\0\xff", 3));
  ASSERT_TRUE(odd);
  EXPECT_EQ(odd->note, std::string("A\xfe\0B", 4));  // whole, not cut at the NUL
  std::string text;
  ASSERT_NO_THROW(text = rccl::position_export_json(all));
  EXPECT_NE(text.find("\"KEEP\""), std::string::npos);
  EXPECT_NE(text.find("\xef\xbf\xbd"), std::string::npos);  // U+FFFD for the bad bytes
  // Such an export is refused on import rather than stored again.
  EXPECT_THROW((void)rccl::parse_position_export(text, "odd.json"), rccl::PositionExportError);
}

}  // namespace
