// The extension module rccx._rccx: the names Python sees and their docstrings. The Python
// package rccx (python/rccx/) re-exports them; python/rccx/*.pyi are their stubs.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "arrays.hpp"
#include "kin.hpp"
#include "rccx/kinematics/robot_model.hpp"

namespace py = pybind11;

// rccx.log, rccx.plot, rccx.db (data_module.cpp).
namespace rccx::python {
void bind_data(py::module_& m);
}
using rccx::python::KinematicsObject;

// Position equations and robots (arm_module.cpp).
namespace rccx::python {
void bind_rccl(py::module_& m);
}
// rccx.view, the web page of a running program (view.cpp).
namespace rccx::python {
void bind_view(py::module_& m);
}

namespace {

constexpr const char* kForwardDoc = R"(T6, the last link's frame in the base frame.

q: joint values, rad (revolute) or m (prismatic): shape (dof,), or (N, dof) for N
configurations at once (one C++ loop, the GIL released).
Returns a float64 array (4, 4), or (N, 4, 4); positions in m.
Raises ValueError for another shape or a non-finite value.)";

constexpr const char* kJacobianDoc = R"(The geometric Jacobian of T6 at q.

q: joint values (rad or m), shape (dof,) or (N, dof).
Returns (6, dof) or (N, 6, dof): rows vx vy vz (m/s) and wx wy wz (rad/s) of T6, both in the
base frame, per unit joint speed (rad/s or m/s).)";

constexpr const char* kInverseDoc =
    R"(Joint values (rad or m), shape (dof,), that put T6 at T, within the joint limits.

T: (4, 4) homogeneous transform of T6 in the base frame, m; its rotation orthonormal and
right-handed (within 1e-6).
configuration: solve for this named configuration only (see configuration_names, e.g. "lun"
for the PUMA); robots solved numerically have none.
near: joint values (rad or m), shape (dof,), to stay closest to: they pick the configuration
and the 2 pi turns, fill joints a singularity leaves free, seed the numeric solver. Default:
the ready pose.
redundant: a 7-axis arm solved given joint 7 (the Panda): hold joint 7 here (rad).
Raises rccx.UnreachableError (a ValueError) with rccx's reason when no solution is within
limits, ValueError for bad arguments. The GIL is released while it solves.)";

constexpr const char* kInverseAllDoc =
    R"(Every configuration's solution within limits, as (configuration name, q) pairs.

T: (4, 4) transform of T6 in the base frame, m. near: as for inverse.
The name is None for robots solved numerically (one solution). q: rad or m, shape (dof,).
Raises rccx.UnreachableError when there is none, with rccx's reason.)";

}  // namespace

PYBIND11_MODULE(_rccx, m) {
  m.doc() = "rccx's compiled core; import rccx (python/rccx) instead.";

  rccx::python::add_exception<rccx::python::UnreachableError>(
      m, "UnreachableError", PyExc_ValueError,
      "No joint values within limits put the robot at the pose; the message says why.");
  rccx::python::add_exception<rccx::kin::RobotFileError>(
      m, "RobotFileError", PyExc_ValueError,
      "A robot file or URDF that cannot be used; the message names the file, joint and key.");

  py::module_ kin =
      m.def_submodule("kin", "Robots and their kinematics: forward, inverse, Jacobian.");

  py::class_<KinematicsObject>(kin, "Kinematics",
                               "A robot model and its solver (C++ rccx::kin::Kinematics). Made "
                               "by rccx.kin.robot, robot_file or urdf.")
      .def("forward", &KinematicsObject::forward, py::arg("q"), kForwardDoc)
      .def("jacobian", &KinematicsObject::jacobian, py::arg("q"), kJacobianDoc)
      .def("inverse", &KinematicsObject::inverse, py::arg("T"),
           py::arg("configuration") = py::none(), py::arg("near") = py::none(),
           py::arg("redundant") = py::none(), kInverseDoc)
      .def("inverse_all", &KinematicsObject::inverse_all, py::arg("T"),
           py::arg("near") = py::none(), kInverseAllDoc)
      .def("configuration_of", &KinematicsObject::configuration_of, py::arg("q"),
           "The name of the configuration joint values q (rad or m) are in; None for robots "
           "solved numerically.")
      .def_property_readonly(
          "name", [](const KinematicsObject& k) { return k.model().name; },
          "Short id (\"puma560\").")
      .def_property_readonly(
          "title", [](const KinematicsObject& k) { return k.model().title; }, "Human name.")
      .def_property_readonly("dof", &KinematicsObject::dof, "Number of joints.")
      .def_property_readonly(
          "solver",
          [](const KinematicsObject& k) { return std::string(to_string(k.model().solver)); },
          "The solver the model asks for: \"microbo\", \"puma\" or \"dh\".")
      .def_property_readonly("configuration_names", &KinematicsObject::configuration_names,
                             "Names of the arm configurations (\"lun\", ...); empty for robots "
                             "solved numerically.")
      .def_property_readonly("joint_names", &KinematicsObject::joint_names, "Joint names.")
      .def_property_readonly("joint_units", &KinematicsObject::joint_units,
                             "Each joint's unit: \"rad\" (revolute) or \"m\" (prismatic).")
      .def_property_readonly(
          "lower", &KinematicsObject::lower,
          "Lower joint limits, rad or m, shape (dof,); -inf for continuous joints.")
      .def_property_readonly(
          "upper", &KinematicsObject::upper,
          "Upper joint limits, rad or m, shape (dof,); +inf for continuous joints.")
      .def_property_readonly("ready", &KinematicsObject::ready,
                             "The ready (nominal) pose, rad or m, shape (dof,).")
      .def_property_readonly("max_velocity", &KinematicsObject::max_velocity,
                             "Fastest joint speeds, rad/s or m/s, shape (dof,).")
      .def("__repr__", &KinematicsObject::repr);

  kin.def("robot_names", &rccx::python::robot_names,
          "Names of the shipped robots (robots/*.json).");
  kin.def("robot", &rccx::python::robot, py::arg("name"),
          "A shipped robot by name (\"puma560\", \"ur5e\", \"panda\", ...: robot_names()). Raises "
          "KeyError for an unknown name.");
  kin.def("robot_file", &rccx::python::robot_file, py::arg("path"),
          "A robot from a robot file (JSON, robots/README.md), lengths m, angles as the file "
          "says. Raises FileNotFoundError, rccx.RobotFileError.");
  kin.def("urdf", &rccx::python::urdf, py::arg("path"), py::arg("base_link") = py::none(),
          py::arg("tip_link") = py::none(),
          "A robot from a URDF: the chain from base_link (default: the tree's root) to tip_link "
          "(default: the only leaf). Raises FileNotFoundError, rccx.RobotFileError.");

  rccx::python::bind_data(m);  // rccx.log, rccx.plot, rccx.db
  // Position equations, robots and cells (arm_module.cpp); after kin: Arm.kinematics returns one.
  rccx::python::bind_rccl(m);
  rccx::python::bind_view(m);  // rccx.view: after bind_rccl (serve takes a Robot or a Cell)
}
