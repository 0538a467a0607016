#include "console_lines.hpp"

#include <fmt/format.h>

#include <array>
#include <cctype>
#include <cmath>
#include <string>
#include <vector>

#include "rccx/io/parse.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rtc/session.hpp"

namespace rccx::tools {
namespace {

bool revolute(const kin::Joint& j) {
  return j.type == kin::JointType::revolute;
}

/// A whole hexadecimal number of 1 .. `digits` digits (no sign, no 0x, no blanks).
bool hex_of(std::string_view text, std::size_t digits, unsigned& value) {
  if (text.empty() || text.size() > digits) return false;
  value = 0;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isxdigit(u) == 0) return false;
    value = value * 16 +
            static_cast<unsigned>(std::isdigit(u) != 0 ? u - '0' : std::tolower(u) - 'a' + 10);
  }
  return true;
}

}  // namespace

JointtestLine parse_jointtest_line(std::string_view line, const kin::RobotModel& model,
                                   std::size_t joint) {
  const std::vector<std::string_view> w = io::words_of(line);
  JointtestLine c;
  if (w.empty()) return c;
  if (w[0].size() != 1) {
    throw io::ParseError(fmt::format("unknown command {}: type ? for the menu", io::quoted(w[0])));
  }
  c.letter = w[0][0];
  const kin::Joint& jm = model.joints.at(joint);
  const char* unit = revolute(jm) ? "deg" : "mm";
  switch (c.letter) {
    case 's':
    case 'h':
    case 'H':
    case 'p':
    case 'P':
    case 'x':
    case 'X':
    case 'q':
    case '?':
      io::expect_words(w, 1, w[0]);
      return c;
    case 'j':
      io::expect_words(w, 2, "j N, the joint number");
      c.joint = io::parse_joint(w[1], "j: the joint", model.dof());
      return c;
    case 'v': {
      io::expect_words(w, 2, revolute(jm) ? "v V, a speed in deg/s" : "v V, a speed in mm/s");
      const double max = revolute(jm) ? math::rad_to_deg(jm.max_velocity) : jm.max_velocity * 1e3;
      const std::string what = fmt::format("v: joint {}'s speed", joint + 1);
      c.value = io::parse_number(w[1], what, {1e-3, max, revolute(jm) ? "deg/s" : "mm/s"});
      return c;
    }
    case 'm':
    case 'M': {
      io::expect_words(w, 2, revolute(jm) ? "m V, a position in deg" : "m V, a position in mm");
      const std::string what = fmt::format("{}: joint {}'s target", c.letter, joint + 1);
      c.value = io::parse_number(w[1], what, {-kMaxJointtestTarget, kMaxJointtestTarget, unit});
      return c;
    }
    case 'o':
    case 'O':
      io::expect_words(w, 2, "o B or O B, with B an output bit 0 to 15");
      c.value = static_cast<double>(
          io::parse_integer(w[1], fmt::format("{}: the output bit", c.letter), 0, 15));
      return c;
    case 'w':
      io::expect_words(w, 2, "w S, a time in seconds (e.g. w 2, w 500ms)");
      c.duration = io::parse_duration(w[1], "w: the wait", io::BareUnit::seconds,
                                      std::chrono::nanoseconds{0},
                                      std::chrono::duration_cast<std::chrono::nanoseconds>(
                                          std::chrono::duration<double>(kMaxJointtestWaitS)));
      return c;
    case 'r':
      io::expect_words(w, 2, "r MS, the sample period (0.25 ms to 56 ms)");
      c.duration = io::parse_duration(w[1], "r: the sample period", io::BareUnit::milliseconds,
                                      rtc::kMinPeriod, rtc::kMaxPeriod);
      return c;
    case 'a':
    case 'f':
    case 'k':
    case 'K':
    case 'V':
    case 'z': {
      io::expect_words(w, 2, "the letter and a whole number in the controller's units");
      const std::int64_t hi = c.letter == 'a' ? 65535 : 255;
      c.value = static_cast<double>(
          io::parse_integer(w[1], fmt::format("{}: the value", c.letter), 0, hi));
      return c;
    }
    default:
      throw io::ParseError(
          fmt::format("unknown command {}: type ? for the menu", io::quoted(w[0])));
  }
}

RcuLine parse_rcu_line(std::string_view line, std::size_t dof) {
  const std::vector<std::string_view> w = io::words_of(line);
  RcuLine c;
  if (w.empty() || w[0][0] == '#') return c;
  const std::string registers =
      fmt::format("{:04X} to {:04X} (hex)", hw::kRcuBase, hw::kRcuBase + 2 * dof - 1);
  const auto address = [&](std::string_view text) {
    unsigned v = 0;
    if (!hex_of(text, 4, v) || v < hw::kRcuBase || v >= hw::kRcuBase + 2 * dof) {
      throw io::ParseError(
          fmt::format("{}: the address {} must be one of the joints' registers, {}", w[0],
                      io::quoted(text), registers));
    }
    return static_cast<std::uint16_t>(v);
  };
  if (w[0] == "out") {
    io::expect_words(w, 3, "out ADDR BYTE, e.g. out 5801 0C (hex)");
    c.kind = RcuLine::Kind::out;
    c.address = address(w[1]);
    unsigned v = 0;
    if (!hex_of(w[2], 2, v)) {
      throw io::ParseError(
          fmt::format("out: the byte {} must be 00 to FF (hex)", io::quoted(w[2])));
    }
    c.byte = static_cast<std::uint8_t>(v);
    return c;
  }
  if (w[0] == "in") {
    io::expect_words(w, 2, "in ADDR, with ADDR one of " + registers);
    c.kind = RcuLine::Kind::in;
    c.address = address(w[1]);
    return c;
  }
  if (w[0] == "step") {
    io::expect_words(w, 2, "step MS, the emulated milliseconds to let pass, e.g. step 0.1");
    c.kind = RcuLine::Kind::step;
    const double ms = io::parse_number(w[1], "step: the time", {0.0, kMaxRcuStepMs, "ms"});
    c.step_us = std::llround(ms * 1000);
    return c;
  }
  if (w[0] == "fault") {
    io::expect_words(w, 3, "fault JOINT KIND, e.g. fault 2 encoder_error");
    c.kind = RcuLine::Kind::fault;
    try {
      c.joint = io::parse_joint(w[1], "fault: the joint", dof);
    } catch (const io::ParseError&) {
      throw io::ParseError(
          fmt::format("fault: {}: the joint must be 1 to {}", io::quoted(w[1]), dof));
    }
    for (const auto f : {hw::RcuFault::joint_not_answering, hw::RcuFault::encoder_error,
                         hw::RcuFault::phase_error, hw::RcuFault::power_loss}) {
      if (w[2] == hw::to_string(f)) {
        c.fault = f;
        return c;
      }
    }
    throw io::ParseError(fmt::format(
        "fault: {}: the fault must be joint_not_answering, encoder_error, phase_error or "
        "power_loss",
        io::quoted(w[2])));
  }
  throw io::ParseError(
      fmt::format("unknown command {}; use out ADDR BYTE, in ADDR, step MS or fault JOINT KIND",
                  io::quoted(w[0])));
}

}  // namespace rccx::tools
