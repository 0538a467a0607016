// Another process's robot as this process sees it from its RobotState samples: its tool frame
// (for a follower's equation, extrapolated in the sample loop without a lock) and its motion
// ledger (for gates and waits). Written by one middleware thread; read by any thread.
//
//   net::RobotMirror puma("puma");
//   puma.apply(state, steady_now_ns);                        // middleware thread, every sample
//   auto t = net::remote_frame("puma_TOOL", "frame:puma", &puma.frame, 20ms);  // a functional
//   rccl::EventGate g{&puma.ledger, rccl::EventGate::Kind::ended, 7};           // a gate
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>

#include "rccx/cell/seqlock.hpp"
#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/math/transform.hpp"
#include "rccx/rccl/motion_sync.hpp"
#include "rccx/rccl/transforms.hpp"
#include "rccx_net.h"

namespace rccx::net {

/// A frame in the world with its motion, as the last sample gave it (trivially copyable).
struct FrameState {
  math::Transform pose;              ///< world <- frame, m
  math::Vec3 velocity_m_per_s;       ///< of pose.p
  math::Vec3 acceleration_m_per_s2;  ///< of pose.p
  math::Vec3 angular_velocity_rad_s;
  std::int64_t stamp_ns = 0;  ///< CLOCK_REALTIME the pose stands for
};

/// A functional transform `name` (with `reference`) whose value is `source`'s newest frame
/// extrapolated to the time the sample's setpoint is for (by velocity and acceleration, and the
/// angular velocity), at most `max_extrapolation` past the sample's stamp: a source that falls
/// silent leaves the goal standing still there instead of running away. The planning level (no
/// rtc::How in the context) gets the newest pose as it is. `source` must outlive the transform.
[[nodiscard]] rccl::TransformPtr remote_frame(std::string name, std::string reference,
                                              const cell::SeqLock<FrameState>* source,
                                              std::chrono::nanoseconds max_extrapolation);

/// A remote robot's newest commanded joints (rad / m) and when they came (steady clock, ns):
/// what the collision check places its capsules from.
struct JointsSample {
  kin::JointVector q;
  kin::JointVector qd;  ///< rad/s / m/s
  std::int64_t received_ns = 0;
};

/// One remote robot: its newest frame, joints and ledger, and whether it is alive.
class RobotMirror {
 public:
  explicit RobotMirror(std::string_view robot) : ledger(robot), name_(robot) {}
  RobotMirror(const RobotMirror&) = delete;
  RobotMirror& operator=(const RobotMirror&) = delete;

  [[nodiscard]] const std::string& name() const noexcept { return name_; }

  /// Middleware thread: takes a state sample received at `steady_ns` (steady clock). Returns
  /// true when it comes from a new instance of a serve process (a restart: the ledger starts
  /// again).
  bool apply(const rccx_net_RobotState& s, std::int64_t steady_ns) noexcept;
  /// Middleware thread: marks the robot lost (true: its motions can no longer happen) or back.
  void set_lost(bool lost) noexcept;

  // Any thread.
  [[nodiscard]] bool has_state() const noexcept { return received_ns_.load() != 0; }
  [[nodiscard]] bool lost() const noexcept { return lost_.load(std::memory_order_acquire); }
  /// Steady-clock ns of the last sample received (0: none yet).
  [[nodiscard]] std::int64_t received_ns() const noexcept {
    return received_ns_.load(std::memory_order_acquire);
  }
  /// The serve process's participant and instance of the last sample (middleware thread).
  [[nodiscard]] const std::string& participant() const noexcept { return participant_; }
  [[nodiscard]] std::uint64_t instance() const noexcept { return instance_; }

  cell::SeqLock<FrameState> frame;
  cell::SeqLock<JointsSample> joints;
  rccl::MotionLedger ledger;

 private:
  std::string name_;
  std::string participant_;
  std::uint64_t instance_ = 0;
  bool control_ended_ = false;  ///< as the state says (lost ends it too)
  std::atomic<std::int64_t> received_ns_{0};
  std::atomic<bool> lost_{false};
  /// The failure ranges applied to the ledger already (the state repeats its newest four).
  std::uint64_t applied_from_[8]{}, applied_to_[8]{};
  std::uint32_t applied_ = 0;
};

/// The steady clock in ns (what "silent for" is measured on).
[[nodiscard]] std::int64_t steady_ns() noexcept;

}  // namespace rccx::net
