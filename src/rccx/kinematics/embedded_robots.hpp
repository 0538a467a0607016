// The robot files of robots/ and the URDFs they may name, compiled in by CMake
// (cmake/embed_robots.cmake) so that the library and the rccx command find them wherever they are
// installed. Programs reach them through builtin_robot() and builtin_robot_names()
// (robot_model.hpp), which do this:
//
//   for (const detail::EmbeddedRobot& r : detail::embedded_robots())   // "puma560.json", ...
//     if (r.file_name == "puma560.json") return parse_robot(r.text, "robots/puma560.json");
#pragma once

#include <span>
#include <string_view>

namespace rccx::kin::detail {

struct EmbeddedRobot {
  std::string_view file_name;  ///< e.g. "puma560.json", or "ur5e.urdf" (named by ur5e.json)
  std::string_view text;
};

std::span<const EmbeddedRobot> embedded_robots() noexcept;

}  // namespace rccx::kin::detail
