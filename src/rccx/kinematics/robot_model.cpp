#include "rccx/kinematics/robot_model.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "rccx/io/file.hpp"
#include "rccx/io/json_reader.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/kinematics/embedded_robots.hpp"
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
    if (robot.file_name.substr(0, robot.file_name.rfind('.')) != name) continue;
    json base = json::parse(robot.text, nullptr, true, /*ignore_comments=*/true);
    doc.erase("extends");
    base.merge_patch(doc);
    return base;
  }
  throw RobotFileError(fmt::format("{}: \"extends\": no shipped robot named {}; known robots: {}",
                                   origin, io::quoted(name),
                                   fmt::join(builtin_robot_names(), ", ")));
}

RobotModel parse_robot_json(std::string_view json_text, std::string_view origin) {
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
  if (doc.is_object() && doc.contains("extends")) doc = extended(std::move(doc), origin);
  Reader r(doc, std::string(origin));
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
  r.no_unknown_keys();
  return model;
}

}  // namespace

RobotModel parse_robot(std::string_view json_text, std::string_view origin) {
  try {
    return parse_robot_json(json_text, origin);
  } catch (const json::exception& e) {  // e.g. text that is not UTF-8 met by dump()
    throw RobotFileError(fmt::format("{}: {}", origin, e.what()));
  }
}

RobotModel load_robot_file(const std::filesystem::path& path) {
  std::string text;
  try {
    text = io::read_file(path, 1U << 20);  // a robot file is a few kB
  } catch (const io::FileError& e) {
    throw RobotFileError(fmt::format("{} (the robot file)", e.what()));
  }
  return parse_robot(text, path.string());
}

std::vector<std::string> builtin_robot_names() {
  std::vector<std::string> names;
  for (const auto& robot : detail::embedded_robots()) {
    std::string_view n = robot.file_name;
    names.emplace_back(n.substr(0, n.rfind('.')));
  }
  return names;
}

RobotModel builtin_robot(std::string_view name) {
  for (const auto& robot : detail::embedded_robots()) {
    if (robot.file_name.substr(0, robot.file_name.rfind('.')) == name) {
      return parse_robot(robot.text, fmt::format("robots/{}", robot.file_name));
    }
  }
  throw RobotFileError(fmt::format("no robot named \"{}\"; known robots: {}", name,
                                   fmt::join(builtin_robot_names(), ", ")));
}

}  // namespace rccx::kin
