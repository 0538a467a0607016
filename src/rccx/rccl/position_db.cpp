#include "rccx/rccl/position_db.hpp"

#include <fmt/format.h>
#include <sqlite3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <thread>

#include "rccx/io/parse.hpp"

namespace rccx::rccl {
namespace {

/// Where an SQLite call failed, for the message.
struct Where {
  sqlite3* db;
  const std::filesystem::path& file;
  std::chrono::milliseconds busy_timeout;
};

/// The error for SQLite result `rc`: busy apart (nothing is wrong with the file), damaged or
/// foreign files apart (those cannot be used), each saying what to do.
[[noreturn]] void fail(const Where& w, int rc, std::string_view what) {
  const std::string f = w.file.string();
  switch (rc & 0xff) {
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      throw DatabaseBusy(fmt::format(
          "position database {} is busy: another process is writing it (waited {:g} s); try "
          "again when it has finished",
          f, std::chrono::duration<double>(w.busy_timeout).count()));
    case SQLITE_NOTADB:
    case SQLITE_CORRUPT:
      throw DatabaseError(fmt::format(
          "position database {}: {} (is it an rccx database? a file of another kind, or a "
          "damaged one, cannot be used; name another file with --db)",
          f, what));
    case SQLITE_FULL:
      throw DatabaseError(fmt::format(
          "position database {}: the disk is full ({}); nothing was changed; free some space "
          "and try again",
          f, what));
    case SQLITE_READONLY:
    case SQLITE_PERM:
      throw DatabaseError(fmt::format(
          "position database {} cannot be written ({}); check the permissions of the file and "
          "of its folder",
          f, what));
    case SQLITE_CANTOPEN:
      throw DatabaseError(fmt::format(
          "position database {} cannot be opened ({}); check the path and the permissions of "
          "its folder",
          f, what));
    default:
      throw DatabaseError(fmt::format("position database {}: {}", f, what));
  }
}

[[noreturn]] void fail(const Where& w, int rc) {
  fail(w, rc, sqlite3_errmsg(w.db));
}

bool is_busy(int rc) {
  return (rc & 0xff) == SQLITE_BUSY || (rc & 0xff) == SQLITE_LOCKED;
}

/// One prepared statement, finalized on every path out.
class Statement {
 public:
  Statement(const Where& w, std::string_view sql) : w_(w) {
    const int rc =
        sqlite3_prepare_v2(w.db, sql.data(), static_cast<int>(sql.size()), &stmt_, nullptr);
    if (rc != SQLITE_OK) fail(w_, rc);
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
  int step() {
    const int rc = sqlite3_step(stmt_);
    if (rc != SQLITE_ROW && rc != SQLITE_DONE) fail(w_, rc);
    return rc;
  }
  /// The whole text, NULs included (a row written by another program may hold any bytes).
  [[nodiscard]] std::string text(int col) const {
    const auto* p = sqlite3_column_text(stmt_, col);
    const int n = sqlite3_column_bytes(stmt_, col);
    return p != nullptr && n > 0
               ? std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(n))
               : std::string();
  }
  [[nodiscard]] double real(int col) const { return sqlite3_column_double(stmt_, col); }
  [[nodiscard]] std::int64_t integer(int col) const { return sqlite3_column_int64(stmt_, col); }

