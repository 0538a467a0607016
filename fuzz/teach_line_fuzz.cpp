// Teach loop lines (rccx teach, rccl::teach_loop): any bytes as one line give a command or an
// io::ParseError, in the menu and in pendant mode, for every shipped robot; never another
// exception, a crash or a hang.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "rccx/io/parse.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/rccl/teach.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::array<rccx::kin::RobotModel, 4> robots = {
      rccx::kin::builtin_robot("microbo"), rccx::kin::builtin_robot("puma560"),
      rccx::kin::builtin_robot("puma260"), rccx::kin::builtin_robot("stanford")};
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  for (const auto& model : robots) {
    for (const bool pendant : {false, true}) {
      try {
        const rccx::rccl::TeachCommand c = rccx::rccl::parse_teach_command(line, model, pendant);
        if (c.joint >= model.dof()) __builtin_trap();  // a joint the robot lacks
        if (c.kind == rccx::rccl::TeachCommand::Kind::move_joint &&
            !(c.value >= model.joints[c.joint].lower && c.value <= model.joints[c.joint].upper)) {
          __builtin_trap();  // a goal beyond the joint's limits
        }
      } catch (const rccx::io::ParseError&) {
      }
    }
  }
  return 0;
}
