// rccx.log, rccx.plot and rccx.db (docs/PYTHON.md): thin wrappers over view::load_run_log,
// view::path_errors_m, view::run_plot and rccl::PositionDb. Their errors are rccx's exceptions
// (RunLogError, DatabaseError ...), which module.cpp registers as Python exceptions.
#include "data.hpp"
#include "transform.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <system_error>
#include <utility>

#include "rccx/io/parse.hpp"
#include "rccx/view/plot.hpp"

namespace rccx::python {

namespace {

/// A column of the rows as an (N,) or (N, width) float64 array.
template <typename F>
OutArray column(const view::RunLog& log, std::size_t width, F&& value) {
  const std::size_t n = log.rows.size();
  OutArray out = width == 0 ? new_array({n}) : new_array({n, width});
  double* o = out.mutable_data();
  for (const view::RunRow& r : log.rows) {
    for (std::size_t k = 0; k < std::max<std::size_t>(width, 1); ++k) *o++ = value(r, k);
  }
  return out;
}

OutArray array_of(const std::vector<double>& v) {
  return to_array(std::span<const double>(v));
}

}  // namespace

RunLogObject::RunLogObject(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    raise_file_not_found(fmt::format("cannot read the log: {}: no such file", path.string()));
  }
  ReleaseGil release;  // a long log takes a while to parse
  log_ = view::load_run_log(path);
}

std::optional<HeaderTuple> RunLogObject::header() const {
  if (!log_.header) return std::nullopt;
  const rtc::LogHeader& h = *log_.header;
  return HeaderTuple{h.robot, h.kinematics, h.name, h.period_ns, h.simulated, h.rccx};
}

OutArray RunLogObject::t_s() const {
  return column(log_, 0, [](const view::RunRow& r, std::size_t) { return r.t_s; });
}
OutInt32Array RunLogObject::segment() const {
  OutInt32Array out(static_cast<py::ssize_t>(log_.rows.size()));
  std::int32_t* o = out.mutable_data();
  for (const view::RunRow& r : log_.rows) *o++ = r.segment;
  return out;
}
OutArray RunLogObject::commanded() const {
  return column(log_, log_.dof,
                [](const view::RunRow& r, std::size_t k) { return r.commanded[k]; });
}
OutArray RunLogObject::measured() const {
  return column(log_, log_.dof, [](const view::RunRow& r, std::size_t k) { return r.measured[k]; });
}
OutArray RunLogObject::p_m() const {
  return column(log_, 3, [](const view::RunRow& r, std::size_t k) { return r.p[k]; });
}
OutArray RunLogObject::approach() const {
  return column(log_, 3, [](const view::RunRow& r, std::size_t k) { return r.a[k]; });
}

kin::RobotModel RunLogObject::model(const KinematicsObject* given) const {
  const kin::RobotModel* m = given != nullptr ? &given->model() : nullptr;
  return view::log_robot(log_, m,
                         m != nullptr ? fmt::format("robot {}", m->name) : std::string("robot"));
}

KinematicsObject RunLogObject::robot(const KinematicsObject* given) const {
  return KinematicsObject(model(given));
}

OutArray RunLogObject::path_errors_m(const KinematicsObject* given) const {
  const kin::RobotModel m = model(given);
  std::vector<double> errors;
  {
    ReleaseGil release;  // 650 segments a sample: a long run takes seconds
    errors = view::path_errors_m(log_, m);
  }
  return array_of(errors);
}

PlotTuple run_plot(const RunLogObject& log, const KinematicsObject* given) {
  const kin::RobotModel m = log.robot(given).model();
  view::RunPlot plot;
  {
    ReleaseGil release;
    plot = view::run_plot(log.log(), m);
  }
  std::vector<PanelTuple> panels;
  for (const view::PlotPanel& p : plot.panels) {
    std::vector<SeriesTuple> series;
    for (const view::PlotSeries& s : p.series) {
      series.emplace_back(array_of(s.x), array_of(s.y), s.colour, s.label, s.dashed, s.width);
    }
    panels.emplace_back(p.title, p.xlabel, p.ylabel, std::move(series), p.equal_axes);
  }
  return {plot.robot_title, plot.samples, plot.duration_s, plot.worst_path_error_m,
          std::move(panels)};
}

// --- The position database --------------------------------------------------------------------

