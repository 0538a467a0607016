#include "rccx/cell/workcell.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <stdexcept>
#include <utility>

#include "rccx/rccl/position.hpp"

namespace rccx::cell {

const CellRobot& Workcell::model_robot(std::string_view name) const {
  const CellModel& m = model();
  if (const CellRobot* r = m.find_robot(name)) return *r;
  std::vector<std::string> known;
  for (const CellRobot& r : m.robots) known.push_back(r.name);
  throw std::invalid_argument(fmt::format("cell {}: no robot \"{}\"; its robots: {}", m.name, name,
                                          fmt::join(known, ", ")));
}

const math::Transform& Workcell::base(std::string_view robot) const {
  return model_robot(robot).base;
}

math::Transform Workcell::world_to_base(std::string_view robot,
                                        const math::Transform& world_pose) const {
  return model_robot(robot).base.inverse() * world_pose;
}

rccl::TransformPtr Workcell::tool_transform(std::string_view robot) const {
  const CellRobot& r = model_robot(robot);
  return rccl::constant(r.name + "_TOOL", r.tool.value_or(math::Transform::identity()));
}

rccl::TransformPtr Workcell::base_inv_transform(std::string_view robot) const {
  const CellRobot& r = model_robot(robot);
  return rccl::constant(r.name + "_BASE_INV", r.base.inverse());
}

rccl::PositionPtr Workcell::world_goal(std::string_view robot, std::string name,
                                       const std::vector<rccl::TransformPtr>& world) const {
  std::vector<rccl::TransformPtr> rhs{base_inv_transform(robot)};
  rhs.insert(rhs.end(), world.begin(), world.end());
  return rccl::Position::make(std::move(name), {rccl::t6(), tool_transform(robot)}, rhs);
}

rccl::PositionPtr Workcell::world_goal(std::string_view robot, std::string name,
                                       const math::Transform& world_pose) const {
  auto goal = rccl::constant(name, world_pose);
  return world_goal(robot, std::move(name), {std::move(goal)});
}

rccl::TransformPtr Workcell::in_base_of(std::string_view robot,
                                        const rccl::TransformPtr& world_transform) const {
  const CellRobot& r = model_robot(robot);
  const math::Transform base_inverse = r.base.inverse();
  const std::string name = world_transform->name() + "_in_" + r.name;
  switch (world_transform->kind()) {
    case rccl::TransformKind::constant:
      return rccl::constant(name, base_inverse * world_transform->value());
    case rccl::TransformKind::functional:
      return rccl::functional(
          name, [b = base_inverse, t = world_transform](const rccl::SampleContext& ctx) {
            return b * t->value_now(ctx);
          });
    case rccl::TransformKind::hold:
    case rccl::TransformKind::t6:
      break;
  }
  throw std::invalid_argument(fmt::format(
      "in_base_of({}, {}): a {} transform cannot be re-expressed; use a constant or functional one",
      robot, world_transform->name(), rccl::to_string(world_transform->kind())));
}

std::uint64_t Workcell::objects(const std::vector<std::string>& names) const {
  const CellModel& m = model();
  std::uint64_t bits = 0;
  for (const std::string& name : names) {
    std::size_t k = 0;
    while (k < m.objects.size() && m.objects[k].name != name) ++k;
    if (k == m.objects.size()) {
      std::vector<std::string> known;
      for (const CellObject& o : m.objects) known.push_back(o.name);
      throw std::invalid_argument(
          fmt::format("cell {}: no object \"{}\"; its objects: {}", m.name, name,
                      known.empty() ? "none" : fmt::format("{}", fmt::join(known, ", "))));
    }
    if (k >= 64) {
      throw std::invalid_argument(fmt::format(
          "cell {}: object \"{}\" is number {}; a motion may touch only the first 64 objects",
          m.name, name, k + 1));
    }
    bits |= std::uint64_t{1} << k;
  }
  return bits;
}

rccl::StartWhen Workcell::touching(const std::vector<std::string>& names) const {
  rccl::StartWhen w;
  w.touch = objects(names);
  return w;
}

rccl::StartWhen Workcell::after(std::string_view robot, const rccl::Event& e) {
  rccl::StartWhen w;
  w.after.push_back(event(robot, e));
  return w;
}

}  // namespace rccx::cell
