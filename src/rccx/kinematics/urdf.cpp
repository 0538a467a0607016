#include "rccx/kinematics/urdf.hpp"

#include <console_bridge/console.h>
#include <fmt/format.h>

#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>
#include <Eigen/Core>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <sstream>
#include <vector>

#include "rccx/kinematics/collision_geometry.hpp"

namespace rccx::kin {

namespace {

/// Limits of what a robot arm's URDF can sensibly say: beyond them a number is a typo or an
/// attack, and the message says which.
constexpr double kMaxOffset_m = 100.0;
constexpr double kMaxMass_kg = 1e5;
constexpr double kMaxInertia_kg_m2 = 1e5;
constexpr double kMaxLimit = 1e3;  // rad or m

/// urdfdom reports through console_bridge; its words go into our message, not to stderr.
class CapturedLog final : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char* /*file*/,
           int /*line*/) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) lines.push_back(text);
  }
  std::vector<std::string> lines;
};

std::mutex& console_mutex() {
  static std::mutex m;  // console_bridge's handler is one for the process
  return m;
}

math::Transform to_transform(const urdf::Pose& pose) {
  const urdf::Rotation& r = pose.rotation;
  const double x = r.x, y = r.y, z = r.z, w = r.w;
  const double n = std::sqrt(x * x + y * y + z * z + w * w);
  math::Transform T;
  if (n > 0.0 && std::isfinite(n)) {
    const double qx = x / n, qy = y / n, qz = z / n, qw = w / n;
    T.R.n = {1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy + qz * qw), 2 * (qx * qz - qy * qw)};
    T.R.o = {2 * (qx * qy - qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz + qx * qw)};
    T.R.a = {2 * (qx * qz + qy * qw), 2 * (qy * qz - qx * qw), 1 - 2 * (qx * qx + qy * qy)};
  } else {
    T.R.n.x = std::nan("");  // caught by the finiteness check
  }
  T.p = {pose.position.x, pose.position.y, pose.position.z};
  return T;
}

bool finite(const math::Transform& T) {
  for (const double v : T.rows()) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

/// The second moment of the bodies lumped into one moving link (their inertia about the
/// gathering frame's origin, in its axes), and whether any body gave a tensor.
struct SecondMoment {
  Eigen::Matrix3d about_origin = Eigen::Matrix3d::Zero();
  bool given = false;
};

Eigen::Matrix3d to_eigen(const math::Rot3& R) {
  Eigen::Matrix3d M;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) M(r, c) = R(r, c);
  }
  return M;
}

/// m (|c|^2 E - c c^T): a point mass's inertia about the origin (the parallel-axis term).
Eigen::Matrix3d point_inertia(double m, const math::Vec3& c) {
  const Eigen::Vector3d v(c.x, c.y, c.z);
  return m * (v.squaredNorm() * Eigen::Matrix3d::Identity() - v * v.transpose());
}

/// Adds a body (mass m, tensor I about its centre of mass in the axes of `at`, the inertial
/// frame placed in the gathering frame) to the second moment: R I R^T plus the parallel-axis
/// term.
void add_second_moment(SecondMoment& s, double m, const Eigen::Matrix3d& I,
                       const math::Transform& at) {
  const Eigen::Matrix3d R = to_eigen(at.R);
  s.about_origin += R * I * R.transpose() + point_inertia(m, at.p);
  s.given = s.given || !I.isZero();
}

/// The lumped link's tensor about its centre of mass `com` (in the gathering frame), turned
/// into the axes of the link's own frame, `own` in the gathering frame: ixx iyy izz ixy ixz
/// iyz, zeros when no body gave one.
std::array<double, 6> inertia_about_com(const SecondMoment& s, double mass, const math::Vec3& com,
                                        const math::Rot3& own) {
  if (!s.given) return {};
  const Eigen::Matrix3d R = to_eigen(own);
  const Eigen::Matrix3d I = R.transpose() * (s.about_origin - point_inertia(mass, com)) * R;
  return {I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)};
}

class Reader {
 public:
  Reader(std::string_view origin, const UrdfOptions& options)
      : origin_(origin), options_(options) {}

