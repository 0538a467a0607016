// URDF files (--urdf, kin::load_urdf): any bytes give a model or a RobotFileError, never another
// exception, a crash, a leak or a hang; a model read is one its solvers take (forward at the
// ready pose is finite).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/urdf.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const rccx::kin::RobotModel model = rccx::kin::parse_urdf(text, "fuzz");
    const auto k = rccx::kin::make_kinematics(model);
    for (const double v : k->forward(model.ready()).rows()) {
      if (!std::isfinite(v)) std::abort();  // the reader let a non-finite number through
    }
  } catch (const rccx::kin::RobotFileError&) {
  }
  return 0;
}
