// The Microbo's driver: the thesis's 86/30 communication task (4.4.3, 4.5) behind RTC's
// Driver interface, talking to the RCU only through a Bus (register bytes) and its Relays, so
// that the emulator (hw::RcuBus) or a real bus adapter may sit below it.
//
//   const kin::RobotModel model = kin::builtin_robot("microbo");
//   hw::Rcu rcu(model);                              // the emulated RCU, also the Relays
//   hw::RcuBus bus(rcu);                             // 75 us a bus exchange
//   rtc::MicroboDriver driver(model, bus, rcu);
//   rtc::Session session(driver, {.period = 28ms});  // about 10 ms of bus traffic a sample
//
// Each sample, per joint: GET STATUS, GET POSITION, then SET TARGET and SET SPEED by the
// synchronous "follow" scheme: with Xd the position the joint should reach at the end of the
// next period and Xm the measured one, the target X = Xd + (Xd - Xm) stays far enough ahead
// that the vendor's joint law never starts to decelerate, and the speed V = K (Xd - Xm) sets
// the pace. Joints 1 and 3, whose ranges need several 16-bit work areas, change area by
// themselves when their encoder passes a threshold (thesis figure 4.4), and are never
// commanded faster than a sample can carry them through a transition zone. Encoder counts,
// range values and joint values are converted here; calibration is the joint-level INITIALIZE.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "rccx/hw/bus.hpp"
#include "rccx/hw/rcu.hpp"
#include "rccx/rtc/driver.hpp"
#include "rccx/rtc/velocity_estimator.hpp"

namespace rccx::rtc {

/// The results of Appendix B.4's put_cmd, put_dat and get_dat, named as there.
enum class BusError : std::uint8_t {
  ok,
  timeout_cmd,            ///< TIMEOUT_CMD: the joint stayed busy, the command was not sent
  timeout_put,            ///< TIMEOUT_PUT: the joint stayed busy, a data byte was not sent
  timeout_get,            ///< TIMEOUT_GET: no data byte came back
  invalid_joint_command,  ///< INVALID_JNT_CMD: no such joint, or no such command
};
std::string_view to_string(BusError e) noexcept;

/// How targets go to the joints: the thesis's follow scheme, or raw (the next setpoint itself
/// as the target, at a speed that would cover the step in one period): the vendor law then
/// decelerates at every target, which is what the follow scheme cures.
enum class TargetScheme : std::uint8_t { follow, raw };

struct MicroboDriverOptions {
  TargetScheme scheme = TargetScheme::follow;
  /// Status reads before a TIMEOUT_*: each is one bus exchange (75 us on the RCU).
  int polls = 20;
  /// The work area each joint is in now, known since its last calibration (the RCU does not
  /// say); calibration sets it to 0.
  std::array<int, kMaxJoints> work_areas{};
};

class MicroboDriver final : public Driver {
 public:
  /// `bus` and `relays` must outlive the driver. Throws std::invalid_argument when the model
  /// has no RCU block (hw::rcu_config).
  MicroboDriver(const kin::RobotModel& model, hw::Bus& bus, hw::Relays& relays,
                MicroboDriverOptions options = {});

  [[nodiscard]] const kin::RobotModel& model() const noexcept override { return model_; }
  void read(double t_s, How& how) noexcept override;
  void send(const JointCommands& commands) noexcept override;
  void hold() noexcept override;
  bool set_power(bool on) noexcept override;
  void set_hand_closed(bool closed) noexcept override;
  void set_zero_gravity(bool on) noexcept override;
  void set_outputs(std::uint16_t bits) noexcept override;
  /// The top speed, and for joints with work areas the speed that crosses the smaller
  /// transition zone in one period (thesis 4.4.3: joint 3, 173 mm/s at 56 ms).
  [[nodiscard]] double velocity_limit(std::size_t joint, double period_s) const noexcept override;
  [[nodiscard]] std::string_view fault_detail(std::size_t joint) const noexcept override;
  /// A sample's bus traffic: 22 exchanges a joint (status, position, target, speed) and a
  /// work-area change for each joint that has them, with a tenth to spare.
  [[nodiscard]] double minimum_period_s() const noexcept override;
  /// Acceleration (10H), speed factor (2CH), the motor parameters k, K, V, z (0EH with the
  /// other 15 as last sent) and examine (RAM reads 22H / 2EH, in the next read).
  bool apply(const SettingChg& setting) noexcept override;

