#include "rccx/hw/mujoco_arm.hpp"

#include <fmt/format.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>

namespace rccx::hw {

namespace {

/// MuJoCo 2.2's XML loader keeps global state (the last model, for mj_saveLastXML).
std::mutex g_load_mutex;

mjModel* load_from_memory(const std::string& xml, const std::string& robot) {
  // mjVFS is 2 MB of fixed arrays: on the heap, and only while loading.
  const auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* file = "rccx_robot.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), file, static_cast<int>(xml.size())) != 0) {
    throw std::invalid_argument(fmt::format("{}: MuJoCo's VFS refused the model", robot));
  }
  const int index = mj_findFileVFS(vfs.get(), file);
  std::memcpy(vfs->filedata[index], xml.data(), xml.size());
  char error[1000] = "";
  mjModel* m = nullptr;
  {
    const std::lock_guard lock(g_load_mutex);
    m = mj_loadXML(file, vfs.get(), error, sizeof error);
  }
  mj_deleteVFS(vfs.get());
  if (m == nullptr) {
    throw std::invalid_argument(fmt::format("{}: MuJoCo refused the model: {}", robot, error));
  }
  return m;
}

math::Transform from_mujoco(const mjtNum* pos, const mjtNum* mat) {
  // MuJoCo's 3x3 matrices are row-major.
  return math::Transform::from_rows({mat[0], mat[1], mat[2], pos[0], mat[3], mat[4], mat[5], pos[1],
                                     mat[6], mat[7], mat[8], pos[2]});
}

}  // namespace

MujocoArm::MujocoArm(kin::RobotModel model, const SimulatedArmOptions& options)
    : ArmBase(std::move(model), options),
      scene_(options.scene ? *options.scene : scene_from_file(this->model())) {
  const kin::RobotModel& rm = this->model();
  mjcf_ = make_mjcf(rm, scene_);
  plants_ = joint_plants(rm);
  m_ = load_from_memory(mjcf_, rm.name);
  d_ = mj_makeData(m_);
  if (d_ == nullptr) {
    mj_deleteModel(m_);
    throw std::invalid_argument(fmt::format("{}: MuJoCo could not allocate its data", rm.name));
  }
  try {
    for (std::size_t i = 0; i < n_; ++i) {
      const int j = id_of(mjOBJ_JOINT, fmt::format("j{}", i + 1));
      qpos_[i] = m_->jnt_qposadr[j];
      dof_[i] = m_->jnt_dofadr[j];
      actuator_[i] = id_of(mjOBJ_ACTUATOR, fmt::format("m{}", i + 1));
      arm_bodies_.push_back(id_of(mjOBJ_BODY, fmt::format("link{}", i + 1)));
    }
    assume_link_inertia();
    for (std::size_t i = 0; i < n_; ++i) {
      const JointPlant& p = plants_[i];
      gains_[i] = servo_gains(p.servo_inertia, p.bandwidth);
    }
    arm_bodies_.push_back(id_of(mjOBJ_BODY, "tool"));
    force_adr_ = m_->sensor_adr[id_of(mjOBJ_SENSOR, "ft_force")];
    torque_adr_ = m_->sensor_adr[id_of(mjOBJ_SENSOR, "ft_torque")];
  } catch (...) {
    mj_deleteData(d_);
    mj_deleteModel(m_);
    throw;
  }
  jacp_.assign(3 * static_cast<std::size_t>(m_->nv), 0.0);
  jacr_.assign(3 * static_cast<std::size_t>(m_->nv), 0.0);
  // Sensors and poses valid before the first tick, with the motors holding against gravity
  // (at rest, a hanging tool then reads its weight at once).
  write_state();
  mj_forward(m_, d_);
  if (options.powered) {
    std::array<double, kin::kMaxJoints> hold{};
    compute_gravity_load(hold);
    for (std::size_t i = 0; i < n_; ++i) d_->ctrl[actuator_[i]] = hold[i];
    mj_forward(m_, d_);
  }
  filtered_wrench_ = raw_wrist_wrench();  // the sensor's filter starts settled
}

MujocoArm::~MujocoArm() {
  mj_deleteData(d_);
  mj_deleteModel(m_);
}

int MujocoArm::id_of(int type, std::string_view name) const {
  const std::string s(name);
  const int id = mj_name2id(m_, type, s.c_str());
  if (id < 0) {
    throw std::invalid_argument(
        fmt::format("{}: the MuJoCo model has no {} \"{}\"", model().name,
                    type == mjOBJ_BODY ? "body" : (type == mjOBJ_SITE ? "site" : "element"), s));
  }
  return id;
}

void MujocoArm::assume_link_inertia() {
  // A URDF gives its links' inertias but no motor's: where the robot file gives no effective
  // inertia, the servo assumes the armature (the default motor) plus the links' inertia about
  // the joint at the ready pose, as robots/puma560.json's inertias are made. With the armature
  // alone an outstretched, loaded arm can be nine times heavier than the gains assume: at that
  // ratio the three-pole servo stops damping (Routh: 3w x 3w^2 > r w^3 needs r < 9).
  const kin::RobotModel& rm = model();
  if (rm.geometry != kin::Geometry::chain) return;
  const kin::JointVector ready = rm.ready();
  for (std::size_t i = 0; i < n_; ++i) d_->qpos[qpos_[i]] = ready[i];
  mj_forward(m_, d_);
  for (std::size_t i = 0; i < n_; ++i) {
    if (rm.joints[i].dynamics.inertia > 0) continue;
    const int dof = dof_[i];
    plants_[i].servo_inertia = d_->qM[m_->dof_Madr[dof]];  // armature + the links' M_ii
  }
}

