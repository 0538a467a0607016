// One Microbo joint micro (thesis 2.5, Appendix B) and the joint it drives: the register
// handshake, every command of Appendix B.3, the vendor's joint law at 1 ms, the encoder with its
// work areas, and the plant. Internal to rccx::hw: Rcu (rcu.hpp) owns up to eight of these.
//
// POSITIONS. The micro counts encoder edges in a counter P = A - 50000 x area wider than 16
// bits; the register E the master reads is P's low 16 bits, and a target the master sends is
// taken in P's frame (0..65535). Past 65535 or below 0 the register wraps while the joint law
// goes on undisturbed: the wrap is undetected (thesis 4.4.3), and a master that misses it
// misplaces the joint by 65536 counts. CHANGE WORK AREA moves P, the target and the reference
// by 50000 together (accepted when P > 50000 or P < 15535), so the joint does not move.
//
// THE JOINT LAW (our emulation of thesis 2.5.2 and figure 2.7; the vendor never published it,
// and the thesis describes it from observation). All positions are in P's frame. Each 1 ms
// tick:
//
// 1. Reference. The micro does not servo to the target directly: it moves an internal
//    reference r toward it.
//    - Dynamic regulation zone, |target - r| > Z (Z = static zone size, motor byte 4): the
//      reference accelerates at the acceleration setting up to the speed setting x speed factor
//      (capped by motor byte 5), and decelerates so as to reach the edge of the static zone at
//      the static speed: its speed is min(v, sqrt(vs^2 + 2 a (|target - r| - Z))), changed by at
//      most a per tick. A target sent every sample is therefore approached with deceleration
//      every sample unless it stays further ahead than the braking distance (the follow scheme).
//    - Static regulation zone, |target - r| <= Z: the acceleration setting is ignored and the
//      reference creeps to the target at the static speed vs (motor byte 8).
// 2. Effort. A servo with the inertia estimate J^ = J x byte13/128 and bandwidth wp (byte 1):
//    Kp = J^ wp^2, Kd = 1.4 J^ wp (damping 0.7) on the reference velocity minus the encoder
//    velocity (averaged over 4 ms), an integral term with Ki = Kp x byte6/8 (1/s) in the
//    dynamic zone; in the static zone the proportional gain drops to Kp/16 and the integral to
//    Ki = Kp x byte7/8, so that the integral dominates: with the defaults the static-zone loop
//    J s^3 + Kd s^2 + Kp/16 s + Ki has a slow pair near 10 rad/s with damping about 0.2
//    (thesis: "the joints may exhibit severely underdamped response when subjected to a small
//    sustained force"). Feedforward: J^ x reference acceleration (dynamic zone), the viscous and
//    dry friction estimates (bytes 14, 15) on the reference velocity, and the gravity
//    compensation (byte 12: 128ths of the configured load). The integral is kept as an effort
//    (switching zones does not jump) and stops integrating while the effort is saturated.
// 3. Stiffness. The effort is clamped to +-max_effort x s with
//        s = min(1, max(speed setting x factor / 32, acceleration setting / 32)):
//    full at the default speed (32) or an acceleration setting of 32 (8 rad/s^2 of the motor)
//    and above, shrinking in proportion below both (thesis: "When the last velocity and
//    acceleration sent to a joint are small, the joint loses its stiffness, and fails to
//    maintain its position under even the most negligible load"). Joint 2 then sags under its
//    own weight once s x max_effort + dry friction < its weight.
// 4. Faults. |r - E| beyond the sensor error tolerance (byte 3 x 64 counts) sets the fault bit
//    and puts the joint in stand-by (servo off, brake on). A later position command (or
//    INITIALIZE) clears the bit.
//
// INITIALIZE: the reference runs toward the calibration stop at the initialization speed
// (byte 2 x 16 speed units) with full stiffness; after 100 ms, 20 ticks in a row with the
// encoder slower than a quarter of that speed mean the joint stalled at the stop: the register
// gets the value sent (area 0), target and reference jump there, and the joint holds, with the
// status bit "initialized".
//
// Stand-by and power off: the servo is off and the brake acts as a dry friction of twice the
// max effort (holding the vertical joint 2 and a push of up to that size). Motor bytes 9, 10,
// 11 (thermal model) and 16 (maximum acceleration/4) are stored and readable but not used.
//
// THE PLANT, integrated in 4 sub-steps per tick (semi-implicit Euler): inertia, viscous and
// dry friction (static = dynamic), a constant gravity load, an external effort, and hard stops
// at which the joint stops dead.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>

