#include "rccx/view/server.hpp"

// Before Boost.Asio 1.74, whose awaitable.hpp uses std::exchange without including it.
#include <utility>

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/lockfree/spsc_queue.hpp>
#include <chrono>
#include <cmath>
#include <deque>
#include <future>
#include <limits>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "rccx/cell/cell.hpp"
#include "rccx/io/console.hpp"
#include "rccx/io/file.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/session.hpp"

#ifndef RCCX_VIEW_BUILD_ASSETS
#define RCCX_VIEW_BUILD_ASSETS ""
#endif

namespace rccx::view {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
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

// ------------------------------------------------------------------------------------------
// The tap: what the communication task calls. Fixed size, lock-free, allocation-free.

struct TapSample {
  double t_s = 0.0;
  std::int32_t segment = 0;
  std::uint8_t dof = 0;
  std::array<double, kin::kMaxJoints> q{};   ///< commanded
  std::array<double, kin::kMaxJoints> qm{};  ///< measured
  std::array<double, kin::kMaxJoints> qd{};  ///< measured speed
};

class RobotTap final : public rtc::SampleTap {
 public:
  explicit RobotTap(double interval_s) : interval_s_(interval_s) {}

  void on_sample(const rtc::How& how, const kin::JointVector& commanded,
                 std::int32_t segment) noexcept override {
    if (how.time_s + 1e-9 < next_t_s_ && how.time_s >= last_t_s_) return;  // decimated
    last_t_s_ = how.time_s;
    next_t_s_ = how.time_s + interval_s_;
    TapSample s;
    s.t_s = how.time_s;
    s.segment = segment;
    s.dof = how.dof;
    for (std::size_t i = 0; i < how.dof; ++i) {
      s.q[i] = commanded[i];
      s.qm[i] = how.joint[i].q;
      s.qd[i] = how.joint[i].velocity;
    }
    if (!queue_.push(s)) dropped_.fetch_add(1, std::memory_order_relaxed);
  }
  bool pop(TapSample& s) noexcept { return queue_.pop(s); }
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(); }

 private:
  double interval_s_;
  double next_t_s_ = -std::numeric_limits<double>::infinity();
  double last_t_s_ = -std::numeric_limits<double>::infinity();
  boost::lockfree::spsc_queue<TapSample, boost::lockfree::capacity<1024>> queue_;
  std::atomic<std::uint64_t> dropped_{0};
};

/// The frames the program adds (add_frame, show, the goals of attached arms' moves) and which
/// goal each queued motion goes to. Written at the planning level, read by the server thread.
/// The arms' move observers hold it weakly: an arm that outlives the server finds it gone.
struct Goals {
  std::mutex mutex;
  std::vector<SceneFrame> frames;
  /// Per scene robot: motion id -> index in frames, for the motions not yet past.
  std::vector<std::map<std::uint64_t, std::size_t>> motion_frame;
  /// Per scene robot, fixed before any thread shares this (the solvers keep no state).
  std::vector<std::unique_ptr<kin::Kinematics>> kinematics;
  std::vector<math::Transform> base;

  /// The world pose of `p`'s goal (the tool frame where the equation puts it) for `robot`,
  /// drawn and named; the same name for the same robot moves its frame. `motion` != 0: the
  /// motion that goes there.
  void show(const rccl::Position& p, std::size_t robot, std::uint64_t motion) {
    math::Transform goal;
    if (p.in_joints()) {
      goal = kinematics.at(robot)->forward(p.joint_values());
    } else if (p.fixed()) {
      goal = p.t6_now();
    } else {
      goal = p.t6_at({});
    }
    SceneFrame f{p.name(), base.at(robot) * goal * p.tool_now(), p.describe(),
                 static_cast<int>(robot)};
    std::lock_guard lock(mutex);
    const auto same = std::find_if(frames.begin(), frames.end(), [&](const SceneFrame& g) {
      return g.robot == f.robot && g.name == f.name;
    });
    const std::size_t index = static_cast<std::size_t>(same - frames.begin());
    if (same == frames.end()) {
      frames.push_back(std::move(f));
    } else {
      *same = std::move(f);
    }
    if (motion != 0) motion_frame.at(robot)[motion] = index;
  }

