// The position database (thesis 4.5.4.5): named transforms taught or typed once and used by
// programs and equations, on SQLite. One file per cell by default; each robot's transforms are
// kept apart. Every write is one transaction in WAL mode: a process killed mid-write leaves the
// file as it was before or after the write, and several processes may read and write it at
// once (a writer waits up to `busy_timeout` for another).
//
//   rccl::PositionDb db("cell.db");
//   db.put({.robot = "microbo", .name = "PICK", .value = t});   // m, rad
//   auto pick = db.constant("microbo", "PICK");                 // a TransformPtr for equations
//
// Names: 1 to 32 characters (the thesis raised RCCL's limit to 32), letters, digits and _ - .
// Robot names follow the same rule; a configuration is up to 8 letters; a note is UTF-8 text
// without control characters, up to 1000 bytes. A value is a rigid transform: every element
// finite, the rotation orthonormal and right-handed (1e-6), the position within
// kMaxPosition_m (100 m) of the origin on each axis. put() refuses anything else
// (InvalidTransform), so what is stored can be printed and exported as it is.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/math/transform.hpp"
#include "rccx/rccl/transforms.hpp"

struct sqlite3;

namespace rccx::rccl {

/// A database that cannot be used (missing, not a database, corrupt, locked too long, from a
/// newer rccx) or a request it refuses (a bad name, a transform that is not rigid). The
/// message says which and what to do; nothing was changed.
class DatabaseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The database is held by another process (SQLITE_BUSY / SQLITE_LOCKED) for longer than the
/// busy timeout: nothing is wrong with it; try again when the other process has finished.
class DatabaseBusy : public DatabaseError {
 public:
  using DatabaseError::DatabaseError;
};

/// A put of many that its caller cancelled (a stop signal) before it committed: nothing stored.
class PutCancelled : public DatabaseError {
 public:
  using DatabaseError::DatabaseError;
};

/// A transform refused before the database is touched: a bad name, robot, configuration or
/// note, or a value that is not rigid. Bad input rather than a failing database.
class InvalidTransform : public DatabaseError {
 public:
  using DatabaseError::DatabaseError;
};

inline constexpr std::size_t kMaxTransformName = 32;
inline constexpr std::size_t kMaxRobotName = 32;
inline constexpr std::size_t kMaxConfiguration = 8;  ///< letters, e.g. "lun"
inline constexpr std::size_t kMaxNote = 1000;        ///< bytes of UTF-8
/// |px|, |py| and |pz| of a stored transform at most this (m), as a cell file's lengths: a
/// workcell's frames (T6 or not: an object, a fixture) lie within it, a larger value is a typo,
/// and mm and products of transforms stay finite.
inline constexpr double kMaxPosition_m = 100.0;

struct StoredTransform {
  std::string robot;  ///< the robot it belongs to ("microbo", "puma560" ...), a name as `name`
  std::string name;   ///< 1 .. kMaxTransformName characters: letters, digits, _ - .
  math::Transform value = math::Transform::identity();  ///< m, rad
  /// The arm configuration it was taught in ("lun" ...): up to 8 letters, or empty.
  std::string configuration;
  std::string note;                 ///< UTF-8, no control characters but tab, up to kMaxNote bytes
  std::int64_t created_unix_s = 0;  ///< 0: put() stamps it the first time (an import keeps it)
  std::int64_t changed_unix_s = 0;  ///< 0: put() stamps it now (an import keeps it)
};

class PositionDb {
 public:
  /// The schema this rccx writes; older files are migrated when opened.
  static constexpr int kSchemaVersion = 1;

  enum class Open : std::uint8_t {
    create,    ///< make the file when it is missing
    existing,  ///< a missing file is an error
  };
  /// Opens (and when asked, creates) the database at `file`. Throws DatabaseError, or
  /// DatabaseBusy when another process holds it for longer than `busy_timeout`. Several
  /// processes may create the same new file at once.
  explicit PositionDb(const std::filesystem::path& file, Open mode = Open::create,
                      std::chrono::milliseconds busy_timeout = std::chrono::seconds(5));
  ~PositionDb();
  PositionDb(const PositionDb&) = delete;
  PositionDb& operator=(const PositionDb&) = delete;

  /// The transform `name` of `robot`, if stored.
  [[nodiscard]] std::optional<StoredTransform> get(std::string_view robot,
                                                   std::string_view name) const;
  /// Stores `t` (inserting or replacing; created time kept), in one transaction.
  void put(const StoredTransform& t);
  /// Stores them all in one transaction: every one or none (each checked first). When
  /// `cancelled` is given and says true just before the commit (Ctrl-C during a long import),
  /// the transaction is rolled back and PutCancelled thrown: nothing is stored.
  void put(const std::vector<StoredTransform>& all, const std::function<bool()>& cancelled = {});
  /// Removes it; false when there was none.
  bool remove(std::string_view robot, std::string_view name);
  /// The robots that have transforms stored, by name.
  [[nodiscard]] std::vector<std::string> robots() const;
  /// The transforms of `robot` (every robot when empty) whose names match the glob `pattern`
  /// ("*", "P?", "PICK*"), by robot then name.
  [[nodiscard]] std::vector<StoredTransform> list(std::string_view robot = {},
                                                  std::string_view pattern = "*") const;

  /// A stored transform as a constant or a hold transform of equations. Throws DatabaseError
  /// when it is not stored.
  [[nodiscard]] TransformPtr constant(std::string_view robot, std::string_view name) const;
  [[nodiscard]] TransformPtr hold(std::string_view robot, std::string_view name) const;

  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }
  /// The schema version in the file.
  [[nodiscard]] int schema_version() const;

  /// Throws InvalidTransform unless `name` is a valid transform name.
  static void check_name(std::string_view name);
  /// Throws InvalidTransform unless `robot` is a valid robot name (the rule of check_name).
  static void check_robot_name(std::string_view robot);
  /// Throws InvalidTransform unless put() would store `t`: every rule above, without opening
  /// a database.
  static void check(const StoredTransform& t);
  /// Why put() would refuse `value` ("" when it would store it): an element not finite, a
  /// rotation not orthonormal and right-handed, a position beyond kMaxPosition_m. Also for a
  /// row read back that another program wrote.
  static std::string value_problem(const math::Transform& value);

 private:
  void migrate();
  void insert(const StoredTransform& t);
  [[nodiscard]] StoredTransform require(std::string_view robot, std::string_view name) const;

  std::filesystem::path path_;
  std::chrono::milliseconds busy_timeout_;
  sqlite3* db_ = nullptr;
};

}  // namespace rccx::rccl