  RobotModel read(std::string_view xml) {
    if (xml.size() > kMaxUrdfBytes) {
      fail(
          fmt::format("{} bytes, more than the {} MB a URDF may have here (an arm's URDF is "
                      "tens of kB; meshes go in their own files)",
                      xml.size(), kMaxUrdfBytes >> 20));
    }
    if (xml.find("xmlns:xacro") != std::string_view::npos ||
        xml.find("<xacro:") != std::string_view::npos) {
      fail("this is a xacro file, not URDF: run `xacro FILE > robot.urdf` first and read that");
    }
    check_tree(xml);
    const urdf::ModelInterfaceSharedPtr model = parse(xml);
    const auto [chain, base] = chain_links(*model);
    return build(*model, chain, base);
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw RobotFileError(fmt::format("{}: {}", origin_, why));
  }

  /// The links' parents as the joints give them, checked before urdfdom builds its tree: a
  /// cycle would leak urdfdom's links (they hold each other), and its words for one are about
  /// roots. A text that is not XML is left to urdfdom's message.
  void check_tree(std::string_view xml) const {
    TiXmlDocument doc;
    doc.Parse(std::string(xml).c_str());
    const TiXmlElement* robot = doc.Error() ? nullptr : doc.FirstChildElement("robot");
    if (robot == nullptr) return;
    std::map<std::string, bool> links;
    for (const TiXmlElement* l = robot->FirstChildElement("link"); l != nullptr;
         l = l->NextSiblingElement("link")) {
      if (const char* name = l->Attribute("name")) links[name] = true;
    }
    struct Up {
      std::string parent, joint;
    };
    std::map<std::string, Up> up;  // child link -> its parent link and joint
    for (const TiXmlElement* j = robot->FirstChildElement("joint"); j != nullptr;
         j = j->NextSiblingElement("joint")) {
      const char* name = j->Attribute("name");
      const TiXmlElement* p = j->FirstChildElement("parent");
      const TiXmlElement* c = j->FirstChildElement("child");
      const char* parent = p != nullptr ? p->Attribute("link") : nullptr;
      const char* child = c != nullptr ? c->Attribute("link") : nullptr;
      if (name == nullptr || parent == nullptr || child == nullptr) continue;  // urdfdom says
      for (const char* l : {parent, child}) {
        if (!links.contains(l)) {
          fail(
              fmt::format("joint '{}' names link '{}', which the file does not declare (a "
                          "<link name=\"{}\"/> is missing, or the name is misspelt)",
                          name, l, l));
        }
      }
      if (const auto it = up.find(child); it != up.end()) {
        fail(fmt::format("link '{}' has two parent joints, '{}' and '{}': a URDF is a tree", child,
                         it->second.joint, name));
      }
      up[child] = {parent, name};
    }
    for (const auto& [start, first] : up) {
      std::vector<std::string> path{start};
      for (auto it = up.find(start); it != up.end(); it = up.find(it->second.parent)) {
        path.push_back(it->second.parent);
        if (it->second.parent == start) {
          fail(fmt::format("the joints make a cycle: {} (a URDF is a tree)",
                           fmt::join(path.rbegin(), path.rend(), " -> ")));
        }
        if (path.size() > up.size() + 1) break;  // a cycle above start: found from its links
      }
    }
  }

  urdf::ModelInterfaceSharedPtr parse(std::string_view xml) const {
    CapturedLog log;
    urdf::ModelInterfaceSharedPtr model;
    {
      const std::lock_guard lock(console_mutex());
      console_bridge::useOutputHandler(&log);
      try {
        model = urdf::parseURDF(std::string(xml));
      } catch (const std::exception& e) {
        log.lines.push_back(e.what());
      }
      console_bridge::restorePreviousOutputHandler();
    }
    if (model == nullptr) {
      // urdfdom says what it found first and then that the element failed: all of it.
      std::string why =
          log.lines.empty() ? "not a URDF robot" : fmt::format("{}", fmt::join(log.lines, "; "));
      // urdfdom's own words for a cycle or a second root are about trees: say what to fix.
      if (why.find("root") != std::string::npos) {
        why +=
            " (a URDF is a tree: every link but one has exactly one parent joint, and no "
            "chain of joints comes back to a link above it)";
      }
      fail(fmt::format("not a usable URDF: {}", why));
    }
    return model;
  }

