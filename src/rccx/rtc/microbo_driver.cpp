#include "rccx/rtc/microbo_driver.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rccx::rtc {

namespace rcu = hw::rcu;

std::string_view to_string(BusError e) noexcept {
  switch (e) {
    case BusError::ok:
      return "ok";
    case BusError::timeout_cmd:
      return "TIMEOUT_CMD";
    case BusError::timeout_put:
      return "TIMEOUT_PUT";
    case BusError::timeout_get:
      return "TIMEOUT_GET";
    case BusError::invalid_joint_command:
      return "INVALID_JNT_CMD";
  }
  return "?";
}

MicroboDriver::MicroboDriver(const kin::RobotModel& model, hw::Bus& bus, hw::Relays& relays,
                             MicroboDriverOptions options)
    : model_(model), config_(hw::rcu_config(model)), bus_(bus), relays_(relays), options_(options) {
  if (config_.joints.size() != model_.dof()) {
    throw std::invalid_argument("the RCU block must describe every joint of the robot");
  }
  for (std::size_t j = 0; j < model_.dof(); ++j) {
    joints_[j].area = options_.work_areas[j];
    motor_parameters_[j] = config_.joints[j].motor_parameters;
  }
}

bool MicroboDriver::apply(const SettingChg& setting) noexcept {
  const std::size_t j = setting.joint;
  if (j >= model_.dof()) return false;
  const auto byte = static_cast<std::uint8_t>(std::min<std::uint16_t>(setting.value, 255));
  // Motor parameter numbers of Appendix B.3 (1-based) for the settings that live there.
  int parameter = 0;
  switch (setting.what) {
    case Setting::none:
      return false;
    case Setting::acceleration:
      return put_word(j, rcu::kSetAcceleration, setting.value) == BusError::ok;
    case Setting::speed_factor:
      return put_cmd(j, rcu::kWriteSpeedFactor) == BusError::ok && put_dat(j, byte) == BusError::ok;
    case Setting::examine:
      examine_ = static_cast<int>(j);
      return true;
    case Setting::dynamic_integral:
      parameter = 6;
      break;
    case Setting::static_integral:
      parameter = 7;
      break;
    case Setting::static_speed:
      parameter = 8;
      break;
    case Setting::static_zone:
      parameter = 4;
      break;
  }
  motor_parameters_[j][static_cast<std::size_t>(parameter - 1)] = byte;
  return send_motor_parameters(j, joints_[j].yielding) == BusError::ok;
}

BusError MicroboDriver::send_motor_parameters(std::size_t j, bool yielding) noexcept {
  std::array<std::uint8_t, 16> p = motor_parameters_[j];
  if (yielding) p[hw::motor::kDynamicIntegration] = p[hw::motor::kStaticIntegration] = 0;
  BusError e = put_cmd(j, rcu::kSetMotorParameters);
  for (std::size_t i = 0; i < p.size() && e == BusError::ok; ++i) e = put_dat(j, p[i]);
  return e;
}

// ---------------------------------------------------------------------------------------------
// Appendix B.4: every access after a status poll that finds the joint ready.

BusError MicroboDriver::put_cmd(std::size_t joint, std::uint8_t command) noexcept {
  if (joint >= model_.dof() || rcu::data_bytes(command) == -128) {
    return BusError::invalid_joint_command;
  }
  for (int i = 0; i < options_.polls; ++i) {
    if ((bus_.in(hw::rcu_command_register(joint)) & hw::kIbe) == 0) {
      bus_.out(hw::rcu_command_register(joint), command);
      return BusError::ok;
    }
  }
  return BusError::timeout_cmd;
}

BusError MicroboDriver::put_dat(std::size_t joint, std::uint8_t data) noexcept {
  if (joint >= model_.dof()) return BusError::invalid_joint_command;
  for (int i = 0; i < options_.polls; ++i) {
    if ((bus_.in(hw::rcu_command_register(joint)) & hw::kIbe) == 0) {
      bus_.out(hw::rcu_data_register(joint), data);
      return BusError::ok;
    }
  }
  return BusError::timeout_put;
}

BusError MicroboDriver::get_dat(std::size_t joint, std::uint8_t& data) noexcept {
  if (joint >= model_.dof()) return BusError::invalid_joint_command;
  for (int i = 0; i < options_.polls; ++i) {
    if ((bus_.in(hw::rcu_command_register(joint)) & hw::kObf) != 0) {
      data = bus_.in(hw::rcu_data_register(joint));
      return BusError::ok;
    }
  }
  return BusError::timeout_get;
}