#include "rccx/hw/rcu.hpp"

namespace rccx::hw::detail {

/// Plant sub-steps per joint law tick.
inline constexpr int kRcuPlantSubsteps = 4;
inline constexpr std::int64_t kRcuSubstep_us = kRcuTick_us / kRcuPlantSubsteps;
/// The stiffness scale s reaches 1 at these settings (speed x factor / 100, acceleration).
inline constexpr double kFullStiffnessSpeed = 32.0;
inline constexpr double kFullStiffnessAcceleration = 32.0;
/// The brake holds up to this multiple of the joint's max effort.
inline constexpr double kBrakeEffortFactor = 2.0;
/// An encoder_error fault moves the joint's counts by this much.
inline constexpr std::int64_t kRcuEncoderJump_counts = 4096;

class RcuJoint {
 public:
  /// Sets the joint up at q0 (rad or m): in stand-by; initialized (the register reads what
  /// INITIALIZE would have made it, in the work area whose band holds it) or not (reads 0).
  void setup(const RcuJointConfig& config, double resolution_per_count, double q0,
             bool initialized) noexcept;

  // Registers (no time passes); `now_us` is the RCU's time.
  [[nodiscard]] std::uint8_t read_status() const noexcept;
  [[nodiscard]] std::uint8_t read_data(std::int64_t now_us) noexcept;
  /// False when the byte was lost (IBE still set, or the joint does not answer).
  bool write(bool command, std::uint8_t value, std::int64_t now_us) noexcept;

  /// When the next byte is taken or given (-1: nothing pending).
  [[nodiscard]] std::int64_t next_event_us() const noexcept;
  /// Takes or gives whatever byte is due at now_us.
  void service(std::int64_t now_us) noexcept;

  /// One tick of the joint law (every kRcuTick_us).
  void tick() noexcept;
  /// Moves the plant on by h seconds with the effort of the last tick.
  void plant_step(double h) noexcept;
  /// Arm power (the amplifiers): off puts the joint in stand-by; on lets it leave stand-by
  /// again (on a position command or INITIALIZE).
  void set_power(bool on) noexcept;

  // Faults.
  void set_not_answering() noexcept { not_answering_ = true; }
  void set_encoder_error() noexcept;
  void set_phase_error() noexcept { phase_error_ = true; }
  void set_fault() noexcept;  ///< fault bit, stand-by (power loss)
  void clear_faults() noexcept;
  void set_external_effort(double effort) noexcept { external_ = effort; }

  // The truth.
  [[nodiscard]] double q() const noexcept { return q_; }
  [[nodiscard]] double qd() const noexcept { return qd_; }
  [[nodiscard]] std::int64_t absolute_counts() const noexcept;
  [[nodiscard]] int area() const noexcept { return area_; }
  [[nodiscard]] std::uint64_t lost_bytes() const noexcept { return lost_bytes_; }
  [[nodiscard]] bool standby() const noexcept { return mode_ == Mode::standby; }
  [[nodiscard]] double reference() const noexcept { return r_; }
  [[nodiscard]] bool static_zone() const noexcept { return static_zone_; }
  /// The micro's position counter P = A - 50000 x area (not limited to 16 bits).
  [[nodiscard]] std::int32_t position() const noexcept;
  /// The register E: P's low 16 bits (it wraps).
  [[nodiscard]] std::uint16_t encoder() const noexcept;
  [[nodiscard]] std::uint8_t status_byte() const noexcept;