  /// The links from the base down to the tip (base first), and the base.
  std::pair<std::vector<urdf::LinkConstSharedPtr>, urdf::LinkConstSharedPtr> chain_links(
      const urdf::ModelInterface& model) const {
    urdf::LinkConstSharedPtr base = model.getRoot();
    if (!options_.base_link.empty()) {
      base = model.getLink(options_.base_link);
      if (base == nullptr) fail(fmt::format("no link named '{}' for the base", options_.base_link));
    }
    urdf::LinkConstSharedPtr tip;
    if (!options_.tip_link.empty()) {
      tip = model.getLink(options_.tip_link);
      if (tip == nullptr) fail(fmt::format("no link named '{}' for the tip", options_.tip_link));
    } else {
      std::vector<std::string> leaves;
      std::vector<urdf::LinkConstSharedPtr> stack{base};
      while (!stack.empty()) {
        const urdf::LinkConstSharedPtr l = stack.back();
        stack.pop_back();
        if (l->child_links.empty()) {
          leaves.push_back(l->name);
          tip = l;
        }
        for (const auto& c : l->child_links) stack.push_back(c);
      }
      if (leaves.size() > 1) {
        std::sort(leaves.begin(), leaves.end());
        fail(fmt::format("the tree branches below '{}': name the tip link (--tip): one of {}",
                         base->name, fmt::join(leaves, ", ")));
      }
    }
    std::vector<urdf::LinkConstSharedPtr> chain{tip};
    while (chain.back() != base) {
      const urdf::LinkConstSharedPtr parent = chain.back()->getParent();
      if (parent == nullptr) {
        fail(fmt::format("link '{}' is not below link '{}': no chain joins them", tip->name,
                         base->name));
      }
      chain.push_back(parent);
    }
    std::reverse(chain.begin(), chain.end());
    return {chain, base};
  }

  void check_transform(const math::Transform& T, const std::string& what) const {
    if (!finite(T)) fail(fmt::format("{}: a number that is not finite", what));
    if (T.p.norm() > kMaxOffset_m) {
      fail(
          fmt::format("{}: an offset of {:.4g} m (more than {} m: a typo, or millimetres "
                      "where URDF has metres?)",
                      what, T.p.norm(), kMaxOffset_m));
    }
  }

  /// The link's mass, centre of mass and inertia, placed by `where` into the moving link's
  /// frame.
  void add_inertial(const urdf::Link& link, const math::Transform& where, double& mass,
                    math::Vec3& moment, SecondMoment& second) const {
    if (link.inertial == nullptr) return;
    const double m = link.inertial->mass;
    if (!std::isfinite(m) || m < 0.0 || m > kMaxMass_kg) {
      fail(fmt::format("link '{}': mass {} (give 0 to {} kg)", link.name, m, kMaxMass_kg));
    }
    const math::Transform com = to_transform(link.inertial->origin);
    check_transform(com, fmt::format("link '{}''s inertial origin", link.name));
    mass += m;
    moment += (where * com.p) * m;
    add_second_moment(second, m, inertia_tensor(link), where * com);
  }

  /// The link's <inertia> as a matrix (about its centre of mass, in the inertial frame).
  Eigen::Matrix3d inertia_tensor(const urdf::Link& link) const {
    const urdf::Inertial& i = *link.inertial;
    Eigen::Matrix3d I;
    I << i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz;
    if (!I.allFinite() || I.cwiseAbs().maxCoeff() > kMaxInertia_kg_m2) {
      fail(fmt::format("link '{}': an inertia element that is not finite or over {} kg m^2",
                       link.name, kMaxInertia_kg_m2));
    }
    return I;
  }

