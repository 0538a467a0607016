// A robot file as a MuJoCo model (MJCF, the XML MuJoCo 2.2 loads): the arm's DH chain or URDF
// chain as a chain of bodies, one joint each (hinge or slide, the file's limits widened to the
// hard stops), masses and inertias where the file gives them, a motor per joint, a tool body beyond
// a six-axis force/torque sensor at T6, and the cell's table and objects as boxes. What MujocoArm
// (mujoco_arm.hpp) loads; a person may load the same text in MuJoCo's viewer.
//
//   auto scene = std::make_shared<hw::Scene>(hw::scene_from_file(model));   // may be empty
//   scene->boxes.push_back({"table", math::Transform::translation(0.5, 0, -0.22),
//                           {0.4, 0.4, 0.02}});            // m; mass 0: fixed to the world
//   const std::string xml = hw::make_mjcf(model, *scene);  // to look at it in MuJoCo
//   auto arm = hw::make_simulated_arm(model, {.plant = hw::Plant::mujoco, .scene = scene});
//
// Frames. Body "link<i>" (i = 1 .. dof) carries joint i: its frame is DH frame i-1 moved by the
// joint, Rot(z, q) or Trans(z, q), and the constant part of A_i, Rot(z, theta) Trans(z, d)
// Trans(x, a) Rot(x, alpha), is where link<i+1> (or the site "t6") sits in it (the joint's
// motion commutes with the first two factors). So link<i>'s DH frame i is link<i> x C_i, the
// file's centre of mass of link i is given there, and the site "t6" is T6 exactly (the FK test
// compares it with Kinematics::forward at 1e-9). A general chain (Geometry::chain, a URDF's):
// link<i> is link frame i-1 times joint i's origin, its joint about (along) the joint's axis;
// link<i+1> sits at `after` times the next origin, "t6" at the last joint's `after`, and the
// link's mass, centre of mass and tensor are given in link frame i. The robot's base is a body
// "base" placed at Scene::base_m in the world; gravity is along world -z.
//
// Inertia: each link's mass at its centre of mass, with its tensor (JointDynamics::
// link_inertia_kg_m2, turned into the body's axes, as principal axes and moments) when the file
// gives one, else a sphere of kLinkGyrationSphere_m; a link without mass weighs
// kDefaultLinkMass_kg.
//
// Contact: the arm's and the tool's geoms touch the scene's boxes and never each other; boxes
// touch each other. Stiff contact (solref 2 ms, critically damped; solimp 0.95 .. 0.99) and
// modest friction (each box's; the tool's and arm's 0.5).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::hw {

/// A box in the cell: a table (fixed) or an object on it (free, with mass).
struct SceneBox {
  std::string name;        ///< the body's and geom's name in the model (letters, digits, _)
  math::Transform pose_m;  ///< the box's centre and axes in the world
  math::Vec3 half_size_m;  ///< half its extent along its x, y, z
  double mass_kg = 0.0;    ///< 0: fixed to the world; > 0: a free body of uniform density
  double friction = 0.5;   ///< sliding friction coefficient
};

/// What surrounds the arm in MuJoCo.
struct Scene {
  std::vector<SceneBox> boxes;
  math::Transform base_m;     ///< the robot's base frame in the world (world z is up)
  double tool_mass_kg = 0.0;  ///< the tool beyond the sensor (0: none, only its geometry)
  math::Vec3 tool_com_m;      ///< its centre of mass in T6
  /// The tool: a capsule along T6's z from T6 to this length, whose round tip (radius
  /// tool_radius_m) can touch; 0: a sphere of that radius at T6.
  double tool_length_m = 0.0;
  double tool_radius_m = 0.01;
  /// The tool's sliding friction coefficient (MuJoCo takes the larger of the two in a contact).
  double tool_friction = 0.5;
  /// MuJoCo steps per 1 ms servo tick (the time step is 1 ms / substeps).
  int substeps = 1;
  /// How stiff contact is: MuJoCo's solref time constant, s (critically damped; at least two
  /// steps). 2 ms is steel on steel; force control through position servos sampled at 10 ms
  /// wants a tool with some give (a rubber tip, a compliance device): 20 ms, MuJoCo's default.
  double contact_time_constant_s = 0.002;
};

