// What passes between the planning level and the trajectory generator: the motion requests in
// (thesis figure 2.3), the events and the path reports out, the generator's options and the
// fractions of the joints' bounds it plans at. Plain data; docs/TRAJECTORY.md tells the story.
//
//   rccl::MotionRequest r;                    // a move: a position and the settings to use
//   r.id = 1;
//   r.position = &goal;                       // kept alive by the planning level
//   r.settings.mode = rccl::Mode::cartesian;
//   generator.submit(r);
//   while (auto e = generator.next_event()) { /* started, ended, failed, cancelled */ }
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/force_settings.hpp"
#include "rccx/rccl/motion_sync.hpp"
#include "rccx/rccl/position.hpp"

namespace rccx::rccl {

enum class Mode : std::uint8_t { joint, cartesian };
std::string_view to_string(Mode m) noexcept;

/// What setmod / setvel / settime / setconf set; each request carries a copy.
struct MotionSettings {
  Mode mode = Mode::joint;
  double translation_m_per_s = 0.1;    ///< tool speed along a segment (RCCL setvel, mm/s there)
  double rotation_rad_per_s = 1.7453;  ///< tool rotation speed (100 deg/s, RCCL's default)
  double segment_time_s = 0.0;         ///< > 0: the segment's duration instead of the speeds
  double transition_time_s = 0.2;      ///< the transition to the next segment (2 tau)
  /// Configuration to reach the goal in (an index of Kinematics::configuration_names()), or
  /// -1 to keep the one the arm is in.
  std::int16_t configuration = -1;
  /// Force sensing (force_settings.hpp): end on contact, yield along tool axes.
  ForceGuard guard;
  Compliance compliance;
  /// The motion's tool product TOOL (T6 to the tool frame F, m): the frame the guard's and
  /// the compliance's axes are in. Set by Manipulator::move from the position.
  math::Transform tool;
  /// The cell's objects (bit i: object i) the tool may touch during this motion (a probe, a
  /// grasp, a guarded descent): the cell's collision check lets the tool's capsules come within
  /// the margin of them. From StartWhen::touch.
  std::uint64_t may_touch = 0;
};

enum class RequestKind : std::uint8_t { move, dwell };

/// A motion request packet (thesis figure 2.3).
struct MotionRequest {
  std::uint64_t id = 0;  ///< 1, 2, ... in queue order
  RequestKind kind = RequestKind::move;
  const Position* position = nullptr;  ///< move: kept alive by the planning level
  MotionSettings settings;
  double dwell_s = 0.0;  ///< dwell: how long to stay
  /// Start only once these events have happened (gates[0 .. gates)); a gate that can no longer
  /// open cancels the motion (and those after it) with the reason.
  std::array<EventGate, StartWhen::kMaxGates> after{};
  std::uint8_t gates = 0;
  /// Start with the other participants of this rendezvous (kept alive by the planning level).
  Rendezvous* together = nullptr;
  std::uint8_t slot = 0;
  [[nodiscard]] bool gated() const noexcept { return gates > 0 || together != nullptr; }
};

enum class EventKind : std::uint8_t { started, ended, failed, cancelled };
std::string_view to_string(EventKind k) noexcept;

inline constexpr std::size_t kEventText = 240;
/// The text of the `ended` event of a motion that request_next() ended before its goal.
inline constexpr std::string_view kNextmoveText = "ended by nextmove";

/// What the generator tells the planning level.
struct MotionEvent {
  EventKind kind = EventKind::started;
  std::uint64_t id = 0;
  double t_s = 0.0;  ///< the time of the sample it happened in (How::time_s), s
  std::uint64_t sample = 0;
  kin::IkStatus status = kin::IkStatus::ok;  ///< failed: why, when the kinematics said so
  int joint = 0;                             ///< failed: the 1-based joint concerned, or 0
  std::array<char, kEventText> text{};       ///< failed: the message for people
  [[nodiscard]] std::string_view message() const noexcept;
};

/// How well a segment followed its path (Cartesian segments; joint ones report times only).
struct SegmentReport {
  std::uint64_t id = 0;
  Mode mode = Mode::joint;
  /// When its transition in began and its transition out ended: the time of those samples
  /// (How::time_s, s), not of their setpoints, which run the robot's pipeline ahead; robots
  /// ending in the same tick report the same end_s whatever their periods.
  double start_s = 0.0;
  double end_s = 0.0;
  double duration_s = 0.0;  ///< the straight part's nominal length T
  /// Outside transitions: the largest distance of the commanded and of the measured tool
  /// point from the straight segment (m), and the largest angle between the measured and the
  /// commanded approach vector (rad).
  double max_commanded_path_error_m = 0.0;
  double max_measured_path_error_m = 0.0;
  double max_approach_error_rad = 0.0;
  double peak_tool_speed_m_per_s = 0.0;  ///< commanded
  /// Samples on the straight part (0: transitions took the whole segment, nothing to judge).
  std::uint32_t straight_samples = 0;
  bool failed = false;
};

struct GeneratorOptions {
  double period_s = 0.01;
  /// Per joint, rad/s or m/s: the fastest the generator commands (default: the model's top
  /// speed). Segment times are planned at kPlanningSpeedFraction of it.
  kin::JointVector max_velocity;
  /// Per joint, rad/s^2 or m/s^2 (default: max_velocity / kDefaultAccelerationTime_s).
  kin::JointVector max_acceleration;
};

/// A joint reaches its top speed from rest in this long under the default acceleration bound.
inline constexpr double kDefaultAccelerationTime_s = 0.25;
/// Segments are planned at this fraction of the joints' top speeds, leaving room for
/// transitions and for the speed of a Cartesian line to vary along it.
inline constexpr double kPlanningSpeedFraction = 0.9;
/// Transitions and segment times are planned at this fraction of the acceleration bound: a
/// Cartesian blend's joint accelerations depend on the kinematics and may exceed the linear
/// estimate they are planned from by some percent.
inline constexpr double kPlanningAccelerationFraction = 0.8;
/// Transitions are checked, sample by sample, against this fraction of the joints' top speeds
/// (the rest is room for a moving goal's prediction); the next segment is slowed while one
/// would pass it.
inline constexpr double kTransitionSpeedFraction = 0.98;
/// Commanded accelerations (second differences of the setpoints) stay within the bound times
/// 1 + this: what the sampled check of a transition cannot see between its samples.
inline constexpr double kAccelerationTolerance = 0.1;

}  // namespace rccx::rccl
