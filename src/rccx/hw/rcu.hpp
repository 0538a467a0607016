// The Microbo Ecureuil's RCU below the wire, at register level (thesis 2.5, 4.4.3, Appendix B):
// up to eight 8085 joint micros, each behind a data register at 5800H + 2n and a
// command/status register at 5801H + 2n (n = 0 for joint 1), with the OBF/IBE handshake,
// every command of Appendix B, the vendor's joint law at 1 ms with its dynamic and static
// regulation zones, 16-bit encoders split into work areas, and a plant per joint.
//
// Register accesses take no time here: time passes only through advance_us(), so a caller
// decides what an exchange costs (RcuBus charges the thesis's 75 us). A byte written while the
// joint micro has not yet taken the previous one (IBE set) is lost, as on the real bus.
//
// The emulated joint micro (rcu_joint.hpp has the whole design):
// - Handshake: a byte written to the command or data register sets IBE; the micro takes it
//   kRcuServiceTime_us later (IBE clears). A read command's first byte appears in the data
//   register when the command is taken, each further byte kRcuServiceTime_us after the master
//   read the previous one (OBF set while a byte waits; reading the data register clears OBF;
//   reading it with OBF clear returns the stale byte). A write command acts when its last data
//   byte is taken. A new command byte abandons a command still waiting for or giving bytes; a
//   data byte no command waits for, and a code that is not in Appendix B.3, are taken and
//   ignored. Addresses of joints the robot does not have read FFH (no card) and ignore writes.
// - Units of the settings: speed 1/32 rad/s and acceleration 1/4 rad/s^2 of the motor
//   (Appendix B.2), in counts through each joint's counts per motor turn (RcuJointConfig);
//   the speed factor is a percentage (default 100) applied to the speed setting.
// - Work areas: the micro counts in a counter P = A - 50000 x area wider than 16 bits, and the
//   register E is P's low 16 bits: past 65535 or below 0 in its area the register WRAPS while
//   the joint moves on undisturbed (the wrap goes undetected, thesis 4.4.3: a master that misses
//   it misplaces the joint by 65536 counts). Targets are taken in P's frame (0..65535). CHANGE
//   WORK AREA is accepted when P > 50000 (P -= 50000, area + 1) or P < 15535 (P += 50000,
//   area - 1), otherwise ignored; it moves P, the target and the joint law's reference
//   together, so the joint does not move. The area is a signed byte (-128..127).
// - INITIALIZE seeks the joint's calibration stop (a hard stop just beyond one limit) at the
//   initialization speed of the motor parameters, waits for the joint to stall there, assigns
//   the value sent (area 0), and holds there, initialized. Stand-by (the state at power-up and
//   after 1AH, a fault or arm power off) switches the servo off and applies the joint's brake.
//
// Errata choice (SEED-GUIDE): Appendix B names 24H "write byte" and 26H "read byte", but their
// data directions are the other way round. We follow the data directions, which are what the
// bus sees: 24H reads a byte of joint RAM (one data byte out), 26H writes one (one data byte in).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "rccx/hw/bus.hpp"
#include "rccx/hw/simulated_arm.hpp"
#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/kinematics/robot_model.hpp"

