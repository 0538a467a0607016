// The constant description of a robot arm: its joints in standard Denavit-Hartenberg form
// (thesis section 3.4), their limits and encoder resolution, and which solver serves it. It is
// read once from a data file under robots/ and never changes while a program runs; everything
// computed from it per call lives in the solvers (the Model / Data split of Pinocchio).
//
//   const kin::RobotModel puma = kin::builtin_robot("puma560");   // robots/, compiled in
//   const kin::RobotModel mine = kin::load_robot_file("arm.json");   // throws RobotFileError
//   puma.dof();                                      // 6
//   puma.joints[1].upper;                            // 225 deg, in rad (m for prismatic)
//   puma.within_limits(puma.ready());                // true
#pragma once

#include <array>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::kin {

enum class JointType : std::uint8_t { revolute, prismatic };

/// Standard DH parameters of one link (thesis eq. 3.3/3.4). The joint variable q is added to
/// theta_rad for a revolute joint and to d_m for a prismatic one.
struct DhParameters {
  double a_m = 0.0;
  double alpha_rad = 0.0;
  double d_m = 0.0;
  double theta_rad = 0.0;
};

/// What a simulator needs to move a joint like the real one (all optional in a robot file:
/// zeros mean "not given", and only the simulated PUMA's plant requires them).
struct JointDynamics {
  double inertia = 0.0;           ///< effective inertia at the joint, motor reflected: kg m^2 or kg
  double viscous_friction = 0.0;  ///< N m s/rad or N s/m
  double coulomb_friction = 0.0;  ///< N m or N
  double max_effort = 0.0;        ///< motor torque (N m) or force (N) limit at the joint
  double link_mass_kg = 0.0;      ///< mass of the link this joint moves
  std::array<double, 3> link_com_m{};  ///< that link's centre of mass in its own frame, m
  /// That link's inertia tensor about its centre of mass, in the axes of its own frame, kg m^2:
  /// ixx, iyy, izz, ixy, ixz, iyz, the tensor's elements as URDF, KDL and MuJoCo take them
  /// (ixy = -integral of x y dm).
  /// All zero: not given (the MuJoCo plant then takes a small sphere). "Its own frame" is DH
  /// frame i for a DH model, link frame i (kin::link_frames) for a chain: for the last joint
  /// of a URDF that is the flange's, where the fixed links out to it are lumped.
  std::array<double, 6> link_inertia_kg_m2{};
};

/// A joint of a general serial chain, as a URDF gives it: the frame of link i is
/// (link i-1) * origin * Motion(axis, q) * after, where Motion rotates about the unit `axis`
/// (revolute, rad) or moves along it (prismatic, m). `after` is the identity but on the last
/// joint, where it carries the fixed joints out to the tip (the flange). Used instead of `dh`
/// when RobotModel::geometry is Geometry::chain.
struct ChainStep {
  math::Transform origin;
  math::Vec3 axis{0, 0, 1};
  math::Transform after;
};

struct Joint {
  std::string name;
  JointType type = JointType::revolute;
  DhParameters dh;
  ChainStep chain;  ///< Geometry::chain only
  /// A URDF continuous joint: revolute with no limits (lower / upper are -inf / +inf). The
  /// generator interpolates it as any revolute joint, and the solvers keep it within a turn of
  /// the pose they are asked to stay near.
  bool continuous = false;
  double lower = 0.0;                 ///< lower limit, rad or m
  double upper = 0.0;                 ///< upper limit, rad or m
  double resolution_per_count = 0.0;  ///< encoder resolution, rad or m per count
  double ready = 0.0;                 ///< value in the robot's ready (nominal) pose, rad or m
  double max_velocity = 0.0;          ///< fastest commanded or observed speed, rad/s or m/s
  JointDynamics dynamics;
};

