// What every simulated arm shares, whatever moves its joints: the servo clock, each joint's
// setpoint travelling to its goal, encoders and calibration, arm power and brakes, hard stops,
// faults, the hand and the output bits. A derived arm supplies only the plant and its servo
// (servo_tick), which runs while power is on:
//
//   class MyArm final : public hw::ArmBase {
//    public:
//     explicit MyArm(kin::RobotModel m) : ArmBase(std::move(m), {}) {}
//    private:
//     void servo_tick(double dt) noexcept override;   // dt s: move joints_[j].q, .qd toward
//   };                                                // .setpoint, then clamp_to_stops()
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "rccx/hw/simulated_arm.hpp"

namespace rccx::hw {

/// Hard stops sit this far beyond a revolute joint's limits (1 deg), rad.
inline constexpr double kHardStopMargin_rad = 0.017453292519943295;
/// ... and this far beyond a prismatic joint's limits, m.
inline constexpr double kHardStopMargin_m = 0.002;
/// No joint moves faster than this times its max_velocity: the ideal servo's cap, and the
/// no-load speed of the simulated PUMA's motors. Above 1 so that a limit check set at
/// max_velocity can see a joint driven too fast.
inline constexpr double kOverspeedFactor = 1.25;
/// The brakes stop a joint moving at max_velocity within this time, s (less than
/// kOverspeedFactor times that from any speed a joint can reach).
inline constexpr double kBrakeStopTime_s = 0.05;
/// A calibrate command seeks the ready pose at this fraction of max_velocity.
inline constexpr double kCalibrationSpeedFactor = 0.1;
/// Calibration completes when the joint is within this many counts of the ready value...
inline constexpr double kCalibrationTolerance_counts = 3.0;
/// ... and slower than this fraction of max_velocity.
inline constexpr double kCalibrationStillFactor = 0.01;
/// An encoder_error fault shifts the joint's counts by this much.
inline constexpr std::int64_t kEncoderErrorJump_counts = 4096;

/// Velocity damping in zero gravity, as a multiple of the joint's inertia, 1/s.
inline constexpr double kZeroGravityDamping_per_s = 20.0;

/// The gains of the joint servo the physical plants share (SimulatedPuma, MujocoArm).
struct ServoGains {
  double kp = 0.0;  ///< N m/rad or N/m
  double ki = 0.0;  ///< N m/(rad s) or N/(m s)
  double kd = 0.0;  ///< N m s/rad or N s/m
};

/// Gains that put the three closed-loop poles of a joint of inertia I at -w (rad/s):
/// Kp = 3 I w^2, Kd = 3 I w, Ki = I w^3.
constexpr ServoGains servo_gains(double inertia, double bandwidth_rad_per_s) noexcept {
  const double w = bandwidth_rad_per_s;
  return {3.0 * inertia * w * w, inertia * w * w * w, 3.0 * inertia * w};
}

class ArmBase : public SimulatedArm {
 public:
  [[nodiscard]] const kin::RobotModel& model() const noexcept final { return model_; }

  void advance_to(double t_s) noexcept final;
  [[nodiscard]] double time_s() const noexcept final;

  [[nodiscard]] JointReading read(std::size_t joint) const noexcept final;
  bool command(std::size_t joint, const ServoCommand& c) noexcept final;

  bool set_power(bool on) noexcept final;
  [[nodiscard]] bool power() const noexcept final { return power_; }
  void set_hand_closed(bool closed) noexcept final { hand_closed_ = closed; }
  [[nodiscard]] bool hand_closed() const noexcept final { return hand_closed_; }
  void set_outputs(std::uint16_t bits) noexcept final { outputs_ = bits; }
  [[nodiscard]] std::uint16_t outputs() const noexcept final { return outputs_; }

  void set_zero_gravity(bool on) noexcept final;
  /// Also the effort's sign convention: positive pushes the joint value up.
  void set_external_effort(std::size_t joint, double effort) noexcept final;

