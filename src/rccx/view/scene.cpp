#include "rccx/view/scene.hpp"

#include <nlohmann/json.hpp>

#include "rccx/cell/cell.hpp"

namespace rccx::view {

Scene Scene::of_robot(const kin::RobotModel& model) {
  Scene s;
  s.title = model.title.empty() ? model.name : model.title;
  s.robots.push_back({model.name, model, math::Transform::identity(), std::nullopt, {}, {}});
  return s;
}

Scene Scene::of_cell(const cell::CellModel& model) {
  Scene s;
  s.title = model.title.empty() ? model.name : model.title;
  for (const cell::CellRobot& r : model.robots) {
    s.robots.push_back(
        {r.name, r.model, r.base, r.tool, r.link_radius_m, cell::Cell::shapes_of(r)});
  }
  s.objects = model.objects;
  for (const cell::CellFrame& f : model.frames) s.frames.push_back({f.name, f.pose, f.note});
  return s;
}

int Scene::find(std::string_view robot) const noexcept {
  for (std::size_t i = 0; i < robots.size(); ++i) {
    if (robots[i].name == robot) return static_cast<int>(i);
  }
  return -1;
}

std::string Scene::robot_list() const {
  std::string out;
  for (const SceneRobot& r : robots) out += (out.empty() ? "" : ", ") + r.name;
  return out;
}

namespace {

nlohmann::json shapes_json(const std::vector<cell::RobotShape>& shapes) {
  nlohmann::json out = nlohmann::json::array();
  for (const cell::RobotShape& k : shapes) {
    out.push_back({{"name", k.name},
                   {"frame", k.frame},
                   {"from", {k.from_m.x, k.from_m.y, k.from_m.z}},
                   {"to", {k.to_m.x, k.to_m.y, k.to_m.z}},
                   {"radius", k.radius_m}});
  }
  return out;
}

}  // namespace

nlohmann::json to_json(const math::Transform& t) {
  return nlohmann::json::array({t.R.n.x, t.R.n.y, t.R.n.z, 0.0, t.R.o.x, t.R.o.y, t.R.o.z, 0.0,
                                t.R.a.x, t.R.a.y, t.R.a.z, 0.0, t.p.x, t.p.y, t.p.z, 1.0});
}

nlohmann::json to_json(const Scene& scene, int only) {
  nlohmann::json robots = nlohmann::json::array();
  for (std::size_t i = 0; i < scene.robots.size(); ++i) {
    if (only >= 0 && static_cast<int>(i) != only) continue;
    const SceneRobot& r = scene.robots[i];
    nlohmann::json joints = nlohmann::json::array();
    for (const kin::Joint& j : r.model.joints) {
      joints.push_back({{"name", j.name},
                        {"prismatic", j.type == kin::JointType::prismatic},
                        {"a", j.dh.a_m},
                        {"alpha", j.dh.alpha_rad},
                        {"d", j.dh.d_m},
                        {"theta", j.dh.theta_rad},
                        {"lower", j.lower},
                        {"upper", j.upper},
                        {"ready", j.ready}});
    }
    robots.push_back({{"index", i},
                      {"name", r.name},
                      {"model", r.model.name},
                      {"title", r.model.title},
                      {"base", to_json(r.base)},
                      {"tool", r.tool ? to_json(*r.tool) : nlohmann::json(nullptr)},
                      {"radii", r.link_radius_m},
                      {"shapes", shapes_json(r.shapes)},
                      {"joints", joints}});
  }
  nlohmann::json objects = nlohmann::json::array();
  for (const cell::CellObject& o : scene.objects) {
    objects.push_back({{"name", o.name},
                       {"kind", o.shape.kind == cell::ShapeKind::box ? "box" : "cylinder"},
                       {"size", {o.shape.size_m.x, o.shape.size_m.y, o.shape.size_m.z}},
                       {"radius", o.shape.radius_m},
                       {"height", o.shape.height_m},
                       {"pose", to_json(o.pose)}});
  }
  nlohmann::json frames = nlohmann::json::array();
  for (const SceneFrame& f : scene.frames) {
    if (only >= 0 && f.robot >= 0 && f.robot != only) continue;
    frames.push_back(
        {{"name", f.name}, {"pose", to_json(f.pose)}, {"note", f.note}, {"robot", f.robot}});
  }
  return {{"title", scene.title}, {"robots", robots}, {"objects", objects}, {"frames", frames}};
}

}  // namespace rccx::view
