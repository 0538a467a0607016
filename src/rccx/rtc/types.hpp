// The RTC data structures of thesis 2.3.2 and 4.5.4.1: `How`, the state of the arm as the
// communication task read it this sample; `Chg`, the commands the control functions hand it;
// and the terminate codes that say why a control session ended. Plain values, fixed size:
// they are copied between the two tasks every sample and must never touch the heap.
//
//   session.control({}, [](rtc::Control& c) {              // f2, every sample
//     const rtc::How& how = c.how();                         // read at the sample's start
//     c.chg().posvel(1, how.joint[1].range + 0.001);         // joint 2: 1 mrad on, next sample
//     if (how.time_s > 2.0) c.terminate();                   // s since the session opened
//   });
//   const rtc::Termination t = session.wait_terminated(5s);  // t.code: user_request
//   rtc::print_terminate_code(t);                            // why control ended
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string_view>

#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/math/wrench.hpp"

namespace rccx::rtc {

using kin::JointVector;
using kin::kMaxJoints;

/// How a joint is to be commanded this sample (thesis 4.5.4.1, `chg.i.motion[i].set`).
enum class SetMode : std::uint8_t {
  none,     ///< leave the joint as it is
  pos,      ///< move to the target at the joint's velocity setting (`JointChg::velocity`)
  posvel,   ///< arrive at the target exactly one sample period from now
  stopcal,  ///< stop and seek the calibration position (joint-level calibration)
};
std::string_view to_string(SetMode m) noexcept;

/// Per-joint command. Positions are range values: zero at the joint's lower limit, rad or m.
struct JointChg {
  SetMode set = SetMode::none;
  double range_target = 0.0;  ///< rad or m above the joint's lower limit
  double velocity = 0.0;      ///< POS only: rad/s or m/s; 0 = the robot's default speed
};

/// Which limit checks the communication task makes (thesis 4.5.2, "checking mode"); a bit set.
enum Check : std::uint8_t {
  kCheckObservedPosition = 1U << 0,  ///< a measured joint outside its limits ends the session
  kCheckTargetPosition = 1U << 1,    ///< a target outside the limits ends the session
  kCheckObservedVelocity = 1U << 2,  ///< a measured speed above the joint's maximum ends it
  kCheckTargetVelocity = 1U << 3,    ///< a commanded speed above the joint's maximum ends it
  kCheckForce = 1U << 4,  ///< a wrist force sensor that saturates or freezes ends the session
  kCheckAll = 0x1f,
};

enum class Request : std::uint8_t { none, on, off };

/// A joint controller setting (the Microbo's, Appendix B; the thesis's `test` program letters).
/// Values are the controller's own units, as the registers take them.
enum class Setting : std::uint8_t {
  none,
  acceleration,      ///< a: SET MAXIMUM ACCELERATION (1/4 rad/s^2 of the motor)
  speed_factor,      ///< f: WRITE SPEED FACTOR (0..255)
  dynamic_integral,  ///< k: motor parameter 6, dynamic integration constant (0..255)
  static_integral,   ///< K: motor parameter 7, static integration constant (0..255)
  static_speed,      ///< V: motor parameter 8, static zone speed (0..255)
  static_zone,       ///< z: motor parameter 4, size of the static regulation zone (0..255)
  examine,           ///< X: read the joint's 16 motor parameters into How
};
std::string_view to_string(Setting s) noexcept;

struct SettingChg {
  Setting what = Setting::none;
  std::uint8_t joint = 0;  ///< 0-based
  std::uint16_t value = 0;
};

/// The command vehicle: written by the control functions, handed to the communication task
/// once per sample (after f1). Commands are one-shot (cleared after each hand-over); the
/// checking mode stays as set.
struct Chg {
  std::array<JointChg, kMaxJoints> motion{};
  std::uint8_t checking = kCheckAll;     ///< `Check` bits
  Request power = Request::none;         ///< arm power on / off
  Request hand = Request::none;          ///< on = close the hand, off = open it
  Request zero_gravity = Request::none;  ///< on: the joints yield to a push and stay ("marsh")
  std::uint16_t outputs_set = 0;         ///< output bits to set this sample
  std::uint16_t outputs_clear = 0;       ///< output bits to clear this sample
  SettingChg setting;                    ///< one controller setting per sample
  std::int32_t segment = 0;  ///< the motion segment this sample belongs to (for the log; kept)

