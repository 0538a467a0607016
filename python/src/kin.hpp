// rccx.kin's C++ side: the Python object over one kin::Kinematics, and the loaders. Plain C++
// over the helpers of arrays.hpp; module.cpp names them for Python.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "arrays.hpp"
#include "rccx/kinematics/kinematics.hpp"

namespace rccx::python {

/// A pose no joint values reach within limits: rccx.UnreachableError (a ValueError).
class UnreachableError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// rccx.kin.Kinematics: a robot model and its solver (kin::make_kinematics). Its calls are
/// const and the solvers keep no state, so that threads may share one object.
class KinematicsObject {
 public:
  explicit KinematicsObject(kin::RobotModel model);

  [[nodiscard]] const kin::RobotModel& model() const noexcept;
  [[nodiscard]] std::size_t dof() const noexcept;

  /// q (dof,) -> T6 (4, 4); q (N, dof) -> (N, 4, 4), the GIL released. Any array-like q: a
  /// float64 (dof,) array is read in place (the common call, kept cheap), others converted.
  [[nodiscard]] OutArray forward(py::handle q) const;
  /// q (dof,) -> (6, dof); q (N, dof) -> (N, 6, dof).
  [[nodiscard]] OutArray jacobian(const InArray& q) const;
  /// q (dof,) within limits; throws UnreachableError.
  [[nodiscard]] OutArray inverse(const InArray& T, const std::optional<std::string>& configuration,
                                 const std::optional<InArray>& near,
                                 std::optional<double> redundant) const;
  [[nodiscard]] std::vector<std::pair<std::optional<std::string>, OutArray>> inverse_all(
      const InArray& T, const std::optional<InArray>& near) const;
  [[nodiscard]] std::optional<std::string> configuration_of(const InArray& q) const;

  [[nodiscard]] std::vector<std::string> configuration_names() const;
  [[nodiscard]] std::vector<std::string> joint_names() const;
  [[nodiscard]] std::vector<std::string> joint_units() const;
  [[nodiscard]] OutArray lower() const;
  [[nodiscard]] OutArray upper() const;
  [[nodiscard]] OutArray ready() const;
  [[nodiscard]] OutArray max_velocity() const;
  [[nodiscard]] std::string repr() const;

 private:
  kin::IkOptions options(const std::optional<std::string>& configuration,
                         const std::optional<InArray>& near, std::optional<double> redundant,
                         const char* what) const;
  std::optional<std::string> name_of(kin::Configuration c) const;
  [[noreturn]] void raise_unreachable(kin::IkStatus status) const;

  std::unique_ptr<const kin::Kinematics> k_;
};

std::vector<std::string> robot_names();
/// A shipped robot; an unknown name raises KeyError listing the known ones.
/// A shipped robot's model by name; KeyError naming the known ones.
kin::RobotModel builtin_model(const std::string& name);
KinematicsObject robot(const std::string& name);
/// A robot file (JSON, robots/README.md); a missing file raises FileNotFoundError.
KinematicsObject robot_file(const std::filesystem::path& path);
/// The chain of a URDF from base_link (default: the root) to tip_link (default: the only leaf).
KinematicsObject urdf(const std::filesystem::path& path,
                      const std::optional<std::string>& base_link,
                      const std::optional<std::string>& tip_link);

}  // namespace rccx::python