  // Appendix B.4, with `joint` 0-based. Each register access is one bus exchange.
  BusError put_cmd(std::size_t joint, std::uint8_t command) noexcept;
  BusError put_dat(std::size_t joint, std::uint8_t data) noexcept;
  BusError get_dat(std::size_t joint, std::uint8_t& data) noexcept;
  /// A command with a 16-bit word of data (low byte first), to or from the joint.
  BusError put_word(std::size_t joint, std::uint8_t command, std::uint16_t value) noexcept;
  BusError get_word(std::size_t joint, std::uint8_t command, std::uint16_t& value) noexcept;
  BusError get_byte(std::size_t joint, std::uint8_t command, std::uint8_t& value) noexcept;

  /// Absolute encoder counts (E + 50000 x area) of joint value q (rad or m), and back.
  [[nodiscard]] double counts_of(std::size_t joint, double q) const noexcept;
  [[nodiscard]] double joint_value_of(std::size_t joint, double counts) const noexcept;
  [[nodiscard]] int work_area(std::size_t joint) const noexcept { return joints_[joint].area; }
  [[nodiscard]] const hw::RcuConfig& config() const noexcept { return config_; }

 private:
  struct JointState {
    int area = 0;
    bool initialized = false;
    bool calibrating = false;
    BusError error = BusError::ok;
    double measured = 0.0;   ///< absolute counts at the last read
    double desired = 0.0;    ///< Xd: where the joint is to be at the end of this period, counts
    double goal = 0.0;       ///< where a POS / POSVEL command goes, counts
    double rate = 0.0;       ///< counts/s toward goal; 0 = at once
    double pace = 0.0;       ///< counts/s the desired point moves at now (signed)
    bool following = false;  ///< a goal is being followed (else: holding `desired`)
    bool set_up = false;     ///< the follow acceleration was sent since the last INITIALIZE
    bool returning = false;  ///< calibrated at the stop, on the way back inside the range
    bool yielding = false;   ///< the joint's integration is off for zero gravity
  };

  /// The desired point of a POS motion accelerates at this fraction of what the joint's
  /// follow acceleration setting gives, so that the joint can keep up without overshoot.
  static constexpr double kPaceAccelerationFraction = 0.5;
  /// A joint within this many counts of where calibration returns it has arrived.
  static constexpr double kSettledCounts = 20.0;
  /// ... and at rest when it moved no more than this between two reads.
  static constexpr double kStillCounts = 2.0;

  /// One joint's status and position into `out` (q, flags); true when it is calibrated.
  bool read_joint(std::size_t j, JointHow& out) noexcept;
  /// INITIALIZE found the stop: the joint goes back inside its range.
  void start_return_from_stop(std::size_t j, JointState& s) noexcept;
  /// The examined joint's motor parameters, from its micro's RAM.
  void read_motor_parameters() noexcept;
  void follow(std::size_t j, JointState& s) noexcept;
  /// The desired point one period further towards the goal (POS / POSVEL).
  void advance_desired(std::size_t j, JointState& s, double period) noexcept;
  /// The target and speed setting this sample, by the follow or the raw scheme.
  void send_target(std::size_t j, JointState& s, double previous, double period) noexcept;
  /// Sends joint j's 16 motor parameters (0EH): as last set, with the integration constants
  /// zeroed while `yielding`.
  BusError send_motor_parameters(std::size_t j, bool yielding) noexcept;
  std::uint16_t speed_setting(std::size_t j, double counts_per_s) const noexcept;

  kin::RobotModel model_;
  hw::RcuConfig config_;
  hw::Bus& bus_;
  hw::Relays& relays_;
  MicroboDriverOptions options_;
  std::array<JointState, kMaxJoints> joints_{};
  VelocityEstimator velocity_;
  double last_read_s_ = -1.0;
  double period_s_ = 0.028;  ///< measured between reads
  bool zero_gravity_ = false;
  std::size_t reads_ = 0;
  std::array<std::array<std::uint8_t, 16>, kMaxJoints> motor_parameters_{};  ///< as last sent
  int examine_ = -1;  ///< joint whose motor parameters the next read fetches
  std::int8_t examined_ = -1;
  std::array<std::uint8_t, 16> examined_parameters_{};
};

}  // namespace rccx::rtc
