#include "rccx/rtc/sample_checks.hpp"

#include <cmath>

namespace rccx::rtc {

const char* unit_of(const kin::Joint& joint) noexcept {
  return joint.type == kin::JointType::revolute ? "rad" : "m";
}

std::optional<Stop> check_requests(const EndRequests& requests,
                                   std::uint32_t& hangups_seen) noexcept {
  if (requests.code != TerminateCode::none) return Stop{requests.code, requests.joint};
  if (requests.hangups != hangups_seen) {
    hangups_seen = requests.hangups;
    if (!requests.user_hangup) return Stop{TerminateCode::user_interrupt, 0};
  }
  return std::nullopt;
}

std::optional<Stop> check_faults(const How& how, bool power_expected,
                                 const Driver& driver) noexcept {
  // Power first: losing it makes every joint report a fault.
  if (power_expected && !how.power) {
    return make_stop(TerminateCode::power_failure, 0, "arm power went off");
  }
  static constexpr std::pair<JointFlag, TerminateCode> kFaults[] = {
      {kNotAnswering, TerminateCode::joint_not_answering},
      {kEncoderError, TerminateCode::encoder_error},
      {kPhaseError, TerminateCode::phase_error},
      {kJointFault, TerminateCode::joint_fault},
  };
  for (std::size_t i = 0; i < how.dof; ++i) {
    for (const auto& [flag, code] : kFaults) {
      if (how.joint[i].has(flag)) {
        Stop s{code, static_cast<int>(i) + 1};
        io::copy_fixed(s.detail, driver.fault_detail(i));
        return s;
      }
    }
  }
  return std::nullopt;
}

std::optional<Stop> check_force(const ForceHow& force, std::uint8_t checking) noexcept {
  // A reading at its range or one that no longer changes means nothing.
  if (!force.present || (checking & kCheckForce) == 0) return std::nullopt;
  if (force.frozen) {
    return make_stop(TerminateCode::force_frozen, 0,
                     "the wrist sensor's reading {} repeated for {} samples", force.sequence,
                     kForceFrozenSamples);
  }
  if (force.saturated) {
    const math::Wrench& w = force.wrench;
    return make_stop(TerminateCode::force_saturated, 0,
                     "wrist force ({:.1f}, {:.1f}, {:.1f}) N, torque ({:.2f}, {:.2f}, {:.2f}) N m",
                     w.force_N.x, w.force_N.y, w.force_N.z, w.torque_N_m.x, w.torque_N_m.y,
                     w.torque_N_m.z);
  }
  return std::nullopt;
}

std::optional<Stop> check_observed_limits(How& how, const Driver& driver, std::int64_t period_ns,
                                          std::uint8_t checking) noexcept {
  const auto& joints = driver.model().joints;
  for (std::size_t i = 0; i < how.dof; ++i) {
    JointHow& j = how.joint[i];
    // Only calibrated joints: an uncalibrated position means nothing yet, and a calibrating
    // joint may stand on its mechanical stop, outside its range.
    if (!j.has(kCalibrated) || j.has(kCalibrating)) continue;
    const kin::Joint& m = joints[i];
    const int number = static_cast<int>(i) + 1;
    const double position_slack = 2.0 * m.resolution_per_count;  // quantisation at a hard stop
    if (!(j.q >= m.lower - position_slack && j.q <= m.upper + position_slack)) {
      j.flags |= kObservedPositionOut;
      if ((checking & kCheckObservedPosition) != 0) {
        return make_stop(TerminateCode::observed_position, number,
                         "joint {} measured at {:.5f} {}, limits [{:.5f}, {:.5f}]", i + 1, j.q,
                         unit_of(m), m.lower, m.upper);
      }
    }
    // Speeds come from encoder differences: allow their quantisation and a little overshoot.
    const double top = driver.velocity_limit(i, static_cast<double>(period_ns) * 1e-9);
    const double speed_slack = 0.05 * top + 2.0 * m.resolution_per_count / 0.010;
    if (std::abs(j.velocity) > top + speed_slack) {
      j.flags |= kObservedVelocityOut;
      if ((checking & kCheckObservedVelocity) != 0) {
        return make_stop(TerminateCode::observed_velocity, number,
                         "joint {} measured at {:.4f} {}/s, maximum {:.4f}", i + 1, j.velocity,
                         unit_of(m), top);
      }
    }
  }
  return std::nullopt;
}

}  // namespace rccx::rtc