  /// The name of the goal motion `id` of `robot` goes to, empty when not known; forgets the
  /// motions before it (a generator runs its motions in the order of their ids). Server thread.
  std::string goal_of(std::size_t robot, std::uint64_t id) {
    if (id == 0) return {};
    std::lock_guard lock(mutex);
    auto& m = motion_frame[robot];
    m.erase(m.begin(), m.lower_bound(id));
    const auto it = m.find(id);
    return it == m.end() ? std::string() : frames[it->second].name;
  }
};

std::string_view content_type(const std::filesystem::path& p) {
  const std::string ext = p.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json" || ext == ".map") return "application/json";
  if (ext == ".png") return "image/png";
  if (ext == ".svg") return "image/svg+xml";
  return "application/octet-stream";
}

bool safe_asset_name(std::string_view name) {
  if (name.empty() || name.size() > 100 || name.front() == '.') return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '.' || c == '-' || c == '_';
    if (!ok) return false;
  }
  return true;
}

/// The value of `key` in a query string ("a=1&b=2"), percent-decoding not needed for names.
std::optional<std::string> query_value(std::string_view query, std::string_view key) {
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    const std::string_view part = query.substr(0, amp);
    const std::size_t eq = part.find('=');
    if (part.substr(0, eq) == key) {
      return std::string(eq == std::string_view::npos ? std::string_view() : part.substr(eq + 1));
    }
    if (amp == std::string_view::npos) break;
    query.remove_prefix(amp + 1);
  }
  return std::nullopt;
}

std::string html_escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

// ------------------------------------------------------------------------------------------
// The server

struct Server::Impl {
  class WsSession;
  class HttpSession;

  Scene scene;
  ServeOptions options;
  std::filesystem::path assets;
  asio::io_context io{1};
  tcp::acceptor acceptor{io};
  asio::steady_timer timer{io};
  std::uint16_t bound_port = 0;
  std::thread thread;

  // Per robot (index of the scene).
  struct RobotState {
    std::unique_ptr<RobotTap> tap;
    rtc::Session* session = nullptr;  ///< planning side only
    std::unique_ptr<kin::Kinematics> kinematics;
    math::Transform tool = math::Transform::identity();
    bool has_last = false;
    double last_t = 0.0;
    math::Vec3 last_p;
    std::deque<json> history;  ///< server thread only
    json latest;               ///< guarded by state_mutex
  };
  std::vector<RobotState> robots;
  std::vector<TapSample> popped;  ///< drain()'s, kept between ticks
  /// At most this many samples a robot a tick go to the pages (see drain()).
  static constexpr std::size_t kPerTick = 3;
  std::optional<RunLog> replay;
  json replay_json;

  mutable std::mutex state_mutex;  ///< latest (server thread vs planning level)
  std::shared_ptr<Goals> goals = std::make_shared<Goals>();
  std::set<WsSession*> pages;  ///< server thread only
  std::atomic<std::uint64_t> samples_sent{0}, messages_dropped{0}, requests{0};
  std::atomic<std::size_t> page_count{0};

  json scene_json(int only) const {
    Scene s = scene;
    {
      std::lock_guard lock(goals->mutex);
      s.frames.insert(s.frames.end(), goals->frames.begin(), goals->frames.end());
    }
    json j = to_json(s, only);
    j["mode"] = replay ? "replay" : "live";
    j["rate_hz"] = options.rate_hz;
    return j;
  }

  // --- WebSocket: one page's live samples --------------------------------------------------
  class WsSession : public std::enable_shared_from_this<WsSession> {
   public:
    WsSession(tcp::socket socket, Impl& server, int robot)
        : ws_(std::move(socket)), server_(server), robot_(robot) {}

