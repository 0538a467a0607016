#include "rccx/io/data_files.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <string>
#include <system_error>

#ifndef RCCX_SOURCE_DATA_DIR
#error "the build defines RCCX_SOURCE_DATA_DIR (src/CMakeLists.txt)"
#endif
#ifndef RCCX_CONFIGURED_DATA_DIR
#error "the build defines RCCX_CONFIGURED_DATA_DIR (src/CMakeLists.txt)"
#endif

namespace rccx::io {

namespace {

/// $RCCX_DATA_DIR; empty when unset or set empty (as the other RCCX_ variables).
std::string_view env_data_dir() {
  const char* env = std::getenv("RCCX_DATA_DIR");
  return env != nullptr ? env : "";
}

}  // namespace

std::vector<std::filesystem::path> data_dirs(std::string_view installed_dir) {
  if (!env_data_dir().empty()) return {env_data_dir()};
  std::vector<std::filesystem::path> dirs;
  for (const std::string_view dir : {installed_dir, std::string_view(RCCX_SOURCE_DATA_DIR),
                                     std::string_view(RCCX_CONFIGURED_DATA_DIR)}) {
    if (!dir.empty()) dirs.emplace_back(dir);
  }
  return dirs;
}

std::filesystem::path find_data_file(const std::filesystem::path& relative,
                                     std::string_view installed_dir) {
  const std::vector<std::filesystem::path> dirs = data_dirs(installed_dir);
  std::string looked;
  for (const std::filesystem::path& dir : dirs) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(dir / relative, ec)) return dir / relative;
    looked += fmt::format("{}{}", looked.empty() ? "" : ", ", dir.string());
  }
  throw DataFileError(fmt::format(
      "rccx's data file {} is not in {}: {}", relative.string(), looked,
      !env_data_dir().empty()
          ? "RCCX_DATA_DIR names a directory without it; set it to the share/rccx of an "
            "install or to a source tree, or unset it"
          : "set RCCX_DATA_DIR to the share/rccx of an install or to a source tree"));
}

}  // namespace rccx::io
