// What the view serves, as the server's thread reads it: the scene, the frames the program
// added (Goals), the sample feed, the pages open, the replay, and the counts stats() reports.
// view::Server owns one; the routes and the page sockets read it. Part of view::Server.
//
//   Site site(std::move(scene), options);    // the taps made, nothing running yet
//   session.set_tap(&site.feed.tap(0));
//   serve_http(std::move(socket), site);     // routes.hpp, on the server's thread
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>

#include "rccx/view/goals.hpp"
#include "rccx/view/page_socket.hpp"
#include "rccx/view/run_log.hpp"
#include "rccx/view/sample_feed.hpp"
#include "rccx/view/scene.hpp"
#include "rccx/view/server.hpp"

namespace rccx::view::detail {

struct Site {
  Site(Scene s, ServeOptions o)
      : scene(std::move(s)),
        options(std::move(o)),
        assets(options.assets.empty() ? find_assets() : options.assets),
        goals(std::make_shared<Goals>(scene)),
        feed(scene, options.rate_hz, options.history, goals) {}

  [[nodiscard]] const char* mode() const noexcept { return replay ? "replay" : "live"; }

  const Scene scene;
  const ServeOptions options;
  const std::filesystem::path assets;  ///< the front end; empty: not built
  const std::shared_ptr<Goals> goals;
  SampleFeed feed;
  Pages pages;
  std::optional<RunLog> replay;  ///< server thread only, as replay_json
  nlohmann::json replay_json;    ///< GET /api/log
  std::atomic<std::uint64_t> requests{0};
};

}  // namespace rccx::view::detail