    void start(http::request<http::string_body> req) {
      ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
      ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
        if (ec) return;
        self->server_.pages.insert(self.get());
        self->server_.page_count = self->server_.pages.size();
        self->greet();
        self->read();
      });
    }
    /// A message for this page; dropped when it has too many waiting (a slow page).
    void send(const std::shared_ptr<const std::string>& msg, bool droppable = true) {
      if (closed_) return;
      if (droppable && outbox_.size() >= 32) {
        server_.messages_dropped.fetch_add(1, std::memory_order_relaxed);
        return;
      }
      outbox_.push_back(msg);
      if (outbox_.size() == 1) write();
    }
    [[nodiscard]] int robot() const noexcept { return robot_; }

   private:
    void greet() {
      json hello = {{"type", "hello"}, {"mode", server_.replay ? "replay" : "live"}};
      send(std::make_shared<const std::string>(hello.dump()), false);
      json frames = json::array();
      for (std::size_t r = 0; r < server_.robots.size(); ++r) {
        if (robot_ >= 0 && static_cast<int>(r) != robot_) continue;
        for (const json& f : server_.robots[r].history) frames.push_back(f);
      }
      if (!frames.empty()) {
        json m = {{"type", "frames"}, {"history", true}, {"frames", std::move(frames)}};
        send(std::make_shared<const std::string>(m.dump()), false);
      }
    }
    void read() {
      ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
        if (ec) return self->close();
        self->buffer_.consume(self->buffer_.size());  // read-only: what a page says is ignored
        self->read();
      });
    }
    void write() {
      ws_.text(true);
      ws_.async_write(asio::buffer(*outbox_.front()),
                      [self = shared_from_this()](beast::error_code ec, std::size_t) {
                        if (ec) return self->close();
                        self->outbox_.pop_front();
                        if (!self->outbox_.empty()) self->write();
                      });
    }
    void close() {
      if (closed_) return;
      closed_ = true;
      outbox_.clear();
      server_.pages.erase(this);
      server_.page_count = server_.pages.size();
    }

    websocket::stream<beast::tcp_stream> ws_;
    Impl& server_;
    int robot_;
    beast::flat_buffer buffer_;
    std::deque<std::shared_ptr<const std::string>> outbox_;
    bool closed_ = false;
  };

  // --- HTTP ----------------------------------------------------------------------------------
  class HttpSession : public std::enable_shared_from_this<HttpSession> {
   public:
    HttpSession(tcp::socket socket, Impl& server) : stream_(std::move(socket)), server_(server) {}
    void start() { read(); }

   private:
    void read() {
      req_ = {};
      stream_.expires_after(std::chrono::seconds(60));
      http::async_read(stream_, buffer_, req_,
                       [self = shared_from_this()](beast::error_code ec, std::size_t) {
                         if (ec) {
                           beast::error_code ignored;
                           self->stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
                           return;
                         }
                         self->handle();
                       });
    }

    void reply(http::status status, std::string body, std::string_view type) {
      auto res = std::make_shared<http::response<http::string_body>>(status, req_.version());
      res->set(http::field::server, "rccx view");
      res->set(http::field::content_type, std::string(type));
      res->set(http::field::cache_control, "no-store");
      res->keep_alive(req_.keep_alive());
      res->body() = req_.method() == http::verb::head ? std::string() : std::move(body);
      res->prepare_payload();
      http::async_write(stream_, *res,
                        [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
                          if (ec) return;
                          if (!res->keep_alive()) {
                            beast::error_code ignored;
                            self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                            return;
                          }
                          self->read();
                        });
    }
    void reply_json(http::status status, const json& j) {
      reply(status, j.dump(), "application/json");
    }
    void not_found(std::string message) {
      const std::string target(req_.target());
      if (target.starts_with("/api/") || target.starts_with("/ws")) {
        return reply_json(http::status::not_found, {{"error", message}});
      }
      reply(http::status::not_found,
            fmt::format("<!doctype html><meta charset=utf-8><title>rccx view: not found</title>"
                        "<h1>rccx view: not found</h1><p>{}</p><p><a href=\"/\">All robots</a></p>",
                        html_escape(message)),
            "text/html; charset=utf-8");
    }
    /// The robot a ?robot= or /robot/NAME names: -1 for all, -2 (and a 404 sent) for unknown.
    int robot_of(const std::optional<std::string>& name) {
      if (!name) return -1;
      const int i = server_.scene.find(*name);
      if (i < 0) {
        not_found(fmt::format("no robot \"{}\" here; the robots are: {}", *name,
                              server_.scene.robot_list()));
        return -2;
      }
      return i;
    }

    void handle() {
      server_.requests.fetch_add(1, std::memory_order_relaxed);
      const std::string target(req_.target());
      const std::size_t q = target.find('?');
      const std::string path = target.substr(0, q);
      const std::string query = q == std::string::npos ? std::string() : target.substr(q + 1);
      if (req_.method() != http::verb::get && req_.method() != http::verb::head) {
        return reply(http::status::method_not_allowed,
                     "rccx view is read-only: it answers GET only\n", "text/plain");
      }
      if (path == "/ws") {
        const int robot = robot_of(query_value(query, "robot"));
        if (robot == -2) return;
        if (!websocket::is_upgrade(req_)) {
          return reply(http::status::bad_request, "/ws is a WebSocket\n", "text/plain");
        }
        std::make_shared<WsSession>(stream_.release_socket(), server_, robot)
            ->start(std::move(req_));
        return;
      }
      if (path == "/" || path == "/index.html" || path.starts_with("/robot/")) {
        if (path.starts_with("/robot/")) {
          if (robot_of(path.substr(7)) == -2) return;
        }
        return asset("index.html");
      }
      if (path.starts_with("/assets/")) return asset(path.substr(8));
      if (path == "/api/scene") {
        const int robot = robot_of(query_value(query, "robot"));
        if (robot == -2) return;
        return reply_json(http::status::ok, server_.scene_json(robot));
      }
      if (path == "/api/state") return state(query);
      if (path == "/api/log") {
        if (!server_.replay) {
          return not_found(
              "no recorded run here: this view is live (rccx view --log FILE replays)");
        }
        return reply(http::status::ok, server_.replay_json.dump(), "application/json");
      }
      if (path == "/favicon.ico") return reply(http::status::no_content, "", "image/x-icon");
      not_found(fmt::format("nothing at {}", path));
    }

    void state(const std::string& query) {
      const int robot = robot_of(query_value(query, "robot"));
      if (robot == -2) return;
      if (const auto t = query_value(query, "t")) {
        if (robot < 0) {
          return reply_json(http::status::bad_request, {{"error", "?t= needs ?robot=NAME"}});
        }
        double when = 0.0;
        try {
          when = std::stod(*t);
        } catch (const std::exception&) {
          return reply_json(http::status::bad_request, {{"error", "?t= is a time in s"}});
        }
        for (const json& f : server_.robots[robot].history) {
          if (std::abs(f["t"].get<double>() - when) < 1e-7) return reply_json(http::status::ok, f);
        }
        return not_found(fmt::format("no sample at t = {} s in the history", when));
      }
      json out = json::array();
      std::lock_guard lock(server_.state_mutex);
      for (std::size_t r = 0; r < server_.robots.size(); ++r) {
        if (robot >= 0 && static_cast<int>(r) != robot) continue;
        out.push_back(server_.robots[r].latest);
      }
      reply_json(http::status::ok, {{"robots", out}});
    }

    void asset(const std::string& name) {
      if (!safe_asset_name(name)) return not_found(fmt::format("no file {}", name));
      if (server_.assets.empty()) {
        return reply(http::status::service_unavailable,
                     "rccx view: the front end was not built (no web/ bundle beside the program). "
                     "Build it: cmake --build BUILD_DIR --target rccx_web (needs node and npm; "
                     "scripts/install-deps), or set RCCX_VIEW_ASSETS to its folder.\n",
                     "text/plain");
      }
      std::string body;
      try {
        body = io::read_file(server_.assets / name);
      } catch (const std::exception&) {
        return not_found(fmt::format("no file {}", name));
      }
      reply(http::status::ok, std::move(body), content_type(name));
    }

    beast::tcp_stream stream_;
    Impl& server_;
    beast::flat_buffer buffer_;
    http::request<http::string_body> req_;
  };

  void accept() {
    acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
      if (ec == asio::error::operation_aborted) return;
      if (!ec) std::make_shared<HttpSession>(std::move(socket), *this)->start();
      accept();
    });
  }

  void tick() {
    timer.expires_after(std::chrono::microseconds(static_cast<long>(1e6 / options.rate_hz)));
    timer.async_wait([this](beast::error_code ec) {
      if (ec) return;
      drain();
      tick();
    });
  }

  /// The server thread: takes what the taps queued, adds the tool frame, sends it on.
  void drain() {
    std::vector<json> per_robot(robots.size(), json::array());
    bool any = false;
    for (std::size_t r = 0; r < robots.size(); ++r) {
      RobotState& rs = robots[r];
      if (!rs.tap) continue;
      // What came since the last tick. Simulated time runs many times faster than the clock
      // on the wall: then only a few of them, evenly spaced and the newest among them, go on
      // (a page takes about the rate a second; the server's work stays as small as in real
      // time, and so does what it takes from the processors the loop runs on).
      popped.clear();
      TapSample one;
      while (rs.tap->pop(one)) popped.push_back(one);
      samples_sent.fetch_add(popped.size(), std::memory_order_relaxed);
      const std::size_t every = (popped.size() + kPerTick - 1) / kPerTick;
      for (std::size_t k = 0; k < popped.size(); ++k) {
        if ((popped.size() - 1 - k) % std::max<std::size_t>(every, 1) != 0) continue;
        const TapSample& s = popped[k];
        kin::JointVector q(std::span<const double>(s.q.data(), s.dof));
        const math::Transform pose = scene.robots[r].base * rs.kinematics->forward(q) * rs.tool;
        double speed = 0.0;
        if (rs.has_last && s.t_s > rs.last_t) {
          speed = (pose.p - rs.last_p).norm() / (s.t_s - rs.last_t);
        }
        rs.has_last = true;
        rs.last_t = s.t_s;
        rs.last_p = pose.p;
        json f = {{"r", r},
                  {"t", s.t_s},
                  {"seg", s.segment},
                  {"q", std::vector<double>(s.q.begin(), s.q.begin() + s.dof)},
                  {"qm", std::vector<double>(s.qm.begin(), s.qm.begin() + s.dof)},
                  {"qd", std::vector<double>(s.qd.begin(), s.qd.begin() + s.dof)},
                  {"p", {pose.p.x, pose.p.y, pose.p.z}},
                  {"v", speed}};
        if (std::string goal =
                goals->goal_of(r, static_cast<std::uint64_t>(std::max(0, s.segment)));
            !goal.empty()) {
          f["goal"] = std::move(goal);
        }
        rs.history.push_back(f);
        while (rs.history.size() > options.history) rs.history.pop_front();
        per_robot[r].push_back(std::move(f));
        any = true;
      }
      if (!per_robot[r].empty()) {
        std::lock_guard lock(state_mutex);
        rs.latest = per_robot[r].back();
      }
    }
    if (!any || pages.empty()) return;
    std::shared_ptr<const std::string> all;
    std::vector<std::shared_ptr<const std::string>> one(robots.size());
    // Copy: a page that fails to write closes and leaves the set while we go through it.
    const std::vector<WsSession*> now(pages.begin(), pages.end());
    for (WsSession* page : now) {
      const int r = page->robot();
      std::shared_ptr<const std::string>* msg = r < 0 ? &all : &one[static_cast<std::size_t>(r)];
      if (!*msg) {
        json frames = json::array();
        for (std::size_t i = 0; i < robots.size(); ++i) {
          if (r >= 0 && static_cast<int>(i) != r) continue;
          for (const json& f : per_robot[i]) frames.push_back(f);
        }
        if (frames.empty()) continue;
        *msg = std::make_shared<const std::string>(
            json({{"type", "frames"}, {"frames", std::move(frames)}}).dump());
      }
      page->send(*msg);
    }
  }
};

