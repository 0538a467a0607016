// The page's WebSocket: one socket a browser page, which gets the live samples of its robot (or
// of every robot) as JSON text messages. On opening, a page gets "hello" (live or replay) and
// the history the sample feed kept; then, each tick, the new frames (Pages::broadcast, one
// message made for all the pages that show the same). What a page says is ignored (the view is
// read-only); a page that does not keep up loses messages (counted), never slows anyone else.
// Server thread only. Part of view::Server.
//
//   // routes: GET /ws?robot=NAME, a WebSocket upgrade
//   open_page(stream.release_socket(), std::move(request), site, robot);  // robot -1: all
//   // the server's tick
//   site.pages.broadcast(site.feed.drain());
#pragma once

// Before Boost.Asio 1.74, whose awaitable.hpp uses std::exchange without including it.
#include <utility>

#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/http.hpp>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <vector>

namespace rccx::view::detail {

// The names the server's files (routes, page_socket) share.
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;
using json = nlohmann::json;

struct Site;
class PageSocket;

/// The pages open now.
class Pages {
 public:
  void add(PageSocket* page);
  void remove(PageSocket* page);
  /// Sends each page this tick's frames (per robot, as SampleFeed::drain gives them) of its
  /// robot, or of every robot.
  void broadcast(const std::vector<nlohmann::json>& per_robot);
  /// A message a slow page did not get.
  void count_dropped() noexcept { dropped_.fetch_add(1, std::memory_order_relaxed); }
  [[nodiscard]] std::size_t count() const noexcept { return count_.load(); }
  [[nodiscard]] std::uint64_t messages_dropped() const noexcept { return dropped_.load(); }

 private:
  std::set<PageSocket*> pages_;  ///< server thread only
  std::atomic<std::size_t> count_{0};
  std::atomic<std::uint64_t> dropped_{0};
};

/// Accepts the WebSocket upgrade `request` on `socket` for the page of `robot` (-1: every
/// robot) and keeps it in site.pages while it is open.
void open_page(boost::asio::ip::tcp::socket socket,
               boost::beast::http::request<boost::beast::http::string_body> request, Site& site,
               int robot);

}  // namespace rccx::view::detail
