// The position database on SQLite: exact round trips, lookups by robot and pattern, clear
// errors that change nothing (bad names, a transform that is not rigid, a missing, foreign or
// newer file), two connections at once, and a writer killed with SIGKILL mid-transaction
// leaving an intact file with every committed row.
#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "rccx/math/units.hpp"
#include "rccx/rccl/position_db.hpp"
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
  EXPECT_EQ(db.list().size(), 2u);  // KEEP and the 32-character one
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

}  // namespace
