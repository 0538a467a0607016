// One arm's motion API as a program sees it, wherever the arm runs: rccl::Manipulator drives an
// arm of this process (its generator in this process's sample loop), net::RemoteArm one that a
// `rccx serve` process drives (docs/NETWORK.md). A program written against Arm& runs on both:
//
//   void probe(rccl::Arm& arm, const rccl::PositionPtr& above, const rccl::PositionPtr& down) {
//     arm.set_mode(rccl::Mode::cartesian);
//     arm.move(above);
//     const rccl::Motion m = arm.move(down);
//     if (arm.waitfor(m.end()) != rccl::WaitResult::reached) { /* arm.failures() says why */ }
//   }
//
// The calls are the planning level's: none runs in a sample loop. Units: m, rad, s.
#pragma once

#include <chrono>
#include <cstdint>
#include <string_view>
#include <vector>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/position.hpp"
#include "rccx/rccl/trajectory/requests.hpp"
#include "rccx/rtc/types.hpp"

namespace rccx::rccl {

/// Something a program may wait for.
struct Event {
  enum class Kind : std::uint8_t { motion_start, motion_end, position_end, completed };
  Kind kind = Kind::completed;
  std::uint64_t id = 0;                ///< motion_start / motion_end
  const Position* position = nullptr;  ///< position_end: every queued motion to it has ended
};

/// A queued motion.
struct Motion {
  std::uint64_t id = 0;
  [[nodiscard]] Event start() const noexcept { return {Event::Kind::motion_start, id, nullptr}; }
  [[nodiscard]] Event end() const noexcept { return {Event::Kind::motion_end, id, nullptr}; }
};

enum class WaitResult : std::uint8_t {
  reached,        ///< the event happened
  failed,         ///< the motion waited for failed or was cancelled (see failures())
  timeout,        ///< the timeout passed first
  session_ended,  ///< control ended (see the session's termination)
};
std::string_view to_string(WaitResult r) noexcept;

class Arm {
 public:
  virtual ~Arm() = default;

  // --- Settings for the motions queued from now on --------------------------------------------
  virtual void set_mode(Mode mode) = 0;
  /// setvel: tool translation (m/s) and rotation (rad/s) speeds, both > 0.
  virtual void set_velocity(double translation_m_per_s, double rotation_rad_per_s) = 0;
  /// settime: segment duration (s; 0 = from the speeds) and transition time (s, > 0).
  virtual void set_segment_time(double seconds) = 0;
  virtual void set_transition_time(double seconds) = 0;
  /// The configuration to reach the next goals in ("lun", "n" ...); empty keeps the present one.
  virtual void set_configuration(std::string_view name) = 0;
  /// End the motions queued from now on on contact (ForceGuard{}: off).
  virtual void set_guard(const ForceGuard& guard) = 0;
  /// comply / lock for the motions queued from now on (Compliance{}: locked).
  virtual void set_compliance(const Compliance& compliance) = 0;
  [[nodiscard]] virtual const MotionSettings& settings() const noexcept = 0;

  // --- Motions ----------------------------------------------------------------------------------
  /// Queues a motion to `position` (throws MotionError, queuing nothing, for a goal known now
  /// to be out of reach or limits, or a full queue).
  virtual Motion move(const PositionPtr& position, const StartWhen& when = {}) = 0;
  /// RCCL's stop(): stay where the previous motion ends for `seconds`.
  virtual Motion dwell(double seconds, const StartWhen& when = {}) = 0;
  /// Stops smoothly where the arm is and cancels everything queued.
  virtual void halt() = 0;
  /// Closes (true) or opens the hand, at the next sample.
  virtual void set_hand(bool closed) = 0;
  /// The arm's park position (its ready pose, in joints).
  [[nodiscard]] virtual const PositionPtr& park() const noexcept = 0;

  // --- Synchronisation --------------------------------------------------------------------------
  [[nodiscard]] static Event completed() noexcept { return {}; }
  [[nodiscard]] static Event ended(const PositionPtr& p) noexcept {
    return {Event::Kind::position_end, 0, p.get()};
  }
  /// Waits for `event` (in simulated time: runs the samples until then).
  virtual WaitResult waitfor(const Event& event,
                             std::chrono::nanoseconds timeout = std::chrono::hours(24 * 365)) = 0;
  /// Lets `d` pass. Returns how control ended if it ended meanwhile, an empty one otherwise.
  virtual rtc::Termination wait_for(std::chrono::nanoseconds d) = 0;
  /// True when `event` has happened.
  [[nodiscard]] virtual bool happened(const Event& event) const noexcept = 0;

  // --- What happened ----------------------------------------------------------------------------
  /// Failures and cancellations so far.
  [[nodiscard]] virtual const std::vector<MotionEvent>& failures() = 0;
  /// Every event since the last call (started, ended, failed, cancelled).
  virtual std::vector<MotionEvent> take_events() = 0;
  /// How motion `m` followed its path (once it has ended).
  [[nodiscard]] virtual SegmentReport report(const Motion& m) const noexcept = 0;
  [[nodiscard]] virtual std::uint64_t last_queued() const noexcept = 0;
  /// The arm's kinematics (its robot model's solver).
  [[nodiscard]] virtual const kin::Kinematics& kinematics() const noexcept = 0;

 protected:
  Arm() = default;
  Arm(const Arm&) = default;
  Arm& operator=(const Arm&) = default;
};

}  // namespace rccx::rccl