  /// The link's <collision> primitives as capsules enclosing them, placed by `where` into the
  /// frame `frame` (0 the base, i link i); a mesh only names its link (CollisionModel).
  void add_collision(const urdf::Link& link, const math::Transform& where, std::size_t frame,
                     CollisionModel& out) const {
    for (const urdf::CollisionSharedPtr& c : link.collision_array) {
      if (c == nullptr || c->geometry == nullptr) continue;
      const std::string what = fmt::format("link '{}''s <collision>", link.name);
      const math::Transform at = where * to_transform(c->origin);
      check_transform(at, what + " origin");
      const auto size = [&](double v, const char* name) {
        if (!std::isfinite(v) || v < 0.0 || v > kMaxOffset_m) {
          fail(fmt::format("{}: {} {} (give 0 to {} m)", what, name, v, kMaxOffset_m));
        }
        return v;
      };
      LinkCapsule capsule;
      switch (c->geometry->type) {
        case urdf::Geometry::SPHERE:
          capsule = enclose_sphere(
              at, size(static_cast<const urdf::Sphere&>(*c->geometry).radius, "radius"));
          break;
        case urdf::Geometry::CYLINDER: {
          const auto& g = static_cast<const urdf::Cylinder&>(*c->geometry);
          capsule = enclose_cylinder(at, size(g.radius, "radius"), size(g.length, "length"));
          break;
        }
        case urdf::Geometry::BOX: {
          const auto& d = static_cast<const urdf::Box&>(*c->geometry).dim;
          capsule =
              enclose_box(at, {size(d.x, "size x"), size(d.y, "size y"), size(d.z, "size z")});
          break;
        }
        default:  // a mesh: rccx reads no mesh files
          if (std::find(out.mesh_links.begin(), out.mesh_links.end(), link.name) ==
              out.mesh_links.end()) {
            out.mesh_links.push_back(link.name);
          }
          continue;
      }
      capsule.frame = frame;
      capsule.link = link.name;
      out.capsules.push_back(std::move(capsule));
    }
  }

  RobotModel build(const urdf::ModelInterface& model,
                   const std::vector<urdf::LinkConstSharedPtr>& chain,
                   const urdf::LinkConstSharedPtr& base) const {
    RobotModel out;
    out.name = model.getName();
    out.title = fmt::format("from {}", origin_);
    out.source = fmt::format("URDF {}, links {} to {}", origin_, base->name, chain.back()->name);
    out.geometry = Geometry::chain;
    out.solver = SolverKind::dh;  // the numeric solver, for any chain
    // From the frame of the current moving link (or the base) to the link being read.
    math::Transform pending;
    double mass = 0.0;
    math::Vec3 moment;
    SecondMoment second;
    add_collision(*base, pending, 0, out.collision);
    // `own`: the link's frame in the frame its bodies were gathered in (the last link's is the
    // flange's).
    const auto close_link = [&](Joint* j, const math::Transform& own) {
      if (j == nullptr) return;  // the base's own mass moves with nothing
      j->dynamics.link_mass_kg = mass;
      const math::Vec3 gathered = mass > 0.0 ? moment / mass : math::Vec3{};
      const math::Vec3 com = mass > 0.0 ? own.inverse() * gathered : math::Vec3{};
      j->dynamics.link_com_m = {com.x, com.y, com.z};
      j->dynamics.link_inertia_kg_m2 = inertia_about_com(second, mass, gathered, own.R);
    };
    for (std::size_t k = 1; k < chain.size(); ++k) {
      const urdf::Link& link = *chain[k];
      const urdf::Joint& uj = *link.parent_joint;
      const std::string what = fmt::format("joint '{}'", uj.name);
      const math::Transform origin = to_transform(uj.parent_to_joint_origin_transform);
      check_transform(origin, what + "'s origin");
      if (uj.mimic != nullptr) {
        fail(
            fmt::format("{} mimics joint '{}': mimic joints are not read (the chain's joints "
                        "move independently); make it fixed or revolute",
                        what, uj.mimic->joint_name));
      }
      if (uj.type == urdf::Joint::FIXED) {
        pending = pending * origin;
        add_inertial(link, pending, mass, moment, second);
        add_collision(link, pending, out.joints.size(), out.collision);
        continue;
      }
      if (uj.type != urdf::Joint::REVOLUTE && uj.type != urdf::Joint::CONTINUOUS &&
          uj.type != urdf::Joint::PRISMATIC) {
        const char* kind = uj.type == urdf::Joint::FLOATING ? "floating"
                           : uj.type == urdf::Joint::PLANAR ? "planar"
                                                            : "of an unknown type";
        fail(
            fmt::format("{} is {}: rccx reads serial arms of revolute, continuous, prismatic "
                        "and fixed joints",
                        what, kind));
      }
      if (out.joints.size() == kMaxJoints) {
        fail(fmt::format("more than {} moving joints between '{}' and '{}'", kMaxJoints, base->name,
                         chain.back()->name));
      }
      close_link(out.joints.empty() ? nullptr : &out.joints.back(), math::Transform{});
      Joint j;
      j.name = uj.name;
      j.type = uj.type == urdf::Joint::PRISMATIC ? JointType::prismatic : JointType::revolute;
      j.chain.origin = pending * origin;
      const math::Vec3 axis{uj.axis.x, uj.axis.y, uj.axis.z};
      if (!std::isfinite(axis.norm()) || axis.norm() < 1e-9) {
        fail(fmt::format("{}: axis ({} {} {}) is not a direction", what, axis.x, axis.y, axis.z));
      }
      j.chain.axis = axis.normalized();
      j.continuous = uj.type == urdf::Joint::CONTINUOUS;
      if (j.continuous) {
        j.lower = -std::numeric_limits<double>::infinity();
        j.upper = std::numeric_limits<double>::infinity();
      } else {
        if (uj.limits == nullptr) fail(fmt::format("{} has no <limit>", what));
        j.lower = uj.limits->lower;
        j.upper = uj.limits->upper;
        if (!std::isfinite(j.lower) || !std::isfinite(j.upper) || j.lower > j.upper ||
            std::abs(j.lower) > kMaxLimit || std::abs(j.upper) > kMaxLimit) {
          fail(
              fmt::format("{}: limits lower {} upper {} (finite, lower <= upper, within {} "
                          "rad or m)",
                          what, j.lower, j.upper, kMaxLimit));
        }
      }
      if (uj.limits != nullptr) {
        const double v = uj.limits->velocity, e = uj.limits->effort;
        if (!std::isfinite(v) || !std::isfinite(e) || v < 0.0 || e < 0.0) {
          fail(fmt::format("{}: velocity {} and effort {} must be finite and >= 0", what, v, e));
        }
        j.max_velocity = v;
        j.dynamics.max_effort = e;
      }
      // URDF has no encoders: a 20-bit one per turn, or 1 um, until a robot file says better.
      j.resolution_per_count =
          j.type == JointType::revolute ? 2.0 * std::numbers::pi / (1 << 20) : 1e-6;
      // URDF has no ready pose: the middle of each joint's range (0 for a continuous joint),
      // away from the limits, and a numeric solver's first seed.
      j.ready = j.continuous ? 0.0 : 0.5 * (j.lower + j.upper);
      out.joints.push_back(std::move(j));
      pending = math::Transform{};
      mass = 0.0;
      moment = {};
      second = {};
      add_inertial(link, pending, mass, moment, second);
      add_collision(link, pending, out.joints.size(), out.collision);
    }
    if (out.joints.empty()) {
      fail(fmt::format("no moving joint between '{}' and '{}'", base->name, chain.back()->name));
    }
    // The fixed joints out to the tip: the flange, in the last joint's `after`. The last link's
    // mass was gathered in its own frame; T6 is the flange's.
    Joint& last = out.joints.back();
    last.chain.after = pending;
    close_link(&last, pending);
    place_collision_in_t6(out);
    return out;
  }

