#include "rccx/cell/load.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "rccx/math/units.hpp"
#include "rccx/rccl/position.hpp"
#include "rccx/rccl/transforms.hpp"

namespace rccx::cell {

CellModel grid_cell(std::size_t count, std::string_view robot, double spacing_m,
                    std::chrono::nanoseconds period, double link_radius_m) {
  CellModel m;
  m.name = "grid";
  m.title = fmt::format("{} x {} on a {:.2f} m grid", count, robot, spacing_m);
  m.source = "rccx::cell::grid_cell (a load for the cycle)";
  m.base_period = period;
  m.collision_margin_m = 0.01;
  const kin::RobotModel model = kin::builtin_robot(robot);
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(count))));
  for (std::size_t i = 0; i < count; ++i) {
    CellRobot r;
    r.name = fmt::format("r{}", i);
    r.model = model;
    r.base = math::Transform::translation(static_cast<double>(i % side) * spacing_m,
                                          static_cast<double>(i / side) * spacing_m, 0.0);
    r.link_radius_m.assign(model.dof(), link_radius_m);
    m.robots.push_back(std::move(r));
  }
  return m;
}

void start_circles(Cell& cell, const math::Vec3& centre_m) {
  using namespace math::literals;
  constexpr double kRadius_m = 0.020;
  constexpr double kTurn_s = 5.0;
  cell.start();
  // Every arm read once before the first move is checked against where it stands: in real
  // time the first samples come a few periods after start, and before them the arm reads zeros.
  for (int k = 0; k < 100; ++k) {
    bool all_read = true;
    for (const std::string& name : cell.robot_names())
      all_read = all_read && cell.session(name).how().sample > 0;
    if (all_read) break;
    cell.wait_for(cell.model().base_period);
  }
  const auto t6 = rccl::t6();
  // The wrist at centre_m (by default 450 mm out and 150 mm below the shoulder, example 05's
  // reach of the PUMA 560), pointing down and out; the circle in the base's x-y plane around it.
  const math::Rot3 pointing = math::Rot3::rot_y(-45_deg) * math::Rot3::rot_x(180_deg);
  const auto grasp = rccl::constant("GRASP", {pointing, {}});
  const auto over =
      rccl::constant("OVER", math::Transform::translation(centre_m.x, centre_m.y, centre_m.z));
  const auto circle = rccl::functional("CIRCLE", [](const rccl::SampleContext& c) {
    const double a = 2.0 * math::kPi * c.t_s / kTurn_s;  // runs in the loop: no allocation
    return math::Transform::translation(kRadius_m * std::cos(a), kRadius_m * std::sin(a), 0.0);
  });
  const auto above = rccl::Position::make("ABOVE", {t6}, {over, grasp});
  const auto round = rccl::Position::make("ROUND", {t6}, {circle, over, grasp});
  for (const std::string& name : cell.robot_names()) {
    rccl::Manipulator& arm = cell.robot(name);
    arm.move(above);  // joint mode
    arm.set_mode(rccl::Mode::cartesian);
    arm.set_velocity(0.1, 1.0);  // m/s, rad/s
    arm.move(round);
  }
}

}  // namespace rccx::cell