namespace {

/// A (4, 4) homogeneous transform (m) from Python; its rigidity is PositionDb::check's to judge
/// (InvalidTransform with rccx's message), the shape and the last row are checked here.
math::Transform transform_from(const InArray& a, const std::string& name) {
  std::string why;
  const std::optional<math::Transform> T = homogeneous(a, why);
  // As PositionDb::check words its refusals.
  if (!T) throw rccl::InvalidTransform(fmt::format("transform {}: {}", io::quoted(name), why));
  return *T;
}

rccl::StoredTransform stored(const std::string& robot, const std::string& name, const InArray& T,
                             const std::string& configuration, const std::string& note) {
  rccl::PositionDb::check_name(name);  // the name before the value, as put() judges them
  rccl::PositionDb::check_robot_name(robot);
  rccl::StoredTransform t;
  t.robot = robot;
  t.name = name;
  t.value = transform_from(T, name);
  t.configuration = configuration;
  t.note = note;
  rccl::PositionDb::check(t);  // every rule of put(), before the database is touched
  return t;
}

PositionTuple tuple_of(const rccl::StoredTransform& t) {
  OutArray T = new_array({4, 4});
  double* o = T.mutable_data();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) *o++ = t.value(r, c);
  }
  return {t.robot, t.name,           std::move(T),    t.configuration,
          t.note,  t.created_unix_s, t.changed_unix_s};
}

}  // namespace

PositionDbObject::PositionDbObject(const std::filesystem::path& path, bool create, double wait_s)
    : path_(path) {
  if (!std::isfinite(wait_s) || wait_s < 0 || wait_s > 3600) {
    raise_value_error(fmt::format("wait_s: {} s is not within 0 .. 3600 s", wait_s));
  }
  const auto wait = std::chrono::milliseconds(std::llround(wait_s * 1e3));
  ReleaseGil release;  // opening waits for another process holding the file
  db_ = std::make_unique<rccl::PositionDb>(
      path, create ? rccl::PositionDb::Open::create : rccl::PositionDb::Open::existing, wait);
}

rccl::PositionDb& PositionDbObject::db() {
  if (!db_) {
    throw rccl::DatabaseError(fmt::format("position database {} is closed", path_.string()));
  }
  return *db_;
}

std::optional<PositionTuple> PositionDbObject::get(const std::string& robot,
                                                   const std::string& name) {
  std::optional<rccl::StoredTransform> t;
  {
    ReleaseGil release;
    std::lock_guard lock(mutex_);
    rccl::PositionDb::check_robot_name(robot);
    rccl::PositionDb::check_name(name);
    t = db().get(robot, name);
  }
  if (!t) return std::nullopt;
  return tuple_of(*t);
}

void PositionDbObject::put(const std::string& robot, const std::string& name, const InArray& T,
                           const std::string& configuration, const std::string& note) {
  const rccl::StoredTransform t = stored(robot, name, T, configuration, note);
  ReleaseGil release;
  std::lock_guard lock(mutex_);
  db().put(t);
}

void PositionDbObject::put_all(
    const std::vector<std::tuple<std::string, std::string, InArray, std::string, std::string>>&
        all) {
  std::vector<rccl::StoredTransform> ts;
  for (const auto& [robot, name, T, configuration, note] : all) {
    ts.push_back(stored(robot, name, T, configuration, note));
  }
  ReleaseGil release;
  std::lock_guard lock(mutex_);
  db().put(ts);
}

bool PositionDbObject::remove(const std::string& robot, const std::string& name) {
  ReleaseGil release;
  std::lock_guard lock(mutex_);
  rccl::PositionDb::check_robot_name(robot);
  rccl::PositionDb::check_name(name);
  return db().remove(robot, name);
}

std::vector<std::string> PositionDbObject::robots() {
  ReleaseGil release;
  std::lock_guard lock(mutex_);
  return db().robots();
}

std::vector<PositionTuple> PositionDbObject::list(const std::string& robot,
                                                  const std::string& pattern) {
  std::vector<rccl::StoredTransform> all;
  {
    ReleaseGil release;
    std::lock_guard lock(mutex_);
    if (!robot.empty()) rccl::PositionDb::check_robot_name(robot);
    all = db().list(robot, pattern);
  }
  std::vector<PositionTuple> out;
  for (const auto& t : all) out.push_back(tuple_of(t));
  return out;
}

int PositionDbObject::schema_version() {
  ReleaseGil release;
  std::lock_guard lock(mutex_);
  return db().schema_version();
}

bool PositionDbObject::closed() {
  std::lock_guard lock(mutex_);
  return !db_;
}

void PositionDbObject::close() {
  ReleaseGil release;  // waits for a call of another thread to finish
  std::lock_guard lock(mutex_);
  db_.reset();
}

}  // namespace rccx::python