BusError MicroboDriver::put_word(std::size_t joint, std::uint8_t command,
                                 std::uint16_t value) noexcept {
  BusError e = put_cmd(joint, command);
  if (e == BusError::ok) e = put_dat(joint, static_cast<std::uint8_t>(value & 0xff));
  if (e == BusError::ok) e = put_dat(joint, static_cast<std::uint8_t>(value >> 8));
  return e;
}

BusError MicroboDriver::get_word(std::size_t joint, std::uint8_t command,
                                 std::uint16_t& value) noexcept {
  std::uint8_t lo = 0, hi = 0;
  BusError e = put_cmd(joint, command);
  if (e == BusError::ok) e = get_dat(joint, lo);
  if (e == BusError::ok) e = get_dat(joint, hi);
  value = static_cast<std::uint16_t>(lo | (hi << 8));
  return e;
}

BusError MicroboDriver::get_byte(std::size_t joint, std::uint8_t command,
                                 std::uint8_t& value) noexcept {
  BusError e = put_cmd(joint, command);
  if (e == BusError::ok) e = get_dat(joint, value);
  return e;
}

// ---------------------------------------------------------------------------------------------
// Conversions

double MicroboDriver::counts_of(std::size_t joint, double q) const noexcept {
  const hw::RcuJointConfig& c = config_.joints[joint];
  return c.initialize_counts +
         (q - c.calibration_position) / model_.joints[joint].resolution_per_count;
}

double MicroboDriver::joint_value_of(std::size_t joint, double counts) const noexcept {
  const hw::RcuJointConfig& c = config_.joints[joint];
  return c.calibration_position +
         (counts - c.initialize_counts) * model_.joints[joint].resolution_per_count;
}

double MicroboDriver::velocity_limit(std::size_t joint, double period_s) const noexcept {
  const double top = model_.joints[joint].max_velocity;
  const hw::RcuJointConfig& c = config_.joints[joint];
  if (!c.work_areas || !(period_s > 0)) return top;
  // A sample must not carry the encoder through a transition zone undetected (thesis 4.4.3).
  const double zone = std::min<double>(c.lower_threshold, 65535 - c.upper_threshold);
  return std::min(top, zone * model_.joints[joint].resolution_per_count / period_s);
}

double MicroboDriver::minimum_period_s() const noexcept {
  double exchanges = 0;
  for (const hw::RcuJointConfig& c : config_.joints) exchanges += c.work_areas ? 24 : 22;
  return 1.1 * exchanges * config_.exchange_us * 1e-6;
}

std::string_view MicroboDriver::fault_detail(std::size_t joint) const noexcept {
  return joint < model_.dof() && joints_[joint].error != BusError::ok
             ? to_string(joints_[joint].error)
             : std::string_view{};
}

std::uint16_t MicroboDriver::speed_setting(std::size_t j, double counts_per_s) const noexcept {
  const double units =
      std::abs(counts_per_s) * 1e-3 / config_.joints[j].counts_per_ms_per_speed_unit;
  // Never 0: the vendor law loses its stiffness at small speed settings.
  return static_cast<std::uint16_t>(std::clamp(std::lround(units), 1L, 65535L));
}

// ---------------------------------------------------------------------------------------------
// The sample

void MicroboDriver::read(double t_s, How& how) noexcept {
  bus_.sync(t_s);
  if (last_read_s_ >= 0.0 && t_s > last_read_s_) period_s_ = t_s - last_read_s_;
  last_read_s_ = t_s;
  const std::size_t n = model_.dof();
  how.dof = static_cast<std::uint8_t>(n);
  JointVector q(n);
  bool all_calibrated = true;
  for (std::size_t j = 0; j < n; ++j) {
    all_calibrated = read_joint(j, how.joint[j]) && all_calibrated;
    q[j] = how.joint[j].q;  // as last read when the joint did not answer
  }
  const JointVector v = velocity_.update(t_s, q);
  for (std::size_t j = 0; j < n; ++j) how.joint[j].velocity = v[j];
  ++reads_;
  if (examine_ >= 0) read_motor_parameters();
  how.examined_joint = examined_;
  how.motor_parameters = examined_parameters_;
  how.all_calibrated = all_calibrated;
  how.power = relays_.power();
  how.hand_closed = relays_.hand_closed();
  how.outputs = relays_.outputs();
}

