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
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
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

inline constexpr std::size_t kMaxTransformName = 32;

struct StoredTransform {
  std::string robot;  ///< the robot it belongs to ("microbo", "puma560" ...)
  std::string name;   ///< 1 .. kMaxTransformName characters: letters, digits, _ - .
  math::Transform value = math::Transform::identity();  ///< m, rad
  /// The arm configuration it was taught in ("lun" ...), or empty.
  std::string configuration;
  std::string note;
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
  /// Opens (and when asked, creates) the database at `file`. Throws DatabaseError.
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
  /// Stores them all in one transaction: every one or none (each checked first).
  void put(const std::vector<StoredTransform>& all);
  /// Removes it; false when there was none.
  bool remove(std::string_view robot, std::string_view name);
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

  /// Throws DatabaseError unless `name` is a valid transform name.
  static void check_name(std::string_view name);

 private:
  void migrate();
  static void check(const StoredTransform& t);
  void insert(const StoredTransform& t);
  [[nodiscard]] StoredTransform require(std::string_view robot, std::string_view name) const;

  std::filesystem::path path_;
  sqlite3* db_ = nullptr;
};

}  // namespace rccx::rccl
