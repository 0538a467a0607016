// The view's routes: which URL gives what, GET (and HEAD) only; anything else is a 405, the view
// is read-only. One HTTP connection reads request after request (keep-alive) until it closes or
// becomes a page's WebSocket. Server thread only. Part of view::Server (the URLs: server.hpp).
//
//   /, /index.html, /robot/NAME  the page            /assets/FILE  the bundled front end
//   /api/scene, /api/state, /api/log                  /ws           the page's WebSocket
//
//   acceptor.async_accept([&site](beast::error_code ec, tcp::socket socket) {
//     if (!ec) serve_http(std::move(socket), site);
//   });
#pragma once

// Before Boost.Asio 1.74, whose awaitable.hpp uses std::exchange without including it.
#include <utility>

#include <boost/asio/ip/tcp.hpp>

namespace rccx::view::detail {

struct Site;

/// Answers the requests that arrive on `socket`.
void serve_http(boost::asio::ip::tcp::socket socket, Site& site);

}  // namespace rccx::view::detail
