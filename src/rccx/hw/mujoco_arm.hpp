// An arm below the wire simulated by MuJoCo 2.2: the robot file's MJCF (mjcf.hpp) with the
// cell's boxes around it, stepped once a 1 ms servo tick (Scene::substeps times), the only
// simulated arm with contact and a wrist force/torque sensor.
//
// The servo, each tick, per joint (the law of SimulatedPuma, on MuJoCo's multibody plant):
//
//   tau = Kp e + Ki int(e) + Kd (v_sp - qd) + B v_sp + g(q)
//
// e = setpoint - q, v_sp the setpoint's velocity, B the joint's viscous friction and g(q) the
// gravity load of the arm and tool as MuJoCo models them (sum over the bodies of J_com^T m g,
// not Coriolis). Kp = 3 I w^2, Kd = 3 I w, Ki = I w^3 with I and w from joint_plants() (the
// file's dynamics, its RCU block, or defaults; for a URDF chain's joint without the file's
// inertia, I is the default armature plus the links' inertia about the joint at the ready pose,
// MuJoCo's M_ii there: JointPlant::servo_inertia); the integrator runs only while |Kp e| is below
// max_effort and the output is not saturated; the output is limited to max_effort and, along
// the motion, on the motor's torque-speed line (zero at kOverspeedFactor x max_velocity). It
// drives the joint's motor actuator (d->ctrl); external effort (set_external_effort) goes to
// qfrc_applied. Zero gravity: tau = g(q) - kZeroGravityDamping_per_s x I qd.
//
// The joints carry the file's inertia as armature, its viscous friction as damping and its
// Coulomb friction as MuJoCo's friction loss; their ranges are the hard stops. ArmBase's joint
// state and MuJoCo's qpos / qvel are kept equal: the tick starts from the joint state (the
// brakes move it while power is off, and MuJoCo does not step then: the scene waits) and ends
// by copying MuJoCo's result back (then clamp_to_stops).
//
// servo_tick is noexcept and allocates nothing: mj_step1 / mj_step2 work in mjData's
// preallocated stack (the test counts MuJoCo's mallocs and C++'s operator new over ticks).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/hw/arm_base.hpp"
#include "rccx/hw/mjcf.hpp"
#include "rccx/math/wrench.hpp"

struct mjModel_;
struct mjData_;

namespace rccx::hw {

class MujocoArm final : public ArmBase {
 public:
  using Gains = ServoGains;

  /// Builds the MJCF of `model` in options.scene (an empty scene when null) and loads it from
  /// memory. Throws std::invalid_argument for an unusable model, scene or initial pose, or when
  /// MuJoCo refuses the model (its message).
  explicit MujocoArm(kin::RobotModel model, const SimulatedArmOptions& options = {});
  ~MujocoArm() override;

  /// The wrench the tool side exerts on the arm about T6's origin in T6's axes (N, N m): the
  /// sensor "ft" of the last step, sign-turned (MuJoCo's force sensor gives the force the
  /// parent body exerts on the tool body).
  [[nodiscard]] bool wrist_wrench(math::Wrench& w) const noexcept override;
  /// The sensor's electronics filter the load with this time constant before it is read, s
  /// (a 16 Hz first-order low-pass): MuJoCo's contact forces come as impulses within steps.
  static constexpr double kSensorFilter_s = 0.03;
  /// The load of the last step, unfiltered (N, N m; as wrist_wrench).
  [[nodiscard]] math::Wrench raw_wrist_wrench() const noexcept;

  [[nodiscard]] const std::string& mjcf() const noexcept { return mjcf_; }
  [[nodiscard]] const Scene& scene() const noexcept { return scene_; }
  [[nodiscard]] const Gains& gains(std::size_t joint) const noexcept { return gains_[joint]; }
  [[nodiscard]] const JointPlant& plant(std::size_t joint) const noexcept { return plants_[joint]; }
  /// The motor efforts of the last servo tick, N m or N.
  [[nodiscard]] kin::JointVector motor_effort() const noexcept;
  /// The gravity load g(q) at the present state (what the motors hold against), N m or N.
  [[nodiscard]] kin::JointVector gravity_load() const noexcept;

  /// MuJoCo's model and data (include <mujoco/mujoco.h> to use them). Change the data only
  /// between ticks.
  [[nodiscard]] const mjModel_* mj_model() const noexcept { return m_; }
  [[nodiscard]] mjData_* mj_data() noexcept { return d_; }
  [[nodiscard]] const mjData_* mj_data() const noexcept { return d_; }

  /// A site's or body's pose in the world now (at the joint state true_position() gives; not
  /// noexcept: it runs MuJoCo's kinematics, outside the servo tick). Throws
  /// std::invalid_argument for an unknown name.
  [[nodiscard]] math::Transform site_pose(std::string_view name) const;
  [[nodiscard]] math::Transform body_pose(std::string_view name) const;
  /// Puts a free box (mass > 0) at `pose` in the world, at rest. Throws std::invalid_argument
  /// for an unknown or fixed body.
  void set_body_pose(std::string_view name, const math::Transform& pose);
  /// A force (N) and torque (N m) in world axes on a body at its centre of mass, applied every
  /// step until changed (zeros remove it): a hand pushing an object. Throws for an unknown body.
  void apply_body_force(std::string_view name, const math::Vec3& force_N,
                        const math::Vec3& torque_N_m = {});
  /// How many contacts the last step found.
  [[nodiscard]] int contact_count() const noexcept;

 private:
  void servo_tick(double dt) noexcept override;
  void on_servo_restart(std::size_t j) noexcept override { integral_[j] = 0.0; }
  void compute_gravity_load(std::array<double, kin::kMaxJoints>& out) const noexcept;
  /// A URDF chain's servo inertia where the file gives none (see above).
  void assume_link_inertia();
  [[nodiscard]] int id_of(int type, std::string_view name) const;
  void write_state() noexcept;

  Scene scene_;
  std::string mjcf_;
  mjModel_* m_ = nullptr;
  mjData_* d_ = nullptr;
  std::array<JointPlant, kin::kMaxJoints> plants_{};
  std::array<Gains, kin::kMaxJoints> gains_{};
  std::array<int, kin::kMaxJoints> qpos_{}, dof_{}, actuator_{};
  std::vector<int> arm_bodies_;       ///< link1 .. link<n> and the tool
  mutable std::vector<double> jacp_;  ///< 3 x nv, for the gravity load
  mutable std::vector<double> jacr_;  ///< 3 x nv
  std::array<double, kin::kMaxJoints> integral_{};
  std::array<double, kin::kMaxJoints> tau_{};
  int force_adr_ = 0, torque_adr_ = 0;  ///< the sensors' places in sensordata
  math::Wrench filtered_wrench_;        ///< wrist_wrench: the filtered load
};

}  // namespace rccx::hw
