// rccx jointtest lines: any bytes as one line give a command or an io::ParseError for every
// shipped robot and selected joint; never another exception, a crash or a hang.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "console_lines.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/kinematics/robot_model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::array<rccx::kin::RobotModel, 4> robots = {
      rccx::kin::builtin_robot("microbo"), rccx::kin::builtin_robot("puma560"),
      rccx::kin::builtin_robot("puma260"), rccx::kin::builtin_robot("stanford")};
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  for (const auto& model : robots) {
    for (std::size_t joint = 0; joint < model.dof(); ++joint) {
      try {
        const rccx::tools::JointtestLine c = rccx::tools::parse_jointtest_line(line, model, joint);
        if (c.joint >= model.dof() || !std::isfinite(c.value) || c.duration.count() < 0) {
          __builtin_trap();
        }
      } catch (const rccx::io::ParseError&) {
      }
    }
  }
  return 0;
}
