#include "rccx/view/server.hpp"

// Before Boost.Asio 1.74, whose awaitable.hpp uses std::exchange without including it.
#include <utility>

#include <fmt/format.h>

#include <boost/asio.hpp>
#include <chrono>
#include <cstdlib>
#include <future>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "rccx/cell/cell.hpp"
#include "rccx/io/console.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/session.hpp"
#include "rccx/view/routes.hpp"
#include "rccx/view/site.hpp"

#ifndef RCCX_VIEW_BUILD_ASSETS
#define RCCX_VIEW_BUILD_ASSETS ""
#endif

namespace rccx::view {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using json = nlohmann::json;

std::filesystem::path find_assets() {
  namespace fs = std::filesystem;
  const auto has_page = [](const fs::path& d) {
    std::error_code ec;
    return !d.empty() && fs::is_regular_file(d / "index.html", ec);
  };
  if (const char* env = std::getenv("RCCX_VIEW_ASSETS"); env != nullptr && *env != '\0') {
    return has_page(env) ? fs::path(env) : fs::path();
  }
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (const fs::path& d : {exe.parent_path().parent_path() / "web" / "dist",
                              exe.parent_path().parent_path() / "share" / "rccx" / "web"}) {
      if (has_page(d)) return d;
    }
  }
  if (has_page(RCCX_VIEW_BUILD_ASSETS)) return RCCX_VIEW_BUILD_ASSETS;
  return {};
}

namespace {

/// Refuses (RunLogError) a log whose joints are not `model`'s.
void check_log_fits(const RunLog& log, const kin::RobotModel& model) {
  if (log.dof != model.dof()) {
    throw RunLogError(
        fmt::format("the log has {} joints, robot {} has {}: give the robot it was "
                    "recorded with (--robot)",
                    log.dof, model.name, model.dof()));
  }
}

/// The whole recorded run as the page replays it (GET /api/log): positions in the world.
json replay_json(const RunLog& log, const SceneRobot& robot) {
  json t = json::array(), q = json::array(), qm = json::array(), p = json::array(),
       seg = json::array();
  for (const RunRow& row : log.rows) {
    t.push_back(row.t_s);
    seg.push_back(row.segment);
    q.push_back(std::vector<double>(row.commanded.begin(), row.commanded.end()));
    qm.push_back(std::vector<double>(row.measured.begin(), row.measured.end()));
    const math::Vec3 world = robot.base * math::Vec3{row.p[0], row.p[1], row.p[2]};
    p.push_back({world.x, world.y, world.z});
  }
  return {{"robot", robot.name}, {"t", t}, {"seg", seg}, {"q", q}, {"qm", qm}, {"p", p}};
}

}  // namespace

// The server: its thread runs one io_context that accepts connections (routes.cpp, which hands
// a page's WebSocket to page_socket.cpp) and, every 1/rate s, drains the sample feed
// (sample_feed.cpp) to the pages.
struct Server::Impl {
  Impl(Scene scene, ServeOptions options) : site(std::move(scene), std::move(options)) {}

  /// Binds and listens on site.options.address:port; ViewError saying what to do.
  void listen(std::uint16_t port);
  void accept() {
    acceptor.async_accept([this](boost::system::error_code ec, tcp::socket socket) {
      if (ec == asio::error::operation_aborted) return;
      if (!ec) detail::serve_http(std::move(socket), site);
      accept();
    });
  }
  void tick() {
    timer.expires_after(std::chrono::microseconds(static_cast<long>(1e6 / site.options.rate_hz)));
    timer.async_wait([this](boost::system::error_code ec) {
      if (ec) return;
      site.pages.broadcast(site.feed.drain());
      tick();
    });
  }

  detail::Site site;
  /// Per scene robot, the session tapped (planning side only).
  std::vector<rtc::Session*> sessions = std::vector<rtc::Session*>(site.scene.robots.size());
  asio::io_context io{1};
  tcp::acceptor acceptor{io};
  asio::steady_timer timer{io};
  std::uint16_t bound_port = 0;
  std::thread thread;
};

void Server::Impl::listen(std::uint16_t port) {
  const std::string& where = site.options.address;
  boost::system::error_code ec;
  const asio::ip::address address = asio::ip::make_address(where, ec);
  if (ec) {
    throw ViewError(
        fmt::format("the view's address \"{}\" is not an IP address; give one such as "
                    "127.0.0.1 (this machine only) or 0.0.0.0 (every network)",
                    where));
  }
  const tcp::endpoint endpoint(address, port);
  acceptor.open(endpoint.protocol(), ec);
  if (!ec) acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) acceptor.bind(endpoint, ec);
  if (ec == asio::error::address_in_use) {
    throw ViewError(
        fmt::format("port {} on {} is in use (another rccx view, or another server); "
                    "choose another with --port, or --port 0 for any free port",
                    port, where));
  }
  if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) {
    throw ViewError(fmt::format("cannot listen on {} port {}: {}", where, port, ec.message()));
  }
  bound_port = acceptor.local_endpoint().port();
}

