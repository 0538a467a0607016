// Chg's joint motions into one sample's joint commands (thesis 4.5.2), what the communication
// task sends the arm after f1: range targets become joint values; a target outside the joint's
// limits is refused (target_position) when the checking mode checks it or it is not a number,
// else clamped to them; POSVEL's rate is the way from the last target in one period, POS's the
// joint's velocity setting or a quarter of its top speed; a rate above the top speed is refused
// (target_velocity) or lowered to it, likewise; a joint not calibrated refuses targets
// (not_calibrated). A pure function of what it is given: no driver call but velocity_limit.
//
//   rtc::JointTargets last;                     // per control session, kept between samples
//   rtc::JointCommands commands{};
//   if (auto stop = rtc::to_joint_commands(chg, driver, period_s, how, last, commands)) {
//     end(*stop);                               // nothing is sent
//   } else {
//     driver.send(commands);
//   }
#pragma once

#include <optional>

#include "rccx/rtc/driver.hpp"
#include "rccx/rtc/sample_checks.hpp"
#include "rccx/rtc/types.hpp"

namespace rccx::rtc {

/// The last target sent to each joint in this control session (where POSVEL starts from, and
/// what the log calls commanded).
struct JointTargets {
  std::array<double, kMaxJoints> target{};  ///< joint value, rad or m
  std::array<bool, kMaxJoints> has{};       ///< a target was sent (a STOPCAL clears it)

  /// The commanded joints: the last targets where there are, `measured` elsewhere.
  [[nodiscard]] JointVector commanded(const JointVector& measured) const noexcept {
    JointVector q = measured;
    for (std::size_t i = 0; i < q.size(); ++i) {
      if (has[i]) q[i] = target[i];
    }
    return q;
  }
};

/// Fills `commands` from chg.motion for how.dof joints, joint after joint, at a sample period of
/// `period_s` (s) with the driver's velocity_limit as each joint's top speed; flags the refused
/// or clamped ones in `how` (kNotCalibratedTarget, kTargetPositionOut, kTargetVelocityOut) and
/// keeps each sent target in `last`. Returns the stop of the first joint refused (the joints
/// before it are already in `commands` and `last`): then nothing is to be sent.
[[nodiscard]] std::optional<Stop> to_joint_commands(const Chg& chg, const Driver& driver,
                                                    double period_s, How& how, JointTargets& last,
                                                    JointCommands& commands) noexcept;

}  // namespace rccx::rtc
