#include "rccx/hw/rcu.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "rccx/hw/rcu_joint.hpp"

namespace rccx::hw {

namespace rcu {

namespace {

struct CommandInfo {
  std::uint8_t code;
  int data;  // + read by the master, - written by it
  std::string_view name;
};

constexpr std::array<CommandInfo, 24> kCommands{{
    {kGetStatus, 1, "GET JOINT STATUS"},
    {kGetTarget, 2, "GET CURRENT TARGET POSITION"},
    {kGetPosition, 2, "GET CURRENT POSITION"},
    {kGetAcceleration, 2, "GET CURRENT ACCELERATION"},
    {kGetVelocity, 2, "GET CURRENT VELOCITY"},
    {kGetTolerance, 2, "GET CURRENT TOLERANCE"},
    {kSetTarget, -2, "SET TARGET POSITION"},
    {kSetMotorParameters, -16, "SET MOTOR PARAMETERS"},
    {kSetAcceleration, -2, "SET MAXIMUM ACCELERATION"},
    {kSetSpeed, -2, "SET MAXIMUM SPEED"},
    {kSetTolerance, -2, "SET TOLERANCE VALUE"},
    {kToleranceModeOn, 0, "SET TOLERANCE MODE ON"},
    {kToleranceModeOff, 0, "SET TOLERANCE MODE OFF"},
    {kStandby, 0, "INITIATE STAND-BY MODE"},
    {kInitialize, -2, "INITIALIZE"},
    {kStop, 0, "STOP"},
    {kSetRamPointer, -2, "SET POINTER FOR ACCESS TO JOINT MICRO RAM"},
    {kReadRamByte, 1, "READ BYTE IN JOINT MICRO RAM"},
    {kWriteRamByte, -1, "WRITE BYTE IN JOINT MICRO RAM"},
    {kChangeWorkArea, 0, "CHANGE WORK AREA"},
    {kReadSpeedFactor, 1, "READ SPEED FACTOR"},
    {kWriteSpeedFactor, -1, "WRITE SPEED FACTOR"},
    {kReadRamWord, 2, "READ WORD IN JOINT MICRO RAM"},
    {kWriteRamWord, -2, "WRITE WORD IN JOINT MICRO RAM"},
}};

const CommandInfo* find(std::uint8_t command) noexcept {
  for (const CommandInfo& c : kCommands) {
    if (c.code == command) return &c;
  }
  return nullptr;
}

}  // namespace

int data_bytes(std::uint8_t command) noexcept {
  const CommandInfo* c = find(command);
  return c != nullptr ? c->data : -128;
}

std::string_view name(std::uint8_t command) noexcept {
  const CommandInfo* c = find(command);
  return c != nullptr ? c->name : std::string_view{};
}

}  // namespace rcu

std::string_view to_string(RcuFault f) noexcept {
  switch (f) {
    case RcuFault::joint_not_answering:
      return "joint_not_answering";
    case RcuFault::encoder_error:
      return "encoder_error";
    case RcuFault::phase_error:
      return "phase_error";
    case RcuFault::power_loss:
      return "power_loss";
  }
  return "?";
}

struct Rcu::Impl {
  kin::RobotModel model;
  RcuConfig config;
  std::size_t n = 0;
  std::array<detail::RcuJoint, kRcuMaxJoints> joints{};
  std::int64_t now_us = 0;
  bool power = true;
  bool power_lost = false;
  bool hand_closed = false;
  std::uint16_t outputs = 0;

