// The names rccx.log, rccx.plot and rccx.db take from the extension module (_rccx.log,
// _rccx.plot, _rccx.db) and their exceptions; python/rccx/{log,plot,db}.py build the API on
// them. Called once from module.cpp.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "data.hpp"

namespace py = pybind11;

namespace rccx::python {

namespace {}  // namespace

void bind_data(py::module_& m) {
  add_exception<view::RunLogError>(
      m, "RunLogError", PyExc_ValueError,
      "A file that is not a run log rccx writes (RCCX_LOG, --log), or a log of another robot "
      "than the one given; the message names the file, the line and the column.");
  // Registered base first: pybind11 tries the translators of the later ones (the derived
  // exceptions) first.
  const py::object database_error = add_exception<rccl::DatabaseError>(
      m, "DatabaseError", PyExc_RuntimeError,
      "A position database that cannot be used (missing, not a database, corrupt, from a newer "
      "rccx, closed), or a request it refuses; nothing was changed.");
  add_exception<rccl::DatabaseBusy>(
      m, "DatabaseBusy", database_error,
      "Another process held the position database for longer than the wait (wait_s); try "
      "again.");
  add_exception<rccl::InvalidTransform>(
      m, "InvalidTransform", py::make_tuple(database_error, py::handle(PyExc_ValueError)),
      "A transform, name, robot, configuration or note put() refuses (a ValueError too); "
      "nothing was stored.");

  py::module_ log = m.def_submodule("log", "Run logs (C++ rccx::view::load_run_log).");
  py::class_<RunLogObject>(log, "RunLogData",
                           "A run log read whole (view::RunLog); rccx.log.RunLog wraps it.")
      .def(py::init<const std::filesystem::path&>(), py::arg("path"))
      .def_property_readonly("origin", &RunLogObject::origin)
      .def_property_readonly("dof", &RunLogObject::dof)
      .def_property_readonly("size", &RunLogObject::size)
      .def("header", &RunLogObject::header)
      .def("t_s", &RunLogObject::t_s)
      .def("segment", &RunLogObject::segment)
      .def("commanded", &RunLogObject::commanded)
      .def("measured", &RunLogObject::measured)
      .def("p_m", &RunLogObject::p_m)
      .def("approach", &RunLogObject::approach)
      .def("robot", &RunLogObject::robot, py::arg("given") = nullptr)
      .def("path_errors_m", &RunLogObject::path_errors_m, py::arg("given") = nullptr);

  py::module_ plot = m.def_submodule("plot", "The series of rccx plot (view::run_plot).");
  plot.def("run_plot", &run_plot, py::arg("log"), py::arg("given") = nullptr);

  py::module_ db = m.def_submodule("db", "The position database (rccl::PositionDb).");
  py::class_<PositionDbObject>(db, "PositionDbData",
                               "One open position database; rccx.db.PositionDb wraps it.")
      .def(py::init<const std::filesystem::path&, bool, double>(), py::arg("path"),
           py::arg("create"), py::arg("wait_s"))
      .def("get", &PositionDbObject::get, py::arg("robot"), py::arg("name"))
      .def("put", &PositionDbObject::put, py::arg("robot"), py::arg("name"), py::arg("T"),
           py::arg("configuration"), py::arg("note"))
      .def("put_all", &PositionDbObject::put_all, py::arg("all"))
      .def("remove", &PositionDbObject::remove, py::arg("robot"), py::arg("name"))
      .def("robots", &PositionDbObject::robots)
      .def("list", &PositionDbObject::list, py::arg("robot"), py::arg("pattern"))
      .def("schema_version", &PositionDbObject::schema_version)
      .def_property_readonly("path", &PositionDbObject::path)
      .def_property_readonly("closed", &PositionDbObject::closed)
      .def("close", &PositionDbObject::close);
}

}  // namespace rccx::python
