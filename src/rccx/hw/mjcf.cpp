#include "rccx/hw/mjcf.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>

#include "rccx/hw/arm_base.hpp"
#include "rccx/hw/gravity.hpp"
#include "rccx/hw/rcu.hpp"
#include "rccx/io/json_reader.hpp"
#include "rccx/math/units.hpp"

namespace rccx::hw {

std::array<JointPlant, kin::kMaxJoints> joint_plants(const kin::RobotModel& model) {
  std::array<JointPlant, kin::kMaxJoints> out{};
  RcuConfig rcu;
  if (has_rcu(model)) rcu = rcu_config(model);
  const std::size_t n = std::min(model.dof(), kin::kMaxJoints);
  for (std::size_t i = 0; i < n; ++i) {
    const kin::Joint& j = model.joints[i];
    const bool revolute = j.type == kin::JointType::revolute;
    JointPlant& p = out[i];
    const kin::JointDynamics& d = j.dynamics;
    // The file's dynamics first, then the RCU's plant (the Microbo), then the defaults.
    const RcuJointConfig* r = i < rcu.joints.size() ? &rcu.joints[i] : nullptr;
    const auto pick = [](double file, double from_rcu, double fallback) {
      return file > 0 ? file : (from_rcu > 0 ? from_rcu : fallback);
    };
    p.inertia = pick(d.inertia, r ? r->inertia : 0.0,
                     revolute ? kDefaultInertia_kg_m2 : kDefaultInertia_kg);
    p.viscous = pick(d.viscous_friction, r ? r->viscous_friction : 0.0, 0.0);
    p.coulomb = pick(d.coulomb_friction, r ? r->coulomb_friction : 0.0, 0.0);
    p.max_effort = pick(d.max_effort, r ? r->max_effort : 0.0,
                        revolute ? kDefaultMaxEffort_N_m : kDefaultMaxEffort_N);
    p.servo_inertia = p.inertia;
    // The vendor law's stiffness: motor parameter 1 is the dynamic zone's bandwidth, rad/s.
    p.bandwidth =
        r && r->motor_parameters[0] > 0 ? r->motor_parameters[0] : kDefaultServoBandwidth_rad_per_s;
  }
  return out;
}

namespace {

/// Shortest exact text of a double (MuJoCo reads it back to the same value).
std::string num(double v) {
  if (v == 0.0) return "0";  // also -0
  return fmt::format("{}", v);
}

std::string vec(const math::Vec3& v) {
  return fmt::format("{} {} {}", num(v.x), num(v.y), num(v.z));
}

/// The unit quaternion (w x y z) of a rotation matrix (Shepperd's method: the largest of the
/// four candidates, so no precision is lost near any angle).
std::array<double, 4> quaternion(const math::Rot3& R) {
  const double m00 = R(0, 0), m11 = R(1, 1), m22 = R(2, 2);
  const double trace = m00 + m11 + m22;
  std::array<double, 4> q{};
  if (trace >= m00 && trace >= m11 && trace >= m22) {
    const double s = 2.0 * std::sqrt(1.0 + trace);
    q = {0.25 * s, (R(2, 1) - R(1, 2)) / s, (R(0, 2) - R(2, 0)) / s, (R(1, 0) - R(0, 1)) / s};
  } else if (m00 >= m11 && m00 >= m22) {
    const double s = 2.0 * std::sqrt(1.0 + m00 - m11 - m22);
    q = {(R(2, 1) - R(1, 2)) / s, 0.25 * s, (R(0, 1) + R(1, 0)) / s, (R(0, 2) + R(2, 0)) / s};
  } else if (m11 >= m22) {
    const double s = 2.0 * std::sqrt(1.0 + m11 - m00 - m22);
    q = {(R(0, 2) - R(2, 0)) / s, (R(0, 1) + R(1, 0)) / s, 0.25 * s, (R(1, 2) + R(2, 1)) / s};
  } else {
    const double s = 2.0 * std::sqrt(1.0 + m22 - m00 - m11);
    q = {(R(1, 0) - R(0, 1)) / s, (R(0, 2) + R(2, 0)) / s, (R(1, 2) + R(2, 1)) / s, 0.25 * s};
  }
  if (q[0] < 0) {
    for (double& c : q) c = -c;
  }
  return q;
}

std::string pose(const math::Transform& T) {
  const auto q = quaternion(T.R);
  return fmt::format(R"(pos="{}" quat="{} {} {} {}")", vec(T.p), num(q[0]), num(q[1]), num(q[2]),
                     num(q[3]));
}

/// The constant part of link i's A matrix: Rot(z, theta) Trans(z, d) Trans(x, a) Rot(x, alpha).
math::Transform dh_constant(const kin::Joint& j) {
  const double ct = std::cos(j.dh.theta_rad), st = std::sin(j.dh.theta_rad);
  double ca = std::cos(j.dh.alpha_rad), sa = std::sin(j.dh.alpha_rad);
  // As kin::DhChain snaps them, so that this chain and the solvers' agree exactly.
  if (std::abs(ca) < 1e-15) ca = 0.0;
  if (std::abs(sa) < 1e-15) sa = 0.0;
  return {{{ct, st, 0.0}, {-st * ca, ct * ca, sa}, {st * sa, -ct * sa, ca}},
          {j.dh.a_m * ct, j.dh.a_m * st, j.dh.d_m}};
}

/// How link<i>'s body sits: in its parent body (link<i-1> or the base), where link i's own
/// frame (DH frame i, or a chain's link frame i) and the next body's joint are in it, and the
/// joint's axis in it. DH: the joint's motion, Rot(z, q) or Trans(z, q), commutes with the
/// first two factors of the constant part C_i, so link<i> is frame i-1 moved and C_i places
/// frame i. A chain: link<i> is frame i-1 times the joint's origin, moved about its axis; then
/// `after` (the flange, on the last joint only) and the next joint's origin.
struct BodyPlacement {
  math::Transform in_parent;
  math::Transform own;
  math::Transform next;
  math::Vec3 axis{0, 0, 1};
};

BodyPlacement placement(const kin::RobotModel& model, std::size_t i) {
  const kin::Joint& j = model.joints[i];
  BodyPlacement b;
  if (model.geometry == kin::Geometry::chain) {
    b.in_parent = i == 0 ? j.chain.origin : model.joints[i - 1].chain.after * j.chain.origin;
    b.own = j.chain.after;
    b.next = i + 1 < model.dof() ? j.chain.after * model.joints[i + 1].chain.origin : b.own;
    b.axis = j.chain.axis.normalized();
    return b;
  }
  b.in_parent = i == 0 ? math::Transform::identity() : dh_constant(model.joints[i - 1]);
  b.own = dh_constant(j);
  b.next = b.own;
  return b;
}

/// The `<inertial>` of link i in its body: its mass at its centre of mass, and its tensor (the
/// file's, turned from its own frame into the body's: R I R^T, given by its principal axes and
/// moments) or, when the file gives none, a small sphere. Throws std::invalid_argument for a tensor
/// no body can have.
std::string link_inertial(const kin::RobotModel& model, std::size_t i, const math::Transform& own) {
  const kin::JointDynamics& d = model.joints[i].dynamics;
  const double mass = d.link_mass_kg > 0 ? d.link_mass_kg : kDefaultLinkMass_kg;
  const math::Vec3 com = own * math::Vec3{d.link_com_m[0], d.link_com_m[1], d.link_com_m[2]};
  const auto& t = d.link_inertia_kg_m2;
  if (std::all_of(t.begin(), t.end(), [](double v) { return v == 0.0; })) {
    const double gyr = 0.4 * mass * kLinkGyrationSphere_m * kLinkGyrationSphere_m;
    return fmt::format(R"(<inertial pos="{}" mass="{}" diaginertia="{} {} {}"/>)", vec(com),
                       num(mass), num(gyr), num(gyr), num(gyr));
  }
  Eigen::Matrix3d I, R;
  I << t[0], t[3], t[4], t[3], t[1], t[5], t[4], t[5], t[2];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R(r, c) = own.R(r, c);
  }
  const Eigen::Matrix3d B = R * I * R.transpose();
  // A body's principal moments are positive and each at most the sum of the other two.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(B);
  const Eigen::Vector3d e = solver.eigenvalues();
  const double tolerance = 1e-9 * std::max(1.0, e.cwiseAbs().maxCoeff());
  if (!(e.minCoeff() > 0.0) || e(0) + e(1) < e(2) - tolerance) {
    throw std::invalid_argument(fmt::format(
        "{}: joint {} ('{}'): the link's inertia tensor [{}] kg m^2 has principal moments {} {} "
        "{}, which no body has (each must be > 0 and at most the sum of the other two): fix "
        "the URDF's <inertia> or the robot file's \"link_inertia_kg_m2\", or give zeros",
        model.name, i + 1, model.joints[i].name, fmt::join(t, " "), e(0), e(1), e(2)));
  }
  // The principal axes and moments, as MuJoCo keeps them: its own decomposition of a
  // fullinertia is good to only ~1e-8 of the largest moment.
  const Eigen::Matrix3d& V = solver.eigenvectors();
  const double handed = V.determinant() > 0 ? 1.0 : -1.0;  // a rotation, not a reflection
  const math::Rot3 axes{{V(0, 0), V(1, 0), V(2, 0)},
                        {V(0, 1), V(1, 1), V(2, 1)},
                        {handed * V(0, 2), handed * V(1, 2), handed * V(2, 2)}};
  const auto q = quaternion(axes);
  return fmt::format(R"(<inertial pos="{}" quat="{} {} {} {}" mass="{}" diaginertia="{} {} {}"/>)",
                     vec(com), num(q[0]), num(q[1]), num(q[2]), num(q[3]), num(mass), num(e(0)),
                     num(e(1)), num(e(2)));
}

bool usable_name(const std::string& s) {
  return !s.empty() && s.size() <= 64 && std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
}

void indent(std::string& out, std::size_t depth) {
  out.append(2 * depth, ' ');
}

}  // namespace