void MujocoArm::write_state() noexcept {
  for (std::size_t i = 0; i < n_; ++i) {
    d_->qpos[qpos_[i]] = joints_[i].q;
    d_->qvel[dof_[i]] = joints_[i].qd;
  }
}

void MujocoArm::compute_gravity_load(std::array<double, kin::kMaxJoints>& out) const noexcept {
  // The motors hold -J^T (m g) summed over the arm's bodies (and the tool's), at their centres
  // of mass; Coriolis and centrifugal terms are left to the feedback.
  out.fill(0.0);
  const std::size_t nv = static_cast<std::size_t>(m_->nv);
  for (const int b : arm_bodies_) {
    const double mass = m_->body_mass[b];
    if (mass == 0.0) continue;
    mj_jacBodyCom(m_, d_, jacp_.data(), jacr_.data(), b);
    for (std::size_t i = 0; i < n_; ++i) {
      const auto k = static_cast<std::size_t>(dof_[i]);
      double f = 0.0;
      for (std::size_t c = 0; c < 3; ++c) f += jacp_[c * nv + k] * m_->opt.gravity[c];
      out[i] -= mass * f;
    }
  }
}

kin::JointVector MujocoArm::gravity_load() const noexcept {
  std::array<double, kin::kMaxJoints> g{};
  compute_gravity_load(g);
  kin::JointVector out(n_);
  for (std::size_t i = 0; i < n_; ++i) out[i] = g[i];
  return out;
}

kin::JointVector MujocoArm::motor_effort() const noexcept {
  kin::JointVector tau(n_);
  for (std::size_t i = 0; i < n_; ++i) tau[i] = tau_[i];
  return tau;
}

void MujocoArm::servo_tick(double dt) noexcept {
  write_state();     // the joint state is the truth between ticks
  mj_step1(m_, d_);  // positions and velocities: kinematics, Jacobians, bias forces
  std::array<double, kin::kMaxJoints> hold{};
  compute_gravity_load(hold);
  for (std::size_t i = 0; i < n_; ++i) {
    const JointPlant& p = plants_[i];
    tau_[i] = servo_effort(joints_[i], gains_[i], p.servo_inertia, p.viscous, p.max_effort, hold[i],
                           dt, integral_[i]);
    d_->ctrl[actuator_[i]] = tau_[i];
    d_->qfrc_applied[dof_[i]] = joints_[i].external;
  }
  mj_step2(m_, d_);
  for (int k = 1; k < scene_.substeps; ++k) mj_step(m_, d_);
  for (std::size_t i = 0; i < n_; ++i) {
    JointState& s = joints_[i];
    s.q = d_->qpos[qpos_[i]];
    s.qd = d_->qvel[dof_[i]];
    clamp_to_stops(s);
  }
  write_state();
  // The sensor's own low-pass filter (a first-order one, as strain-gauge electronics filter
  // before sampling): contact forces in MuJoCo come as impulses within single steps.
  const math::Wrench raw = raw_wrist_wrench();
  const double a = dt / (kSensorFilter_s + dt);
  filtered_wrench_ = filtered_wrench_ + (raw - filtered_wrench_) * a;
}

math::Wrench MujocoArm::raw_wrist_wrench() const noexcept {
  const mjtNum* f = d_->sensordata + force_adr_;
  const mjtNum* t = d_->sensordata + torque_adr_;
  return {{-f[0], -f[1], -f[2]}, {-t[0], -t[1], -t[2]}};
}

bool MujocoArm::wrist_wrench(math::Wrench& w) const noexcept {
  w = filtered_wrench_;
  return true;
}

math::Transform MujocoArm::site_pose(std::string_view name) const {
  const int id = id_of(mjOBJ_SITE, name);
  mj_kinematics(m_, d_);  // the step left the poses of its start; these are of its end
  return from_mujoco(d_->site_xpos + 3 * id, d_->site_xmat + 9 * id);
}

math::Transform MujocoArm::body_pose(std::string_view name) const {
  const int id = id_of(mjOBJ_BODY, name);
  mj_kinematics(m_, d_);
  return from_mujoco(d_->xpos + 3 * id, d_->xmat + 9 * id);
}

void MujocoArm::set_body_pose(std::string_view name, const math::Transform& pose) {
  const int id = id_of(mjOBJ_BODY, name);
  const int joint = m_->body_jntadr[id];
  if (m_->body_jntnum[id] != 1 || m_->jnt_type[joint] != mjJNT_FREE) {
    throw std::invalid_argument(
        fmt::format("{}: body \"{}\" is not a free box", model().name, std::string(name)));
  }
  mjtNum* q = d_->qpos + m_->jnt_qposadr[joint];
  const auto rows = pose.rows();
  const mjtNum mat[9] = {rows[0], rows[1], rows[2], rows[4], rows[5],
                         rows[6], rows[8], rows[9], rows[10]};
  q[0] = pose.p.x;
  q[1] = pose.p.y;
  q[2] = pose.p.z;
  mju_mat2Quat(q + 3, mat);
  mju_zero(d_->qvel + m_->jnt_dofadr[joint], 6);
  mj_forward(m_, d_);
}

void MujocoArm::apply_body_force(std::string_view name, const math::Vec3& force_N,
                                 const math::Vec3& torque_N_m) {
  const int id = id_of(mjOBJ_BODY, name);
  mjtNum* x = d_->xfrc_applied + 6 * id;
  x[0] = force_N.x;
  x[1] = force_N.y;
  x[2] = force_N.z;
  x[3] = torque_N_m.x;
  x[4] = torque_N_m.y;
  x[5] = torque_N_m.z;
}

int MujocoArm::contact_count() const noexcept {
  return d_->ncon;
}

}  // namespace rccx::hw