  /// The joint whose registers are at `address`, or n when none.
  [[nodiscard]] std::size_t joint_of(std::uint16_t address) const noexcept {
    if (address < kRcuBase || address >= kRcuBase + 2 * n) return n;
    return static_cast<std::size_t>(address - kRcuBase) / 2;
  }
};

Rcu::Rcu(const kin::RobotModel& model, const SimulatedArmOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.model = model;
  m.config = rcu_config(model);
  m.n = model.dof();
  if (m.n == 0 || m.n > kRcuMaxJoints) {
    throw std::invalid_argument(
        fmt::format("{}: an RCU serves 1 to {} joints", model.name, kRcuMaxJoints));
  }
  const kin::JointVector initial = options.initial.empty() ? model.ready() : options.initial;
  if (initial.size() != m.n) {
    throw std::invalid_argument(
        fmt::format("{}: {} initial joint values for {} joints", model.name, initial.size(), m.n));
  }
  for (std::size_t j = 0; j < m.n; ++j) {
    const RcuJointConfig& c = m.config.joints[j];
    if (!(initial[j] >= c.lower_stop && initial[j] <= c.upper_stop)) {
      throw std::invalid_argument(fmt::format("{}: joint {}'s initial value {} is beyond its stops",
                                              model.name, j + 1, initial[j]));
    }
    m.joints[j].setup(c, model.joints[j].resolution_per_count, initial[j], options.calibrated);
  }
  m.power = options.powered;
  for (std::size_t j = 0; j < m.n; ++j) m.joints[j].set_power(m.power);
}

Rcu::~Rcu() = default;

const kin::RobotModel& Rcu::model() const noexcept {
  return impl_->model;
}
const RcuConfig& Rcu::config() const noexcept {
  return impl_->config;
}

std::uint8_t Rcu::in(std::uint16_t address) noexcept {
  Impl& m = *impl_;
  const std::size_t j = m.joint_of(address);
  if (j == m.n) return 0xFF;  // no card answers there
  if ((address & 1U) != 0) return m.joints[j].read_status();
  return m.joints[j].read_data(m.now_us);
}

void Rcu::out(std::uint16_t address, std::uint8_t value) noexcept {
  Impl& m = *impl_;
  const std::size_t j = m.joint_of(address);
  if (j == m.n) return;
  m.joints[j].write((address & 1U) != 0, value, m.now_us);
}

void Rcu::advance_us(std::int64_t us) noexcept {
  Impl& m = *impl_;
  if (us <= 0) return;
  const std::int64_t end = m.now_us + us;
  constexpr double kSubstep_s = static_cast<double>(detail::kRcuSubstep_us) * 1e-6;
  for (;;) {
    const std::int64_t t_step = (m.now_us / detail::kRcuSubstep_us + 1) * detail::kRcuSubstep_us;
    std::int64_t t_byte = std::numeric_limits<std::int64_t>::max();
    for (std::size_t j = 0; j < m.n; ++j) {
      const std::int64_t e = m.joints[j].next_event_us();
      if (e >= 0) t_byte = std::min(t_byte, std::max(e, m.now_us));
    }
    const std::int64_t t = std::min(t_step, t_byte);
    if (t > end) break;
    m.now_us = t;
    if (t_byte <= t) {
      for (std::size_t j = 0; j < m.n; ++j) m.joints[j].service(t);
    }
    if (t_step == t) {
      // The plant catches up to t with the effort of the last tick; then the law runs on it.
      for (std::size_t j = 0; j < m.n; ++j) m.joints[j].plant_step(kSubstep_s);
      if (t % kRcuTick_us == 0) {
        for (std::size_t j = 0; j < m.n; ++j) m.joints[j].tick();
      }
    }
  }
  m.now_us = end;
}

std::int64_t Rcu::time_us() const noexcept {
  return impl_->now_us;
}

bool Rcu::set_power(bool on) noexcept {
  Impl& m = *impl_;
  if (on && m.power_lost) return false;
  m.power = on;
  for (std::size_t j = 0; j < m.n; ++j) m.joints[j].set_power(on);
  return true;
}
bool Rcu::power() const noexcept {
  return impl_->power;
}
void Rcu::set_hand_closed(bool closed) noexcept {
  impl_->hand_closed = closed;
}
bool Rcu::hand_closed() const noexcept {
  return impl_->hand_closed;
}
void Rcu::set_outputs(std::uint16_t bits) noexcept {
  impl_->outputs = bits;
}
std::uint16_t Rcu::outputs() const noexcept {
  return impl_->outputs;
}

void Rcu::inject(RcuFault fault, std::size_t joint) noexcept {
  Impl& m = *impl_;
  if (fault == RcuFault::power_loss) {
    m.power_lost = true;
    m.power = false;
    for (std::size_t j = 0; j < m.n; ++j) {
      m.joints[j].set_power(false);
      m.joints[j].set_fault();
    }
    return;
  }
  if (joint >= m.n) return;
  switch (fault) {
    case RcuFault::joint_not_answering:
      m.joints[joint].set_not_answering();
      break;
    case RcuFault::encoder_error:
      m.joints[joint].set_encoder_error();
      break;
    case RcuFault::phase_error:
      m.joints[joint].set_phase_error();
      break;
    case RcuFault::power_loss:
      break;
  }
}

void Rcu::clear_faults() noexcept {
  Impl& m = *impl_;
  m.power_lost = false;
  for (std::size_t j = 0; j < m.n; ++j) m.joints[j].clear_faults();
}

void Rcu::set_external_effort(std::size_t joint, double effort) noexcept {
  if (joint < impl_->n && std::isfinite(effort)) impl_->joints[joint].set_external_effort(effort);
}

kin::JointVector Rcu::true_position() const noexcept {
  kin::JointVector q(impl_->n);
  for (std::size_t j = 0; j < impl_->n; ++j) q[j] = impl_->joints[j].q();
  return q;
}

kin::JointVector Rcu::true_velocity() const noexcept {
  kin::JointVector v(impl_->n);
  for (std::size_t j = 0; j < impl_->n; ++j) v[j] = impl_->joints[j].qd();
  return v;
}

std::int64_t Rcu::absolute_counts(std::size_t joint) const noexcept {
  return joint < impl_->n ? impl_->joints[joint].absolute_counts() : 0;
}
int Rcu::work_area(std::size_t joint) const noexcept {
  return joint < impl_->n ? impl_->joints[joint].area() : 0;
}
std::uint64_t Rcu::lost_bytes(std::size_t joint) const noexcept {
  return joint < impl_->n ? impl_->joints[joint].lost_bytes() : 0;
}
bool Rcu::standby(std::size_t joint) const noexcept {
  return joint < impl_->n && impl_->joints[joint].standby();
}
double Rcu::reference(std::size_t joint) const noexcept {
  return joint < impl_->n ? impl_->joints[joint].reference() : 0.0;
}
bool Rcu::static_zone(std::size_t joint) const noexcept {
  return joint < impl_->n && impl_->joints[joint].static_zone();
}

// ---------------------------------------------------------------------------------------------
// RcuBus

RcuBus::RcuBus(Rcu& rcu) noexcept : rcu_(rcu) {}

namespace {
void charge(Rcu& rcu, double& carry_us) noexcept {
  carry_us += rcu.config().exchange_us;
  const double whole = std::floor(carry_us);
  carry_us -= whole;
  rcu.advance_us(static_cast<std::int64_t>(whole));
}
}  // namespace

std::uint8_t RcuBus::in(std::uint16_t address) noexcept {
  charge(rcu_, carry_us_);
  ++exchanges_;
  return rcu_.in(address);
}

void RcuBus::out(std::uint16_t address, std::uint8_t value) noexcept {
  charge(rcu_, carry_us_);
  ++exchanges_;
  rcu_.out(address, value);
}

double RcuBus::bus_time_us() const noexcept {
  return static_cast<double>(exchanges_) * rcu_.config().exchange_us;
}

}  // namespace rccx::hw
