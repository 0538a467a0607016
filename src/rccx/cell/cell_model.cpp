#include "rccx/cell/cell_model.hpp"

#include <fmt/format.h>

#include <fmt/ranges.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>

#include "rccx/io/file.hpp"
#include "rccx/io/json_reader.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/urdf.hpp"
#include "rccx/math/units.hpp"

namespace rccx::cell {

using nlohmann::json;

std::string_view to_string(ShapeKind kind) noexcept {
  return kind == ShapeKind::box ? "box" : "cylinder";
}

const CellRobot* CellModel::find_robot(std::string_view robot_name) const noexcept {
  for (const CellRobot& r : robots) {
    if (r.name == robot_name) return &r;
  }
  return nullptr;
}

const CellObject* CellModel::find_object(std::string_view object_name) const noexcept {
  for (const CellObject& o : objects) {
    if (o.name == object_name) return &o;
  }
  return nullptr;
}

const CellFrame* CellModel::find_frame(std::string_view frame_name) const noexcept {
  for (const CellFrame& f : frames) {
    if (f.name == frame_name) return &f;
  }
  return nullptr;
}

namespace {

double ms_of(std::chrono::nanoseconds t) {
  return static_cast<double>(t.count()) * 1e-6;
}

// ---- Rules on the data, whether it came from a file or from code ----

class Checker {
 public:
  explicit Checker(std::string where) : where_(std::move(where)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw CellFileError(fmt::format("{}: {}", where_, what));
  }

  void name(const std::string& n, const char* key = "name") const {
    try {
      io::check_name(n, fmt::format("\"{}\"", key), kMaxName);
    } catch (const io::ParseError& e) {
      fail(e.what());
    }
  }

  void text(const std::string& t, const char* key) const {
    try {
      io::check_text(t, fmt::format("\"{}\"", key), kMaxText);
    } catch (const io::ParseError& e) {
      fail(e.what());
    }
  }

  /// A pose: finite, within kMaxLength_m on each axis, and a proper rotation (orthonormal,
  /// right-handed), which every product of poses downstream takes for granted.
  void pose(const math::Transform& T, const char* key) const {
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite(T.p[i]) || std::abs(T.p[i]) > kMaxLength_m) {
        fail(fmt::format("\"{}\": the position must be finite and within {:g} m of the origin", key,
                         kMaxLength_m));
      }
    }
    const math::Rot3 RtR = T.R.transposed() * T.R;
    double error = 0.0;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        const double e = std::abs(RtR(r, c) - (r == c ? 1.0 : 0.0));
        error = std::isfinite(e) ? std::max(error, e) : INFINITY;
      }
    }
    const double det = math::dot(math::cross(T.R.n, T.R.o), T.R.a);
    if (!(error <= 1e-6) || !(det > 0)) {
      fail(fmt::format("\"{}\": the rotation is not orthonormal and right-handed", key));
    }
  }

  /// A length in (0, limit] m.
  void positive_length(double v, const char* key, double limit = kMaxLength_m) const {
    if (!std::isfinite(v) || v <= 0.0 || v > limit) {
      fail(fmt::format("\"{}\" is {:g}; more than 0 and at most {:g} m", key, v, limit));
    }
  }

  const std::string& where() const { return where_; }

 private:
  std::string where_;
};

std::string robot_where(std::string_view origin, std::size_t i, const std::string& name) {
  return fmt::format("{}: robot {} \"{}\"", origin, i + 1, name);  // a checked name
}

}  // namespace

