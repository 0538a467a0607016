// rccx.kin: robots and their kinematics for Python (docs/PYTHON.md). Thin wrappers over
// kin::Kinematics: joint values and transforms checked and copied between NumPy arrays and
// JointVector / math::Transform, C++ errors turned into Python exceptions with rccx's messages.
#include "kin.hpp"
#include "transform.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/seven_axis_kinematics.hpp"
#include "rccx/kinematics/urdf.hpp"

namespace rccx::python {

namespace {

std::string unit_of(const kin::Joint& j) {
  return j.type == kin::JointType::revolute ? "rad" : "m";
}

[[noreturn]] void raise_joint_shape(const kin::Kinematics& k, const InArray& a, const char* what,
                                    bool batch) {
  const std::size_t n = k.dof();
  raise_value_error(fmt::format(
      "{}: {} must have shape ({},){} for robot {} (rad or m), got shape {}", what,
      batch ? "q" : "the joint values", n, batch ? fmt::format(" or (N, {})", n) : std::string(),
      k.model().name, shape_text(a)));
}

/// One joint vector (rad or m) from a 1-D array of dof() finite values.
kin::JointVector joints_from(const kin::Kinematics& k, const InArray& a, const char* what) {
  if (ndim(a) != 1 || extent(a, 0) != k.dof()) raise_joint_shape(k, a, what, false);
  if (!all_finite(a.data(), k.dof())) {
    raise_value_error(fmt::format("{}: a joint value is not finite", what));
  }
  return kin::JointVector(std::span<const double>(a.data(), k.dof()));
}

/// The rows of a 2-D (N, dof) array, or the one row of a 1-D one; throws for other shapes.
std::size_t batch_rows(const kin::Kinematics& k, const InArray& q, const char* what) {
  if (ndim(q) == 2 && extent(q, 1) == k.dof()) return extent(q, 0);
  raise_joint_shape(k, q, what, true);
}

/// Runs f(row, JointVector) for each row of an (N, dof) array without the GIL; the first row
/// with a non-finite value stops it and raises.
template <typename F>
void for_each_row(const kin::Kinematics& k, const InArray& q, std::size_t rows, const char* what,
                  F&& f) {
  const std::size_t n = k.dof();
  const double* in = q.data();
  std::size_t bad = rows;
  {
    ReleaseGil release;
    for (std::size_t i = 0; i < rows; ++i, in += n) {
      if (!all_finite(in, n)) {
        bad = i;
        break;
      }
      f(i, kin::JointVector(std::span<const double>(in, n)));
    }
  }
  if (bad < rows) raise_value_error(fmt::format("{}: q[{}] has a non-finite value", what, bad));
}

}  // namespace

KinematicsObject::KinematicsObject(kin::RobotModel model) : k_(kin::make_kinematics(model)) {}

const kin::RobotModel& KinematicsObject::model() const noexcept {
  return k_->model();
}
std::size_t KinematicsObject::dof() const noexcept {
  return k_->dof();
}

OutArray KinematicsObject::forward(py::handle q_arg) const {
  // One configuration as a float64 array, the common call: read in place, the same checks
  // (the shape by f64_vector, finite values here), the pose written into the new (4, 4).
  if (const double* v = f64_vector(q_arg, k_->dof())) {
    if (!all_finite(v, k_->dof())) raise_value_error("forward: a joint value is not finite");
    OutArray out = new_array({4, 4});
    write_transform(k_->forward(kin::JointVector(std::span<const double>(v, k_->dof()))),
                    out.mutable_data());
    return out;
  }
  const InArray q = to_in_array(q_arg, "forward");
  if (ndim(q) == 1) {
    const kin::JointVector v = joints_from(*k_, q, "forward");
    OutArray out = new_array({4, 4});
    write_transform(k_->forward(v), out.mutable_data());
    return out;
  }
  const std::size_t rows = batch_rows(*k_, q, "forward");
  OutArray out = new_array({rows, 4, 4});
  double* o = out.mutable_data();
  for_each_row(*k_, q, rows, "forward", [&](std::size_t i, const kin::JointVector& v) {
    write_transform(k_->forward(v), o + 16 * i);
  });
  return out;
}

OutArray KinematicsObject::jacobian(const InArray& q) const {
  const std::size_t n = dof();
  auto write = [n](const kin::Jacobian& J, double* out) {
    for (std::size_t r = 0; r < 6; ++r) {
      for (std::size_t c = 0; c < n; ++c) {
        *out++ = J(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c));
      }
    }
  };
  if (ndim(q) == 1) {
    const kin::JointVector v = joints_from(*k_, q, "jacobian");
    OutArray out = new_array({6, n});
    write(k_->jacobian(v), out.mutable_data());
    return out;
  }
  const std::size_t rows = batch_rows(*k_, q, "jacobian");
  OutArray out = new_array({rows, 6, n});
  double* o = out.mutable_data();
  for_each_row(*k_, q, rows, "jacobian", [&](std::size_t i, const kin::JointVector& v) {
    write(k_->jacobian(v), o + 6 * n * i);
  });
  return out;
}

