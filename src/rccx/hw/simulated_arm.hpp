// What sits below the wire of a simulated arm: joint servos stepped at 1 kHz on a plant, read
// and commanded the way a communication task reads and commands real joint controllers (an
// encoder count and a few status bits per joint; a target and a speed per joint). The RTC
// driver (rtc/servo_driver.hpp) is the only intended client; tests also read the plant's true
// state to check what the servo really did.
//
//   using hw::ServoCommand;
//   const auto arm = hw::make_simulated_arm(kin::builtin_robot("puma560"));   // PID servos
//   arm->command(1, {ServoCommand::Kind::move, 90_deg, 20_deg});   // joint 2: 90 deg at 20 deg/s
//   arm->advance_to(1.0);                            // 1000 servo ticks: t = 1 s
//   const hw::JointReading r = arm->read(1);         // encoder counts and status bits
//   arm->true_position()[1];                         // the plant itself, rad
//
// Time is whatever the caller says it is: advance_to(t) runs the servo ticks up to t, so the
// same arm serves simulated time (deterministic) and real time (catch up on each read).
// Every call is noexcept and allocation-free: the communication task makes them every sample.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>

#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/wrench.hpp"

namespace rccx::hw {

/// The servo rate of every simulated arm (the Unimation joint micros ran at about 1 kHz).
inline constexpr double kServoPeriod_s = 1e-3;

/// What one joint's servo is told.
struct ServoCommand {
  enum class Kind : std::uint8_t {
    move,       ///< take `target` as the new goal, reached at `rate`
    hold,       ///< stop where the joint is now (decelerating as the servo can) and stay there
    calibrate,  ///< seek the calibration position (the ready pose) slowly, then zero the encoder
  };
  Kind kind = Kind::hold;
  double target = 0.0;  ///< joint value, rad or m
  /// rad/s or m/s: the servo's own setpoint travels to `target` at this speed; 0 makes it a
  /// step (the setpoint jumps to target at once).
  double rate = 0.0;
};
// Before calibration a joint controller knows only its encoder, so `target` is then taken
// relative to the power-up position (as the counts are); a calibrate command seeks the true
// ready pose. The simulated arms answer but ignore commands while power is off or zero gravity
// is on (power-on and leaving zero gravity both hold the present position), and refuse (false)
// a non-finite target or rate.

/// One joint as the communication task sees it after a read.
struct JointReading {
  bool answered = true;     ///< false: the joint controller did not answer (fault)
  std::int64_t counts = 0;  ///< encoder counts; joint value = counts x resolution once calibrated
  bool encoder_error = false;  ///< the controller flags its encoder (count jump, lost phase)
  bool calibrated = false;     ///< counts are absolute (zero at joint value zero)
  bool calibrating = false;    ///< a calibrate command is still seeking
};

enum class Fault : std::uint8_t {
  joint_not_answering,  ///< the joint's controller stops answering reads and commands
  encoder_error,        ///< the joint's encoder reports an error and its counts jump
  power_loss,           ///< arm power drops (brakes on) and cannot be turned back on
};
std::string_view to_string(Fault f) noexcept;

struct Scene;  // mjcf.hpp: what surrounds a MuJoCo arm

/// Which plant simulates the arm (kin::Plant, the robot file's "plant"): automatic, ideal
/// (IdealArm), servo (SimulatedPuma) or mujoco (MujocoArm).
using Plant = kin::Plant;

/// How a simulated arm starts.
struct SimulatedArmOptions {
  kin::JointVector initial;  ///< initial joint values, rad or m; empty: the model's ready pose
  bool calibrated = true;  ///< false: counts are relative to the initial position until calibrated
  bool powered = true;     ///< arm power on (servo holding the initial position) or off (brakes)
  /// The plant; automatic: the robot file's "plant", and when that is automatic too, the
  /// simulated PUMA or the ideal servo as make_simulated_arm says.
  Plant plant = Plant::automatic;
  /// What surrounds a MuJoCo arm (the table, objects, the tool, the base's place); null: the
  /// robot file's scene ("hardware": {"mujoco": ...}, hw::scene_from_file), else nothing and
  /// the base at the world's origin. Other plants ignore it.
  std::shared_ptr<const Scene> scene;
};

class SimulatedArm {
 public:
  virtual ~SimulatedArm() = default;
  SimulatedArm() = default;
  SimulatedArm(const SimulatedArm&) = delete;
  SimulatedArm& operator=(const SimulatedArm&) = delete;