void validate(const CellModel& cell, std::string_view origin) {
  const Checker top{std::string(origin)};
  top.name(cell.name);
  top.text(cell.title, "title");
  top.text(cell.source, "source");
  if (cell.base_period < kMinPeriod || cell.base_period > kMaxPeriod) {
    top.fail(fmt::format("\"base_period_ms\" is {:g}; {:g} to {:g} ms", ms_of(cell.base_period),
                         ms_of(kMinPeriod), ms_of(kMaxPeriod)));
  }
  if (cell.robots.empty() || cell.robots.size() > kMaxRobots) {
    top.fail(fmt::format("\"robots\" has {}; a cell has 1 to {} robots", cell.robots.size(),
                         kMaxRobots));
  }
  if (!std::isfinite(cell.collision_margin_m) || cell.collision_margin_m < 0.0 ||
      cell.collision_margin_m > kMaxRadius_m) {
    top.fail(fmt::format("\"collision_margin_m\" is {:g}; 0 to {:g} m", cell.collision_margin_m,
                         kMaxRadius_m));
  }

  std::map<std::string, std::size_t, std::less<>> robot_names;
  for (std::size_t i = 0; i < cell.robots.size(); ++i) {
    const CellRobot& r = cell.robots[i];
    const Checker at{fmt::format("{}: robot {}", origin, i + 1)};
    at.name(r.name);
    const Checker c{robot_where(origin, i, r.name)};
    if (const auto [it, fresh] = robot_names.emplace(r.name, i); !fresh) {
      c.fail(fmt::format("\"name\" \"{}\" is robot {}'s already; robot names must be unique",
                         r.name, it->second + 1));
    }
    if (r.model.dof() == 0 || r.model.dof() > kin::kMaxJoints) {
      c.fail(fmt::format("its robot model has {} joints; 1 to {}", r.model.dof(), kin::kMaxJoints));
    }
    c.pose(r.base, "base");
    if (r.tool) c.pose(*r.tool, "tool");
    if (r.period_multiple < 1 || r.period_multiple > kMaxPeriodMultiple) {
      c.fail(
          fmt::format("\"period_multiple\" is {}; 1 to {}", r.period_multiple, kMaxPeriodMultiple));
    }
    const std::chrono::nanoseconds period = cell.period(i);
    if (period < kMinPeriod || period > kMaxPeriod) {
      c.fail(fmt::format(
          "\"period_multiple\" {} makes its period {:g} ms ({:g} ms x {}); RTC serves {:g} to "
          "{:g} ms",
          r.period_multiple, ms_of(period), ms_of(cell.base_period), r.period_multiple,
          ms_of(kMinPeriod), ms_of(kMaxPeriod)));
    }
    if (r.model.collision.capsules.size() > kin::kMaxCollisionCapsules) {
      c.fail(fmt::format(
          "its robot model has {} collision capsules (its URDF's <collision> elements, those "
          "inside others dropped); at most {}: merge some",
          r.model.collision.capsules.size(), kin::kMaxCollisionCapsules));
    }
    const bool own_capsules = !r.model.collision.capsules.empty();
    if (r.link_radius_m.empty() && !own_capsules) {
      c.fail(fmt::format(
          "\"link_radius_m\" is missing; robot {} has no collision capsules of its own (give "
          "one number for all its links, or one per joint)",
          r.model.name));
    }
    if (!r.link_radius_m.empty() && r.link_radius_m.size() != r.model.dof()) {
      c.fail(fmt::format(
          "\"link_radius_m\" has {} values; robot {} has {} joints (give one number for all, "
          "or one per joint)",
          r.link_radius_m.size(), r.model.name, r.model.dof()));
    }
    for (const double radius : r.link_radius_m)
      c.positive_length(radius, "link_radius_m", kMaxRadius_m);
    if (r.shapes.size() > kMaxRobotShapes) {
      c.fail(fmt::format("\"shapes\" has {}; at most {}", r.shapes.size(), kMaxRobotShapes));
    }
    std::set<std::string, std::less<>> shape_names;
    for (std::size_t k = 0; k < r.shapes.size(); ++k) {
      const RobotShape& s = r.shapes[k];
      const Checker unnamed{fmt::format("{}: shape {}", c.where(), k + 1)};
      unnamed.name(s.name);
      const Checker sc{fmt::format("{}: shape {} \"{}\"", c.where(), k + 1, s.name)};
      if (!shape_names.insert(s.name).second) {
        sc.fail("\"name\" is another shape's already; shape names must be unique");
      }
      if (s.frame > r.model.dof()) {
        sc.fail(
            fmt::format("\"frame\" is {}; \"base\", 1 to {} or \"t6\"", s.frame, r.model.dof()));
      }
      for (const math::Vec3* v : {&s.from_m, &s.to_m}) {
        for (int axis = 0; axis < 3; ++axis) {
          if (!std::isfinite((*v)[axis]) || std::abs((*v)[axis]) > kMaxLength_m) {
            sc.fail(fmt::format("\"from_m\" and \"to_m\" must be finite and within {:g} m",
                                kMaxLength_m));
          }
        }
      }
      sc.positive_length(s.radius_m, "radius_m", kMaxRadius_m);
      sc.text(s.note, "note");
    }
    c.text(r.note, "note");
  }

  if (cell.objects.size() > kMaxObjects) {
    top.fail(fmt::format("\"objects\" has {}; at most {}", cell.objects.size(), kMaxObjects));
  }
  if (cell.frames.size() > kMaxFrames) {
    top.fail(fmt::format("\"frames\" has {}; at most {}", cell.frames.size(), kMaxFrames));
  }
  // Objects and frames share one namespace: a program names a place without saying which.
  std::map<std::string, std::string, std::less<>> place_names;
  for (std::size_t i = 0; i < cell.objects.size(); ++i) {
    const CellObject& o = cell.objects[i];
    const Checker at{fmt::format("{}: object {}", origin, i + 1)};
    at.name(o.name);
    const Checker c{fmt::format("{}: object {} \"{}\"", origin, i + 1, o.name)};
    const std::string self = fmt::format("object {}", i + 1);
    if (const auto [it, fresh] = place_names.emplace(o.name, self); !fresh) {
      c.fail(fmt::format("\"name\" \"{}\" is {}'s already; object and frame names must be unique",
                         o.name, it->second));
    }
    if (o.shape.kind == ShapeKind::box) {
      for (int k = 0; k < 3; ++k) c.positive_length(o.shape.size_m[k], "size_m");
    } else {
      c.positive_length(o.shape.radius_m, "radius_m");
      c.positive_length(o.shape.height_m, "height_m");
    }
    c.pose(o.pose, "pose");
    c.text(o.note, "note");
  }
  for (std::size_t i = 0; i < cell.robots.size(); ++i) {
    const CellRobot& r = cell.robots[i];
    if (!r.mounted_on.empty() && cell.find_object(r.mounted_on) == nullptr) {
      std::string names;
      for (const CellObject& o : cell.objects) names += (names.empty() ? "" : ", ") + o.name;
      Checker{robot_where(origin, i, r.name)}.fail(
          fmt::format("\"mounted_on\" names no object of the cell: \"{}\"; its objects: {}",
                      r.mounted_on, names.empty() ? "none" : names));
    }
  }
  for (std::size_t i = 0; i < cell.frames.size(); ++i) {
    const CellFrame& f = cell.frames[i];
    const Checker at{fmt::format("{}: frame {}", origin, i + 1)};
    at.name(f.name);
    const Checker c{fmt::format("{}: frame {} \"{}\"", origin, i + 1, f.name)};
    const std::string self = fmt::format("frame {}", i + 1);
    if (const auto [it, fresh] = place_names.emplace(f.name, self); !fresh) {
      c.fail(fmt::format("\"name\" \"{}\" is {}'s already; object and frame names must be unique",
                         f.name, it->second));
    }
    c.pose(f.pose, "pose");
    c.text(f.note, "note");
  }
}