/// A capsule fixed in one of the robot's frames, m: the points within radius_m of the segment
/// from_m .. to_m. A robot's own collision model (RobotModel::collision), read from a URDF's
/// <collision> geometry, each primitive enclosed by one (collision_geometry.hpp).
struct LinkCapsule {
  std::size_t frame = 0;  ///< 0: the base frame; i: link i's frame (dof: T6, the flange)
  math::Vec3 from_m;
  math::Vec3 to_m;
  double radius_m = 0.0;
  std::string link;  ///< the URDF link whose geometry it encloses
};

/// Capsules a robot's own collision model may have for the cell's check (cell::RobotCapsules).
inline constexpr std::size_t kMaxCollisionCapsules = 32;

/// The robot's own collision model. Empty for a DH robot file: the cell's "link_radius_m"
/// capsules stand for its links then.
struct CollisionModel {
  std::vector<LinkCapsule> capsules;
  /// Links whose <collision> is a mesh, which rccx does not enclose: a cell asks for
  /// "link_radius_m" for such a robot rather than take the primitives alone.
  std::vector<std::string> mesh_links;
  [[nodiscard]] bool empty() const noexcept { return capsules.empty() && mesh_links.empty(); }
};

/// Which solver a model asks for: the thesis's closed form for the Microbo, the PUMA closed
/// form, or the numeric solver that serves any DH chain.
enum class SolverKind : std::uint8_t { microbo, puma, dh };

/// Which simulated plant serves the robot below the wire (rccx::hw::make_simulated_arm): the
/// file's optional "plant". automatic: the Microbo's RCU when the file has one, else the
/// simulated PUMA when every joint has dynamics, else the ideal servo.
enum class Plant : std::uint8_t { automatic, ideal, servo, mujoco };

/// How a model gives its links: a standard DH table (thesis 3.4, robots/*.json) or a general
/// chain of origins and axes (a URDF, kin::load_urdf).
enum class Geometry : std::uint8_t { dh, chain };

struct RobotModel {
  std::string name;    ///< short id used on the command line ("microbo", "puma560")
  std::string title;   ///< human name
  std::string source;  ///< where the numbers come from
  SolverKind solver = SolverKind::dh;
  Geometry geometry = Geometry::dh;
  std::vector<Joint> joints;
  /// The file's "hardware" object as JSON text (empty when none): what a simulator of this
  /// robot's controller needs (the Microbo's RCU), parsed and checked by rccx::hw.
  std::string hardware_json;
  Plant plant = Plant::automatic;
  /// Capsules enclosing the links' <collision> geometry (a URDF's); empty for DH robot files.
  CollisionModel collision;

  [[nodiscard]] std::size_t dof() const noexcept { return joints.size(); }
  [[nodiscard]] JointVector ready() const noexcept;
  [[nodiscard]] JointVector lower() const noexcept;
  [[nodiscard]] JointVector upper() const noexcept;
  /// True when every joint is within its limits, widened by tolerance (rad or m).
  [[nodiscard]] bool within_limits(const JointVector& q, double tolerance = 0.0) const noexcept;
  /// The index of the first joint outside its limits, or -1.
  [[nodiscard]] int first_joint_outside_limits(const JointVector& q,
                                               double tolerance = 0.0) const noexcept;
};

/// A robot file that cannot be used; the message names the file, the joint and the key.
class RobotFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Parses a robot description (JSON with // comments allowed; see robots/README.md).
/// `origin` names the text in error messages; a URDF the text names ("urdf") is read relative
/// to origin's folder (the working directory when origin has none).
RobotModel parse_robot(std::string_view json_text, std::string_view origin);
/// Reads and parses a robot file (a URDF it names relative to the file's folder).
RobotModel load_robot_file(const std::filesystem::path& path);

/// The robots shipped in robots/ (its *.json; the URDFs they name are compiled in with them),
/// compiled into the library.
std::vector<std::string> builtin_robot_names();
/// A shipped robot by name; throws RobotFileError listing the known names when there is none.
RobotModel builtin_robot(std::string_view name);

std::string_view to_string(JointType type) noexcept;
std::string_view to_string(SolverKind kind) noexcept;
std::string_view to_string(Plant plant) noexcept;
std::string_view to_string(Geometry geometry) noexcept;

}  // namespace rccx::kin