/// The physical data of one joint as the MuJoCo plant uses it: from the file's "dynamics" when
/// given, else from its RCU block ("hardware": the Microbo), else defaults (below).
struct JointPlant {
  double inertia = 0.0;     ///< effective inertia at the joint (the motor's), kg m^2 or kg
  double viscous = 0.0;     ///< N m s/rad or N s/m
  double coulomb = 0.0;     ///< N m or N
  double max_effort = 0.0;  ///< N m or N
  double bandwidth = 0.0;   ///< the servo's closed-loop poles, rad/s
  /// The inertia the servo's gains assume, kg m^2 or kg: `inertia` here; MujocoArm adds a URDF
  /// chain's link inertia about the joint at the ready pose where the file gives no inertia.
  double servo_inertia = 0.0;
};

/// Defaults for a joint the file says nothing about: a stiff servo, no friction.
inline constexpr double kDefaultInertia_kg_m2 = 1.0;
inline constexpr double kDefaultInertia_kg = 10.0;
inline constexpr double kDefaultMaxEffort_N_m = 200.0;
inline constexpr double kDefaultMaxEffort_N = 1000.0;
/// The servo bandwidth when the file gives none, rad/s: stiffer than SimulatedPuma's 40, so that
/// a locked axis stays within 0.1 mm while a compliant one yields (docs/FORCE.md, the servo).
inline constexpr double kDefaultServoBandwidth_rad_per_s = 50.0;
/// A link whose mass the file does not give weighs this much, kg.
inline constexpr double kDefaultLinkMass_kg = 1.0;
/// A link whose file gives no inertia tensor (a DH file without "link_inertia_kg_m2", a URDF
/// without <inertia>) is taken as a solid sphere of this radius about its centre of mass (the
/// joints' armature, the motors' inertia, dominates).
inline constexpr double kLinkGyrationSphere_m = 0.05;
/// The radius of the arm links' capsules, m.
inline constexpr double kLinkRadius_m = 0.03;

/// Every joint's plant data (model.dof() of them). Throws std::invalid_argument for a bad RCU
/// block.
std::array<JointPlant, kin::kMaxJoints> joint_plants(const kin::RobotModel& model);

/// The scene a robot file gives its MuJoCo plant, so that a program that only names a file (a C
/// program, `rccx` commands) can have a table and a tool. In the file's "hardware" block:
///
///   "mujoco": {
///     "base_m": [0, 0, 0], "base_rpy_deg": [0, 0, 0],      the base in the world
///     "tool": {"mass_kg": 0.4, "com_m": [0, 0, 0.05], "length_m": 0.1, "radius_m": 0.008,
///              "friction": 0.2},
///     "boxes": [{"name": "table", "center_m": [0.5, 0, -0.22], "rpy_deg": [0, 0, 0],
///                "half_size_m": [0.4, 0.4, 0.02], "mass_kg": 0, "friction": 0.5}],
///     "contact_time_constant_s": 0.02, "substeps": 1
///   }
///
/// Turns are Paul's roll, pitch, yaw in degrees, as in cell files: Rot(z, roll) Rot(y, pitch)
/// Rot(x, yaw). Every key is optional (Scene's defaults). An empty Scene when the file has no such
/// block. Throws std::invalid_argument naming the key for a bad value or an unknown key.
Scene scene_from_file(const kin::RobotModel& model);

/// The MJCF of `model` in `scene`. Names: bodies "base", "link1" .. "link<dof>", "tool", the
/// boxes' names; joints "j1" ...; motors "m1" ...; sites "t6" (T6) and "ft" (the sensor, at T6
/// on the tool body); sensors "ft_force" and "ft_torque". Throws std::invalid_argument for a
/// box without a usable name or size, substeps < 1, or a link inertia tensor no body has.
std::string make_mjcf(const kin::RobotModel& model, const Scene& scene = {});

}  // namespace rccx::hw
