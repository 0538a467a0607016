#include "rccx/rccl/position_db.hpp"

#include <fmt/format.h>
#include <sqlite3.h>

#include <array>
#include <cctype>
#include <memory>

namespace rccx::rccl {
namespace {

/// One prepared statement, finalized on every path out.
class Statement {
 public:
  Statement(sqlite3* db, std::string_view sql, const std::filesystem::path& file) : db_(db) {
    if (sqlite3_prepare_v2(db, sql.data(), static_cast<int>(sql.size()), &stmt_, nullptr) !=
        SQLITE_OK) {
      throw DatabaseError(
          fmt::format("position database {}: {} (is it an rccx database? a "
                      "file of another kind, or a damaged one, cannot be used)",
                      file.string(), sqlite3_errmsg(db)));
    }
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  void bind(int i, std::string_view text) {
    // An empty view may have no data pointer, which SQLite would bind as NULL, not ''.
    sqlite3_bind_text(stmt_, i, text.empty() ? "" : text.data(), static_cast<int>(text.size()),
                      SQLITE_TRANSIENT);
  }
  void bind(int i, double v) { sqlite3_bind_double(stmt_, i, v); }
  void bind(int i, std::int64_t v) { sqlite3_bind_int64(stmt_, i, v); }
  /// SQLITE_ROW or SQLITE_DONE; anything else throws.
  int step(const std::filesystem::path& file) {
    const int rc = sqlite3_step(stmt_);
    if (rc != SQLITE_ROW && rc != SQLITE_DONE) {
      throw DatabaseError(
          fmt::format("position database {}: {}{}", file.string(), sqlite3_errmsg(db_),
                      rc == SQLITE_BUSY ? " (another process holds it: try again)" : ""));
    }
    return rc;
  }
  [[nodiscard]] std::string text(int col) const {
    const auto* p = sqlite3_column_text(stmt_, col);
    return p ? std::string(reinterpret_cast<const char*>(p)) : std::string();
  }
  [[nodiscard]] double real(int col) const { return sqlite3_column_double(stmt_, col); }
  [[nodiscard]] std::int64_t integer(int col) const { return sqlite3_column_int64(stmt_, col); }

 private:
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

void exec(sqlite3* db, const char* sql, const std::filesystem::path& file) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string what = error ? error : sqlite3_errmsg(db);
    sqlite3_free(error);
    throw DatabaseError(
        fmt::format("position database {}: {} (is it an rccx database? a file "
                    "of another kind, or a damaged one, cannot be used)",
                    file.string(), what));
  }
}

std::int64_t now_unix_s() {
  return std::chrono::duration_cast<std::chrono::seconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

constexpr const char* kColumns =
    "robot, name, nx, ny, nz, ox, oy, oz, ax, ay, az, px, py, pz, configuration, note, "
    "created, changed";

StoredTransform row(const Statement& s) {
  StoredTransform t;
  t.robot = s.text(0);
  t.name = s.text(1);
  t.value.R.n = {s.real(2), s.real(3), s.real(4)};
  t.value.R.o = {s.real(5), s.real(6), s.real(7)};
  t.value.R.a = {s.real(8), s.real(9), s.real(10)};
  t.value.p = {s.real(11), s.real(12), s.real(13)};
  t.configuration = s.text(14);
  t.note = s.text(15);
  t.created_unix_s = s.integer(16);
  t.changed_unix_s = s.integer(17);
  return t;
}

/// A transaction that rolls back unless committed.
class Transaction {
 public:
  Transaction(sqlite3* db, const std::filesystem::path& file) : db_(db), file_(file) {
    exec(db_, "BEGIN IMMEDIATE", file_);
  }
  ~Transaction() {
    if (!done_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit() {
    exec(db_, "COMMIT", file_);
    done_ = true;
  }

 private:
  sqlite3* db_;
  const std::filesystem::path& file_;
  bool done_ = false;
};

}  // namespace

void PositionDb::check_name(std::string_view name) {
  if (name.empty()) throw DatabaseError("a transform name may not be empty");
  if (name.size() > kMaxTransformName) {
    throw DatabaseError(fmt::format("transform name '{}' has {} characters; at most {}", name,
                                    name.size(), kMaxTransformName));
  }
  for (const char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) {
      throw DatabaseError(fmt::format(
          "transform name '{}': '{}' is not allowed (letters, digits, _ - . only)", name, c));
    }
  }
}

PositionDb::PositionDb(const std::filesystem::path& file, Open mode,
                       std::chrono::milliseconds busy_timeout)
    : path_(file) {
  std::error_code ec;
  if (mode == Open::existing && !std::filesystem::exists(file, ec)) {
    throw DatabaseError(
        fmt::format("position database {} does not exist (create it with a "
                    "first put, e.g. `rccx db put`, or check the path)",
                    file.string()));
  }
  const int flags = SQLITE_OPEN_READWRITE | (mode == Open::create ? SQLITE_OPEN_CREATE : 0) |
                    SQLITE_OPEN_FULLMUTEX;
  if (sqlite3_open_v2(file.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
    const std::string what = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw DatabaseError(
        fmt::format("position database {} cannot be opened: {}", file.string(), what));
  }
  try {
    sqlite3_busy_timeout(db_, static_cast<int>(busy_timeout.count()));
    exec(db_, "PRAGMA journal_mode=WAL", path_);  // also the first read: "not a database"
    exec(db_, "PRAGMA synchronous=NORMAL", path_);
    migrate();
  } catch (...) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  }
}

PositionDb::~PositionDb() {
  sqlite3_close(db_);
}

int PositionDb::schema_version() const {
  Statement s(db_, "PRAGMA user_version", path_);
  s.step(path_);
  return static_cast<int>(s.integer(0));
}

void PositionDb::migrate() {
  const int version = schema_version();
  if (version > kSchemaVersion) {
    throw DatabaseError(
        fmt::format("position database {} has schema version {}; this rccx "
                    "knows up to {} (use a newer rccx)",
                    path_.string(), version, kSchemaVersion));
  }
  if (version == kSchemaVersion) return;
  Transaction t(db_, path_);
  // Each step takes the file one version up; a new schema adds a step here.
  if (version < 1) {
    exec(db_,
         "CREATE TABLE transforms ("
         " robot TEXT NOT NULL, name TEXT NOT NULL,"
         " nx REAL NOT NULL, ny REAL NOT NULL, nz REAL NOT NULL,"
         " ox REAL NOT NULL, oy REAL NOT NULL, oz REAL NOT NULL,"
         " ax REAL NOT NULL, ay REAL NOT NULL, az REAL NOT NULL,"
         " px REAL NOT NULL, py REAL NOT NULL, pz REAL NOT NULL,"  // m
         " units TEXT NOT NULL DEFAULT 'm, rad',"
         " configuration TEXT NOT NULL DEFAULT '', note TEXT NOT NULL DEFAULT '',"
         " created INTEGER NOT NULL, changed INTEGER NOT NULL,"  // unix s
         " PRIMARY KEY (robot, name))",
         path_);
  }
  exec(db_, fmt::format("PRAGMA user_version = {}", kSchemaVersion).c_str(), path_);
  t.commit();
}

std::optional<StoredTransform> PositionDb::get(std::string_view robot,
                                               std::string_view name) const {
  Statement s(db_,
              fmt::format("SELECT {} FROM transforms WHERE robot = ?1 AND name = ?2", kColumns),
              path_);
  s.bind(1, robot);
  s.bind(2, name);
  if (s.step(path_) != SQLITE_ROW) return std::nullopt;
  return row(s);
}

void PositionDb::check(const StoredTransform& t) {
  check_name(t.name);
  if (t.robot.empty()) throw DatabaseError(fmt::format("transform {}: name its robot", t.name));
  if (!is_rigid(t.value)) {
    throw DatabaseError(
        fmt::format("transform {}: not a rigid transform (its rotation must be "
                    "orthonormal and right-handed, every element finite)",
                    t.name));
  }
}

void PositionDb::put(const StoredTransform& t) {
  check(t);
  Transaction tr(db_, path_);
  insert(t);
  tr.commit();
}

void PositionDb::put(const std::vector<StoredTransform>& all) {
  for (const StoredTransform& t : all) check(t);
  Transaction tr(db_, path_);
  for (const StoredTransform& t : all) insert(t);
  tr.commit();
}

void PositionDb::insert(const StoredTransform& t) {
  const std::int64_t now = now_unix_s();
  Statement s(db_,
              fmt::format("INSERT INTO transforms ({}) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, "
                          "?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16, ?17, ?18) "
                          "ON CONFLICT (robot, name) DO UPDATE SET nx = ?3, ny = ?4, nz = ?5, "
                          "ox = ?6, oy = ?7, oz = ?8, ax = ?9, ay = ?10, az = ?11, px = ?12, "
                          "py = ?13, pz = ?14, configuration = ?15, note = ?16, changed = ?18",
                          kColumns),
              path_);
  s.bind(1, t.robot);
  s.bind(2, t.name);
  const std::array<double, 12> v = {t.value.R.n.x, t.value.R.n.y, t.value.R.n.z, t.value.R.o.x,
                                    t.value.R.o.y, t.value.R.o.z, t.value.R.a.x, t.value.R.a.y,
                                    t.value.R.a.z, t.value.p.x,   t.value.p.y,   t.value.p.z};
  for (int i = 0; i < 12; ++i) s.bind(3 + i, v[static_cast<std::size_t>(i)]);
  s.bind(15, t.configuration);
  s.bind(16, t.note);
  // Times given (an import) are kept; a new put is stamped now.
  s.bind(17, t.created_unix_s > 0 ? t.created_unix_s : now);
  s.bind(18, t.changed_unix_s > 0 ? t.changed_unix_s : now);
  s.step(path_);
}

bool PositionDb::remove(std::string_view robot, std::string_view name) {
  Transaction tr(db_, path_);
  Statement s(db_, "DELETE FROM transforms WHERE robot = ?1 AND name = ?2", path_);
  s.bind(1, robot);
  s.bind(2, name);
  s.step(path_);
  const bool removed = sqlite3_changes(db_) > 0;
  tr.commit();
  return removed;
}

std::vector<StoredTransform> PositionDb::list(std::string_view robot,
                                              std::string_view pattern) const {
  Statement s(db_,
              fmt::format("SELECT {} FROM transforms WHERE (?1 = '' OR robot = ?1) AND name GLOB "
                          "?2 ORDER BY robot, name",
                          kColumns),
              path_);
  s.bind(1, robot);
  s.bind(2, pattern);
  std::vector<StoredTransform> out;
  while (s.step(path_) == SQLITE_ROW) out.push_back(row(s));
  return out;
}

StoredTransform PositionDb::require(std::string_view robot, std::string_view name) const {
  auto t = get(robot, name);
  if (!t) {
    throw DatabaseError(
        fmt::format("position database {} has no transform {} for robot {} "
                    "(`rccx db list` shows what it has)",
                    path_.string(), name, robot));
  }
  return *t;
}

TransformPtr PositionDb::constant(std::string_view robot, std::string_view name) const {
  const StoredTransform t = require(robot, name);
  return rccl::constant(t.name, t.value);
}

TransformPtr PositionDb::hold(std::string_view robot, std::string_view name) const {
  const StoredTransform t = require(robot, name);
  return rccl::hold(t.name, t.value);
}

}  // namespace rccx::rccl