bool MicroboDriver::read_joint(std::size_t j, JointHow& out) noexcept {
  JointState& s = joints_[j];
  const hw::RcuJointConfig& c = config_.joints[j];
  std::uint16_t flags = 0;
  std::uint8_t status = 0;
  std::uint16_t e = 0;
  s.error = get_byte(j, rcu::kGetStatus, status);
  if (s.error == BusError::ok) s.error = get_word(j, rcu::kGetPosition, e);
  if (s.error != BusError::ok) {
    out.flags = kNotAnswering;  // q stays as last read
    return false;
  }
  const bool initialized = (status & hw::kStatusInitialized) != 0;
  const bool just_initialized = initialized && s.calibrating && !s.returning;
  if (just_initialized) s.area = 0;  // INITIALIZE done at the stop: that is area 0
  const bool restarted = reads_ == 0 || initialized != s.initialized;
  s.initialized = initialized;
  if (restarted) s.set_up = false;  // INITIALIZE restores the vendor's defaults
  if ((status & hw::kStatusEncoderError) != 0) flags |= kEncoderError;
  if ((status & hw::kStatusPhaseError) != 0) flags |= kPhaseError;
  if ((status & hw::kStatusFault) != 0) flags |= kJointFault;
  const double before = s.measured;
  s.measured = e + static_cast<double>(hw::kWorkAreaShift) * s.area;
  // Work areas (figure 4.4): past a threshold the joint changes area, which it accepts there;
  // the absolute count stays, the register moves by 50000.
  if (c.work_areas && initialized) {
    if (e > c.upper_threshold && put_cmd(j, rcu::kChangeWorkArea) == BusError::ok) ++s.area;
    if (e < c.lower_threshold && put_cmd(j, rcu::kChangeWorkArea) == BusError::ok) --s.area;
  }
  if (restarted) {  // nothing commanded yet: hold where the joint is
    s.desired = s.measured;
    s.following = false;
  }
  if (just_initialized) start_return_from_stop(j, s);
  if (s.returning && !s.following && std::abs(s.measured - s.goal) <= kSettledCounts &&
      std::abs(s.measured - before) <= kStillCounts) {
    s.returning = false;
    s.calibrating = false;
  }
  const double q = joint_value_of(j, s.measured);
  if (initialized) flags |= kCalibrated;
  if (s.calibrating) flags |= kCalibrating;
  if (reads_ > 0 && restarted) velocity_.restart(j, q);
  out.q = q;
  out.flags = flags;
  return initialized;
}

void MicroboDriver::start_return_from_stop(std::size_t j, JointState& s) noexcept {
  // The stop lies outside the joint's range: calibration ends back inside it, at the lower
  // limit plus the stop's margin, at the speed INITIALIZE sought the stop with.
  const kin::Joint& m = model_.joints[j];
  s.returning = true;
  s.goal = counts_of(j, m.lower + config_.joints[j].hard_stop_margin);
  s.rate = 0.1 * m.max_velocity / m.resolution_per_count;
  s.following = true;
}

void MicroboDriver::read_motor_parameters() noexcept {
  // The motor parameters, read back from the joint micro's RAM.
  const auto j = static_cast<std::size_t>(examine_);
  examine_ = -1;
  BusError e = BusError::ok;
  for (std::size_t i = 0; i < 16 && e == BusError::ok; i += 2) {
    std::uint16_t word = 0;
    e = put_word(j, rcu::kSetRamPointer, static_cast<std::uint16_t>(hw::kRcuMotorParameterRam + i));
    if (e == BusError::ok) e = get_word(j, rcu::kReadRamWord, word);
    examined_parameters_[i] = static_cast<std::uint8_t>(word & 0xff);
    examined_parameters_[i + 1] = static_cast<std::uint8_t>(word >> 8);
  }
  examined_ = e == BusError::ok ? static_cast<std::int8_t>(j) : std::int8_t{-1};
}

void MicroboDriver::send(const JointCommands& commands) noexcept {
  for (std::size_t j = 0; j < model_.dof(); ++j) {
    JointState& s = joints_[j];
    const JointCommand& cmd = commands[j];
    if (cmd.kind == JointCommand::Kind::calibrate) {
      s.error = put_word(j, rcu::kInitialize, config_.joints[j].initialize_counts);
      s.calibrating = s.error == BusError::ok;
      s.following = false;
      continue;
    }
    if (cmd.kind == JointCommand::Kind::move && !s.calibrating) {
      // The desired point goes on from where it is (set to the joint by hold() and restarts).
      s.goal = counts_of(j, cmd.target);
      s.rate = cmd.rate / model_.joints[j].resolution_per_count;
      s.following = true;
    }
    if (s.initialized && (!s.calibrating || s.returning)) follow(j, s);
  }
}