  /// The last link's capsules were gathered in its own frame; T6 is the flange's (`after`).
  /// Then capsules inside others go (a URDF capsule is a cylinder and two spheres).
  static void place_collision_in_t6(RobotModel& model) {
    const math::Transform to_t6 = model.joints.back().chain.after.inverse();
    for (LinkCapsule& c : model.collision.capsules) {
      if (c.frame != model.dof()) continue;
      c.from_m = to_t6 * c.from_m;
      c.to_m = to_t6 * c.to_m;
    }
    drop_enclosed(model.collision.capsules);
  }

  std::string origin_;
  UrdfOptions options_;
};

}  // namespace

RobotModel parse_urdf(std::string_view xml, std::string_view origin, const UrdfOptions& options) {
  return Reader(origin, options).read(xml);
}

RobotModel load_urdf(const std::filesystem::path& path, const UrdfOptions& options) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) {
    throw RobotFileError(fmt::format("{}: cannot read: {}", path.string(), ec.message()));
  }
  if (size > kMaxUrdfBytes) {
    throw RobotFileError(fmt::format("{}: {} bytes, more than the {} MB a URDF may have here",
                                     path.string(), size, kMaxUrdfBytes >> 20));
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw RobotFileError(fmt::format("{}: cannot read", path.string()));
  return parse_urdf(text.str(), path.string(), options);
}

bool is_urdf_path(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".urdf";
}

}  // namespace rccx::kin
