// Cell files (cells/*.json, `rccx cell show`): any bytes give a cell or a CellFileError, never
// another exception, a crash or a hang. No base directory: "robot_file" is refused, so the
// fuzzer reads no files.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "rccx/cell/cell_model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const rccx::cell::CellModel cell = rccx::cell::parse_cell(text, "fuzz", {});
    // The geometry of `rccx cell show`, with few samples: what a good file leads to.
    (void)rccx::cell::reach_overlaps(cell, 64);
  } catch (const rccx::cell::CellFileError&) {
  }
  return 0;
}
