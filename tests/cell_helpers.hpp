// What the workcell's tests share: positions in the world of cells/cvarl.json for one of its
// robots, a robot's tool point, its failures as text.
#pragma once

#include <algorithm>
#include <memory>
#include <string>

#include "rccx/cell/cell.hpp"
#include "rccx/math/units.hpp"

namespace rccx::cell_test {

inline const char* const kCvarl = RCCX_CVARL_CELL;

/// Tool pointing down (a = -z of the world) at world point p.
inline math::Transform down_at(const math::Vec3& p) {
  return {math::Rot3::rot_x(math::kPi), p};
}

/// The equation T6 TOOL = BASE_INV(robot) WORLD_GOAL for a world pose.
inline rccl::PositionPtr world_position(cell::Cell& c, const std::string& robot,
                                        const std::string& name,
                                        const math::Transform& world_goal) {
  return c.world_goal(robot, name, world_goal);
}

/// A robot's tool point in the world for joints q.
inline math::Vec3 tool_point(cell::Cell& c, const std::string& robot, const kin::JointVector& q) {
  const cell::CellRobot& r = *c.model().find_robot(robot);
  return (r.base * c.robot(robot).kinematics().forward(q) * r.tool.value()).p;
}

/// Where the board is: 50 mm above its top face.
inline const math::Vec3 kAbove{0.0, 0.0, 0.1516};

/// The closest the two first robots' parts have come, m, updated after every tick by the cell's
/// cycle observer (before start()). Shared, so that it outlives the ticks the cell's destructor
/// may still run.
inline std::shared_ptr<double> watch_closest(cell::Cell& c) {
  auto closest = std::make_shared<double>(1e9);
  c.set_cycle_observer([&c, closest](std::uint32_t) {
    *closest = std::min(*closest, c.collision_world().min_distance(0, 1).distance_m);
  });
  return closest;
}

/// Every failure message of a robot, for assertion output.
inline std::string failures_of(rccl::Manipulator& m) {
  std::string s;
  for (const rccl::MotionEvent& e : m.failures()) s += std::string(e.message()) + "; ";
  return s;
}

}  // namespace rccx::cell_test
