#include "rccx/hw/rcu_joint.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rccx::hw::detail {

namespace {

constexpr std::int32_t kRegisterSpan = 65536;
constexpr int kMinArea = -128;  // the micro keeps its work area in a signed byte
constexpr int kMaxArea = 127;
constexpr int kSeekSettleTicks = 100;  // INITIALIZE: ticks before a stall may be seen
constexpr int kStallTicks = 20;        // ... and ticks slower than a quarter of the seek speed

std::uint8_t lo(std::uint16_t w) noexcept {
  return static_cast<std::uint8_t>(w & 0xFF);
}
std::uint8_t hi(std::uint16_t w) noexcept {
  return static_cast<std::uint8_t>(w >> 8);
}
double sign(double x) noexcept {
  return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0);
}

}  // namespace

void RcuJoint::setup(const RcuJointConfig& config, double resolution_per_count, double q0,
                     bool initialized) noexcept {
  c_ = config;
  resolution_ = resolution_per_count;
  speed_unit_ = c_.counts_per_ms_per_speed_unit;
  acceleration_unit_ = c_.counts_per_ms2_per_acceleration_unit;
  seek_direction_ = c_.calibration_position < 0.5 * (c_.lower_stop + c_.upper_stop) ? -1 : 1;
  q_ = q0;
  qd_ = 0.0;
  ram_.fill(0);
  ram_[kRcuRamVersion] = lo(kRcuSoftwareVersion);
  ram_[kRcuRamVersion + 1] = hi(kRcuSoftwareVersion);
  std::copy(c_.motor_parameters.begin(), c_.motor_parameters.end(),
            ram_.begin() + kRcuRamMotorParameters);
  speed_ = c_.default_speed;
  acceleration_ = c_.default_acceleration;
  tolerance_ = 1;
  area_ = 0;
  if (initialized) {
    offset_ = c_.initialize_counts + 0.5 - c_.calibration_position / resolution_;
    if (c_.work_areas) {
      // The lowest area whose band (up to the upper threshold) holds the count.
      const std::int64_t a = absolute_counts();
      const std::int64_t above = a - c_.upper_threshold;
      area_ = above > 0 ? static_cast<int>((above + kWorkAreaShift - 1) / kWorkAreaShift) : 0;
    }
  } else {
    offset_ = 0.5 - q_ / resolution_;  // an incremental encoder reads 0 at power-up
  }
  initialized_ = initialized;
  mode_ = Mode::standby;
  target_ = position();
  restart_law();
}

// ---------------------------------------------------------------------------------------------
// Encoder

std::int64_t RcuJoint::absolute_counts() const noexcept {
  return static_cast<std::int64_t>(std::floor(q_ / resolution_ + offset_));
}

std::int32_t RcuJoint::position() const noexcept {
  return static_cast<std::int32_t>(absolute_counts() -
                                   static_cast<std::int64_t>(kWorkAreaShift) * area_);
}

std::uint16_t RcuJoint::encoder() const noexcept {
  const std::int32_t p = position();
  return static_cast<std::uint16_t>(((p % kRegisterSpan) + kRegisterSpan) % kRegisterSpan);
}

void RcuJoint::assign(std::uint16_t value) noexcept {
  offset_ = value + 0.5 - q_ / resolution_;
  area_ = 0;
}

void RcuJoint::change_work_area() noexcept {
  const std::int32_t e = position();
  int delta = 0;
  if (e > kWorkAreaAcceptAbove) delta = 1;
  if (e < kWorkAreaAcceptBelow) delta = -1;
  if (delta == 0 || area_ + delta < kMinArea || area_ + delta > kMaxArea) return;  // ignored
  area_ += delta;
  const std::int32_t shift = delta * kWorkAreaShift;
  target_ -= shift;
  r_ -= shift;
  for (std::int32_t& h : history_) h -= shift;
}

std::uint8_t RcuJoint::status_byte() const noexcept {
  const std::int32_t tolerance = tolerance_mode_ ? tolerance_ : 1;
  std::uint8_t s = 0;
  if (std::abs(target_ - position()) <= tolerance) s |= kStatusInPosition;
  if (initialized_) s |= kStatusInitialized;
  if (fault_) s |= kStatusFault;
  if (phase_error_) s |= kStatusPhaseError;
  if (encoder_error_) s |= kStatusEncoderError;
  if (tolerance_mode_) s |= kStatusToleranceMode;
  return s;
}

