#include "rccx/view/routes.hpp"

#include <fmt/format.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "rccx/io/file.hpp"
#include "rccx/view/page_socket.hpp"
#include "rccx/view/site.hpp"

namespace rccx::view::detail {

namespace websocket = beast::websocket;

namespace {

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

/// The scene with the frames the program added, its mode and its rate.
json scene_json(const Site& site, int only) {
  Scene s = site.scene;
  site.goals->copy_frames(s.frames);
  json j = to_json(s, only);
  j["mode"] = site.mode();
  j["rate_hz"] = site.options.rate_hz;
  return j;
}

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket socket, Site& site) : stream_(std::move(socket)), site_(site) {}
  void start() { read(); }

 private:
  /// A route's answer: `rest` is the path after the route's own (for a prefix), `query` the
  /// part after '?'.
  using Answer = void (HttpSession::*)(const std::string& rest, const std::string& query);
  struct Route {
    std::string_view path;
    bool prefix;  ///< every path that starts with `path`
    Answer answer;
  };
  static const Route* route(const std::string& path) noexcept;

  void read();
  void handle();
  void reply(http::status status, std::string body, std::string_view type);
  void reply_json(http::status status, const json& j) {
    reply(status, j.dump(), "application/json");
  }
  void not_found(const std::string& message);
  /// The robot a ?robot= or /robot/NAME names: -1 for all, -2 (and a 404 sent) for unknown.
  int robot_of(const std::optional<std::string>& name);

  // The routes.
  void page_socket(const std::string& rest, const std::string& query);
  void page(const std::string& rest, const std::string& query);
  void robot_page(const std::string& rest, const std::string& query);
  void asset_file(const std::string& rest, const std::string& query);
  void scene(const std::string& rest, const std::string& query);
  void state(const std::string& rest, const std::string& query);
  void state_at(int robot, const std::string& t);
  void log(const std::string& rest, const std::string& query);
  void favicon(const std::string& rest, const std::string& query);
  void asset(const std::string& name);

  beast::tcp_stream stream_;
  Site& site_;
  beast::flat_buffer buffer_;
  http::request<http::string_body> req_;
};

const HttpSession::Route* HttpSession::route(const std::string& path) noexcept {
  static constexpr Route kRoutes[] = {
      {"/ws", false, &HttpSession::page_socket},      {"/", false, &HttpSession::page},
      {"/index.html", false, &HttpSession::page},     {"/robot/", true, &HttpSession::robot_page},
      {"/assets/", true, &HttpSession::asset_file},   {"/api/scene", false, &HttpSession::scene},
      {"/api/state", false, &HttpSession::state},     {"/api/log", false, &HttpSession::log},
      {"/favicon.ico", false, &HttpSession::favicon},
  };
  for (const Route& r : kRoutes) {
    if (r.prefix ? path.starts_with(r.path) : path == r.path) return &r;
  }
  return nullptr;
}

void HttpSession::read() {
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

void HttpSession::handle() {
  site_.requests.fetch_add(1, std::memory_order_relaxed);
  const std::string target(req_.target());
  const std::size_t q = target.find('?');
  const std::string path = target.substr(0, q);
  const std::string query = q == std::string::npos ? std::string() : target.substr(q + 1);
  if (req_.method() != http::verb::get && req_.method() != http::verb::head) {
    return reply(http::status::method_not_allowed, "rccx view is read-only: it answers GET only\n",
                 "text/plain");
  }
  const Route* r = route(path);
  if (r == nullptr) return not_found(fmt::format("nothing at {}", path));
  (this->*r->answer)(path.substr(r->prefix ? r->path.size() : path.size()), query);
}

void HttpSession::reply(http::status status, std::string body, std::string_view type) {
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

void HttpSession::not_found(const std::string& message) {
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

int HttpSession::robot_of(const std::optional<std::string>& name) {
  if (!name) return -1;
  const int i = site_.scene.find(*name);
  if (i < 0) {
    not_found(
        fmt::format("no robot \"{}\" here; the robots are: {}", *name, site_.scene.robot_list()));
    return -2;
  }
  return i;
}

void HttpSession::page_socket(const std::string&, const std::string& query) {
  const int robot = robot_of(query_value(query, "robot"));
  if (robot == -2) return;
  if (!websocket::is_upgrade(req_)) {
    return reply(http::status::bad_request, "/ws is a WebSocket\n", "text/plain");
  }
  open_page(stream_.release_socket(), std::move(req_), site_, robot);
}

void HttpSession::page(const std::string&, const std::string&) {
  asset("index.html");
}

void HttpSession::robot_page(const std::string& rest, const std::string&) {
  if (robot_of(rest) == -2) return;
  asset("index.html");
}

void HttpSession::asset_file(const std::string& rest, const std::string&) {
  asset(rest);
}

void HttpSession::scene(const std::string&, const std::string& query) {
  const int robot = robot_of(query_value(query, "robot"));
  if (robot == -2) return;
  reply_json(http::status::ok, scene_json(site_, robot));
}

void HttpSession::state(const std::string&, const std::string& query) {
  const int robot = robot_of(query_value(query, "robot"));
  if (robot == -2) return;
  if (const auto t = query_value(query, "t")) return state_at(robot, *t);
  reply_json(http::status::ok, {{"robots", site_.feed.latest(robot)}});
}

/// ?robot=NAME&t=T: the sample of the history at time T.
void HttpSession::state_at(int robot, const std::string& t) {
  if (robot < 0) {
    return reply_json(http::status::bad_request, {{"error", "?t= needs ?robot=NAME"}});
  }
  double when = 0.0;
  try {
    when = std::stod(t);
  } catch (const std::exception&) {
    return reply_json(http::status::bad_request, {{"error", "?t= is a time in s"}});
  }
  for (const json& f : site_.feed.history(static_cast<std::size_t>(robot))) {
    if (std::abs(f["t"].get<double>() - when) < 1e-7) return reply_json(http::status::ok, f);
  }
  not_found(fmt::format("no sample at t = {} s in the history", when));
}

void HttpSession::log(const std::string&, const std::string&) {
  if (!site_.replay) {
    return not_found("no recorded run here: this view is live (rccx view --log FILE replays)");
  }
  reply(http::status::ok, site_.replay_json.dump(), "application/json");
}

void HttpSession::favicon(const std::string&, const std::string&) {
  reply(http::status::no_content, "", "image/x-icon");
}

void HttpSession::asset(const std::string& name) {
  if (!safe_asset_name(name)) return not_found(fmt::format("no file {}", name));
  if (site_.assets.empty()) {
    return reply(http::status::service_unavailable,
                 "rccx view: the front end was not built (no web/ bundle beside the program). "
                 "Build it: cmake --build BUILD_DIR --target rccx_web (needs node and npm; "
                 "scripts/install-deps), or set RCCX_VIEW_ASSETS to its folder.\n",
                 "text/plain");
  }
  std::string body;
  try {
    body = io::read_file(site_.assets / name);
  } catch (const std::exception&) {
    return not_found(fmt::format("no file {}", name));
  }
  reply(http::status::ok, std::move(body), content_type(name));
}

}  // namespace

void serve_http(tcp::socket socket, Site& site) {
  std::make_shared<HttpSession>(std::move(socket), site)->start();
}

}  // namespace rccx::view::detail
