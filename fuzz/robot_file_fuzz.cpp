// Robot files (robots/*.json, --robot-file): any bytes give a model or a RobotFileError,
// never another exception, a crash or a hang.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/robot_model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const rccx::kin::RobotModel model = rccx::kin::parse_robot(text, "fuzz");
    (void)rccx::kin::make_kinematics(model);
  } catch (const rccx::kin::RobotFileError&) {
  }
  return 0;
}