// ---------------------------------------------------------------------------------------------
// Handshake

std::uint8_t RcuJoint::read_status() const noexcept {
  if (not_answering_) return kIbe;
  std::uint8_t s = 0;
  if (obf_) s |= kObf;
  if (ibe_) s |= kIbe;
  return s;
}

std::uint8_t RcuJoint::read_data(std::int64_t now_us) noexcept {
  const std::uint8_t v = data_register_;
  if (not_answering_ || !obf_) return v;  // the stale byte
  obf_ = false;
  if (out_next_ < out_len_) give_at_us_ = now_us + kRcuServiceTime_us;
  return v;
}

bool RcuJoint::write(bool command, std::uint8_t value, std::int64_t now_us) noexcept {
  if (not_answering_ || ibe_) {
    ++lost_bytes_;
    return false;
  }
  ibe_ = true;
  in_is_command_ = command;
  in_byte_ = value;
  take_at_us_ = now_us + kRcuServiceTime_us;
  return true;
}

std::int64_t RcuJoint::next_event_us() const noexcept {
  if (not_answering_) return -1;
  if (take_at_us_ < 0) return give_at_us_;
  if (give_at_us_ < 0) return take_at_us_;
  return std::min(take_at_us_, give_at_us_);
}

void RcuJoint::service(std::int64_t now_us) noexcept {
  if (not_answering_) return;
  if (take_at_us_ >= 0 && take_at_us_ <= now_us) {
    take_at_us_ = -1;
    ibe_ = false;
    take(in_is_command_, in_byte_, now_us);
  }
  if (give_at_us_ >= 0 && give_at_us_ <= now_us) {
    give_at_us_ = -1;
    data_register_ = out_[out_next_++];
    obf_ = true;
  }
}

void RcuJoint::take(bool command, std::uint8_t value, std::int64_t now_us) noexcept {
  if (command) {
    start_command(value, now_us);
    return;
  }
  if (!waiting_data_) return;  // a data byte no command waits for
  in_[in_have_++] = value;
  if (in_have_ == in_need_) {
    waiting_data_ = false;
    execute(command_);
  }
}

void RcuJoint::answer(std::initializer_list<std::uint8_t> bytes, std::int64_t now_us) noexcept {
  (void)now_us;
  out_len_ = std::min(bytes.size(), out_.size());
  std::copy_n(bytes.begin(), out_len_, out_.begin());
  data_register_ = out_[0];
  out_next_ = 1;
  obf_ = true;
}

void RcuJoint::answer_word(std::uint16_t w, std::int64_t now_us) noexcept {
  answer({lo(w), hi(w)}, now_us);
}

std::uint16_t RcuJoint::data_word() const noexcept {
  return static_cast<std::uint16_t>(in_[0] | (in_[1] << 8));
}

void RcuJoint::start_command(std::uint8_t command, std::int64_t now_us) noexcept {
  // A new command abandons whatever the last one was still waiting for or giving.
  waiting_data_ = false;
  out_len_ = out_next_ = 0;
  give_at_us_ = -1;
  const int n = rcu::data_bytes(command);
  if (n == -128) return;  // not a command: ignored
  if (n < 0) {
    command_ = command;
    in_need_ = static_cast<std::size_t>(-n);
    in_have_ = 0;
    waiting_data_ = true;
    return;
  }
  const std::size_t p = ram_pointer_ % kRcuRamSize;
  switch (command) {
    case rcu::kGetStatus:
      answer({status_byte()}, now_us);
      break;
    case rcu::kGetTarget:
      answer_word(static_cast<std::uint16_t>(target_ & 0xFFFF), now_us);
      break;
    case rcu::kGetPosition:
      answer_word(encoder(), now_us);
      break;
    case rcu::kGetAcceleration:
      answer_word(acceleration_, now_us);
      break;
    case rcu::kGetVelocity:
      answer_word(speed_, now_us);
      break;
    case rcu::kGetTolerance:
      answer_word(tolerance_, now_us);
      break;
    case rcu::kReadRamByte:
      answer({ram_[p]}, now_us);
      break;
    case rcu::kReadSpeedFactor:
      answer({speed_factor_}, now_us);
      break;
    case rcu::kReadRamWord:
      answer({ram_[p], ram_[(p + 1) % kRcuRamSize]}, now_us);
      break;
    default:  // no data: acts at once
      execute(command);
      break;
  }
}