Server::Server(Scene scene, std::uint16_t port, ServeOptions options)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  if (!(options.rate_hz >= 1.0 && options.rate_hz <= 200.0)) {
    throw ViewError(fmt::format("the view's rate {} Hz is outside 1 .. 200 Hz", options.rate_hz));
  }
  s.scene = std::move(scene);
  s.options = std::move(options);
  s.assets = s.options.assets.empty() ? find_assets() : s.options.assets;
  for (const SceneRobot& r : s.scene.robots) {
    s.goals->kinematics.push_back(kin::make_kinematics(r.model));
    s.goals->base.push_back(r.base);
    s.goals->motion_frame.emplace_back();
    Impl::RobotState rs;
    rs.kinematics = kin::make_kinematics(r.model);
    // Every robot's tap is made now, before the server thread runs: attach() only hands it over.
    rs.tap = std::make_unique<RobotTap>(1.0 / s.options.rate_hz);
    if (r.tool) rs.tool = *r.tool;
    s.robots.push_back(std::move(rs));
  }
  beast::error_code ec;
  const asio::ip::address address = asio::ip::make_address(s.options.address, ec);
  if (ec) {
    throw ViewError(
        fmt::format("the view's address \"{}\" is not an IP address; give one such as "
                    "127.0.0.1 (this machine only) or 0.0.0.0 (every network)",
                    s.options.address));
  }
  const tcp::endpoint endpoint(address, port);
  s.acceptor.open(endpoint.protocol(), ec);
  if (!ec) s.acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) s.acceptor.bind(endpoint, ec);
  if (ec == asio::error::address_in_use) {
    throw ViewError(
        fmt::format("port {} on {} is in use (another rccx view, or another server); "
                    "choose another with --port, or --port 0 for any free port",
                    port, s.options.address));
  }
  if (!ec) s.acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) {
    throw ViewError(
        fmt::format("cannot listen on {} port {}: {}", s.options.address, port, ec.message()));
  }
  s.bound_port = s.acceptor.local_endpoint().port();
  s.accept();
  s.tick();
  s.thread = std::thread([&s] { s.io.run(); });
  if (s.options.announce) {
    io::eprint("rccx view: open {} (Ctrl-C to stop){}\n", url(),
               s.assets.empty() ? "; the front end was not built, the page will say how" : "");
  }
}