namespace {

// ---- The file ----

using Reader = io::JsonObjectReader<CellFileError>;

/// {"xyz_m": [x, y, z], "rpy_deg": [roll, pitch, yaw]} (Paul's RPY: Rot(z, roll) Rot(y, pitch)
/// Rot(x, yaw); rpy_deg may be left out) or {"rows_m": [12 numbers, row by row]}.
math::Transform parse_pose(const json& j, const std::string& where) {
  Reader r(j, where);
  const bool rows = j.is_object() && j.contains("rows_m");
  if (rows && (j.contains("xyz_m") || j.contains("rpy_deg"))) {
    r.fail("give \"xyz_m\" and \"rpy_deg\", or \"rows_m\", not both");
  }
  math::Transform T;
  if (rows) {
    const auto m = r.numbers<12>("rows_m", kMaxLength_m);
    T = math::Transform::from_rows(m);
    // The rotation is checked by validate(); round-off in a typed matrix is not an error, so it
    // is made exactly orthonormal once it has passed.
    const Checker c{where};
    c.pose(T, "rows_m");
    T.R = T.R.orthonormalized();
  } else {
    const auto p = r.numbers<3>("xyz_m", kMaxLength_m);
    T.p = {p[0], p[1], p[2]};
    if (r.has("rpy_deg")) {
      const auto rpy = r.numbers<3>("rpy_deg", 360.0);
      T.R = math::Rot3::from_rpy(math::deg_to_rad(rpy[0]), math::deg_to_rad(rpy[1]),
                                 math::deg_to_rad(rpy[2]));
    }
  }
  r.no_unknown_keys();
  return T;
}

/// {"name": "probe", "frame": "t6", "from_m": [0, 0, 0.06], "to_m": [0, 0, 0.16],
/// "radius_m": 0.005}; "frame" is "base", "t6" or a link number 1 .. dof.
RobotShape parse_shape(const json& j, const std::string& where, std::size_t dof) {
  Reader r(j, where);
  RobotShape s;
  s.name = r.string("name");
  const json& frame = r.get("frame");
  if (frame.is_string() && frame.get<std::string>() == "base") {
    s.frame = 0;
  } else if (frame.is_string() && frame.get<std::string>() == "t6") {
    s.frame = dof;
  } else if (frame.is_number_integer()) {
    s.frame = static_cast<std::size_t>(r.integer("frame", 1, static_cast<std::int64_t>(dof)));
  } else {
    r.fail(fmt::format("\"frame\" must be \"base\", \"t6\" or a link number 1 to {}", dof));
  }
  const auto from = r.numbers<3>("from_m", kMaxLength_m);
  const auto to = r.numbers<3>("to_m", kMaxLength_m);
  s.from_m = {from[0], from[1], from[2]};
  s.to_m = {to[0], to[1], to[2]};
  s.radius_m = r.number("radius_m", kMaxRadius_m);
  s.note = r.string_or("note");
  r.no_unknown_keys();
  return s;
}

CellRobot parse_robot(const json& j, const std::string& where,
                      const std::filesystem::path& base_dir) {
  Reader r(j, where);
  CellRobot robot;
  robot.name = r.string("name");
  const bool shipped = r.has("robot");
  const bool file = r.has("robot_file");
  const bool urdf = r.has("urdf");
  if (int{shipped} + int{file} + int{urdf} != 1) {
    r.fail(
        "give one of \"robot\" (a shipped robot), \"robot_file\" (a robot file's path) or "
        "\"urdf\" (a URDF's path)");
  }
  if (!urdf && (r.has("base_link") || r.has("tip_link"))) {
    r.fail("\"base_link\" and \"tip_link\" choose a URDF's chain: give them with \"urdf\"");
  }
  const char* key = shipped ? "robot" : file ? "robot_file" : "urdf";
  try {
    if (shipped) {
      robot.model = kin::builtin_robot(r.string("robot"));
    } else {
      const std::string path = r.string(key);
      if (path.empty()) r.fail(fmt::format("\"{}\" is empty; name a file", key));
      if (base_dir.empty()) {
        r.fail(fmt::format("\"{}\" needs the cell to be read from a file; use \"robot\"", key));
      }
      if (file) {
        robot.model_file = path;
        robot.model = kin::load_robot_file(base_dir / path);
      } else {
        robot.urdf_file = path;
        kin::UrdfOptions links;
        if (r.has("base_link")) links.base_link = r.string("base_link");
        if (r.has("tip_link")) links.tip_link = r.string("tip_link");
        robot.model = kin::load_urdf(base_dir / path, links);
      }
    }
    // The solver the model asks for must accept its chain (a closed form checks at build).
    (void)kin::make_kinematics(robot.model);
  } catch (const kin::RobotFileError& e) {
    r.fail(fmt::format("\"{}\": {}", key, e.what()));
  }
  robot.base = parse_pose(r.get("base"), where + ": \"base\"");
  robot.period_multiple =
      static_cast<std::uint32_t>(r.integer("period_multiple", 1, kMaxPeriodMultiple));
  // A model with collision capsules of its own (a URDF's <collision>) needs no link radii;
  // one whose URDF gives meshes for some links does: rccx encloses no mesh.
  const kin::CollisionModel& own = robot.model.collision;
  if (!r.has("link_radius_m") && !own.capsules.empty() && own.mesh_links.empty()) {
    // its own capsules stand for its links
  } else if (!r.has("link_radius_m") && !own.mesh_links.empty()) {
    r.fail(fmt::format(
        "its URDF's <collision> of link{} {} {} a mesh, which rccx does not read: give "
        "\"link_radius_m\" (capsules along the chain, of radii that enclose the arm), or give "
        "those links <collision> spheres, cylinders or boxes enclosing the mesh",
        own.mesh_links.size() == 1 ? "" : "s", fmt::join(own.mesh_links, ", "),
        own.mesh_links.size() == 1 ? "is" : "are"));
  } else if (const json& radius = r.get("link_radius_m"); radius.is_number()) {
    robot.link_radius_m.assign(robot.model.dof(), r.number("link_radius_m", kMaxRadius_m));
  } else if (radius.is_array() && radius.size() <= kin::kMaxJoints) {
    for (std::size_t i = 0; i < radius.size(); ++i) {
      robot.link_radius_m.push_back(
          r.number(radius[i], fmt::format("\"link_radius_m\" [{}]", i + 1), kMaxRadius_m));
    }
  } else {
    r.fail("\"link_radius_m\" must be a number, or one number per joint");
  }
  if (r.has("tool")) robot.tool = parse_pose(r.get("tool"), where + ": \"tool\"");
  if (r.has("shapes")) {
    const json& shapes = r.get("shapes");
    if (!shapes.is_array() || shapes.size() > kMaxRobotShapes) {
      r.fail(fmt::format("\"shapes\" must be a list of at most {} shapes", kMaxRobotShapes));
    }
    for (std::size_t k = 0; k < shapes.size(); ++k) {
      robot.shapes.push_back(
          parse_shape(shapes[k], fmt::format("{}: shape {}", where, k + 1), robot.model.dof()));
    }
  }
  if (r.has("mounted_on")) robot.mounted_on = r.string("mounted_on");
  robot.note = r.string_or("note");
  r.no_unknown_keys();
  return robot;
}

CellObject parse_object(const json& j, const std::string& where) {
  Reader r(j, where);
  CellObject o;
  o.name = r.string("name");
  const std::string shape = r.string("shape");
  if (shape == "box") {
    o.shape.kind = ShapeKind::box;
    const auto s = r.numbers<3>("size_m", kMaxLength_m);
    o.shape.size_m = {s[0], s[1], s[2]};
  } else if (shape == "cylinder") {
    o.shape.kind = ShapeKind::cylinder;
    o.shape.radius_m = r.number("radius_m", kMaxLength_m);
    o.shape.height_m = r.number("height_m", kMaxLength_m);
  } else {
    r.fail(
        fmt::format("\"shape\" is {}; use \"box\" (with \"size_m\") or \"cylinder\" (with "
                    "\"radius_m\" and \"height_m\")",
                    io::quoted(shape)));
  }
  o.pose = parse_pose(r.get("pose"), where + ": \"pose\"");
  if (r.has("movable")) {
    const json& m = r.get("movable");
    if (!m.is_boolean()) r.fail("\"movable\" must be true or false");
    o.movable = m.get<bool>();
  }
  o.note = r.string_or("note");
  r.no_unknown_keys();
  return o;
}

CellFrame parse_frame(const json& j, const std::string& where) {
  Reader r(j, where);
  CellFrame f;
  f.name = r.string("name");
  f.pose = parse_pose(r.get("pose"), where + ": \"pose\"");
  f.note = r.string_or("note");
  r.no_unknown_keys();
  return f;
}

/// An array member of the top object, at most `max` long (checked before anything is built
/// from it, so that a huge list costs nothing).
const json& list(Reader& r, const char* key, std::size_t max, bool required) {
  static const json kEmpty = json::array();
  if (!required && !r.has(key)) return kEmpty;
  const json& v = r.get(key);
  if (!v.is_array()) r.fail(fmt::format("\"{}\" must be a list", key));
  if (v.size() > max) r.fail(fmt::format("\"{}\" has {}; at most {}", key, v.size(), max));
  return v;
}

CellModel parse_cell_json(std::string_view text, std::string_view origin,
                          const std::filesystem::path& base_dir) {
  json doc;
  try {
    doc = json::parse(text, nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const json::exception& e) {  // syntax, or a number that overflows a double
    throw CellFileError(fmt::format("{}: not valid JSON: {}", origin, e.what()));
  }
  Reader r(doc, std::string(origin));
  CellModel cell;
  cell.name = r.string("name");
  cell.title = r.string("title");
  cell.source = r.string("source");
  if (r.has("notes")) {
    const json& notes = r.get("notes");
    if (!notes.is_string() && !notes.is_array()) r.fail("\"notes\" must be text or a list of it");
    const Checker c{r.where()};
    for (const json& note : notes.is_array() ? notes : json::array({notes})) {
      if (!note.is_string()) r.fail("\"notes\" must be text or a list of it");
      c.text(note.get<std::string>(), "notes");
    }
  }
  // Milliseconds as people think of sample periods; kept whole in ns from here on.
  const double period_ms = r.number("base_period_ms", 1e6);
  cell.base_period = std::chrono::nanoseconds{std::llround(period_ms * 1e6)};
  cell.collision_margin_m = r.number("collision_margin_m", kMaxLength_m);
  const json& robots = list(r, "robots", kMaxRobots, true);
  for (std::size_t i = 0; i < robots.size(); ++i) {
    cell.robots.push_back(
        parse_robot(robots[i], fmt::format("{}: robot {}", origin, i + 1), base_dir));
  }
  const json& objects = list(r, "objects", kMaxObjects, false);
  for (std::size_t i = 0; i < objects.size(); ++i) {
    cell.objects.push_back(parse_object(objects[i], fmt::format("{}: object {}", origin, i + 1)));
  }
  const json& frames = list(r, "frames", kMaxFrames, false);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    cell.frames.push_back(parse_frame(frames[i], fmt::format("{}: frame {}", origin, i + 1)));
  }
  r.no_unknown_keys();
  validate(cell, origin);
  return cell;
}

/// "line:column" (1-based) of the key `"key":` in the file's text when it appears there once
/// (the parsed document keeps no positions); empty otherwise.
std::string key_position(std::string_view text, std::string_view key) {
  const std::string quoted = fmt::format("\"{}\"", key);
  std::size_t found = std::string_view::npos;
  for (std::size_t at = text.find(quoted); at != std::string_view::npos;
       at = text.find(quoted, at + 1)) {
    const std::size_t after = text.find_first_not_of(" \t\r\n", at + quoted.size());
    if (after == std::string_view::npos || text[after] != ':') continue;
    if (found != std::string_view::npos) return {};  // twice: which one is meant is unknown
    found = at;
  }
  if (found == std::string_view::npos) return {};
  const std::size_t line_start = text.rfind('\n', found);
  const std::size_t column = line_start == std::string_view::npos ? found + 1 : found - line_start;
  const auto line =
      1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(found), '\n');
  return fmt::format("{}:{}", line, column);
}