namespace rccx::hw {

inline constexpr std::uint16_t kRcuBase = 0x5800;  ///< joint n's data register: base + 2n
inline constexpr std::size_t kRcuMaxJoints = 8;
[[nodiscard]] constexpr std::uint16_t rcu_data_register(std::size_t joint) noexcept {
  return static_cast<std::uint16_t>(kRcuBase + 2 * joint);
}
[[nodiscard]] constexpr std::uint16_t rcu_command_register(std::size_t joint) noexcept {
  return static_cast<std::uint16_t>(kRcuBase + 2 * joint + 1);
}

/// Status register bits (Appendix B.2).
enum RcuHandshake : std::uint8_t {
  kObf = 1U << 0,  ///< output buffer full: a byte waits in the data register for the master
  kIbe = 1U << 1,  ///< input buffer full: the joint micro has not taken the last byte (busy)
};

/// The joint status byte that command 00H returns (Appendix B.3).
enum RcuJointStatus : std::uint8_t {
  kStatusInPosition = 1U << 0,   ///< within the tolerance of the target
  kStatusInitialized = 1U << 1,  ///< calibrated (INITIALIZE done)
  kStatusFault = 1U << 2,        ///< fault during motion or initialization
  kStatusPhaseError = 1U << 5,   ///< simultaneous transition on both encoder channels
  kStatusEncoderError = 1U << 6,
  kStatusToleranceMode = 1U << 7,  ///< user tolerance (14H) in force
};

/// Time the joint micro takes to take a byte written to it, or to put the next byte of an answer
/// in its data register, us. Shorter than an exchange (75 us), so a master that polls status
/// before every access finds it ready at the first poll.
inline constexpr std::int64_t kRcuServiceTime_us = 25;
/// The joint law's period, us (thesis 2.5.2: 1 ms).
inline constexpr std::int64_t kRcuTick_us = 1000;
/// Joint micro RAM (commands 22H-30H): its size, and where things are in it. The RAM pointer is
/// taken modulo the size and does not move by itself (a word is at the pointer and the next).
inline constexpr std::size_t kRcuRamSize = 2048;
inline constexpr std::uint16_t kRcuRamVersion = 0x0010;  ///< the pointer's default: the version
inline constexpr std::uint16_t kRcuSoftwareVersion = 0x0103;     ///< reads 03H, 01H: "1.03"
inline constexpr std::uint16_t kRcuRamMotorParameters = 0x0040;  ///< the 16 bytes of 0EH
inline constexpr std::uint8_t kRcuDefaultSpeedFactor = 100;      ///< percent

/// The 16 motor parameter bytes of command 0EH (Appendix B.3), by index (byte 1 is index 0),
/// with the meaning the emulated joint law gives them (rcu_joint.hpp). Stored in joint RAM at
/// kRcuRamMotorParameters, where the law reads them every tick: RAM writes change them too.
namespace motor {
inline constexpr std::size_t kProportionalGain = 0;      ///< dynamic zone bandwidth, rad/s
inline constexpr std::size_t kInitializationSpeed = 1;   ///< x 16 speed units
inline constexpr std::size_t kSensorErrorTolerance = 2;  ///< following error limit, x 64 counts
inline constexpr std::size_t kStaticZone = 3;            ///< static zone half width, x 4 counts
inline constexpr std::size_t kMaximumSpeed = 4;          ///< speed setting cap, x 256 speed units
inline constexpr std::size_t kDynamicIntegration = 5;    ///< Ki / Kp, 1/8 s^-1 (dynamic zone)
inline constexpr std::size_t kStaticIntegration = 6;     ///< Ki / Kp, 1/8 s^-1 (static zone)
inline constexpr std::size_t kStaticSpeed = 7;           ///< static zone creep, x 8 speed units
inline constexpr std::size_t kMotorResistance = 8;       ///< resistance/thermal capacity (unused)
inline constexpr std::size_t kThermalConductance = 9;    ///< 1.0/thermal resistance (unused)
inline constexpr std::size_t kMaximumTemperature = 10;   ///< (unused)
inline constexpr std::size_t kGravityCompensation = 11;  ///< feedforward, 128ths of the load
inline constexpr std::size_t kInertia = 12;              ///< model inertia, 128ths of the plant's
inline constexpr std::size_t kViscousFriction = 13;      ///< feedforward, 128ths of the plant's
inline constexpr std::size_t kDryFriction = 14;          ///< feedforward, 128ths of the plant's
inline constexpr std::size_t kMaximumAcceleration = 15;  ///< max acceleration/4 (unused)
}  // namespace motor

/// Command codes (Appendix B.3).
namespace rcu {
inline constexpr std::uint8_t kGetStatus = 0x00;           // read 1
inline constexpr std::uint8_t kGetTarget = 0x02;           // read 2 (low, high)
inline constexpr std::uint8_t kGetPosition = 0x04;         // read 2
inline constexpr std::uint8_t kGetAcceleration = 0x06;     // read 2
inline constexpr std::uint8_t kGetVelocity = 0x08;         // read 2
inline constexpr std::uint8_t kGetTolerance = 0x0A;        // read 2
inline constexpr std::uint8_t kSetTarget = 0x0C;           // write 2
inline constexpr std::uint8_t kSetMotorParameters = 0x0E;  // write 16
inline constexpr std::uint8_t kSetAcceleration = 0x10;     // write 2
inline constexpr std::uint8_t kSetSpeed = 0x12;            // write 2
inline constexpr std::uint8_t kSetTolerance = 0x14;        // write 2
inline constexpr std::uint8_t kToleranceModeOn = 0x16;
inline constexpr std::uint8_t kToleranceModeOff = 0x18;
inline constexpr std::uint8_t kStandby = 0x1A;
inline constexpr std::uint8_t kInitialize = 0x1C;  // write 2: the calibration value
inline constexpr std::uint8_t kStop = 0x1E;
inline constexpr std::uint8_t kSetRamPointer = 0x22;  // write 2
inline constexpr std::uint8_t kReadRamByte = 0x24;    // read 1 (named "write byte" in B.3)
inline constexpr std::uint8_t kWriteRamByte = 0x26;   // write 1 (named "read byte" in B.3)
inline constexpr std::uint8_t kChangeWorkArea = 0x28;
inline constexpr std::uint8_t kReadSpeedFactor = 0x2A;   // read 1
inline constexpr std::uint8_t kWriteSpeedFactor = 0x2C;  // write 1
inline constexpr std::uint8_t kReadRamWord = 0x2E;       // read 2
inline constexpr std::uint8_t kWriteRamWord = 0x30;      // write 2
/// Data bytes of a command, as the master sees them: read from the joint (+, GET commands) or
/// written to it (-, SET commands); 0 for none, and -128 when the code is not a command.
int data_bytes(std::uint8_t command) noexcept;
/// Appendix B.3's name ("GET JOINT STATUS"); "" when the code is not a command.
std::string_view name(std::uint8_t command) noexcept;
}  // namespace rcu

/// Where a joint micro keeps the 16 motor parameters of command 0EH in its RAM (bytes 1 to 16
/// at this address and the 15 after it), so that RAM reads (22H, 2EH) examine them.
inline constexpr std::uint16_t kRcuMotorParameterRam = 0x0040;

/// Encoder counts per work area change, and where a change is accepted (Appendix B, 2.5.2).
inline constexpr std::int32_t kWorkAreaShift = 50000;
inline constexpr std::int32_t kWorkAreaAcceptAbove = 50000;  ///< E > this: E -= 50000
inline constexpr std::int32_t kWorkAreaAcceptBelow = 15535;  ///< E < this: E += 50000

/// One joint's RCU data from the robot file's "hardware": {"rcu": {...}} block (robots/README.md).
struct RcuJointConfig {
  // Encoder and calibration. Absolute counts A = E + 50000 x area; A grows with the joint value.
  double calibration_position = 0.0;    ///< joint value at the mechanical initial position, rad/m
  std::uint16_t initialize_counts = 0;  ///< the value INITIALIZE assigns there (area 0)
  /// The hard stops sit this far beyond the limits (rad or m); the calibration position is one.
  double hard_stop_margin = 0.0;
  double lower_stop = 0.0, upper_stop = 0.0;  ///< where the hard stops are, rad or m
  double counts_per_motor_turn = 0.0;         ///< encoder counts per turn of the motor
  bool work_areas = false;                    ///< the joint's range needs more than one work area
  std::int32_t lower_threshold = 7450;        ///< driver: change area below this (thesis fig. 4.4)
  std::int32_t upper_threshold = 57550;       ///< driver: change area above this
  // Units of the velocity and acceleration settings (Appendix B.2: 1/32 rad/s and 1/4 rad/s^2
  // of the motor), in encoder counts.
  double counts_per_ms_per_speed_unit = 0.0;
  double counts_per_ms2_per_acceleration_unit = 0.0;
  std::uint16_t default_speed = 32;        ///< 1 rad/s
  std::uint16_t default_acceleration = 1;  ///< 1/4 rad/s^2
  /// The acceleration setting for synchronous control: send it once (10H) before following;
  /// the default of 1 moves the joints at a crawl and leaves them soft.
  std::uint16_t follow_acceleration = 0;
  std::array<std::uint8_t, 16> motor_parameters{};  ///< the defaults command 0EH would send
  // The plant below the amplifier.
  double inertia = 0.0;           ///< kg m^2 or kg, at the joint
  double viscous_friction = 0.0;  ///< N m s/rad or N s/m
  double coulomb_friction = 0.0;  ///< N m or N
  double max_effort = 0.0;        ///< N m or N
  double gravity_effort = 0.0;    ///< constant load (the vertical joint's weight), N m or N;
                                  ///< signed: negative pulls the joint value down
};

struct RcuConfig {
  std::vector<RcuJointConfig> joints;  ///< one per robot joint
  double exchange_us = 75.0;           ///< bus time per register access (thesis 4.4.3)
  double follow_gain = 1.0;            ///< K of the follow scheme as a fraction of 1 / period
};

/// Reads the RCU block of a robot file; throws std::invalid_argument naming the key.
RcuConfig rcu_config(const kin::RobotModel& model);
/// Whether the robot file describes an RCU ("hardware": {"rcu": ...}): the Microbo's. False for
/// no "hardware" block, or one with only a MuJoCo scene; throws std::invalid_argument for a
/// "hardware" block that is not JSON.
bool has_rcu(const kin::RobotModel& model);

/// Faults the emulator can inject (beyond SimulatedArm's): the joint stops answering (its
/// registers stay busy), its encoder errs (status bit 6, counts jump), a phase error (bit 5),
/// or arm power drops (every joint faulted, amplifiers off).
enum class RcuFault : std::uint8_t { joint_not_answering, encoder_error, phase_error, power_loss };
std::string_view to_string(RcuFault f) noexcept;

class Rcu final : public Relays {
 public:
  /// Throws std::invalid_argument when the model has no usable RCU block. The joints start in
  /// stand-by at `initial` (default: the ready pose), arm power as `powered` says. With
  /// `calibrated` (the default) they are initialized as if INITIALIZE had run, each in the work
  /// area that puts its register between the thresholds (work_area() says which: a driver must
  /// start from it); without it they are not initialized and their registers read 0 where they
  /// stand, as after power-up.
  explicit Rcu(const kin::RobotModel& model, const SimulatedArmOptions& options = {});
  ~Rcu() override;