 private:
  Where w_;
  sqlite3_stmt* stmt_ = nullptr;
};

int try_exec(sqlite3* db, const char* sql, std::string& what) {
  char* error = nullptr;
  const int rc = sqlite3_exec(db, sql, nullptr, nullptr, &error);
  if (rc != SQLITE_OK) what = error != nullptr ? error : sqlite3_errmsg(db);
  sqlite3_free(error);
  return rc;
}

void exec(const Where& w, const char* sql) {
  std::string what;
  if (const int rc = try_exec(w.db, sql, what); rc != SQLITE_OK) fail(w, rc, what);
}

/// exec, retrying SQLITE_BUSY until the busy timeout has passed: SQLite does not call the busy
/// handler in every case (a journal mode change racing another process's, WAL recovery).
void exec_retrying(const Where& w, const char* sql) {
  const auto deadline = std::chrono::steady_clock::now() + w.busy_timeout;
  for (;;) {
    std::string what;
    const int rc = try_exec(w.db, sql, what);
    if (rc == SQLITE_OK) return;
    if (!is_busy(rc) || std::chrono::steady_clock::now() >= deadline) fail(w, rc, what);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
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
/// BEGIN IMMEDIATE: the write lock is taken first, so what is read inside is what is written.
class Transaction {
 public:
  explicit Transaction(const Where& w) : w_(w) { exec(w_, "BEGIN IMMEDIATE"); }
  ~Transaction() {
    if (!done_) sqlite3_exec(w_.db, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit() {
    exec(w_, "COMMIT");
    done_ = true;
  }

 private:
  Where w_;
  bool done_ = false;
};

int user_version(const Where& w) {
  Statement s(w, "PRAGMA user_version");
  s.step();
  return static_cast<int>(s.integer(0));
}

/// A ParseError of the shared rules as the database's own error.
template <class F>
void refuse_unless(F&& check) {
  try {
    check();
  } catch (const io::ParseError& e) {
    throw InvalidTransform(e.what());
  }
}

}  // namespace

void PositionDb::check_name(std::string_view name) {
  if (name.empty()) {
    throw InvalidTransform(
        fmt::format("transform name: \"\" is empty; give 1 to {} letters, digits and _ - .",
                    kMaxTransformName));
  }
  refuse_unless([&] { io::check_name(name, "transform name", kMaxTransformName); });
}

void PositionDb::check_robot_name(std::string_view robot) {
  refuse_unless([&] { io::check_name(robot, "robot name", kMaxRobotName); });
}

void PositionDb::check(const StoredTransform& t) {
  check_name(t.name);
  check_robot_name(t.robot);
  const std::string what = fmt::format("transform {}", io::quoted(t.name));
  if (t.configuration.size() > kMaxConfiguration ||
      !std::all_of(t.configuration.begin(), t.configuration.end(),
                   [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); })) {
    throw InvalidTransform(
        fmt::format("{}: configuration {} is not one; give up to {} letters (e.g. lun) or nothing",
                    what, io::quoted(t.configuration), kMaxConfiguration));
  }
  refuse_unless([&] { io::check_text(t.note, what + ": note", kMaxNote); });
  if (t.created_unix_s < 0 || t.changed_unix_s < 0) {
    throw InvalidTransform(fmt::format("{}: times are seconds since 1970, 0 or more", what));
  }
  if (const std::string problem = value_problem(t.value); !problem.empty()) {
    throw InvalidTransform(fmt::format("{}: {}", what, problem));
  }
}

std::string PositionDb::value_problem(const math::Transform& value) {
  if (!is_rigid(value)) {
    return "not a rigid transform (its rotation must be orthonormal and right-handed, every "
           "element finite)";
  }
  const math::Vec3& p = value.p;
  if (std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) > kMaxPosition_m) {
    return fmt::format(
        "position ({:g}, {:g}, {:g}) m is beyond {:g} m of the origin; give x, y and z within "
        "+-{:g} m",
        p.x, p.y, p.z, kMaxPosition_m, kMaxPosition_m);
  }
  return {};
}

PositionDb::PositionDb(const std::filesystem::path& file, Open mode,
                       std::chrono::milliseconds busy_timeout)
    : path_(file), busy_timeout_(busy_timeout) {
  std::error_code ec;
  if (mode == Open::existing && !std::filesystem::exists(file, ec)) {
    throw DatabaseError(
        fmt::format("position database {} does not exist (create it with a "
                    "first put, e.g. `rccx db put`, or check the path)",
                    file.string()));
  }
  if (const auto type = std::filesystem::status(file, ec).type();
      !ec && type != std::filesystem::file_type::not_found &&
      type != std::filesystem::file_type::regular) {
    // SQLite would open a device or a directory and put its -wal file beside it.
    throw DatabaseError(fmt::format(
        "position database {} is {}; name a database file", file.string(),
        type == std::filesystem::file_type::directory ? "a directory" : "not a regular file"));
  }
  const int flags = SQLITE_OPEN_READWRITE | (mode == Open::create ? SQLITE_OPEN_CREATE : 0) |
                    SQLITE_OPEN_FULLMUTEX;
  if (const int rc = sqlite3_open_v2(file.c_str(), &db_, flags, nullptr); rc != SQLITE_OK) {
    const std::string what = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    fail({nullptr, path_, busy_timeout_}, rc, what);
  }
  try {
    const Where w{db_, path_, busy_timeout_};
    sqlite3_busy_timeout(db_, static_cast<int>(busy_timeout.count()));
    // Also the first read ("not a database"); several processes may make a new file WAL at once.
    exec_retrying(w, "PRAGMA journal_mode=WAL");
    exec(w, "PRAGMA synchronous=NORMAL");
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
  return user_version({db_, path_, busy_timeout_});
}

void PositionDb::migrate() {
  const Where w{db_, path_, busy_timeout_};
  const auto check_not_newer = [&](int version) {
    if (version > kSchemaVersion) {
      throw DatabaseError(
          fmt::format("position database {} has schema version {}; this rccx "
                      "knows up to {} (use a newer rccx)",
                      path_.string(), version, kSchemaVersion));
    }
  };
  const int seen = user_version(w);
  check_not_newer(seen);
  if (seen == kSchemaVersion) return;  // the usual case: no write lock needed
  // Read the version again under the write lock: another process may have just created or
  // migrated the file ("table already exists" otherwise).
  Transaction t(w);
  const int version = user_version(w);
  check_not_newer(version);
  if (version == kSchemaVersion) return;
  // Each step takes the file one version up; a new schema adds a step here.
  if (version < 1) {
    exec(w,
         "CREATE TABLE transforms ("
         " robot TEXT NOT NULL, name TEXT NOT NULL,"
         " nx REAL NOT NULL, ny REAL NOT NULL, nz REAL NOT NULL,"
         " ox REAL NOT NULL, oy REAL NOT NULL, oz REAL NOT NULL,"
         " ax REAL NOT NULL, ay REAL NOT NULL, az REAL NOT NULL,"
         " px REAL NOT NULL, py REAL NOT NULL, pz REAL NOT NULL,"  // m
         " units TEXT NOT NULL DEFAULT 'm, rad',"
         " configuration TEXT NOT NULL DEFAULT '', note TEXT NOT NULL DEFAULT '',"
         " created INTEGER NOT NULL, changed INTEGER NOT NULL,"  // unix s
         " PRIMARY KEY (robot, name))");
  }
  exec(w, fmt::format("PRAGMA user_version = {}", kSchemaVersion).c_str());
  t.commit();
}

std::optional<StoredTransform> PositionDb::get(std::string_view robot,
                                               std::string_view name) const {
  Statement s({db_, path_, busy_timeout_},
              fmt::format("SELECT {} FROM transforms WHERE robot = ?1 AND name = ?2", kColumns));
  s.bind(1, robot);
  s.bind(2, name);
  if (s.step() != SQLITE_ROW) return std::nullopt;
  return row(s);
}

void PositionDb::put(const StoredTransform& t) {
  check(t);
  Transaction tr({db_, path_, busy_timeout_});
  insert(t);
  tr.commit();
}

void PositionDb::put(const std::vector<StoredTransform>& all,
                     const std::function<bool()>& cancelled) {
  for (const StoredTransform& t : all) check(t);
  Transaction tr({db_, path_, busy_timeout_});
  for (const StoredTransform& t : all) insert(t);
  if (cancelled && cancelled()) {
    throw PutCancelled(
        fmt::format("position database {}: stopped before the commit; nothing "
                    "stored",
                    path_.string()));  // the Transaction rolls back
  }
  tr.commit();
}

void PositionDb::insert(const StoredTransform& t) {
  const std::int64_t now = now_unix_s();
  Statement s({db_, path_, busy_timeout_},
              fmt::format("INSERT INTO transforms ({}) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, "
                          "?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16, ?17, ?18) "
                          "ON CONFLICT (robot, name) DO UPDATE SET nx = ?3, ny = ?4, nz = ?5, "
                          "ox = ?6, oy = ?7, oz = ?8, ax = ?9, ay = ?10, az = ?11, px = ?12, "
                          "py = ?13, pz = ?14, configuration = ?15, note = ?16, changed = ?18",
                          kColumns));
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
  s.step();
}

bool PositionDb::remove(std::string_view robot, std::string_view name) {
  Transaction tr({db_, path_, busy_timeout_});
  Statement s({db_, path_, busy_timeout_}, "DELETE FROM transforms WHERE robot = ?1 AND name = ?2");
  s.bind(1, robot);
  s.bind(2, name);
  s.step();
  const bool removed = sqlite3_changes(db_) > 0;
  tr.commit();
  return removed;
}

std::vector<StoredTransform> PositionDb::list(std::string_view robot,
                                              std::string_view pattern) const {
  Statement s({db_, path_, busy_timeout_},
              fmt::format("SELECT {} FROM transforms WHERE (?1 = '' OR robot = ?1) AND name GLOB "
                          "?2 ORDER BY robot, name",
                          kColumns));
  s.bind(1, robot);
  s.bind(2, pattern);
  std::vector<StoredTransform> out;
  while (s.step() == SQLITE_ROW) out.push_back(row(s));
  return out;
}

std::vector<std::string> PositionDb::robots() const {
  Statement s({db_, path_, busy_timeout_}, "SELECT DISTINCT robot FROM transforms ORDER BY robot");
  std::vector<std::string> out;
  while (s.step() == SQLITE_ROW) out.push_back(s.text(0));
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