void RcuJoint::execute(std::uint8_t command) noexcept {
  const std::uint16_t w = data_word();
  const std::size_t p = ram_pointer_ % kRcuRamSize;
  switch (command) {
    case rcu::kSetTarget:
      target_ = w;
      if (mode_ == Mode::standby && initialized_ && power_) leave_standby();
      break;
    case rcu::kSetMotorParameters:
      std::copy_n(in_.begin(), 16, ram_.begin() + kRcuRamMotorParameters);
      break;
    case rcu::kSetAcceleration:
      acceleration_ = w;
      break;
    case rcu::kSetSpeed:
      speed_ = w;
      break;
    case rcu::kSetTolerance:
      tolerance_ = w;
      break;
    case rcu::kToleranceModeOn:
      tolerance_mode_ = true;
      break;
    case rcu::kToleranceModeOff:
      tolerance_mode_ = false;
      break;
    case rcu::kStandby:
      enter_standby();
      break;
    case rcu::kInitialize:
      if (!power_) break;  // the amplifiers are off: nothing to seek with
      initialize_value_ = w;
      initialized_ = false;
      fault_ = false;
      mode_ = Mode::initializing;
      restart_law();
      seek_ticks_ = stall_ticks_ = 0;
      break;
    case rcu::kStop:
      target_ = position();
      if (mode_ == Mode::servo) {
        r_ = target_;
        rv_ = ra_ = 0.0;
      } else if (mode_ == Mode::initializing) {
        enter_standby();  // the seek is abandoned; the joint stays uninitialized
      }
      break;
    case rcu::kSetRamPointer:
      ram_pointer_ = w;
      break;
    case rcu::kWriteRamByte:
      ram_[p] = in_[0];
      break;
    case rcu::kChangeWorkArea:
      change_work_area();
      break;
    case rcu::kWriteSpeedFactor:
      speed_factor_ = in_[0];
      break;
    case rcu::kWriteRamWord:
      ram_[p] = in_[0];
      ram_[(p + 1) % kRcuRamSize] = in_[1];
      break;
    default:
      break;
  }
}

// ---------------------------------------------------------------------------------------------
// Modes

void RcuJoint::restart_law() noexcept {
  r_ = position();
  rv_ = ra_ = 0.0;
  integral_ = 0.0;
  static_zone_ = true;
  history_.fill(position());
}

void RcuJoint::leave_standby() noexcept {
  mode_ = Mode::servo;
  fault_ = false;
  restart_law();
}

void RcuJoint::enter_standby() noexcept {
  mode_ = Mode::standby;
  effort_ = 0.0;
  integral_ = 0.0;
  rv_ = ra_ = 0.0;
}

void RcuJoint::set_power(bool on) noexcept {
  power_ = on;
  if (!on) enter_standby();
}

void RcuJoint::set_encoder_error() noexcept {
  encoder_error_ = true;
  offset_ += static_cast<double>(kRcuEncoderJump_counts);
}

void RcuJoint::set_fault() noexcept {
  fault_ = true;
  enter_standby();
}

void RcuJoint::clear_faults() noexcept {
  not_answering_ = false;
  encoder_error_ = false;
  phase_error_ = false;
  fault_ = false;
}

// ---------------------------------------------------------------------------------------------
// The joint law