  [[nodiscard]] const kin::RobotModel& model() const noexcept;
  [[nodiscard]] const RcuConfig& config() const noexcept;

  // The C1 bus: register reads and writes, no time passing.
  [[nodiscard]] std::uint8_t in(std::uint16_t address) noexcept;
  void out(std::uint16_t address, std::uint8_t value) noexcept;

  /// Runs the joint micros (byte service, the 1 ms joint law) and the plants for `us`.
  void advance_us(std::int64_t us) noexcept;
  [[nodiscard]] std::int64_t time_us() const noexcept;

  // The C2 side: relays.
  bool set_power(bool on) noexcept override;
  [[nodiscard]] bool power() const noexcept override;
  void set_hand_closed(bool closed) noexcept override;
  [[nodiscard]] bool hand_closed() const noexcept override;
  void set_outputs(std::uint16_t bits) noexcept override;
  [[nodiscard]] std::uint16_t outputs() const noexcept override;

  void inject(RcuFault fault, std::size_t joint) noexcept;
  void clear_faults() noexcept;
  /// A push on a joint (N m or N), e.g. a hand moving it in teach mode; 0 removes it.
  void set_external_effort(std::size_t joint, double effort) noexcept;

  // The truth, for tests and documents.
  [[nodiscard]] kin::JointVector true_position() const noexcept;  ///< rad / m
  [[nodiscard]] kin::JointVector true_velocity() const noexcept;
  /// The joint's absolute encoder count (E + 50000 x area) and its work area. The count is the
  /// one its position is worth, so after a wrap it is no longer E + 50000 x area.
  [[nodiscard]] std::int64_t absolute_counts(std::size_t joint) const noexcept;
  [[nodiscard]] int work_area(std::size_t joint) const noexcept;
  /// Register bytes written while IBE was set, and so lost, since construction.
  [[nodiscard]] std::uint64_t lost_bytes(std::size_t joint) const noexcept;
  /// The joint micro is in stand-by (servo off, brake on).
  [[nodiscard]] bool standby(std::size_t joint) const noexcept;
  /// The joint law's reference position (counts in the frame of the register, unwrapped) and
  /// whether the law is in its static regulation zone.
  [[nodiscard]] double reference(std::size_t joint) const noexcept;
  [[nodiscard]] bool static_zone(std::size_t joint) const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The bus adapter: every register access is one exchange, charging `config().exchange_us` of
/// emulated time before it completes. Counts exchanges and bus time.
class RcuBus final : public Bus {
 public:
  explicit RcuBus(Rcu& rcu) noexcept;
  [[nodiscard]] std::uint8_t in(std::uint16_t address) noexcept override;
  void out(std::uint16_t address, std::uint8_t value) noexcept override;
  /// Advances the RCU to t_s when it is behind (the bus's own exchanges may have taken it past).
  void sync(double t_s) noexcept override {
    const auto us = static_cast<std::int64_t>(t_s * 1e6 + 0.5);
    if (us > rcu_.time_us()) rcu_.advance_us(us - rcu_.time_us());
  }
  [[nodiscard]] std::uint64_t exchanges() const noexcept { return exchanges_; }
  [[nodiscard]] double bus_time_us() const noexcept;
  void reset_counters() noexcept { exchanges_ = 0; }
  [[nodiscard]] Rcu& rcu() noexcept { return rcu_; }

 private:
  Rcu& rcu_;
  std::uint64_t exchanges_ = 0;
  double carry_us_ = 0.0;  ///< fractions of a microsecond not yet charged
};

}  // namespace rccx::hw
