// The robot files of robots/, compiled in by CMake (cmake/embed_robots.cmake) so that the
// library and the rccx command find them wherever they are installed.
#pragma once

#include <span>
#include <string_view>

namespace rccx::kin::detail {

struct EmbeddedRobot {
  std::string_view file_name;  ///< e.g. "puma560.json"
  std::string_view text;
};

std::span<const EmbeddedRobot> embedded_robots() noexcept;

}  // namespace rccx::kin::detail
