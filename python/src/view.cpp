// rccx.view: `rccx view`'s web page of a robot or a cell that a Python program drives
// (docs/PYTHON.md, "Watching a program"): view::serve over the rccx.Robot's Manipulator, a cell
// robot's, or a rccx.Cell. The server's own thread serves the page; the sample loop only copies
// samples into its queue (view/server.hpp), so nothing of Python runs in either.
//
// Lifetimes: a Server holds the owner (Owner::keep: the simulated robot or the cell) so that the
// sessions it taps outlive it, and is destroyed before them (member order). One view a session
// (a session has one tap): a second serve of a served robot raises, naming the first's address.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "arm.hpp"
#include "rccx/view/server.hpp"

namespace rccx::python {

namespace {

/// The sessions a live Server taps, process-wide (two Python Servers of one robot would replace
/// each other's tap, and the first to close would stop the other's samples).
std::mutex served_mutex;
std::set<const rtc::Session*>& served() {
  static std::set<const rtc::Session*> s;
  return s;
}

}  // namespace

/// rccx.view.Server: a running view::Server and what it shows.
class ViewObject {
 public:
  ViewObject(const py::object& target, long port, const std::string& address, double rate_hz,
             bool announce, const std::optional<std::filesystem::path>& assets) {
    if (port < 0 || port > 65535) {
      raise_value_error(fmt::format("port must be 0 (any free port) .. 65535, got {}", port));
    }
    rccl::Manipulator* arm = nullptr;
    cell::Cell* cell = nullptr;
    if (py::isinstance<CellObject>(target)) {
      const auto& c = target.cast<const CellObject&>();
      owner_ = c.owner();
      cell = &c.cell();
      what_ = "cell";
    } else if (py::isinstance<ArmObject>(target)) {
      const auto& a = target.cast<const ArmObject&>();
      owner_ = a.owner();
      arm = &a.manipulator();
      what_ = "robot " + a.name();
    } else {
      throw py::type_error(
          fmt::format("rccx.view.serve: give a rccx.Robot, a cell's robot (cell.robot(name)) or "
                      "a rccx.Cell, got {}",
                      py::repr(py::type::of(target)).cast<std::string>()));
    }
    view::ServeOptions o;
    o.address = address;
    o.rate_hz = rate_hz;
    o.announce = announce;
    if (assets) o.assets = *assets;
    const ReleaseGil release;                      // binding, the server's thread starting
    const std::lock_guard lock(owner_->planning);  // attach sets the arms' move observers
    if (owner_->closed)
      throw rtc::SessionError(fmt::format("rccx.view.serve: {} is closed", what_));
    if (cell != nullptr) {
      for (const std::string& n : cell->robot_names()) sessions_.push_back(&cell->session(n));
    } else {
      sessions_.push_back(&arm->session());
    }
    const std::lock_guard served_lock(served_mutex);
    for (const rtc::Session* s : sessions_) {
      if (served().count(s) != 0) {
        sessions_.clear();
        throw view::ViewError(fmt::format(
            "{} is already served by a view; close that one (server.close()) first", what_));
      }
    }
    server_ = cell != nullptr ? view::serve(*cell, static_cast<std::uint16_t>(port), std::move(o))
                              : view::serve(*arm, static_cast<std::uint16_t>(port), std::move(o));
    served().insert(sessions_.begin(), sessions_.end());
  }
  ~ViewObject() { stop(); }
  ViewObject(const ViewObject&) = delete;
  ViewObject& operator=(const ViewObject&) = delete;

  /// Stops the server and frees its port; the robots go on. Idempotent.
  void close() {
    const ReleaseGil release;
    stop();
  }
  [[nodiscard]] bool closed() const noexcept { return server_ == nullptr; }
  [[nodiscard]] std::string url() const { return live().url(); }
  [[nodiscard]] std::uint16_t port() const { return live().port(); }
  [[nodiscard]] py::dict stats() const {
    const view::ServerStats s = live().stats();
    py::dict d;
    d["samples_sent"] = s.samples_sent;
    d["samples_dropped"] = s.samples_dropped;
    d["messages_dropped"] = s.messages_dropped;
    d["pages"] = s.pages;
    d["requests"] = s.requests;
    return d;
  }
  /// Draws a position's goal (named) for robot `robot` of the view; planning level.
  void show(const rccl::PositionPtr& position, std::size_t robot) {
    if (!position) raise_value_error("show: no position given");
    const ReleaseGil release;
    const std::lock_guard lock(owner_->planning);
    if (robot >= sessions_.size()) {
      throw py::index_error(
          fmt::format("show: robot {} of a view of {} robot(s)", robot, sessions_.size()));
    }
    live().show(position, robot);
  }
  [[nodiscard]] std::string repr() const {
    return server_ ? fmt::format("<rccx.view.Server {} at {}>", what_, server_->url())
                   : fmt::format("<rccx.view.Server {}, closed>", what_);
  }

