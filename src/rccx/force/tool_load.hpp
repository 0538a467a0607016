// (placeholder until the force layer lands: the same API)
#pragma once

#include "rccx/math/wrench.hpp"

namespace rccx::force {

struct ToolLoad {
  math::Wrench bias;
  double mass_kg = 0.0;
  math::Vec3 com_m;
};

[[nodiscard]] inline math::Wrench external_wrench(const ToolLoad& load,
                                                  const math::Rot3& world_from_sensor,
                                                  const math::Wrench& reading) noexcept {
  return reading - load.bias - math::weight_wrench(world_from_sensor, load.mass_kg, load.com_m);
}

[[nodiscard]] inline math::Wrench at_tool(const math::Transform& t6_from_tool,
                                          const math::Wrench& at_t6) noexcept {
  return math::transform_wrench(t6_from_tool.inverse(), at_t6);
}

}  // namespace rccx::force