/// An unknown key's message with the key's line and column after the file's name, as compilers
/// write it: `cells/x.json:12:5: robot 1: unknown key "robts"; did you mean "robots"?`.
std::string with_key_position(std::string_view text, std::string_view origin,
                              const std::string& message) {
  const std::string_view marker = "unknown key \"";
  const std::size_t k = message.find(marker);
  if (k == std::string::npos || message.rfind(origin, 0) != 0) return message;
  const std::size_t from = k + marker.size();
  const std::string key = message.substr(from, message.find('"', from) - from);
  const std::string at = key_position(text, key);
  if (at.empty()) return message;
  return fmt::format("{}:{}{}", origin, at, message.substr(origin.size()));
}

}  // namespace

CellModel parse_cell(std::string_view text, std::string_view origin,
                     const std::filesystem::path& base_dir) {
  try {
    return parse_cell_json(text, origin, base_dir);
  } catch (const json::exception& e) {  // e.g. a key that is not UTF-8 met by a message
    throw CellFileError(fmt::format("{}: {}", origin, e.what()));
  } catch (const CellFileError& e) {
    throw CellFileError(with_key_position(text, origin, e.what()));
  }
}

CellModel load_cell_file(const std::filesystem::path& path) {
  std::string text;
  try {
    text = io::read_file(path, 16U << 20);  // 1024 robots with notes stay far below
  } catch (const io::FileError& e) {
    throw CellFileError(fmt::format("{} (the cell file)", e.what()));
  }
  std::filesystem::path dir = path.parent_path();
  if (dir.empty()) dir = ".";
  return parse_cell(text, path.string(), dir);
}