  void inject(Fault fault, std::size_t joint) noexcept final;
  void clear_faults() noexcept final;

  [[nodiscard]] kin::JointVector true_position() const noexcept final;
  [[nodiscard]] kin::JointVector true_velocity() const noexcept final;

  /// Where joint j's hard stops are (its limits widened by the hard-stop margin), rad or m.
  [[nodiscard]] double lower_stop(std::size_t j) const noexcept { return joints_[j].stop_lo; }
  [[nodiscard]] double upper_stop(std::size_t j) const noexcept { return joints_[j].stop_hi; }
  /// The servo's present setpoint for joint j (true joint value, rad or m).
  [[nodiscard]] double setpoint(std::size_t j) const noexcept { return joints_[j].setpoint; }
  [[nodiscard]] bool zero_gravity() const noexcept { return zero_gravity_; }

 protected:
  /// Checks the model and the options; throws std::invalid_argument when they cannot be used.
  ArmBase(kin::RobotModel model, const SimulatedArmOptions& options);

  struct JointState {
    double q = 0.0;                       ///< true position, rad or m
    double qd = 0.0;                      ///< true velocity, rad/s or m/s
    double goal = 0.0;                    ///< where the setpoint is going (true joint value)
    double rate = 0.0;                    ///< how fast it goes there; 0: at once
    double setpoint = 0.0;                ///< what the servo follows this tick (true joint value)
    double setpoint_velocity = 0.0;       ///< its rate of change this tick (0 after a step)
    double external = 0.0;                ///< external effort, N m or N
    double stop_lo = 0.0, stop_hi = 0.0;  ///< hard stops
    double max_velocity = 0.0;            ///< the model's, rad/s or m/s
    double resolution = 0.0;              ///< encoder, rad or m per count
    double origin = 0.0;                  ///< true joint value where the counts are zero
    std::int64_t count_jump = 0;          ///< added to the counts by an encoder fault
    bool calibrated = false;
    bool calibrating = false;
    bool encoder_error = false;
    bool not_answering = false;
  };

  /// One servo period with power on: move q and qd of every joint (the setpoints are already
  /// advanced). In zero gravity the setpoints follow the joints, and the servo must yield.
  virtual void servo_tick(double dt) noexcept = 0;
  /// The joint servo of the physical plants, one tick of joint `s`: the motor effort (N m or
  /// N) of  tau = Kp e + Ki int(e) + Kd (v_sp - qd) + B v_sp + hold  (e = setpoint - q, B the
  /// viscous friction, hold the gravity load), the integrator running only while |Kp e| is
  /// below max_effort and the output is not saturated (`integral` carries it, e s); limited to
  /// max_effort, and along the motion on the motor's torque-speed line (zero at
  /// kOverspeedFactor x max_velocity). Zero gravity: hold - kZeroGravityDamping_per_s I qd.
  [[nodiscard]] double servo_effort(const JointState& s, const ServoGains& g, double inertia,
                                    double viscous, double max_effort, double hold, double dt,
                                    double& integral) const noexcept;
  /// The servo of joint j restarts from the present position (power on, zero gravity off):
  /// drop any state such as an integrator.
  virtual void on_servo_restart(std::size_t j) noexcept { (void)j; }

  /// Keeps q within the hard stops; a joint that hits one stops dead.
  void clamp_to_stops(JointState& s) const noexcept;

  std::array<JointState, kin::kMaxJoints> joints_{};
  std::size_t n_ = 0;

 private:
  void tick() noexcept;
  void advance_setpoint(JointState& s, double dt) const noexcept;
  void hold_here(std::size_t j) noexcept;

  kin::RobotModel model_;
  std::int64_t ticks_ = 0;
  bool power_ = true;
  bool power_lost_ = false;
  bool zero_gravity_ = false;
  bool hand_closed_ = false;
  std::uint16_t outputs_ = 0;
};

}  // namespace rccx::hw