namespace {

using SceneReader = io::JsonObjectReader<std::invalid_argument>;

math::Vec3 vec3(SceneReader& r, const std::string& key, const math::Vec3& fallback) {
  if (!r.has(key)) return fallback;
  const auto v = r.numbers<3>(key, 1e3);
  return {v[0], v[1], v[2]};
}

math::Rot3 rpy_deg(SceneReader& r, const std::string& key) {
  if (!r.has(key)) return math::Rot3::identity();
  const auto v = r.numbers<3>(key, 360.0);
  return math::Rot3::from_rpy(math::deg_to_rad(v[0]), math::deg_to_rad(v[1]),
                              math::deg_to_rad(v[2]));
}

}  // namespace

Scene scene_from_file(const kin::RobotModel& model) {
  Scene scene;
  if (model.hardware_json.empty()) return scene;
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(model.hardware_json, nullptr, true, true);
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(fmt::format("{}: \"hardware\": {}", model.name, e.what()));
  }
  if (!doc.is_object() || !doc.contains("mujoco")) return scene;
  SceneReader r(doc.at("mujoco"), fmt::format("{}: \"hardware\": \"mujoco\"", model.name));
  scene.base_m = {rpy_deg(r, "base_rpy_deg"), vec3(r, "base_m", {})};
  if (r.has("tool")) {
    SceneReader t(r.get("tool"), r.where() + ": \"tool\"");
    scene.tool_mass_kg = t.non_negative_or("mass_kg", 0.0);
    scene.tool_com_m = vec3(t, "com_m", {});
    scene.tool_length_m = t.non_negative_or("length_m", 0.0);
    scene.tool_radius_m = t.number_or("radius_m", scene.tool_radius_m);
    if (!(scene.tool_radius_m > 0)) t.fail("\"radius_m\" must be > 0");
    scene.tool_friction = t.non_negative_or("friction", scene.tool_friction);
    t.no_unknown_keys();
  }
  if (r.has("boxes")) {
    const nlohmann::json& boxes = r.get("boxes");
    if (!boxes.is_array()) r.fail("\"boxes\" must be a list of objects");
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      SceneReader b(boxes[i], fmt::format("{}: \"boxes\" [{}]", r.where(), i + 1));
      SceneBox box;
      box.name = b.name("name", 64);
      box.pose_m = {rpy_deg(b, "rpy_deg"), vec3(b, "center_m", {})};
      box.half_size_m = vec3(b, "half_size_m", {});
      if (!(box.half_size_m.x > 0 && box.half_size_m.y > 0 && box.half_size_m.z > 0)) {
        b.fail("\"half_size_m\" must be three numbers > 0");
      }
      box.mass_kg = b.non_negative_or("mass_kg", 0.0);
      box.friction = b.non_negative_or("friction", box.friction);
      b.no_unknown_keys();
      scene.boxes.push_back(std::move(box));
    }
  }
  scene.contact_time_constant_s =
      r.number_or("contact_time_constant_s", scene.contact_time_constant_s);
  scene.substeps = static_cast<int>(r.integer_or("substeps", 1, 100, scene.substeps));
  r.no_unknown_keys();
  return scene;
}

