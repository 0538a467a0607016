// Position exports (rccx db import): any bytes give transforms or a PositionExportError, never
// another exception, a crash or a hang. What is accepted is written out and read back the same.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "rccx/rccl/position_export.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto all = rccx::rccl::parse_position_export(text, "fuzz");
    const auto again =
        rccx::rccl::parse_position_export(rccx::rccl::position_export_json(all), "fuzz round trip");
    if (again.size() != all.size()) std::abort();
  } catch (const rccx::rccl::PositionExportError&) {
  }
  return 0;
}
