// What the view draws, as data: robots (each its chain, DH or URDF, every joint as an origin, an
// axis and an `after` transform, its base transform, tool and collision capsules), the cell's
// objects and named frames. The page receives it as JSON (GET /api/scene) and draws every link
// from it; the joint values arrive apart.
//
//   const view::Scene scene = view::Scene::of_cell(cell::load_cell_file("cells/cvarl.json"));
//   const nlohmann::json page = view::to_json(scene);   // what GET /api/scene returns
//   view::Server server(scene, 8080);                   // serves it (server.hpp)
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "rccx/cell/cell_model.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::view {

struct SceneRobot {
  std::string name;
  kin::RobotModel model;
  math::Transform base;                 ///< world <- base, m
  std::optional<math::Transform> tool;  ///< T6 <- tool
  std::vector<double> link_radius_m;    ///< the cell's capsules; empty: none
  /// The collision model's named capsules beyond the links (cell::Cell::shapes_of): a
  /// pedestal, a flange, a hand, the tool.
  std::vector<cell::RobotShape> shapes;
};

/// A named frame to draw (a cell frame, the goal of a position equation).
struct SceneFrame {
  std::string name;
  math::Transform pose;  ///< world <- frame
  std::string note;
  int robot = -1;  ///< the scene robot whose equation's goal this is; -1: the cell's, or none
};

struct Scene {
  std::string title;
  std::vector<SceneRobot> robots;
  std::vector<cell::CellObject> objects;
  std::vector<SceneFrame> frames;

  static Scene of_robot(const kin::RobotModel& model);
  static Scene of_cell(const cell::CellModel& model);
  /// The index of a robot, or -1.
  [[nodiscard]] int find(std::string_view robot) const noexcept;
  [[nodiscard]] std::string robot_list() const;
};

/// A transform as the page takes it: 16 numbers, column-major (three.js Matrix4.fromArray).
nlohmann::json to_json(const math::Transform& t);
/// The scene as the page reads it; `only` >= 0: that robot alone (and no other robot's goals).
nlohmann::json to_json(const Scene& scene, int only = -1);

}  // namespace rccx::view
