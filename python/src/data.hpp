// rccx.log, rccx.plot and rccx.db's C++ side: a run log read by view::load_run_log, the series of
// `rccx plot` (view::run_plot), the position database (rccl::PositionDb). Plain C++ over the
// helpers of arrays.hpp; module.cpp names them for Python, python/rccx/{log,plot,db}.py shape
// them (the structured array, the figures, the context manager).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "arrays.hpp"
#include "kin.hpp"
#include "rccx/rccl/position_db.hpp"
#include "rccx/view/run_log.hpp"

namespace rccx::python {

/// A 1-D int32 array returned to Python (the logs' segment numbers).
using OutInt32Array = py::array_t<std::int32_t>;

using HeaderTuple =
    std::tuple<std::string, std::string, std::string, std::int64_t, bool, std::string>;

/// rccx.log's C++ object: one view::RunLog, read whole when made (the GIL released).
class RunLogObject {
 public:
  explicit RunLogObject(const std::filesystem::path& path);

  [[nodiscard]] const view::RunLog& log() const noexcept { return log_; }
  [[nodiscard]] std::string origin() const { return log_.origin; }
  [[nodiscard]] std::size_t dof() const noexcept { return log_.dof; }
  [[nodiscard]] std::size_t size() const noexcept { return log_.rows.size(); }
  /// The header line's words: (robot, kinematics, name, period_ns, simulated, rccx version);
  /// none for a log written before headers.
  [[nodiscard]] std::optional<HeaderTuple> header() const;

  /// The columns as arrays: t (N,) s, segment (N,), commanded and measured (N, dof) rad or m,
  /// p (N, 3) m, a (N, 3).
  [[nodiscard]] OutArray t_s() const;
  [[nodiscard]] OutInt32Array segment() const;
  [[nodiscard]] OutArray commanded() const;
  [[nodiscard]] OutArray measured() const;
  [[nodiscard]] OutArray p_m() const;
  [[nodiscard]] OutArray approach() const;

  /// The robot the log is drawn as (view::log_robot): the header's, or `given` (which must then
  /// be the header's); RunLogError otherwise.
  [[nodiscard]] KinematicsObject robot(const KinematicsObject* given) const;
  /// view::path_errors_m, m, shape (N,); the GIL released.
  [[nodiscard]] OutArray path_errors_m(const KinematicsObject* given) const;

 private:
  [[nodiscard]] kin::RobotModel model(const KinematicsObject* given) const;
  view::RunLog log_;
};

/// One line of a panel: (x, y, colour, label, dashed, width px).
using SeriesTuple = std::tuple<OutArray, OutArray, std::string, std::string, bool, double>;
/// One panel: (title, xlabel, ylabel, [series], equal axes).
using PanelTuple =
    std::tuple<std::string, std::string, std::string, std::vector<SeriesTuple>, bool>;
/// view::run_plot: (robot title, samples, duration s, worst path error m, [panels]).
using PlotTuple = std::tuple<std::string, std::size_t, double, double, std::vector<PanelTuple>>;
PlotTuple run_plot(const RunLogObject& log, const KinematicsObject* given);

/// One stored transform: (robot, name, T (4, 4) m, configuration, note, created, changed unix s).
using PositionTuple = std::tuple<std::string, std::string, OutArray, std::string, std::string,
                                 std::int64_t, std::int64_t>;

/// rccx.db's C++ object: one rccl::PositionDb. Every call releases the GIL (the database may
/// wait up to the busy timeout for another process) and takes a mutex, so that Python threads
/// may share it; close() ends it, later calls raise DatabaseError.
class PositionDbObject {
 public:
  PositionDbObject(const std::filesystem::path& path, bool create, double wait_s);

  [[nodiscard]] std::optional<PositionTuple> get(const std::string& robot, const std::string& name);
  void put(const std::string& robot, const std::string& name, const InArray& T,
           const std::string& configuration, const std::string& note);
  /// Every (robot, name, T, configuration, note) or none, in one transaction.
  void put_all(
      const std::vector<std::tuple<std::string, std::string, InArray, std::string, std::string>>&
          all);
  bool remove(const std::string& robot, const std::string& name);
  [[nodiscard]] std::vector<std::string> robots();
  [[nodiscard]] std::vector<PositionTuple> list(const std::string& robot,
                                                const std::string& pattern);
  [[nodiscard]] int schema_version();
  [[nodiscard]] std::string path() const { return path_.string(); }
  [[nodiscard]] bool closed();
  void close();

 private:
  /// The database, or DatabaseError when closed; the caller holds mutex_.
  rccl::PositionDb& db();

  std::filesystem::path path_;
  std::mutex mutex_;
  std::unique_ptr<rccl::PositionDb> db_;
};

}  // namespace rccx::python
