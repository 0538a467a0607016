#include "rccx/rtc/types.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace rccx::rtc {

std::string_view to_string(SetMode m) noexcept {
  switch (m) {
    case SetMode::none:
      return "none";
    case SetMode::pos:
      return "POS";
    case SetMode::posvel:
      return "POSVEL";
    case SetMode::stopcal:
      return "STOPCAL";
  }
  return "?";
}

std::string_view to_string(Setting s) noexcept {
  switch (s) {
    case Setting::none:
      return "none";
    case Setting::acceleration:
      return "acceleration";
    case Setting::speed_factor:
      return "speed factor";
    case Setting::dynamic_integral:
      return "dynamic integral";
    case Setting::static_integral:
      return "static integral";
    case Setting::static_speed:
      return "static speed";
    case Setting::static_zone:
      return "static zone";
    case Setting::examine:
      return "examine";
  }
  return "?";
}

namespace {
template <class F>
JointVector per_joint(const How& h, F f) noexcept {
  JointVector v(h.dof);
  for (std::size_t i = 0; i < h.dof; ++i) v[i] = f(h.joint[i]);
  return v;
}
}  // namespace

JointVector How::q() const noexcept {
  return per_joint(*this, [](const JointHow& j) { return j.q; });
}
JointVector How::range() const noexcept {
  return per_joint(*this, [](const JointHow& j) { return j.range; });
}
JointVector How::velocity() const noexcept {
  return per_joint(*this, [](const JointHow& j) { return j.velocity; });
}
std::uint16_t How::any_flags() const noexcept {
  std::uint16_t f = 0;
  for (std::size_t i = 0; i < dof; ++i) f = static_cast<std::uint16_t>(f | joint[i].flags);
  return f;
}

namespace {

struct CodeInfo {
  TerminateCode code;
  std::string_view name;
  std::string_view meaning;
};

constexpr CodeInfo kCodes[] = {
    {TerminateCode::none, "none", "control is running (no termination)"},
    {TerminateCode::user_request, "user_request",
     "the program or a control function asked the session to end"},
    {TerminateCode::user_interrupt, "user_interrupt", "Ctrl-C was typed during control"},
    {TerminateCode::control_exception, "control_exception",
     "a control function threw an exception (its text is in rtc_message)"},
    {TerminateCode::overrun, "overrun",
     "a control cycle did not finish within its sample period: make f1/f2 faster or the period "
     "longer"},
    {TerminateCode::observed_position, "observed_position",
     "a joint was measured outside its limits"},
    {TerminateCode::target_position, "target_position",
     "a joint was commanded outside its limits (the command was not sent)"},
    {TerminateCode::observed_velocity, "observed_velocity",
     "a joint was measured moving faster than its maximum speed"},
    {TerminateCode::target_velocity, "target_velocity",
     "a joint was commanded faster than its maximum speed (the command was not sent)"},
    {TerminateCode::not_calibrated, "not_calibrated",
     "a position was commanded to a joint that is not calibrated: calibrate first (rccx calib)"},
    {TerminateCode::joint_not_answering, "joint_not_answering",
     "a joint controller stopped answering; arm power was turned off"},
    {TerminateCode::encoder_error, "encoder_error", "a joint's encoder reported an error"},
    {TerminateCode::power_failure, "power_failure", "arm power was lost or could not be turned on"},
    {TerminateCode::phase_error, "phase_error",
     "a joint's encoder reported a phase error (both channels switched at once)"},
    {TerminateCode::joint_fault, "joint_fault",
     "a joint controller reported a fault during motion (following error or overheating)"},
    {TerminateCode::force_saturated, "force_saturated",
     "the wrist force sensor reached its measuring range: the arm pushed too hard; lower the "
     "force asked or the speed of approach"},
    {TerminateCode::force_frozen, "force_frozen",
     "the wrist force sensor stopped sending new readings: check its cable and power"},
};

const CodeInfo* info(TerminateCode code) noexcept {
  const auto it = std::find_if(std::begin(kCodes), std::end(kCodes),
                               [code](const CodeInfo& c) { return c.code == code; });
  return it == std::end(kCodes) ? nullptr : it;
}

constexpr auto kAllCodes = [] {
  std::array<TerminateCode, std::size(kCodes)> a{};
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = kCodes[i].code;
  return a;
}();

}  // namespace

std::string_view describe(TerminateCode code) noexcept {
  const CodeInfo* c = info(code);
  return c ? c->meaning : "unknown terminate code";
}

std::string_view to_string(TerminateCode code) noexcept {
  const CodeInfo* c = info(code);
  return c ? c->name : "unknown";
}

std::span<const TerminateCode> all_terminate_codes() noexcept {
  return kAllCodes;
}

bool powers_down(TerminateCode code) noexcept {
  return code == TerminateCode::joint_not_answering || code == TerminateCode::power_failure;
}

namespace {
std::string_view text_of(const std::array<char, kMessageCapacity>& a) noexcept {
  return {a.data(), static_cast<std::size_t>(std::find(a.begin(), a.end(), '\0') - a.begin())};
}
}  // namespace

std::string_view Termination::message_view() const noexcept {
  return text_of(message);
}
std::string_view Termination::detail_view() const noexcept {
  return text_of(detail);
}

void print_terminate_code(const Termination& t, std::FILE* out) {
  if (!t.ended()) {
    fmt::print(out, "rtc: control is running\n");
    return;
  }
  fmt::print(out, "rtc: control ended at sample {} (t = {:.3f} s) with {} ({}", t.sample, t.time_s,
             to_string(t.code), static_cast<int>(t.code));
  if (t.joint > 0) fmt::print(out, ", joint {}", t.joint);
  fmt::print(out, "): {}", describe(t.code));
  if (!t.detail_view().empty()) fmt::print(out, "; {}", t.detail_view());
  if (!t.message_view().empty()) fmt::print(out, "; rtc_message \"{}\"", t.message_view());
  fmt::print(out, "\n");
}

void print_terminate_codes(std::FILE* out) {
  for (const CodeInfo& c : kCodes) {
    fmt::print(out, "{:3}  {:<20} {}\n", static_cast<int>(c.code), c.name, c.meaning);
  }
}

}  // namespace rccx::rtc
