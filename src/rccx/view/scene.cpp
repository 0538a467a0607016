#include "rccx/view/scene.hpp"

#include <nlohmann/json.hpp>

#include "rccx/cell/cell.hpp"
#include "rccx/cell/robot_capsules.hpp"

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

nlohmann::json vec_json(const math::Vec3& v) {
  return nlohmann::json::array({v.x, v.y, v.z});
}

/// Joint i as the page computes every link frame, one rule for DH and chain models:
/// frame i = frame i-1 * origin * Motion(axis, q) * after. A DH link is origin = I, axis z,
/// after = Rot(z, theta) Trans(0, 0, d) Trans(a, 0, 0) Rot(x, alpha) (the motion about or along
/// z commutes with Rot(z, theta) and Trans(0, 0, d)). `via` is where the drawn link bends, in
/// the frame after the motion: (0, 0, d) for DH (the d part, then the a part), the joint's
/// origin for a chain.
nlohmann::json chain_json(const kin::RobotModel& model, const kin::Joint& j) {
  kin::ChainStep step = j.chain;
  math::Vec3 via;
  if (model.geometry == kin::Geometry::dh) {
    step.origin = math::Transform::identity();
    step.axis = {0, 0, 1};
    step.after = math::Transform{math::Rot3::rot_z(j.dh.theta_rad), {0, 0, j.dh.d_m}} *
                 math::Transform{math::Rot3::rot_x(j.dh.alpha_rad), {j.dh.a_m, 0, 0}};
    via = {0, 0, j.dh.d_m};
  }
  return {{"origin", to_json(step.origin)},
          {"axis", vec_json(step.axis)},
          {"after", to_json(step.after)},
          {"via", vec_json(via)}};
}

/// The collision model as the cell checks it (cell::RobotCapsules: the links of the cell's
/// radii, the model's own capsules, the shapes), each capsule in its frame; empty when the
/// robot has none (a lone DH robot).
nlohmann::json capsules_json(const SceneRobot& r) {
  nlohmann::json out = nlohmann::json::array();
  if (r.link_radius_m.empty() && r.model.collision.capsules.empty()) return out;
  const cell::RobotCapsules capsules(r.model, r.link_radius_m, r.base, r.shapes);
  const auto pieces = capsules.pieces();
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const cell::RobotCapsules::Piece& p = pieces[k];
    const cell::Capsule& c = capsules.capsules()[k];
    using M = cell::RobotCapsules::Motion;
    out.push_back({{"frame", p.frame},
                   {"from", vec_json(p.from_m)},
                   {"to", vec_json(p.to_m)},
                   {"radius", c.radius_m},
                   {"motion", p.motion == M::fixed          ? "fixed"
                              : p.motion == M::dh_prismatic ? "dh_prismatic"
                                                            : "chain_prismatic"},
                   {"joint", p.joint},
                   {"name", std::string(capsules.shape_name(c))}});
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
    const bool dh = r.model.geometry == kin::Geometry::dh;
    for (const kin::Joint& j : r.model.joints) {
      nlohmann::json joint{{"name", j.name},
                           {"prismatic", j.type == kin::JointType::prismatic},
                           {"lower", j.lower},
                           {"upper", j.upper},
                           {"ready", j.ready}};
      if (dh) {  // as the robot file has them (the page draws from chain_json's)
        joint.update({{"a", j.dh.a_m},
                      {"alpha", j.dh.alpha_rad},
                      {"d", j.dh.d_m},
                      {"theta", j.dh.theta_rad}});
      }
      if (j.continuous) joint.update({{"lower", nullptr}, {"upper", nullptr}});  // JSON has no inf
      joint.update(chain_json(r.model, j));
      joints.push_back(joint);
    }
    robots.push_back({{"index", i},
                      {"name", r.name},
                      {"model", r.model.name},
                      {"title", r.model.title},
                      {"base", to_json(r.base)},
                      {"tool", r.tool ? to_json(*r.tool) : nlohmann::json(nullptr)},
                      {"geometry", kin::to_string(r.model.geometry)},
                      {"radii", r.link_radius_m},
                      {"shapes", shapes_json(r.shapes)},
                      {"capsules", capsules_json(r)},
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