  [[nodiscard]] virtual const kin::RobotModel& model() const noexcept = 0;
  [[nodiscard]] std::size_t dof() const noexcept { return model().dof(); }

  /// Runs servo ticks until the arm's time reaches t_s (s); earlier times do nothing.
  virtual void advance_to(double t_s) noexcept = 0;
  [[nodiscard]] virtual double time_s() const noexcept = 0;

  /// Reads one joint (0-based). A joint that does not answer returns answered = false.
  [[nodiscard]] virtual JointReading read(std::size_t joint) const noexcept = 0;
  /// Sends one joint a command; false (and nothing happens) when the joint does not answer.
  virtual bool command(std::size_t joint, const ServoCommand& c) noexcept = 0;

  /// Arm power: off applies the brakes (joints stop and stay); on resumes servoing where the
  /// joints are. Turning power on fails (returns false) after a power-loss fault.
  virtual bool set_power(bool on) noexcept = 0;
  [[nodiscard]] virtual bool power() const noexcept = 0;
  /// The gripper relay pair: closed or open.
  virtual void set_hand_closed(bool closed) noexcept = 0;
  [[nodiscard]] virtual bool hand_closed() const noexcept = 0;
  /// Sixteen output bits (the controller's digital outputs).
  virtual void set_outputs(std::uint16_t bits) noexcept = 0;
  [[nodiscard]] virtual std::uint16_t outputs() const noexcept = 0;

  /// Zero-gravity servoing ("marsh"): the servo yields to external effort, compensating
  /// gravity, so a pushed joint follows the push and stays where it is left.
  virtual void set_zero_gravity(bool on) noexcept = 0;
  /// An external torque (N m) or force (N) on a joint, e.g. a hand pushing it; 0 removes it.
  virtual void set_external_effort(std::size_t joint, double effort) noexcept = 0;

  virtual void inject(Fault fault, std::size_t joint) noexcept = 0;
  virtual void clear_faults() noexcept = 0;

  /// The plant's true state, not through encoders: for tests and the viewer.
  [[nodiscard]] virtual kin::JointVector true_position() const noexcept = 0;
  [[nodiscard]] virtual kin::JointVector true_velocity() const noexcept = 0;

  /// The true load on the wrist, as an ideal six-axis sensor mounted at the flange would feel
  /// it: the wrench the tool side (the tool's weight and whatever touches it) exerts on the
  /// arm, about T6's origin in T6's axes (N, N m), where T6 is the kinematic model's last frame.
  /// False, and `w` untouched, when this arm has no sensor (no contact model): only a plant
  /// with contact (MujocoArm) has one. Called by the communication task every sample.
  [[nodiscard]] virtual bool wrist_wrench(math::Wrench& w) const noexcept {
    (void)w;
    return false;
  }
};

/// The simulated arm for a model: the plant options.plant names, else the one the robot file's
/// "plant" names (MujocoArm, mujoco_arm.hpp: MuJoCo with contact and a wrist sensor; or one of
/// the two below), else a SimulatedPuma (simulated_puma.hpp: joint PID servos on a plant with
/// inertia, friction and gravity) when every joint has dynamics (inertia and max_effort given),
/// else an IdealArm (ideal_arm.hpp: joints follow their setpoints at up to their top speed).
/// Throws std::invalid_argument for an unusable model or initial pose, or a servo plant for a
/// model without dynamics.
std::unique_ptr<SimulatedArm> make_simulated_arm(const kin::RobotModel& model,
                                                 const SimulatedArmOptions& options = {});

}  // namespace rccx::hw