 private:
  [[nodiscard]] view::Server& live() const {
    if (!server_) throw view::ViewError("the view is closed");
    return *server_;
  }
  /// Without the GIL (the server's thread is joined) or from Python's deallocation (the thread
  /// touches no Python object, so holding the GIL cannot block it).
  void stop() {
    if (!server_) return;
    // The planning lock: the arms' move observers are planning level (attach set them).
    const std::lock_guard lock(owner_->planning);
    server_.reset();  // detaches every tap, joins the server's thread
    const std::lock_guard served_lock(served_mutex);
    for (const rtc::Session* s : sessions_) served().erase(s);
  }

  std::shared_ptr<Owner> owner_;  ///< keeps the sessions alive: declared before server_
  std::vector<const rtc::Session*> sessions_;
  std::string what_;
  std::unique_ptr<view::Server> server_;
};

namespace {

constexpr const char* kServeDoc =
    R"(Serves `rccx view`'s web page of `target` while the program runs
(C++ rccx::view::serve): a rccx.Robot, a cell's robot (cell.robot(name)) or a rccx.Cell.

port: TCP port, 0 for any free one (Server.port says which). address: the address to listen on,
"127.0.0.1" (this machine only) or "0.0.0.0" (the network; the page is read-only). rate: samples
a second sent to the page, 1 .. 200 Hz. announce: print "rccx view: open URL" on stderr.
assets: the front end's folder (None: RCCX_VIEW_ASSETS, the build tree, the install).
The page draws the robots as they move and the goal of every position they move to.
Returns a Server (.url, .close(), a context manager); it keeps the robot or cell alive.
Raises rccx.ViewError with rccx's message for a port in use, an address that cannot be bound,
a robot another view serves; rccx.SessionError for a closed robot.)";

}  // namespace

void bind_view(py::module_& m) {
  py::module_ v = m.def_submodule(
      "view", "The web page of robots at work (C++ rccx::view), served from this program.");
  add_exception<view::ViewError>(
      m, "ViewError", PyExc_RuntimeError,
      "The view cannot start (a port in use, an address that cannot be bound, a robot another "
      "view serves) or is closed; the message says what to do.");
  py::class_<ViewObject>(v, "Server",
                         "A running view (C++ rccx::view::Server): its page at .url until "
                         "close(). Made by rccx.view.serve.")
      .def_property_readonly("url", &ViewObject::url, "The page's address, http://ADDRESS:PORT/.")
      .def_property_readonly("port", &ViewObject::port, "The TCP port it listens on.")
      .def_property_readonly("closed", &ViewObject::closed, "True once close() ran.")
      .def("stats", &ViewObject::stats,
           "dict: samples_sent, samples_dropped (the sample loop's queue full), "
           "messages_dropped (pages that did not keep up), pages (open now), requests.")
      .def("show", &ViewObject::show, py::arg("position"), py::arg("robot") = 0,
           "Draws a position's goal (where its equation puts the tool) for robot `robot` "
           "(0-based) of the view; the robots' moves draw theirs by themselves.")
      .def("close", &ViewObject::close,
           "Stops the server and frees its port; the robots go on. Idempotent.")
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](ViewObject& s, const py::args&) { s.close(); })
      .def("__repr__", &ViewObject::repr);
  v.def(
      "serve",
      [](const py::object& target, long port, const std::string& address, double rate,
         bool announce, const std::optional<std::filesystem::path>& assets) {
        return std::make_unique<ViewObject>(target, port, address, rate, announce, assets);
      },
      py::arg("target"), py::arg("port") = 8080, py::kw_only(), py::arg("address") = "127.0.0.1",
      py::arg("rate") = 50.0, py::arg("announce") = true, py::arg("assets") = py::none(),
      kServeDoc);
  v.def(
      "find_assets",
      []() -> std::optional<std::filesystem::path> {
        auto p = view::find_assets();
        if (p.empty()) return std::nullopt;
        return p;
      },
      "The front end's folder the view serves by default (RCCX_VIEW_ASSETS, the build tree, the "
      "install), or None when none was built.");
}

}  // namespace rccx::python