void MicroboDriver::follow(std::size_t j, JointState& s) noexcept {
  const double period = period_s_;
  if (!s.set_up) {
    // Synchronous control needs a brisk acceleration setting: the vendor's default crawls.
    const std::uint16_t a = config_.joints[j].follow_acceleration;
    s.set_up = a == 0 || put_word(j, rcu::kSetAcceleration, a) == BusError::ok;
  }
  if (zero_gravity_ != s.yielding) {
    // Zero gravity as the thesis did it (4.5.4.4): integration off at the joint level, so
    // that a push is not fought back once it ends; on leaving, the parameters as they were.
    if (send_motor_parameters(j, zero_gravity_) == BusError::ok) s.yielding = zero_gravity_;
  }
  if (zero_gravity_) {
    s.following = false;
    s.desired = s.measured;  // servo to where the joint is: it yields to a push
  }
  const double previous = s.desired;
  if (s.following && !zero_gravity_) advance_desired(j, s, period);
  send_target(j, s, previous, period);
}

void MicroboDriver::advance_desired(std::size_t j, JointState& s, double period) noexcept {
  const double left = s.goal - s.desired;
  if (s.rate <= 0.0) {
    s.desired = s.goal;  // POSVEL: there at the end of this period
  } else {
    // POS: a trapezoid at the joint's pace: accelerate to the rate, brake to stop on the goal.
    const hw::RcuJointConfig& c = config_.joints[j];
    const double accel = kPaceAccelerationFraction * c.follow_acceleration *
                         c.counts_per_ms2_per_acceleration_unit * 1e6;  // counts/s^2
    const double braking = std::sqrt(2.0 * accel * std::abs(left));
    const double wanted = std::copysign(std::min(s.rate, braking), left);
    s.pace += std::clamp(wanted - s.pace, -accel * period, accel * period);
    const double step = s.pace * period;
    s.desired = std::abs(step) >= std::abs(left) || step * left <= 0.0 ? s.goal : s.desired + step;
  }
  if (s.desired == s.goal) {  // then held there
    s.following = false;
    s.pace = 0.0;
  }
}

void MicroboDriver::send_target(std::size_t j, JointState& s, double previous,
                                double period) noexcept {
  const double lag = s.desired - s.measured;
  double target = s.desired;
  // Raw: a speed setting twice what this sample's step needs (sent exactly that, the law
  // merely lags by its braking distance; faster, it brakes at every target, as in the thesis).
  double speed = 2.0 * std::abs(s.desired - previous) / period;
  if (options_.scheme == TargetScheme::follow) {
    target = s.desired + lag;                    // X = Xd + (Xd - Xm)
    speed = config_.follow_gain * lag / period;  // V = K (Xd - Xm)
  }
  // The vendor law never moves faster than its speed setting: catching up on a lag, the joint
  // must still not outrun what a sample may carry it (the work areas) or its top speed.
  speed =
      std::min(std::abs(speed), velocity_limit(j, period) / model_.joints[j].resolution_per_count);
  // X runs ahead of Xd by the lag: never past the joint's limits (while calibration brings a
  // joint in from its stop, its target is inside already).
  const kin::Joint& m = model_.joints[j];
  target = std::clamp(target, counts_of(j, m.lower), counts_of(j, m.upper));
  std::uint16_t setting = speed_setting(j, speed);
  // Holding still (or following a push in zero gravity), the default speed keeps the joint
  // stiff enough not to sag: the vendor law softens at small settings (thesis 2.5.2).
  if (!s.following) setting = std::max(setting, config_.joints[j].default_speed);
  // In the joint's present work area, never wrapped: a target beyond the register's range is
  // held at its end until the area changes (the speed limit keeps that short).
  const double e = target - static_cast<double>(hw::kWorkAreaShift) * s.area;
  const auto register_target = static_cast<std::uint16_t>(std::clamp(std::lround(e), 0L, 65535L));
  BusError err = put_word(j, rcu::kSetTarget, register_target);
  if (err == BusError::ok) err = put_word(j, rcu::kSetSpeed, setting);
  if (err != BusError::ok) s.error = err;
}

void MicroboDriver::hold() noexcept {
  for (std::size_t j = 0; j < model_.dof(); ++j) {
    JointState& s = joints_[j];
    s.following = false;
    s.pace = 0.0;
    s.desired = s.measured;
    // STOP sets the target to where the joint is; the default speed keeps it stiff there.
    if (put_cmd(j, rcu::kStop) == BusError::ok) {
      put_word(j, rcu::kSetSpeed, config_.joints[j].default_speed);
    }
  }
  zero_gravity_ = false;
}

bool MicroboDriver::set_power(bool on) noexcept {
  return relays_.set_power(on);
}
void MicroboDriver::set_hand_closed(bool closed) noexcept {
  relays_.set_hand_closed(closed);
}
void MicroboDriver::set_zero_gravity(bool on) noexcept {
  zero_gravity_ = on;
}
void MicroboDriver::set_outputs(std::uint16_t bits) noexcept {
  relays_.set_outputs(bits);
}

}  // namespace rccx::rtc