  /// Conveniences; `joint` is 0-based.
  void pos(std::size_t joint, double range_target, double velocity = 0.0) noexcept {
    motion[joint] = {SetMode::pos, range_target, velocity};
  }
  void posvel(std::size_t joint, double range_target) noexcept {
    motion[joint] = {SetMode::posvel, range_target, 0.0};
  }
  void stopcal(std::size_t joint) noexcept { motion[joint] = {SetMode::stopcal, 0.0, 0.0}; }
  /// Clears the one-shot commands, keeps the checking mode and the segment.
  void clear_commands() noexcept {
    const std::uint8_t keep = checking;
    const std::int32_t seg = segment;
    *this = Chg{};
    checking = keep;
    segment = seg;
  }
};

/// Per-joint status bits in `JointHow::flags`.
enum JointFlag : std::uint16_t {
  kCalibrated = 1U << 0,           ///< positions are absolute
  kCalibrating = 1U << 1,          ///< a STOPCAL is still seeking
  kNotAnswering = 1U << 2,         ///< the joint's controller did not answer this sample
  kEncoderError = 1U << 3,         ///< the joint's controller flags its encoder
  kObservedPositionOut = 1U << 4,  ///< measured position outside the limits
  kTargetPositionOut = 1U << 5,    ///< a commanded target outside the limits (not sent)
  kObservedVelocityOut = 1U << 6,  ///< measured speed above the joint's maximum
  kTargetVelocityOut = 1U << 7,    ///< a commanded speed above the joint's maximum (not sent)
  kNotCalibratedTarget = 1U << 8,  ///< a position target for a joint that is not calibrated
  kPhaseError = 1U << 9,           ///< the joint's encoder channels switched at once
  kJointFault = 1U << 10,          ///< the joint's controller reports a fault (following error)
};

struct JointHow {
  double range = 0.0;     ///< range value: rad or m above the lower limit
  double q = 0.0;         ///< joint value, rad or m
  double velocity = 0.0;  ///< rad/s or m/s
  std::uint16_t flags = 0;
  [[nodiscard]] bool has(JointFlag f) const noexcept { return (flags & f) != 0; }
};

/// The wrist force/torque sensor as the communication task read it this sample (thesis 4.4.2:
/// a six-axis sensor at the flange whose readings a force transform carries to the tool).
struct ForceHow {
  bool present = false;  ///< this robot has a wrist sensor; the rest means nothing otherwise
  /// The reading as the sensor reports it: the load the tool side puts on the wrist (the
  /// tool's weight, contacts) plus the sensor's bias and noise, about T6's origin in T6's axes
  /// (N, N m). Gravity compensation and the force transform to the tool are the reader's
  /// (rccx::force).
  math::Wrench wrench;
  std::uint32_t sequence = 0;  ///< the sensor's own reading counter: it advances every reading
  bool saturated = false;      ///< an axis stood at its measuring range this sample
  /// The counter has not advanced for kForceFrozenSamples samples: the reading is stale.
  bool frozen = false;
};
/// A force sensor whose reading counter stands still this many samples in a row is frozen.
inline constexpr std::uint32_t kForceFrozenSamples = 3;

/// The state of the arm, as read by the communication task at the start of a sample.
struct How {
  std::uint64_t sample = 0;  ///< sample number since the session was opened (first is 1)
  double time_s = 0.0;       ///< time of this sample, s since the session was opened (nominal)
  std::uint8_t dof = 0;
  std::array<JointHow, kMaxJoints> joint{};
  bool power = false;  ///< arm power on
  bool hand_closed = false;
  bool all_calibrated = false;  ///< every joint calibrated (the thesis's "ALL JOINTS")
  std::uint16_t outputs = 0;    ///< the output bits as they stand
  /// The motor parameters of the joint last examined (Setting::examine), as its controller
  /// holds them; examined_joint is 0-based, -1 before any.
  std::int8_t examined_joint = -1;
  std::array<std::uint8_t, 16> motor_parameters{};
  ForceHow force;  ///< the wrist sensor, when the robot has one

  [[nodiscard]] JointVector q() const noexcept;
  [[nodiscard]] JointVector range() const noexcept;
  [[nodiscard]] JointVector velocity() const noexcept;
  /// The flags of all joints or-ed together.
  [[nodiscard]] std::uint16_t any_flags() const noexcept;
};

/// Why a control session ended (the `terminate` variable). `none` while it runs.
enum class TerminateCode : std::int32_t {
  none = 0,
  user_request = 1,          ///< a control function or the program asked to end
  user_interrupt = 2,        ///< Ctrl-C (the default hang-up handler)
  control_exception = 3,     ///< a control function threw
  overrun = 10,              ///< a control cycle did not finish within its sample period
  observed_position = 20,    ///< a joint was measured outside its limits
  target_position = 21,      ///< a joint was commanded outside its limits
  observed_velocity = 22,    ///< a joint was measured faster than its maximum speed
  target_velocity = 23,      ///< a joint was commanded faster than its maximum speed
  not_calibrated = 24,       ///< a position target for a joint that is not calibrated
  joint_not_answering = 30,  ///< a joint's controller stopped answering (arm powered down)
  encoder_error = 31,        ///< a joint's encoder failed
  power_failure = 32,        ///< arm power was lost (or could not be turned on)
  phase_error = 33,          ///< a joint's encoder reported a phase error
  joint_fault = 34,          ///< a joint's controller reported a fault during motion
  force_saturated = 40,      ///< the wrist force sensor reached its measuring range
  force_frozen = 41,         ///< the wrist force sensor's readings stopped changing
};

/// What each code means, one line, for people.
std::string_view describe(TerminateCode code) noexcept;
std::string_view to_string(TerminateCode code) noexcept;
/// Every code, in order (for `rccx rtc codes` and the tests).
std::span<const TerminateCode> all_terminate_codes() noexcept;
/// True for the codes after which the arm is powered down rather than held.
bool powers_down(TerminateCode code) noexcept;

inline constexpr std::size_t kMessageCapacity = 128;

/// How a control session ended: the terminate code, where, when, and the `rtc_message`.
struct Termination {
  TerminateCode code = TerminateCode::none;
  int joint = 0;             ///< 1-based joint the code is about, 0 when none
  std::uint64_t sample = 0;  ///< the sample in which the session ended
  double time_s = 0.0;
  std::array<char, kMessageCapacity> message{};  ///< rtc_message: a control function's last word
  std::array<char, kMessageCapacity> detail{};   ///< what the communication task saw

  [[nodiscard]] bool ended() const noexcept { return code != TerminateCode::none; }
  [[nodiscard]] std::string_view message_view() const noexcept;
  [[nodiscard]] std::string_view detail_view() const noexcept;
};

/// Prints the termination's meaning on one line (the thesis's print_terminate_code()).
void print_terminate_code(const Termination& t, std::FILE* out = stdout);
/// Prints every terminate code with its meaning.
void print_terminate_codes(std::FILE* out = stdout);

}  // namespace rccx::rtc