// ---- Geometry ----

double reach_m(const kin::RobotModel& model, const std::optional<math::Transform>& tool) {
  double sum = 0.0;
  if (model.geometry == kin::Geometry::chain) {
    // Each joint moves the next frame's origin by at most its offsets (origin, after) and a
    // prismatic joint's travel; rotations move nothing farther from the previous origin.
    for (const kin::Joint& j : model.joints) {
      sum += j.chain.origin.p.norm() + j.chain.after.p.norm();
      if (j.type == kin::JointType::prismatic) {
        sum += std::max(std::abs(j.lower), std::abs(j.upper));
      }
    }
    if (tool) sum += tool->p.norm();
    return sum;
  }
  for (const kin::Joint& j : model.joints) {
    sum += std::abs(j.dh.a_m);
    if (j.type == kin::JointType::prismatic) {
      sum += std::max(std::abs(j.dh.d_m + j.lower), std::abs(j.dh.d_m + j.upper));
    } else {
      sum += std::abs(j.dh.d_m);
    }
  }
  if (tool) sum += tool->p.norm();
  return sum;
}

double reach_m(const CellRobot& robot) {
  return reach_m(robot.model, robot.tool);
}

double shared_volume_m3(double r1_m, double r2_m, double distance_m, std::size_t samples,
                        std::uint64_t seed) {
  if (samples == 0 || !(distance_m < r1_m + r2_m)) return 0.0;
  // Sample the smaller sphere's bounding cube: the common part lies inside it. The larger
  // sphere's centre is distance_m away along x.
  const double small = std::min(r1_m, r2_m);
  const double large = std::max(r1_m, r2_m);
  // mt19937_64's sequence is fixed by the standard; the conversion to [0, 1) is written out
  // because uniform_real_distribution's is not.
  std::mt19937_64 random(seed);
  const auto uniform = [&random] { return static_cast<double>(random() >> 11) * 0x1.0p-53; };
  std::size_t inside = 0;
  for (std::size_t i = 0; i < samples; ++i) {
    const math::Vec3 p{(2 * uniform() - 1) * small, (2 * uniform() - 1) * small,
                       (2 * uniform() - 1) * small};
    const math::Vec3 q = p - math::Vec3{distance_m, 0, 0};
    if (math::dot(p, p) <= small * small && math::dot(q, q) <= large * large) ++inside;
  }
  const double cube = 8.0 * small * small * small;
  return cube * static_cast<double>(inside) / static_cast<double>(samples);
}

