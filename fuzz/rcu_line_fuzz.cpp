// rccx rcu lines: any bytes as one line give a command or an io::ParseError; never another
// exception, a crash or a hang.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "console_lines.hpp"
#include "rccx/hw/rcu.hpp"
#include "rccx/io/parse.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  for (const std::size_t dof : {std::size_t{1}, std::size_t{6}}) {
    try {
      const rccx::tools::RcuLine c = rccx::tools::parse_rcu_line(line, dof);
      using Kind = rccx::tools::RcuLine::Kind;
      if ((c.kind == Kind::out || c.kind == Kind::in) &&
          (c.address < rccx::hw::kRcuBase || c.address >= rccx::hw::kRcuBase + 2 * dof)) {
        __builtin_trap();  // a register no joint has
      }
      if (c.joint >= dof || c.step_us < 0) __builtin_trap();
    } catch (const rccx::io::ParseError&) {
    }
  }
  return 0;
}
