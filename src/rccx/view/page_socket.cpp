#include "rccx/view/page_socket.hpp"

#include <algorithm>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <deque>
#include <memory>
#include <string>

#include "rccx/view/site.hpp"

namespace rccx::view::detail {

namespace websocket = beast::websocket;

class PageSocket : public std::enable_shared_from_this<PageSocket> {
 public:
  PageSocket(tcp::socket socket, Site& site, int robot)
      : ws_(std::move(socket)), site_(site), robot_(robot) {}

  void start(http::request<http::string_body> req) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->site_.pages.add(self.get());
      self->greet();
      self->read();
    });
  }
  /// A message for this page; dropped when it has too many waiting (a slow page).
  void send(const std::shared_ptr<const std::string>& msg, bool droppable = true) {
    if (closed_) return;
    if (droppable && outbox_.size() >= 32) {
      site_.pages.count_dropped();
      return;
    }
    outbox_.push_back(msg);
    if (outbox_.size() == 1) write();
  }
  [[nodiscard]] int robot() const noexcept { return robot_; }

 private:
  void greet() {
    json hello = {{"type", "hello"}, {"mode", site_.mode()}};
    send(std::make_shared<const std::string>(hello.dump()), false);
    json frames = json::array();
    for (std::size_t r = 0; r < site_.feed.robots(); ++r) {
      if (robot_ >= 0 && static_cast<int>(r) != robot_) continue;
      for (const json& f : site_.feed.history(r)) frames.push_back(f);
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
    site_.pages.remove(this);
  }

  websocket::stream<beast::tcp_stream> ws_;
  Site& site_;
  int robot_;
  beast::flat_buffer buffer_;
  std::deque<std::shared_ptr<const std::string>> outbox_;
  bool closed_ = false;
};

void Pages::add(PageSocket* page) {
  pages_.insert(page);
  count_ = pages_.size();
}

void Pages::remove(PageSocket* page) {
  pages_.erase(page);
  count_ = pages_.size();
}

void Pages::broadcast(const std::vector<json>& per_robot) {
  const bool any = std::any_of(per_robot.begin(), per_robot.end(),
                               [](const json& frames) { return !frames.empty(); });
  if (!any || pages_.empty()) return;
  std::shared_ptr<const std::string> all;
  std::vector<std::shared_ptr<const std::string>> one(per_robot.size());
  // Copy: a page that fails to write closes and leaves the set while we go through it.
  const std::vector<PageSocket*> now(pages_.begin(), pages_.end());
  for (PageSocket* page : now) {
    const int r = page->robot();
    std::shared_ptr<const std::string>* msg = r < 0 ? &all : &one[static_cast<std::size_t>(r)];
    if (!*msg) {
      json frames = json::array();
      for (std::size_t i = 0; i < per_robot.size(); ++i) {
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

void open_page(tcp::socket socket, http::request<http::string_body> request, Site& site,
               int robot) {
  std::make_shared<PageSocket>(std::move(socket), site, robot)->start(std::move(request));
}

}  // namespace rccx::view::detail