std::vector<ReachOverlap> reach_overlaps(const CellModel& cell, std::size_t samples) {
  std::vector<double> reach;
  for (const CellRobot& r : cell.robots) reach.push_back(reach_m(r));
  const std::size_t n = cell.robots.size();
  std::vector<ReachOverlap> out;
  std::size_t meeting = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = i + 1; k < n; ++k) {
      ReachOverlap o;
      o.first = i;
      o.second = k;
      o.distance_m = (cell.robots[k].base.p - cell.robots[i].base.p).norm();
      o.depth_m = reach[i] + reach[k] - o.distance_m;
      if (o.overlaps()) ++meeting;
      out.push_back(o);
    }
  }
  // At most 2e7 points in all (a thousand robots in one room would otherwise take minutes),
  // but never fewer than 1000 a pair.
  constexpr std::size_t kBudget = 20'000'000;
  const std::size_t per_pair =
      meeting == 0 ? 0 : std::max<std::size_t>(1000, std::min(samples, kBudget / meeting));
  for (std::size_t index = 0; index < out.size(); ++index) {
    ReachOverlap& o = out[index];
    if (!o.overlaps()) continue;
    o.shared_volume_m3 = shared_volume_m3(reach[o.first], reach[o.second], o.distance_m,
                                          std::min(per_pair, samples), 0x5eedce11ULL + index);
  }
  return out;
}

}  // namespace rccx::cell
