// The checks the communication task makes on a controlled sample's How before handing it to the
// control task (thesis 4.5.2), each a function of what it is given that returns the stop it
// finds, or none: requests to end control, faults (power, then each joint's), the wrist force
// sensor, the observed limits. A robot's channel (robot_channel.hpp) runs them in that order and
// ends control with the first stop; the pipeline of one sample is in session.hpp.
//
//   std::uint32_t hangups_seen = detail::hangup_count();        // when control starts
//   if (auto stop = rtc::check_requests(requests, hangups_seen)) return end(*stop);
//   if (auto stop = rtc::check_faults(how, power_expected, driver)) return end(*stop);
//   if (auto stop = rtc::check_force(how.force, chg.checking)) return end(*stop);
//   if (auto stop = rtc::check_observed_limits(how, driver, period_ns, chg.checking)) ...
//
// No allocation, no lock, no exception: they run in the sample loop.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <utility>

#include "rccx/io/fixed_text.hpp"
#include "rccx/rtc/driver.hpp"
#include "rccx/rtc/types.hpp"

namespace rccx::rtc {

/// What ends a robot's control: the terminate code, the joint it is about, and what the
/// communication task saw (Termination's `detail`).
struct Stop {
  TerminateCode code = TerminateCode::none;
  int joint = 0;  ///< 1-based, 0 when none
  std::array<char, kMessageCapacity> detail{};

  [[nodiscard]] std::string_view detail_view() const noexcept { return detail.data(); }
};

/// A stop whose detail is formatted (io::format_fixed: cut to fit, never throws).
template <class... Args>
[[nodiscard]] Stop make_stop(TerminateCode code, int joint, fmt::format_string<Args...> f,
                             Args&&... args) noexcept {
  Stop s{code, joint};
  io::format_fixed(s.detail, f, std::forward<Args>(args)...);
  return s;
}

/// The unit of a joint's values: "rad" (revolute) or "m" (prismatic), for the stops' details.
[[nodiscard]] const char* unit_of(const kin::Joint& joint) noexcept;

/// Requests to end control since the last tick, as the channel read them.
struct EndRequests {
  TerminateCode code = TerminateCode::none;  ///< a terminate() (Session's or Control's)
  int joint = 0;                             ///< the 1-based joint that request names
  std::uint32_t hangups = 0;                 ///< detail::hangup_count() now (Ctrl-C, SIGTERM)
  bool user_hangup = false;  ///< a hang-up handler of the user's deals with Ctrl-C instead
};

/// A terminate() request ends control with its code; else a new Ctrl-C (`hangups` past
/// `hangups_seen`, which it updates) with user_interrupt, unless the user's handler takes it.
[[nodiscard]] std::optional<Stop> check_requests(const EndRequests& requests,
                                                 std::uint32_t& hangups_seen) noexcept;

/// Power lost while expected on (power_failure), then the first joint, in order, whose
/// controller reports kNotAnswering, kEncoderError, kPhaseError or kJointFault (that order of
/// precedence), with the driver's fault_detail.
[[nodiscard]] std::optional<Stop> check_faults(const How& how, bool power_expected,
                                               const Driver& driver) noexcept;

/// With kCheckForce and a sensor present: its reading frozen (force_frozen), else saturated
/// (force_saturated).
[[nodiscard]] std::optional<Stop> check_force(const ForceHow& force,
                                              std::uint8_t checking) noexcept;

/// Each calibrated joint (not calibrating) measured outside its limits, with two counts of slack,
/// or faster than driver.velocity_limit at `period_ns` (5 % and two counts in 10 ms of slack):
/// flagged in `how` (kObservedPositionOut, kObservedVelocityOut); the first such joint ends
/// control when `checking` has the check's bit.
[[nodiscard]] std::optional<Stop> check_observed_limits(How& how, const Driver& driver,
                                                        std::int64_t period_ns,
                                                        std::uint8_t checking) noexcept;

}  // namespace rccx::rtc
