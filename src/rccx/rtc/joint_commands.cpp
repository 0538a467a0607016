#include "rccx/rtc/joint_commands.hpp"

#include <algorithm>
#include <cmath>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rtc/session.hpp"

namespace rccx::rtc {

namespace {

// A target outside the joint's limits (beyond kLimitTolerance): refused when the checking mode
// checks targets or it is not a number, else clamped (never sent outside the limits).
std::optional<Stop> limit_target(double& target, const kin::Joint& joint, int number,
                                 std::uint8_t checking, JointHow& j) noexcept {
  if (target >= joint.lower - kin::kLimitTolerance &&
      target <= joint.upper + kin::kLimitTolerance) {
    return std::nullopt;
  }
  j.flags |= kTargetPositionOut;
  if ((checking & kCheckTargetPosition) != 0 || !std::isfinite(target)) {
    return make_stop(TerminateCode::target_position, number,
                     "joint {} commanded to {:.5f} {}, limits [{:.5f}, {:.5f}]", number, target,
                     unit_of(joint), joint.lower, joint.upper);
  }
  target = std::clamp(target, joint.lower, joint.upper);
  return std::nullopt;
}

// The rate to travel to `target` from `from` at, rad/s or m/s.
double rate_of(const JointChg& m, double target, double from, double top,
               double period_s) noexcept {
  // POSVEL to the last target again, give or take a rounding (a joint that a Cartesian motion
  // no longer moves): rate 0, at once. A rate of 1e-13 m/s would leave a driver that paces its
  // desired point by the rate (the Microbo's) behind the target for good.
  return m.set == SetMode::posvel ? (std::abs(target - from) <= kin::kLimitTolerance
                                         ? 0.0
                                         : std::abs(target - from) / period_s)
                                  : (m.velocity > 0.0 ? m.velocity : kDefaultSpeedFraction * top);
}

// A rate above the top speed: refused when the checking mode checks it or it is not a number,
// else lowered to it (the joint arrives late rather than too fast).
std::optional<Stop> limit_rate(double& rate, double top, const kin::Joint& joint, int number,
                               std::uint8_t checking, JointHow& j) noexcept {
  if (rate <= top * (1.0 + 1e-9)) return std::nullopt;
  j.flags |= kTargetVelocityOut;
  if ((checking & kCheckTargetVelocity) != 0 || !std::isfinite(rate)) {
    return make_stop(TerminateCode::target_velocity, number,
                     "joint {} commanded at {:.4f} {}/s, maximum {:.4f}", number, rate,
                     unit_of(joint), top);
  }
  rate = top;
  return std::nullopt;
}

}  // namespace

std::optional<Stop> to_joint_commands(const Chg& chg, const Driver& driver, double period_s,
                                      How& how, JointTargets& last,
                                      JointCommands& commands) noexcept {
  const auto& joints = driver.model().joints;
  for (std::size_t i = 0; i < how.dof; ++i) {
    const JointChg& m = chg.motion[i];
    const kin::Joint& joint = joints[i];
    JointHow& j = how.joint[i];
    const int number = static_cast<int>(i) + 1;
    if (m.set == SetMode::none) continue;
    if (m.set == SetMode::stopcal) {
      commands[i].kind = JointCommand::Kind::calibrate;
      last.has[i] = false;
      continue;
    }
    if (!j.has(kCalibrated)) {
      j.flags |= kNotCalibratedTarget;
      return Stop{TerminateCode::not_calibrated, number};
    }
    double target = joint.lower + m.range_target;
    if (auto stop = limit_target(target, joint, number, chg.checking, j)) return stop;
    const double from = last.has[i] ? last.target[i] : j.q;
    const double top = driver.velocity_limit(i, period_s);  // at most the model's top speed
    double rate = rate_of(m, target, from, top, period_s);
    if (auto stop = limit_rate(rate, top, joint, number, chg.checking, j)) return stop;
    commands[i] = {JointCommand::Kind::move, target, rate};
    last.target[i] = target;
    last.has[i] = true;
  }
  return std::nullopt;
}

}  // namespace rccx::rtc