Server::Server(Scene scene, std::uint16_t port, ServeOptions options) {
  if (!(options.rate_hz >= 1.0 && options.rate_hz <= 200.0)) {
    throw ViewError(fmt::format("the view's rate {} Hz is outside 1 .. 200 Hz", options.rate_hz));
  }
  impl_ = std::make_unique<Impl>(std::move(scene), std::move(options));
  Impl& s = *impl_;
  s.listen(port);
  s.accept();
  s.tick();
  s.thread = std::thread([&s] { s.io.run(); });
  if (s.site.options.announce) announce();
}

void Server::announce() const {
  io::eprint(
      "rccx view: open {} (Ctrl-C to stop){}\n", url(),
      impl_->site.assets.empty() ? "; the front end was not built, the page will say how" : "");
}

Server::~Server() {
  for (rtc::Session* session : impl_->sessions) {
    if (session != nullptr) session->set_tap(nullptr);
  }
  impl_->io.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

void Server::attach(std::size_t robot, rtc::Session& session) {
  rtc::Session*& tapped = impl_->sessions.at(robot);
  if (tapped != nullptr) throw ViewError("a robot of the view is tapped once");
  tapped = &session;
  session.set_tap(&impl_->site.feed.tap(robot));
}

void Server::set_replay(RunLog log) {
  detail::Site& s = impl_->site;
  if (s.scene.robots.empty()) throw ViewError("a replay needs a robot");
  const SceneRobot& robot = s.scene.robots[0];
  check_log_fits(log, robot.model);
  json replay = replay_json(log, robot);
  // Handed to the server thread, which alone reads it.
  std::promise<void> done;
  asio::post(impl_->io, [&] {
    s.replay_json = std::move(replay);
    s.replay = std::move(log);
    done.set_value();
  });
  done.get_future().wait();
}

void Server::attach(std::size_t robot, rccl::Manipulator& arm) {
  rtc::Session* tapped = impl_->sessions.at(robot);
  if (tapped == nullptr) {
    attach(robot, arm.session());
  } else if (tapped != &arm.session()) {
    throw ViewError(fmt::format("robot {} of the view taps another session than this arm's",
                                impl_->site.scene.robots[robot].name));
  }
  arm.set_move_observer([goals = std::weak_ptr<detail::Goals>(impl_->site.goals), robot](
                            const rccl::Motion& m, const rccl::PositionPtr& p) {
    const std::shared_ptr<detail::Goals> g = goals.lock();
    if (!g || !p) return;
    try {
      g->show(*p, robot, m.id);
    } catch (const std::exception&) {
      // Only a drawing: a goal that cannot be evaluated now is not drawn, the motion goes on.
    }
  });
}

void Server::show(const rccl::PositionPtr& position, std::size_t robot) {
  if (!position) return;
  (void)impl_->site.scene.robots.at(robot);
  impl_->site.goals->show(*position, robot, 0);
}

void Server::add_frame(SceneFrame frame) {
  impl_->site.goals->add_frame(std::move(frame));
}

std::uint16_t Server::port() const noexcept {
  return impl_->bound_port;
}

std::string Server::url() const {
  const std::string& a = impl_->site.options.address;
  const std::string host =
      a == "0.0.0.0" ? "127.0.0.1" : (a.find(':') != a.npos ? "[" + a + "]" : a);
  return fmt::format("http://{}:{}/", host, impl_->bound_port);
}

ServerStats Server::stats() const {
  const detail::Site& s = impl_->site;
  ServerStats st;
  st.samples_sent = s.feed.samples_sent();
  st.samples_dropped = s.feed.samples_dropped();
  st.messages_dropped = s.pages.messages_dropped();
  st.pages = s.pages.count();
  st.requests = s.requests.load();
  return st;
}

std::unique_ptr<Server> serve(rtc::Session& session, std::uint16_t port, ServeOptions options) {
  auto server =
      std::make_unique<Server>(Scene::of_robot(session.driver().model()), port, std::move(options));
  server->attach(0, session);
  return server;
}

std::unique_ptr<Server> serve(rccl::Manipulator& arm, std::uint16_t port, ServeOptions options) {
  auto server = std::make_unique<Server>(Scene::of_robot(arm.session().driver().model()), port,
                                         std::move(options));
  server->attach(0, arm);
  return server;
}

std::unique_ptr<Server> serve(cell::Cell& cell, std::uint16_t port, ServeOptions options) {
  auto server = std::make_unique<Server>(Scene::of_cell(cell.model()), port, std::move(options));
  for (std::size_t i = 0; i < cell.model().robots.size(); ++i) {
    server->attach(i, cell.robot(cell.model().robots[i].name));
  }
  return server;
}

std::unique_ptr<Server> serve_replay(const kin::RobotModel& model, RunLog log, std::uint16_t port,
                                     ServeOptions options) {
  Scene scene = Scene::of_robot(model);
  scene.title += " (replay)";
  check_log_fits(log, model);  // before the port is taken
  // Announced once the log is in: a page opened at the address at once (a test, a user's
  // click) would otherwise get the live page of a robot that never moves.
  const bool announce = options.announce;
  options.announce = false;
  auto server = std::make_unique<Server>(std::move(scene), port, std::move(options));
  server->set_replay(std::move(log));
  if (announce) server->announce();
  return server;
}

}  // namespace rccx::view