void RcuJoint::tick() noexcept {
  std::int32_t e_now = position();
  // Encoder velocity over the last 4 ms, counts/ms.
  history_at_ = (history_at_ + 1) % history_.size();
  history_[history_at_] = e_now;
  double xv = (e_now - history_[(history_at_ + 1) % history_.size()]) / 4.0;

  if (mode_ == Mode::standby || !power_) {
    effort_ = 0.0;
    return;
  }
  const double factor = speed_factor_ / 100.0;
  double stiffness = std::min(1.0, std::max(speed_ * factor / kFullStiffnessSpeed,
                                            acceleration_ / kFullStiffnessAcceleration));

  if (mode_ == Mode::initializing) {
    const double v = motor(motor::kInitializationSpeed) * 16.0 * speed_unit_;
    stiffness = 1.0;
    static_zone_ = false;
    ra_ = seek_direction_ * v - rv_;
    rv_ = seek_direction_ * v;
    r_ += rv_;
    ++seek_ticks_;
    stall_ticks_ = seek_ticks_ > kSeekSettleTicks && std::abs(xv) < 0.25 * v ? stall_ticks_ + 1 : 0;
    if (stall_ticks_ >= kStallTicks) {  // at the stop
      assign(initialize_value_);
      initialized_ = true;
      mode_ = Mode::servo;
      target_ = e_now = position();
      xv = 0.0;
      restart_law();
    }
  } else {
    const double speed_cap = 256.0 * motor(motor::kMaximumSpeed);
    const double v_max = std::min(speed_ * factor, speed_cap) * speed_unit_;
    const double a = acceleration_ * acceleration_unit_;
    const double zone = 4.0 * motor(motor::kStaticZone);
    const double v_static = 8.0 * motor(motor::kStaticSpeed) * speed_unit_;
    const double d = target_ - r_;
    if (std::abs(d) <= zone) {
      // Static regulation zone: creep to the target at the static speed.
      static_zone_ = true;
      const double v = sign(d) * std::min(v_static, std::abs(d));
      ra_ = 0.0;
      rv_ = v;
    } else {
      // Dynamic regulation zone: accelerate to the speed setting, brake to arrive at the edge of
      // the static zone at the static speed.
      static_zone_ = false;
      const double braking = std::sqrt(v_static * v_static + 2.0 * a * (std::abs(d) - zone));
      const double wanted = sign(d) * std::min(v_max, braking);
      ra_ = std::clamp(wanted - rv_, -a, a);
      rv_ += ra_;
    }
    r_ += rv_;
  }

  // Effort (SI: N m or N).
  const double res = resolution_;
  const double j_hat = c_.inertia * motor(motor::kInertia) / 128.0;
  const double wp = motor(motor::kProportionalGain);
  const double kp_full = j_hat * wp * wp;
  const double kd = 1.4 * j_hat * wp;
  const double kp = static_zone_ ? kp_full / 16.0 : kp_full;
  const double ki =
      kp_full *
      (static_zone_ ? motor(motor::kStaticIntegration) : motor(motor::kDynamicIntegration)) / 8.0;
  const double error = (r_ - e_now) * res;
  const double error_rate = (rv_ - xv) * res * 1e3;
  const double v_ref = rv_ * res * 1e3;
  double feedforward = c_.viscous_friction * motor(motor::kViscousFriction) / 128.0 * v_ref -
                       c_.gravity_effort * motor(motor::kGravityCompensation) / 128.0;
  if (!static_zone_) feedforward += j_hat * ra_ * res * 1e6;
  if (std::abs(rv_) > 1e-6) {
    feedforward += sign(rv_) * c_.coulomb_friction * motor(motor::kDryFriction) / 128.0;
  }
  const double u = kp * error + kd * error_rate + integral_ + feedforward;
  const double limit = stiffness * c_.max_effort;
  if (std::abs(u) < limit || u * error < 0.0) integral_ += ki * error * 1e-3;
  effort_ = std::clamp(u, -limit, limit);

  // Following error.
  if (std::abs(r_ - e_now) > 64.0 * motor(motor::kSensorErrorTolerance)) {
    fault_ = true;
    enter_standby();
  }
}

// ---------------------------------------------------------------------------------------------
// The plant

void RcuJoint::plant_step(double h) noexcept {
  const bool braked = mode_ == Mode::standby || !power_;
  double force = (braked ? 0.0 : effort_) + external_ + c_.gravity_effort;
  const double dry = c_.coulomb_friction + (braked ? kBrakeEffortFactor * c_.max_effort : 0.0);
  if (qd_ == 0.0) {
    if (std::abs(force) <= dry) return;  // stuck
    force -= std::copysign(dry, force);
  } else {
    force -= std::copysign(dry, qd_);
  }
  const double j = c_.inertia;
  double v = (qd_ + force / j * h) / (1.0 + c_.viscous_friction / j * h);
  if (qd_ != 0.0 && v * qd_ < 0.0) v = 0.0;  // friction stops it; it does not reverse it
  qd_ = v;
  q_ += v * h;
  if (q_ < c_.lower_stop) {
    q_ = c_.lower_stop;
    qd_ = 0.0;
  } else if (q_ > c_.upper_stop) {
    q_ = c_.upper_stop;
    qd_ = 0.0;
  }
}

}  // namespace rccx::hw::detail
