// The force side of the sample loop (thesis 4.4.2, RCCL's force control): after the trajectory
// generator has made this sample's setpoint, the wrist sensor's reading is compensated for the
// tool's weight and the sensor's bias, carried to the running motion's tool frame by the force
// transform, and then
//   - a guard (ForceGuard) that trips records where the contact began and ends the motion as
//     nextmove does;
//   - compliance (Compliance) moves the setpoint off the path along the compliant tool axes by
//     an admittance, and back onto it along the locked ones.
// One object per arm, used by its control thread only: noexcept and allocation-free.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "rccx/force/tool_load.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/trajectory.hpp"
#include "rccx/rtc/types.hpp"

namespace rccx::rccl {

/// Where a guarded motion touched.
struct Contact {
  std::uint64_t motion = 0;  ///< the motion's id; 0: none recorded
  double t_s = 0.0;          ///< when the force began to rise, s since the session opened
  /// T6 (m) at that sample, measured, and the tool frame F = T6 TOOL there: F.p is the
  /// contact point when the tool frame sits where the tool touches.
  math::Transform t6, tool_frame;
  math::Wrench wrench;  ///< the force the tool exerted when the guard tripped, tool frame
};

class ForceControl {
 public:
  /// Samples kept to look back for where a contact began.
  static constexpr std::size_t kHistory = 64;
  /// A contact begins at the first sample, going back from the trip, whose guarded force
  /// exceeds this fraction of the guard's threshold.
  static constexpr double kOnsetFraction = 0.15;
  static constexpr std::size_t kContacts = 64;
  /// A compliant motion that starts with the tool exerting more than its limits (a stop that
  /// left the command inside a surface) yields toward the set force first: it fails only if
  /// the force is still above the limits this long after its start, s.
  static constexpr double kYieldWithin_s = 1.0;

  explicit ForceControl(const kin::Kinematics& kinematics) noexcept : kin_(kinematics) {}

  /// The tool's load (bias, mass, centre of mass in T6) and the base's orientation in the
  /// world (gravity along world -z): from the planning level, between samples or while the
  /// loop runs (read once a sample).
  void set_tool_load(const force::ToolLoad& load) noexcept;
  void set_world_from_base(const math::Rot3& r) noexcept;

  enum class Outcome : std::uint8_t {
    none,
    contact,      ///< the guard tripped: end the motion (nextmove)
    overload,     ///< compliant, the tool exerted more than the limit: stop the motion
    unreachable,  ///< the offset setpoint has no solution within limits: stop the motion
  };

  /// One sample: `how` as read, the setpoint q (rad / m) the generator made for motion `id`
  /// run with `settings` (null at rest), the sample period. May change q (compliance).
  Outcome step(const rtc::How& how, std::uint64_t id, const MotionSettings* settings,
               double period_s, kin::JointVector& q) noexcept;
  /// Starts over (control starting): no offset, no history.
  void reset() noexcept;

  /// This sample's contact wrench in the running motion's tool frame (what the tool exerts;
  /// N, N m): zero without a sensor.
  [[nodiscard]] const math::Wrench& applied() const noexcept { return applied_; }
  /// The compliance offset from the path, tool frame: m along x y z, rad about them.
  [[nodiscard]] const std::array<double, 6>& offset() const noexcept { return offset_; }
  /// The contact of motion `id` (Contact::motion == id when it was recorded). Written before
  /// the generator ends the motion, so a planning thread that saw the end event may read it.
  [[nodiscard]] Contact contact(std::uint64_t id) const noexcept;
  /// Why the last overload or unreachable outcome happened, for the motion's failure.
  [[nodiscard]] const std::array<char, 160>& why() const noexcept { return why_; }

 private:
  struct Past {
    double t_s = 0.0;
    double guarded = 0.0;  ///< the guard's quantity at that sample
    math::Transform t6;
  };
  [[nodiscard]] double guarded_value(const ForceGuard& g) const noexcept;
  void record_contact(std::uint64_t id, const ForceGuard& g, const math::Transform& tool) noexcept;
  /// Moves the offset one sample (dt, s) by the admittance along compliant axes, back to the
  /// path along locked ones.
  void comply(const Compliance& c, double dt) noexcept;
  /// Moves setpoint q by the offset in the tool frame (unreachable: q stays on the path's
  /// last followable offset).
  Outcome apply_offset(const math::Transform& tool, kin::JointVector& q) noexcept;

  const kin::Kinematics& kin_;
  force::ToolLoad load_;
  math::Rot3 world_from_base_;
  std::atomic<bool> load_changed_{false};
  force::ToolLoad pending_load_;
  math::Rot3 pending_world_;
  math::Wrench applied_;
  std::array<double, 6> offset_{}, last_good_offset_{};
  math::Transform last_tool_;
  std::uint64_t yield_motion_ = 0;  ///< the compliant motion the yield rule was set for
  bool yielding_ = false;           ///< it started above the limits and has not come below yet
  double yield_since_s_ = 0.0;      ///< its first compliant sample's time, s
  std::uint64_t held_for_ = 0;      ///< the offset stays as it is while motion held_for_ runs
  bool held_after_stop_ = false;    ///< ... and at rest after it
  std::array<Past, kHistory> past_{};
  std::size_t past_count_ = 0, past_next_ = 0;
  std::uint64_t past_motion_ = 0;
  std::array<Contact, kContacts> contacts_{};
  std::array<char, 160> why_{};
};

}  // namespace rccx::rccl