Server::~Server() {
  for (Impl::RobotState& r : impl_->robots) {
    if (r.session != nullptr) r.session->set_tap(nullptr);
  }
  impl_->io.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

void Server::attach(std::size_t robot, rtc::Session& session) {
  Impl::RobotState& r = impl_->robots.at(robot);
  if (r.session != nullptr) throw ViewError("a robot of the view is tapped once");
  r.session = &session;
  session.set_tap(r.tap.get());
}

void Server::set_replay(RunLog log) {
  Impl& s = *impl_;
  if (s.scene.robots.empty()) throw ViewError("a replay needs a robot");
  const SceneRobot& robot = s.scene.robots[0];
  if (log.dof != robot.model.dof()) {
    throw RunLogError(
        fmt::format("the log has {} joints, robot {} has {}: give the robot it was "
                    "recorded with (--robot)",
                    log.dof, robot.model.name, robot.model.dof()));
  }
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
  json replay_json = {
      {"robot", robot.name}, {"t", t}, {"seg", seg}, {"q", q}, {"qm", qm}, {"p", p}};
  // Handed to the server thread, which alone reads it.
  std::promise<void> done;
  asio::post(s.io, [&] {
    s.replay_json = std::move(replay_json);
    s.replay = std::move(log);
    done.set_value();
  });
  done.get_future().wait();
}

void Server::attach(std::size_t robot, rccl::Manipulator& arm) {
  Impl::RobotState& r = impl_->robots.at(robot);
  if (r.session == nullptr) {
    attach(robot, arm.session());
  } else if (r.session != &arm.session()) {
    throw ViewError(fmt::format("robot {} of the view taps another session than this arm's",
                                impl_->scene.robots[robot].name));
  }
  arm.set_move_observer([goals = std::weak_ptr<Goals>(impl_->goals), robot](
                            const rccl::Motion& m, const rccl::PositionPtr& p) {
    const std::shared_ptr<Goals> g = goals.lock();
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
  (void)impl_->scene.robots.at(robot);
  impl_->goals->show(*position, robot, 0);
}

void Server::add_frame(SceneFrame frame) {
  std::lock_guard lock(impl_->goals->mutex);
  impl_->goals->frames.push_back(std::move(frame));
}

std::uint16_t Server::port() const noexcept {
  return impl_->bound_port;
}

std::string Server::url() const {
  const std::string& a = impl_->options.address;
  const std::string host =
      a == "0.0.0.0" ? "127.0.0.1" : (a.find(':') != a.npos ? "[" + a + "]" : a);
  return fmt::format("http://{}:{}/", host, impl_->bound_port);
}

ServerStats Server::stats() const {
  ServerStats st;
  st.samples_sent = impl_->samples_sent.load();
  for (const auto& r : impl_->robots) {
    if (r.tap) st.samples_dropped += r.tap->dropped();
  }
  st.messages_dropped = impl_->messages_dropped.load();
  st.pages = impl_->page_count.load();
  st.requests = impl_->requests.load();
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
  // Checked before the port is taken.
  if (log.dof != model.dof()) {
    throw RunLogError(
        fmt::format("the log has {} joints, robot {} has {}: give the robot it was "
                    "recorded with (--robot)",
                    log.dof, model.name, model.dof()));
  }
  auto server = std::make_unique<Server>(std::move(scene), port, std::move(options));
  server->set_replay(std::move(log));
  return server;
}

}  // namespace rccx::view
