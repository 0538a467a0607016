#include "rccx/kinematics/robot_model.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "rccx/io/file.hpp"
#include "rccx/io/json_reader.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/kinematics/embedded_robots.hpp"
#include "rccx/kinematics/urdf.hpp"
#include "rccx/math/units.hpp"

namespace rccx::kin {

using nlohmann::json;

JointVector RobotModel::ready() const noexcept {
  JointVector q(dof());
  for (std::size_t i = 0; i < dof(); ++i) q[i] = joints[i].ready;
  return q;
}

JointVector RobotModel::lower() const noexcept {
  JointVector q(dof());
  for (std::size_t i = 0; i < dof(); ++i) q[i] = joints[i].lower;
  return q;
}

JointVector RobotModel::upper() const noexcept {
  JointVector q(dof());
  for (std::size_t i = 0; i < dof(); ++i) q[i] = joints[i].upper;
  return q;
}

int RobotModel::first_joint_outside_limits(const JointVector& q, double tolerance) const noexcept {
  if (q.size() != dof()) return 0;
  for (std::size_t i = 0; i < dof(); ++i) {
    // Written so that NaN counts as outside.
    if (!(q[i] >= joints[i].lower - tolerance && q[i] <= joints[i].upper + tolerance)) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

bool RobotModel::within_limits(const JointVector& q, double tolerance) const noexcept {
  return first_joint_outside_limits(q, tolerance) < 0;
}

std::string_view to_string(JointType type) noexcept {
  return type == JointType::revolute ? "revolute" : "prismatic";
}

std::string_view to_string(SolverKind kind) noexcept {
  switch (kind) {
    case SolverKind::microbo:
      return "microbo";
    case SolverKind::puma:
      return "puma";
    case SolverKind::dh:
      return "dh";
  }
  return "?";
}

std::string_view to_string(Geometry geometry) noexcept {
  return geometry == Geometry::dh ? "dh" : "chain";
}

std::string_view to_string(Plant plant) noexcept {
  switch (plant) {
    case Plant::automatic:
      return "automatic";
    case Plant::ideal:
      return "ideal";
    case Plant::servo:
      return "servo";
    case Plant::mujoco:
      return "mujoco";
  }
  return "?";
}

namespace {

using Reader = io::JsonObjectReader<RobotFileError>;

// The optional "dynamics" object of a joint; its keys carry the unit of the joint's type.
JointDynamics parse_dynamics(const json& j, JointType type, const std::string& where) {
  Reader r(j, where);
  const bool revolute = type == JointType::revolute;
  // A key of the other joint type's units is named as such rather than as merely unknown.
  static constexpr std::array<const char*, 4> kRevoluteKeys = {
      "inertia_kg_m2", "viscous_N_m_s_per_rad", "coulomb_N_m", "max_effort_N_m"};
  static constexpr std::array<const char*, 4> kPrismaticKeys = {"inertia_kg", "viscous_N_s_per_m",
                                                                "coulomb_N", "max_effort_N"};
  const auto& own = revolute ? kRevoluteKeys : kPrismaticKeys;
  for (const char* wrong : revolute ? kPrismaticKeys : kRevoluteKeys) {
    if (j.contains(wrong)) {
      r.fail(fmt::format("\"{}\" is for a {} joint; this one is {}", wrong,
                         revolute ? "prismatic" : "revolute", to_string(type)));
    }
  }
  const auto non_negative = [&r](const char* key) {
    const double v = r.number_or(key, 0.0);
    if (v < 0) r.fail(fmt::format("\"{}\" must not be negative", key));
    return v;
  };
  JointDynamics d;
  d.inertia = non_negative(own[0]);
  d.viscous_friction = non_negative(own[1]);
  d.coulomb_friction = non_negative(own[2]);
  d.max_effort = non_negative(own[3]);
  d.link_mass_kg = non_negative("link_mass_kg");
  if (r.has("link_com_m")) {
    const json& com = r.get("link_com_m");
    if (!com.is_array() || com.size() != 3) r.fail("\"link_com_m\" must be [x, y, z]");
    for (std::size_t i = 0; i < 3; ++i) {
      if (!com[i].is_number() || !std::isfinite(com[i].get<double>())) {
        r.fail("\"link_com_m\" must hold three finite numbers");
      }
      d.link_com_m[i] = com[i].get<double>();
    }
  }
  if (r.has("link_inertia_kg_m2")) {
    const json& inertia = r.get("link_inertia_kg_m2");
    if (!inertia.is_array() || inertia.size() != 6) {
      r.fail("\"link_inertia_kg_m2\" must be [ixx, iyy, izz, ixy, ixz, iyz]");
    }
    for (std::size_t i = 0; i < 6; ++i) {
      if (!inertia[i].is_number() || !std::isfinite(inertia[i].get<double>())) {
        r.fail("\"link_inertia_kg_m2\" must hold six finite numbers");
      }
      d.link_inertia_kg_m2[i] = inertia[i].get<double>();
    }
  }
  if (r.has("note")) r.text("note");
  r.no_unknown_keys();
  return d;
}

Joint parse_joint(const json& j, const std::string& where) {
  Reader r(j, where);
  Joint joint;
  joint.name = r.name("name");
  const std::string type = r.string("type");
  if (type == "revolute") {
    joint.type = JointType::revolute;
  } else if (type == "prismatic") {
    joint.type = JointType::prismatic;
  } else {
    r.fail(fmt::format("\"type\" is \"{}\"; use \"revolute\" or \"prismatic\"", type));
  }
  // A link longer than 100 m or an angle of more than a turn is a typo.
  joint.dh.a_m = r.number("a_m", 100.0);
  joint.dh.alpha_rad = math::deg_to_rad(r.number("alpha_deg", 360.0));
  joint.dh.d_m = r.number_or("d_m", 0.0, 100.0);
  joint.dh.theta_rad = math::deg_to_rad(r.number_or("theta_deg", 0.0, 360.0));
  if (joint.type == JointType::revolute) {
    joint.lower = math::deg_to_rad(r.number("lower_deg"));
    joint.upper = math::deg_to_rad(r.number("upper_deg"));
    joint.resolution_per_count = math::deg_to_rad(r.number("resolution_deg_per_count"));
    joint.ready = math::deg_to_rad(r.number("ready_deg"));
  } else {
    joint.lower = r.number("lower_m");
    joint.upper = r.number("upper_m");
    joint.resolution_per_count = r.number("resolution_mm_per_count") * 1e-3;
    joint.ready = r.number("ready_m");
  }
  const bool revolute = joint.type == JointType::revolute;
  const char* const velocity_key = revolute ? "max_velocity_deg_per_s" : "max_velocity_mm_per_s";
  joint.max_velocity =
      revolute ? math::deg_to_rad(r.number(velocity_key)) : r.number(velocity_key) * 1e-3;
  if (r.has("dynamics")) {
    joint.dynamics = parse_dynamics(r.get("dynamics"), joint.type, r.where() + ": dynamics");
  }
  if (r.has("note")) r.text("note");  // free text, for people
  r.no_unknown_keys();
  if (!(joint.lower < joint.upper)) r.fail("the lower limit must be below the upper limit");
  if (!(joint.resolution_per_count > 0)) r.fail("the encoder resolution must be positive");
  if (!(joint.max_velocity > 0)) r.fail(fmt::format("\"{}\" must be positive", velocity_key));
  if (joint.ready < joint.lower || joint.ready > joint.upper) {
    r.fail("the ready value lies outside the joint limits");
  }
  return joint;
}

}  // namespace

namespace {

/// A robot file is 6 levels deep (hardware, rcu, joints, a joint, motor_parameters); deeper
/// nesting is refused while parsing, before recursion over it (dump(), the destructor) could
/// overflow the stack.
constexpr int kMaxDepth = 32;

/// A file that "extends" a shipped robot: the shipped file with the file's keys put over it
/// (RFC 7386 merge: an object merges key by key, anything else, a list of joints too, replaces),
/// so that a cell's robot file says only what differs (its plant, its scene, its name).
json extended(json doc, std::string_view origin) {
  const json& base_name = doc.at("extends");
  if (!base_name.is_string()) {
    throw RobotFileError(fmt::format("{}: \"extends\" must name a shipped robot ({})", origin,
                                     fmt::join(builtin_robot_names(), ", ")));
  }
  const std::string name = base_name.get<std::string>();
  for (const auto& robot : detail::embedded_robots()) {
    if (!robot.file_name.ends_with(".json") ||
        robot.file_name.substr(0, robot.file_name.rfind('.')) != name) {
      continue;
    }
    json base = json::parse(robot.text, nullptr, true, /*ignore_comments=*/true);
    doc.erase("extends");
    base.merge_patch(doc);
    return base;
  }
  throw RobotFileError(fmt::format("{}: \"extends\": no shipped robot named {}; known robots: {}",
                                   origin, io::quoted(name),
                                   fmt::join(builtin_robot_names(), ", ")));
}

/// The keys of any robot file beside its joints: notes, hardware, plant.
void parse_file_level(Reader& r, RobotModel& model) {
  if (r.has("notes")) {
    const json& notes = r.get("notes");
    if (!notes.is_string() && !notes.is_array()) r.fail("\"notes\" must be text or a list of it");
  }
  if (r.has("hardware")) {
    // What lies below the wire belongs to rccx::hw, which reads it with its own checks.
    const json& hardware = r.get("hardware");
    if (!hardware.is_object()) r.fail("\"hardware\" must be an object");
    model.hardware_json = hardware.dump();
  }
  if (r.has("plant")) {
    const std::string plant = r.string("plant");
    if (plant == "ideal") {
      model.plant = Plant::ideal;
    } else if (plant == "servo") {
      model.plant = Plant::servo;
    } else if (plant == "mujoco") {
      model.plant = Plant::mujoco;
    } else {
      r.fail(
          fmt::format("\"plant\" is {}; use \"ideal\", \"servo\" or \"mujoco\" (or leave it out)",
                      io::quoted(plant)));
    }
  }
}

/// Reads the URDF a robot file names: the file's "urdf" text, its base and tip links.
using UrdfLoader = std::function<RobotModel(const std::string& file, const UrdfOptions& options)>;

/// A URDF path relative to a robot file's folder (an absolute one as it is).
UrdfLoader urdf_beside(const std::filesystem::path& folder) {
  return [folder](const std::string& file, const UrdfOptions& options) {
    return load_urdf(folder / file, options);
  };
}

/// A URDF shipped in robots/ (compiled in beside the robot files that name it).
RobotModel shipped_urdf(const std::string& file, const UrdfOptions& options) {
  std::vector<std::string_view> shipped;
  for (const auto& robot : detail::embedded_robots()) {
    if (!robot.file_name.ends_with(".urdf")) continue;
    if (robot.file_name == file) {
      return parse_urdf(robot.text, fmt::format("robots/{}", robot.file_name), options);
    }
    shipped.push_back(robot.file_name);
  }
  throw RobotFileError(fmt::format("no shipped URDF named {} (shipped: {})", io::quoted(file),
                                   fmt::join(shipped, ", ")));
}

/// What a robot file adds to joint `joint` of its URDF: encoder resolution, top speed, ready
/// value, motor and friction dynamics. The URDF's geometry, limits and links stay its own.
void add_to_urdf_joint(const json& j, Joint& joint, std::size_t index, const std::string& where) {
  Reader r(j, where);
  const std::string name = r.text("name", 256);
  if (name != joint.name) {
    r.fail(
        fmt::format("\"name\" is {}, but joint {} of the URDF's chain is {}: list the chain's "
                    "moving joints in order, base to tip",
                    io::quoted(name), index + 1, io::quoted(joint.name)));
  }
  for (const char* key : {"type", "a_m", "alpha_deg", "d_m", "theta_deg", "lower_deg", "upper_deg",
                          "lower_m", "upper_m"}) {
    if (j.contains(key)) {
      r.fail(
          fmt::format("\"{}\": the URDF gives the joint's type, geometry and limits; a robot "
                      "file adds only what URDF lacks (robots/README.md)",
                      key));
    }
  }
  const bool revolute = joint.type == JointType::revolute;
  static constexpr std::array<const char*, 3> kRevoluteKeys = {
      "resolution_deg_per_count", "max_velocity_deg_per_s", "ready_deg"};
  static constexpr std::array<const char*, 3> kPrismaticKeys = {"resolution_mm_per_count",
                                                                "max_velocity_mm_per_s", "ready_m"};
  for (const char* wrong : revolute ? kPrismaticKeys : kRevoluteKeys) {
    if (j.contains(wrong)) {
      r.fail(fmt::format("\"{}\" is for a {} joint; URDF joint {} is {}", wrong,
                         revolute ? "prismatic" : "revolute", io::quoted(joint.name),
                         to_string(joint.type)));
    }
  }
  const auto& keys = revolute ? kRevoluteKeys : kPrismaticKeys;
  const double unit = revolute ? math::deg_to_rad(1.0) : 1e-3;  // deg or mm
  if (r.has(keys[0])) joint.resolution_per_count = r.positive(keys[0]) * unit;
  if (r.has(keys[1])) joint.max_velocity = r.positive(keys[1]) * unit;
  if (r.has(keys[2])) {
    joint.ready = revolute ? math::deg_to_rad(r.number(keys[2])) : r.number(keys[2]);
  }
  if (r.has("dynamics")) {
    const json& d = r.get("dynamics");
    for (const char* key : {"link_mass_kg", "link_com_m", "link_inertia_kg_m2"}) {
      if (d.is_object() && d.contains(key)) {
        r.fail(
            fmt::format("dynamics: \"{}\": the URDF gives the link's mass, centre of mass "
                        "and inertia",
                        key));
      }
    }
    const JointDynamics given = parse_dynamics(d, joint.type, r.where() + ": dynamics");
    joint.dynamics.inertia = given.inertia;
    joint.dynamics.viscous_friction = given.viscous_friction;
    joint.dynamics.coulomb_friction = given.coulomb_friction;
    if (given.max_effort > 0) joint.dynamics.max_effort = given.max_effort;
  }
  if (r.has("note")) r.text("note");
  r.no_unknown_keys();
}

/// A robot file that points at a URDF ("urdf"): the URDF's chain, with the file's name, title,
/// source, plant and hardware, and per joint what URDF lacks.
RobotModel parse_urdf_robot(Reader& r, std::string_view origin, const UrdfLoader& load) {
  const std::string file = r.text("urdf", 4096);
  UrdfOptions options;
  if (r.has("base_link")) options.base_link = r.text("base_link", 256);
  if (r.has("tip_link")) options.tip_link = r.text("tip_link", 256);
  if (r.has("solver")) {
    r.fail(
        "\"solver\" is not read beside \"urdf\": rccx finds a URDF chain's closed form itself "
        "(the UR family's, the PUMA's) or takes the numeric solver (docs/KINEMATICS.md)");
  }
  RobotModel model;
  try {
    model = load(file, options);
  } catch (const RobotFileError& e) {
    r.fail(fmt::format("\"urdf\": {}", e.what()));
  }
  model.name = r.name("name");
  model.title = r.text("title");
  model.source = r.text("source");
  if (r.has("joints")) {
    const json& joints = r.get("joints");
    std::vector<std::string_view> names;
    for (const Joint& j : model.joints) names.push_back(j.name);
    if (!joints.is_array() || joints.size() != model.dof()) {
      r.fail(fmt::format(
          "\"joints\" must list the {} moving joints of the URDF's chain ({}), base to tip; it "
          "lists {}",
          model.dof(), fmt::join(names, ", "), joints.is_array() ? joints.size() : 0));
    }
    for (std::size_t i = 0; i < joints.size(); ++i) {
      add_to_urdf_joint(joints[i], model.joints[i], i,
                        fmt::format("{}: joint {} ({})", origin, i + 1, model.joints[i].name));
    }
  }
  for (std::size_t i = 0; i < model.dof(); ++i) {
    const Joint& j = model.joints[i];
    if (!(j.max_velocity > 0)) {
      r.fail(fmt::format(
          "joint {} ({}): the URDF gives no velocity limit: give \"{}\"", i + 1, j.name,
          j.type == JointType::revolute ? "max_velocity_deg_per_s" : "max_velocity_mm_per_s"));
    }
    if (!(j.ready >= j.lower && j.ready <= j.upper)) {
      r.fail(fmt::format("joint {} ({}): the ready value lies outside the URDF's limits", i + 1,
                         j.name));
    }
  }
  parse_file_level(r, model);
  r.no_unknown_keys();
  return model;
}

/// `load` finds a URDF the file names by "urdf" (one an extended shipped robot names is the
/// shipped one).
RobotModel parse_robot_json(std::string_view json_text, std::string_view origin,
                            const UrdfLoader& load) {
  json doc;
  std::vector<std::set<std::string>> keys;  // one set per open object
  const auto strict = [&](int depth, json::parse_event_t event, json& parsed) {
    if (depth > kMaxDepth) {
      throw RobotFileError(fmt::format(
          "{}: nested more than {} deep; a robot file is 6 levels deep", origin, kMaxDepth));
    }
    if (event == json::parse_event_t::object_start) keys.emplace_back();
    if (event == json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
    // The JSON library would keep the last of a repeated key silently.
    if (event == json::parse_event_t::key && !keys.empty() &&
        !keys.back().insert(parsed.get<std::string>()).second) {
      throw RobotFileError(fmt::format("{}: key {} is given twice in one object; give it once",
                                       origin, io::quoted(parsed.get<std::string>())));
    }
    return true;
  };
  try {
    doc = json::parse(json_text, strict, /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const json::exception& e) {  // syntax, or a number that overflows a double
    throw RobotFileError(fmt::format("{}: not valid JSON: {}", origin, e.what()));
  }
  const bool names_urdf = doc.is_object() && doc.contains("urdf");
  if (doc.is_object() && doc.contains("extends")) doc = extended(std::move(doc), origin);
  Reader r(doc, std::string(origin));
  if (doc.contains("urdf")) return parse_urdf_robot(r, origin, names_urdf ? load : shipped_urdf);
  RobotModel model;
  model.name = r.name("name");
  model.title = r.text("title");
  model.source = r.text("source");
  const std::string solver = r.string("solver");
  if (solver == "microbo") {
    model.solver = SolverKind::microbo;
  } else if (solver == "puma") {
    model.solver = SolverKind::puma;
  } else if (solver == "dh") {
    model.solver = SolverKind::dh;
  } else {
    r.fail(fmt::format("\"solver\" is \"{}\"; use \"microbo\", \"puma\" or \"dh\"", solver));
  }
  const json& joints = r.get("joints");
  if (!joints.is_array() || joints.empty() || joints.size() > kMaxJoints) {
    r.fail(fmt::format("\"joints\" must be an array of 1 to {} joints", kMaxJoints));
  }
  for (std::size_t i = 0; i < joints.size(); ++i) {
    model.joints.push_back(parse_joint(joints[i], fmt::format("{}: joint {}", origin, i + 1)));
  }
  parse_file_level(r, model);
  r.no_unknown_keys();
  return model;
}

RobotModel parse_robot_with(std::string_view json_text, std::string_view origin,
                            const UrdfLoader& load) {
  try {
    return parse_robot_json(json_text, origin, load);
  } catch (const json::exception& e) {  // e.g. text that is not UTF-8 met by dump()
    throw RobotFileError(fmt::format("{}: {}", origin, e.what()));
  }
}

bool is_robot_file(std::string_view file_name) {
  return file_name.ends_with(".json");
}

}  // namespace

RobotModel parse_robot(std::string_view json_text, std::string_view origin) {
  return parse_robot_with(json_text, origin,
                          urdf_beside(std::filesystem::path(origin).parent_path()));
}

RobotModel load_robot_file(const std::filesystem::path& path) {
  std::string text;
  try {
    text = io::read_file(path, 1U << 20);  // a robot file is a few kB
  } catch (const io::FileError& e) {
    throw RobotFileError(fmt::format("{} (the robot file)", e.what()));
  }
  return parse_robot_with(text, path.string(), urdf_beside(path.parent_path()));
}

std::vector<std::string> builtin_robot_names() {
  std::vector<std::string> names;
  for (const auto& robot : detail::embedded_robots()) {
    std::string_view n = robot.file_name;
    if (is_robot_file(n)) names.emplace_back(n.substr(0, n.rfind('.')));
  }
  return names;
}

RobotModel builtin_robot(std::string_view name) {
  for (const auto& robot : detail::embedded_robots()) {
    if (is_robot_file(robot.file_name) &&
        robot.file_name.substr(0, robot.file_name.rfind('.')) == name) {
      return parse_robot_with(robot.text, fmt::format("robots/{}", robot.file_name), shipped_urdf);
    }
  }
  throw RobotFileError(fmt::format("no robot named \"{}\"; known robots: {}", name,
                                   fmt::join(builtin_robot_names(), ", ")));
}

}  // namespace rccx::kin