kin::IkOptions KinematicsObject::options(const std::optional<std::string>& configuration,
                                         const std::optional<InArray>& near,
                                         std::optional<double> redundant, const char* what) const {
  kin::IkOptions options;
  if (configuration) {
    const auto names = k_->configuration_names();
    if (names.empty()) {
      raise_value_error(fmt::format(
          "{}: robot {} is solved numerically and has no named configurations; use near", what,
          model().name));
    }
    options.configuration = k_->find_configuration(*configuration);
    if (!options.configuration) {
      std::string list;
      for (auto n : names) list += std::string(list.empty() ? "" : ", ") + std::string(n);
      raise_value_error(fmt::format("{}: robot {} has no configuration \"{}\"; use one of {}", what,
                                    model().name, *configuration, list));
    }
  }
  if (near) options.near = joints_from(*k_, *near, "near");
  if (redundant) {
    if (dynamic_cast<const kin::SevenAxisKinematics*>(k_.get()) == nullptr) {
      raise_value_error(fmt::format(
          "{}: redundant: robot {} is not a 7-axis arm solved given joint 7 (such as the Panda); "
          "leave it out",
          what, model().name));
    }
    if (!std::isfinite(*redundant))
      raise_value_error(fmt::format("{}: redundant is not finite", what));
    options.redundant = *redundant;
  }
  return options;
}

std::optional<std::string> KinematicsObject::name_of(kin::Configuration c) const {
  if (k_->configuration_names().empty()) return std::nullopt;
  return std::string(k_->configuration_name(c));
}

[[noreturn]] void KinematicsObject::raise_unreachable(kin::IkStatus status) const {
  // Bad input is caught above; should the solver still say so, it is the caller's error.
  const std::string message = fmt::format("{}: {}", model().name, kin::describe(status));
  if (status == kin::IkStatus::bad_input || status == kin::IkStatus::bad_configuration) {
    raise_value_error(message);
  }
  throw UnreachableError(message);
}

OutArray KinematicsObject::inverse(const InArray& T,
                                   const std::optional<std::string>& configuration,
                                   const std::optional<InArray>& near,
                                   std::optional<double> redundant) const {
  const math::Transform pose = transform_in(T, "inverse");
  const kin::IkOptions o = options(configuration, near, redundant, "inverse");
  kin::IkResult r;
  {
    ReleaseGil release;  // the numeric solvers take tens of us to ms
    r = k_->inverse(pose, o);
  }
  if (!r) raise_unreachable(r.status);
  return to_array(r.q.span());
}

std::vector<std::pair<std::optional<std::string>, OutArray>> KinematicsObject::inverse_all(
    const InArray& T, const std::optional<InArray>& near) const {
  const math::Transform pose = transform_in(T, "inverse_all");
  const kin::IkOptions o = options(std::nullopt, near, std::nullopt, "inverse_all");
  kin::IkSolutions all;
  {
    ReleaseGil release;
    all = k_->inverse_all(pose, o);
  }
  if (all.count == 0) raise_unreachable(all.status);
  std::vector<std::pair<std::optional<std::string>, OutArray>> out;
  for (const kin::IkResult& r : all.solutions()) {
    out.emplace_back(name_of(r.configuration), to_array(r.q.span()));
  }
  return out;
}

std::optional<std::string> KinematicsObject::configuration_of(const InArray& q) const {
  return name_of(k_->configuration_of(joints_from(*k_, q, "configuration_of")));
}

std::vector<std::string> KinematicsObject::configuration_names() const {
  const auto names = k_->configuration_names();
  return {names.begin(), names.end()};
}

std::vector<std::string> KinematicsObject::joint_names() const {
  std::vector<std::string> out;
  for (const kin::Joint& j : model().joints) out.push_back(j.name);
  return out;
}
std::vector<std::string> KinematicsObject::joint_units() const {
  std::vector<std::string> out;
  for (const kin::Joint& j : model().joints) out.push_back(unit_of(j));
  return out;
}
OutArray KinematicsObject::lower() const {
  return to_array(model().lower().span());
}
OutArray KinematicsObject::upper() const {
  return to_array(model().upper().span());
}
OutArray KinematicsObject::ready() const {
  return to_array(model().ready().span());
}
OutArray KinematicsObject::max_velocity() const {
  std::vector<double> v;
  for (const kin::Joint& j : model().joints) v.push_back(j.max_velocity);
  return to_array(v);
}

std::string KinematicsObject::repr() const {
  return fmt::format("<rccx.kin.Kinematics {} ({}): {} joints, {} solver, {} geometry>",
                     model().name, model().title, dof(), kin::to_string(model().solver),
                     kin::to_string(model().geometry));
}

// ---- loading ----

std::vector<std::string> robot_names() {
  return kin::builtin_robot_names();
}

kin::RobotModel builtin_model(const std::string& name) {
  const auto names = kin::builtin_robot_names();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    try {
      (void)kin::builtin_robot(name);  // its message lists the known names
    } catch (const kin::RobotFileError& e) {
      raise_key_error(e.what());
    }
  }
  return kin::builtin_robot(name);
}

KinematicsObject robot(const std::string& name) {
  return KinematicsObject(builtin_model(name));
}

namespace {
/// Runs load(); a RobotFileError about a file that is not there becomes FileNotFoundError.
template <typename Load>
KinematicsObject load_file(const std::filesystem::path& path, Load&& load) {
  try {
    return KinematicsObject(load());
  } catch (const kin::RobotFileError& e) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) raise_file_not_found(e.what());
    throw;
  }
}
}  // namespace

KinematicsObject robot_file(const std::filesystem::path& path) {
  return load_file(path, [&] { return kin::load_robot_file(path); });
}

KinematicsObject urdf(const std::filesystem::path& path,
                      const std::optional<std::string>& base_link,
                      const std::optional<std::string>& tip_link) {
  kin::UrdfOptions o;
  if (base_link) o.base_link = *base_link;
  if (tip_link) o.tip_link = *tip_link;
  return load_file(path, [&] { return kin::load_urdf(path, o); });
}

}  // namespace rccx::python
