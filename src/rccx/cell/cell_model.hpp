// The constant description of a workcell: which robots stand where, on which clock, and what
// else is in the world (a table, a circuit board) and which named places users refer to. Read
// once from a cell file under cells/ (or built in code and checked with validate()); data only,
// no sessions and no motion: the multi-robot session (cell.hpp) reads it.
//
//   cell::CellModel model = cell::load_cell_file("cells/cvarl.json");   // throws CellFileError
//   model.find_robot("puma")->base;                  // world <- the PUMA's base, m
//   model.period(0);                                 // robot 0's sample period
//   model.robots[0].base = math::Transform::translation(0.0, 1.2, 0.0);   // moved in code,
//   cell::validate(model);                                                // so checked again
//
// One world frame per cell (m, rad, z up by convention); every robot's base, every object and
// every frame is a transform from the world.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/cell/capsule.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::cell {

/// The sample periods RTC serves (rtc::kMinPeriod / kMaxPeriod, repeated here so that the data
/// layer need not link the real-time one; tests/cell_model_test.cpp checks they agree).
inline constexpr std::chrono::nanoseconds kMinPeriod{250'000};
inline constexpr std::chrono::nanoseconds kMaxPeriod{56'000'000};
inline constexpr std::size_t kMaxRobots = 1024;
inline constexpr std::uint32_t kMaxPeriodMultiple = 1000;
inline constexpr std::size_t kMaxObjects = 4096;
inline constexpr std::size_t kMaxFrames = 4096;
/// Any length in a cell (a position, a size, a radius) beyond this is a typo, m.
inline constexpr double kMaxLength_m = 100.0;
/// A capsule radius or the collision margin beyond this is a typo, m.
inline constexpr double kMaxRadius_m = 1.0;
/// Names of robots, objects and frames: as transform names (letters, digits, _ - .).
inline constexpr std::size_t kMaxName = 32;
inline constexpr std::size_t kMaxText = 4096;  ///< bytes of a title, source or note

/// One robot of the cell.
struct CellRobot {
  std::string name;  ///< its name in the cell ("puma"), unique among the robots
  kin::RobotModel model;
  std::string model_file;  ///< the robot file as the cell names it; empty for a shipped robot
  std::string urdf_file;   ///< the URDF as the cell names it ("urdf"); empty otherwise
  math::Transform base;    ///< world <- robot base frame, m
  std::uint32_t period_multiple = 1;  ///< sampled every k-th tick of the cell's clock
  /// Capsule radius per joint's link, m (dof() values); empty when the model has collision
  /// capsules of its own (a URDF's <collision>) and the cell file gives none.
  std::vector<double> link_radius_m;
  std::optional<math::Transform> tool;  ///< T6 <- tool frame, m; none: the tool is T6
  /// Named capsules beyond the links; without one in T6, a robot with a tool gets a capsule
  /// from T6's origin to the tool's of its last link's radius (cell::Cell).
  std::vector<RobotShape> shapes;
  /// The object the robot stands on (its mounting capsules may rest on it); empty: none.
  std::string mounted_on;
  std::string note;
};

enum class ShapeKind : std::uint8_t { box, cylinder };
std::string_view to_string(ShapeKind kind) noexcept;

/// A solid centred on its object's pose: a box of size_m (x, y, z edges), or a cylinder of
/// radius_m and height_m whose axis is the pose's z.
struct Shape {
  ShapeKind kind = ShapeKind::box;
  math::Vec3 size_m;
  double radius_m = 0.0;
  double height_m = 0.0;
};

/// A thing in the cell that is not a robot: the table, the x-y stage, the circuit board.
struct CellObject {
  std::string name;
  Shape shape;
  math::Transform pose;  ///< world <- the shape's centre frame, m
  bool movable = false;  ///< false: fixed to the world (collision checks may cache it)
  std::string note;
};

/// A named place fixed in the world ("board_home") that programs refer to.
struct CellFrame {
  std::string name;
  math::Transform pose;  ///< world <- frame, m
  std::string note;
};

struct CellModel {
  std::string name;                                 ///< short id ("cvarl")
  std::string title;                                ///< human name
  std::string source;                               ///< where the layout comes from
  std::chrono::nanoseconds base_period{7'000'000};  ///< the cell's clock tick
  std::vector<CellRobot> robots;
  double collision_margin_m = 0.0;  ///< clearance collision checks keep between solids, m
  std::vector<CellObject> objects;
  std::vector<CellFrame> frames;  ///< names unique with the objects' (one namespace)

  /// The sample period of robot i: base_period x its period_multiple.
  [[nodiscard]] std::chrono::nanoseconds period(std::size_t robot) const noexcept {
    return base_period * robots[robot].period_multiple;
  }
  [[nodiscard]] const CellRobot* find_robot(std::string_view robot_name) const noexcept;
  [[nodiscard]] const CellObject* find_object(std::string_view object_name) const noexcept;
  [[nodiscard]] const CellFrame* find_frame(std::string_view frame_name) const noexcept;
};

/// A cell that cannot be used; the message names the file, the robot, object or frame, and the
/// key ("cells/x.json: robot 2 \"microbo\": \"period_multiple\" is 0; 1 to 1000").
class CellFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Checks every rule a cell file's content must meet (docs/CELL.md): names, finite and bounded
/// numbers, proper rotations, unique names, periods, one link radius per joint. Throws
/// CellFileError naming `origin` and the key. parse_cell calls it; a cell built in code
/// should too.
void validate(const CellModel& cell, std::string_view origin = "cell");

/// Parses a cell description (JSON with // comments; cells/README.md). `origin` names the text
/// in messages; `"robot_file"` and `"urdf"` paths are relative to `base_dir` (when base_dir
/// is empty, they are refused: the text has no place on disk).
CellModel parse_cell(std::string_view text, std::string_view origin,
                     const std::filesystem::path& base_dir);
/// Reads and parses a cell file; its robot files are found relative to its directory.
CellModel load_cell_file(const std::filesystem::path& path);

// ---- Geometry for `rccx cell show` (conservative, set-up time) ----

/// A radius around the base origin that the tool point cannot leave, m: each link moves the
/// next frame by at most |a| + |d| (a prismatic joint's |d| at the end of its travel farther
/// from zero), and the tool adds |its offset|.
double reach_m(const kin::RobotModel& model, const std::optional<math::Transform>& tool);
double reach_m(const CellRobot& robot);

/// Where two robots' reach spheres meet.
struct ReachOverlap {
  std::size_t first = 0;          ///< robot index
  std::size_t second = 0;         ///< robot index, > first
  double distance_m = 0.0;        ///< between the base origins (the spheres' centres)
  double depth_m = 0.0;           ///< sum of the reaches - distance; <= 0: they do not meet
  double shared_volume_m3 = 0.0;  ///< sampled estimate of the spheres' common volume
  [[nodiscard]] bool overlaps() const noexcept { return depth_m > 0.0; }
};

/// Every pair of robots, in index order. The shared volume is counted over `samples` points
/// drawn uniformly in the smaller sphere's bounding cube from a fixed seed: the same cell gives
/// the same numbers on every machine.
std::vector<ReachOverlap> reach_overlaps(const CellModel& cell, std::size_t samples = 20000);

/// The sampling estimate alone: spheres of radius r1 and r2 whose centres are distance_m
/// apart.
double shared_volume_m3(double r1_m, double r2_m, double distance_m, std::size_t samples,
                        std::uint64_t seed);

}  // namespace rccx::cell