std::string make_mjcf(const kin::RobotModel& model, const Scene& scene) {
  const std::size_t n = model.dof();
  if (n == 0 || n > kin::kMaxJoints) {
    throw std::invalid_argument(
        fmt::format("{}: MuJoCo needs 1 to {} joints", model.name, kin::kMaxJoints));
  }
  if (scene.substeps < 1 || scene.substeps > 100) {
    throw std::invalid_argument(
        fmt::format("scene: {} MuJoCo steps a servo tick; give 1 to 100", scene.substeps));
  }
  if (!(scene.contact_time_constant_s >= 2.0 * kServoPeriod_s / scene.substeps) ||
      !std::isfinite(scene.contact_time_constant_s)) {
    throw std::invalid_argument(fmt::format(
        "scene: the contact time constant must be at least two MuJoCo steps ({} s), got {} s",
        2.0 * kServoPeriod_s / scene.substeps, scene.contact_time_constant_s));
  }
  if (!(scene.tool_mass_kg >= 0) || !(scene.tool_length_m >= 0) || !(scene.tool_radius_m > 0)) {
    throw std::invalid_argument("scene: the tool's mass, length and radius must not be negative");
  }
  for (const SceneBox& b : scene.boxes) {
    if (!usable_name(b.name)) {
      throw std::invalid_argument(fmt::format(
          "scene: box name \"{}\": use 1 to 64 letters, digits and underscores", b.name));
    }
    if (!(b.half_size_m.x > 0 && b.half_size_m.y > 0 && b.half_size_m.z > 0) || !(b.mass_kg >= 0) ||
        !(b.friction >= 0) || !(scene.tool_friction >= 0)) {
      throw std::invalid_argument(fmt::format(
          "scene: box {} needs half sizes > 0, a mass and friction not negative", b.name));
    }
  }
  const auto plants = joint_plants(model);
  const double timestep = kServoPeriod_s / scene.substeps;

  std::string x;
  x += fmt::format("<mujoco model=\"{}\">\n", model.name);
  x += "  <!-- generated by rccx::hw::make_mjcf from the robot file; SI units -->\n";
  // balanceinertia: a thin rod's or plate's tensor may miss A + B >= C by rounding alone.
  x += R"(  <compiler angle="radian" inertiafromgeom="false" balanceinertia="true"/>)"
       "\n";
  x += fmt::format(
      R"(  <option timestep="{}" gravity="0 0 {}" integrator="Euler" cone="pyramidal"/>)"
      "\n",
      num(timestep), num(-kGravity_m_per_s2));
  x += "  <size nconmax=\"200\" njmax=\"600\"/>\n";
  // Contact: critically damped with the scene's time constant (at least 2 steps), hard
  // impedance, three-dimensional friction cones.
  x += "  <default>\n";
  x += fmt::format("    <geom condim=\"3\" solref=\"{} 1\" solimp=\"0.95 0.99 0.001\"/>\n",
                   num(scene.contact_time_constant_s));
  x += "    <joint limited=\"true\" solreflimit=\"0.004 1\"/>\n";
  x += "  </default>\n";
  x += "  <worldbody>\n";

  // The scene: fixed boxes straight in the world, free ones as bodies with a free joint.
  // contype 1 / conaffinity 3: boxes touch boxes and the arm (contype 2 / conaffinity 1),
  // which never touches itself.
  for (const SceneBox& b : scene.boxes) {
    const std::string geom = fmt::format(
        R"(type="box" size="{}" friction="{} 0.005 0.0001" contype="1" conaffinity="3")",
        vec(b.half_size_m), num(b.friction));
    if (b.mass_kg == 0.0) {
      x += fmt::format("    <geom name=\"{}\" {} {}/>\n", b.name, pose(b.pose_m), geom);
    } else {
      const math::Vec3& h = b.half_size_m;
      const double m = b.mass_kg;
      const math::Vec3 I{m / 3.0 * (h.y * h.y + h.z * h.z), m / 3.0 * (h.x * h.x + h.z * h.z),
                         m / 3.0 * (h.x * h.x + h.y * h.y)};
      x += fmt::format("    <body name=\"{}\" {}>\n", b.name, pose(b.pose_m));
      x += fmt::format("      <freejoint name=\"{}_free\"/>\n", b.name);
      x += fmt::format("      <inertial pos=\"0 0 0\" mass=\"{}\" diaginertia=\"{}\"/>\n", num(m),
                       vec(I));
      x += fmt::format("      <geom name=\"{}\" {}/>\n", b.name, geom);
      x += "    </body>\n";
    }
  }

  // The arm: base, then link1 .. link<n>, each carrying its joint at its origin along its z.
  x += fmt::format("    <body name=\"base\" {}>\n", pose(scene.base_m));
  std::size_t depth = 3;
  for (std::size_t i = 0; i < n; ++i) {
    const kin::Joint& j = model.joints[i];
    const bool revolute = j.type == kin::JointType::revolute;
    const JointPlant& p = plants[i];
    const BodyPlacement b = placement(model, i);
    indent(x, depth);
    x += fmt::format("<body name=\"link{}\" {}>\n", i + 1, pose(b.in_parent));
    ++depth;
    const double margin = revolute ? kHardStopMargin_rad : kHardStopMargin_m;
    indent(x, depth);
    // Armature: the file's effective inertia (the motor reflected), so the servo's gains, set
    // from it, never meet a joint lighter than they assume.
    x += fmt::format(
        R"(<joint name="j{}" type="{}" pos="0 0 0" axis="{}" range="{} {}" armature="{}" damping="{}" frictionloss="{}"/>)"
        "\n",
        i + 1, revolute ? "hinge" : "slide", vec(b.axis), num(j.lower - margin),
        num(j.upper + margin), num(p.inertia), num(p.viscous), num(p.coulomb));
    // The link's mass and inertia, given in its own frame (DH frame i, or the chain's link
    // frame i) = this body x b.own.
    indent(x, depth);
    x += link_inertial(model, i, b.own) + "\n";
    // The link's shape: a capsule from this body's origin to the next joint's (a prismatic
    // link also reaches back along its axis by its lower limit, as a sliding rod does).
    const math::Vec3 from = b.axis * (revolute ? 0.0 : -std::max(0.0, j.lower));
    const math::Vec3 to = b.next.p;
    indent(x, depth);
    if ((to - from).norm() < 1e-6) {
      x += fmt::format(
          R"(<geom name="link{}" type="sphere" size="{}" pos="{}" contype="2" conaffinity="1"/>)"
          "\n",
          i + 1, num(kLinkRadius_m), vec(to));
    } else {
      x += fmt::format(
          R"(<geom name="link{}" type="capsule" size="{}" fromto="{} {}" contype="2" conaffinity="1"/>)"
          "\n",
          i + 1, num(kLinkRadius_m), vec(from), vec(to));
    }
  }
  // T6, and the tool beyond the sensor: the sensor measures what the tool body exchanges with
  // the last link.
  const math::Transform C6 = placement(model, n - 1).own;
  indent(x, depth);
  x += fmt::format("<site name=\"t6\" {} size=\"0.005\"/>\n", pose(C6));
  indent(x, depth);
  x += fmt::format("<body name=\"tool\" {}>\n", pose(C6));
  ++depth;
  indent(x, depth);
  x += "<site name=\"ft\" pos=\"0 0 0\" size=\"0.01\"/>\n";
  if (scene.tool_mass_kg > 0) {
    const double m = scene.tool_mass_kg;
    const double r = std::max(scene.tool_radius_m, 0.5 * scene.tool_length_m);
    const double gyr = 0.4 * m * r * r;
    indent(x, depth);
    x += fmt::format(R"(<inertial pos="{}" mass="{}" diaginertia="{} {} {}"/>)"
                     "\n",
                     vec(scene.tool_com_m), num(m), num(gyr), num(gyr), num(gyr));
  }
  // The tip, the point that touches first, is at tool_length_m along T6's z.
  const double r = scene.tool_radius_m;
  const double axis_end = scene.tool_length_m - r;
  indent(x, depth);
  if (axis_end < 1e-6) {
    x += fmt::format(
        R"(<geom name="tool" type="sphere" size="{}" pos="0 0 {}" friction="{} 0.005 0.0001" contype="2" conaffinity="1"/>)"
        "\n",
        num(r), num(axis_end), num(scene.tool_friction));
  } else {
    x += fmt::format(
        R"(<geom name="tool" type="capsule" size="{}" fromto="0 0 0 0 0 {}" friction="{} 0.005 0.0001" contype="2" conaffinity="1"/>)"
        "\n",
        num(r), num(axis_end), num(scene.tool_friction));
  }
  --depth;
  indent(x, depth);
  x += "</body>\n";
  for (std::size_t i = n; i-- > 0;) {
    --depth;
    indent(x, depth);
    x += "</body>\n";
  }
  x += "    </body>\n";
  x += "  </worldbody>\n";

  x += "  <actuator>\n";
  for (std::size_t i = 0; i < n; ++i) {
    const double e = plants[i].max_effort;
    x += fmt::format(
        R"(    <motor name="m{0}" joint="j{0}" gear="1" ctrllimited="true" ctrlrange="{1} {2}"/>)"
        "\n",
        i + 1, num(-e), num(e));
  }
  x += "  </actuator>\n";
  x += "  <sensor>\n";
  x += "    <force name=\"ft_force\" site=\"ft\"/>\n";
  x += "    <torque name=\"ft_torque\" site=\"ft\"/>\n";
  x += "  </sensor>\n";
  x += "</mujoco>\n";
  return x;
}

}  // namespace rccx::hw