 private:
  enum class Mode : std::uint8_t { standby, servo, initializing };

  void take(bool command, std::uint8_t value, std::int64_t now_us) noexcept;
  void start_command(std::uint8_t command, std::int64_t now_us) noexcept;
  void execute(std::uint8_t command) noexcept;
  void answer(std::initializer_list<std::uint8_t> bytes, std::int64_t now_us) noexcept;
  void answer_word(std::uint16_t w, std::int64_t now_us) noexcept;
  [[nodiscard]] std::uint16_t data_word() const noexcept;
  void leave_standby() noexcept;
  void enter_standby() noexcept;
  void restart_law() noexcept;  ///< reference and integral start at the present position
  void change_work_area() noexcept;
  void assign(std::uint16_t value) noexcept;  ///< the register reads value here (area 0)
  [[nodiscard]] std::uint8_t motor(std::size_t i) const noexcept {
    return ram_[kRcuRamMotorParameters + i];
  }

  // Configuration.
  RcuJointConfig c_{};
  double resolution_ = 0.0;         ///< rad or m per count
  double speed_unit_ = 0.0;         ///< counts/ms per speed unit
  double acceleration_unit_ = 0.0;  ///< counts/ms^2 per acceleration unit
  int seek_direction_ = -1;         ///< toward the calibration stop

  // Plant.
  double q_ = 0.0, qd_ = 0.0;
  double external_ = 0.0;
  double effort_ = 0.0;  ///< motor effort of the last tick, N m or N

  // Encoder: A = floor(q / resolution + offset); P = A - 50000 x area; E = P modulo 65536.
  double offset_ = 0.0;
  int area_ = 0;

  // Joint micro registers and state.
  Mode mode_ = Mode::standby;
  bool initialized_ = false;
  bool fault_ = false;
  bool encoder_error_ = false;
  bool phase_error_ = false;
  bool tolerance_mode_ = false;
  bool not_answering_ = false;
  bool power_ = true;
  std::int32_t target_ = 0;  ///< in P's frame (may leave 0..65535 after an area change)
  std::uint16_t speed_ = 32, acceleration_ = 1, tolerance_ = 0;
  std::uint8_t speed_factor_ = kRcuDefaultSpeedFactor;
  std::uint16_t ram_pointer_ = kRcuRamVersion;
  std::array<std::uint8_t, kRcuRamSize> ram_{};

  // The law.
  double r_ = 0.0;         ///< reference, counts (P's frame)
  double rv_ = 0.0;        ///< reference velocity, counts/ms
  double ra_ = 0.0;        ///< reference acceleration this tick, counts/ms^2
  double integral_ = 0.0;  ///< integral term, N m or N
  bool static_zone_ = true;
  std::array<std::int32_t, 5> history_{};  ///< P at the last 5 ticks (velocity over 4 ms)
  std::size_t history_at_ = 0;
  int seek_ticks_ = 0, stall_ticks_ = 0;
  std::uint16_t initialize_value_ = 0;

  // Handshake.
  bool ibe_ = false, obf_ = false;
  bool in_is_command_ = false;
  std::uint8_t in_byte_ = 0;
  std::int64_t take_at_us_ = -1;
  std::uint8_t data_register_ = 0;
  std::array<std::uint8_t, 2> out_{};
  std::size_t out_len_ = 0, out_next_ = 0;
  std::int64_t give_at_us_ = -1;
  std::uint8_t command_ = 0;  ///< waiting for data bytes
  bool waiting_data_ = false;
  std::array<std::uint8_t, 16> in_{};
  std::size_t in_need_ = 0, in_have_ = 0;
  std::uint64_t lost_bytes_ = 0;
};

}  // namespace rccx::hw::detail
