// The lines of the rccx consoles, read strictly and apart from doing them, so that the readers
// can be tested and fuzzed on their own: `rccx jointtest` (the thesis's test program) and
// `rccx rcu` (the Microbo RCU's register console). The teach loop's reader is
// rccl::parse_teach_command. Every refusal is an io::ParseError saying what to write.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <istream>
#include <string_view>

#include "rccx/hw/rcu.hpp"
#include "rccx/io/console.hpp"  // what the consoles use with these readers
#include "rccx/io/input.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/io/signals.hpp"
#include "rccx/kinematics/robot_model.hpp"

namespace rccx::tools {

/// The longest `w S` of jointtest, s.
inline constexpr double kMaxJointtestWaitS = 1e6;
/// The farthest jointtest target, deg or mm: beyond a joint's limits on purpose (the test
/// program exercises RTC's limit checks), but finite and sane.
inline constexpr double kMaxJointtestTarget = 1e5;
/// The longest `step MS` of the RCU console, ms (an hour).
inline constexpr double kMaxRcuStepMs = 3.6e6;

/// One jointtest line. `letter` is the thesis's letter ('\0' for a blank line).
struct JointtestLine {
  char letter = '\0';
  std::size_t joint = 0;  ///< j: 0 .. dof - 1
  /// m / M: the target (deg or mm, as typed); v: the speed (deg/s or mm/s, > 0); o / O: the bit
  /// 0 .. 15; a f k K V z: the controller's value (whole, 0 .. 255 or 0 .. 65535 for a).
  double value = 0.0;
  std::chrono::nanoseconds duration{0};  ///< w: the wait; r: the sample period
};

/// Reads a jointtest line; `joint` (0-based) is the joint selected by `j`, for the ranges of
/// v. Throws io::ParseError.
JointtestLine parse_jointtest_line(std::string_view line, const kin::RobotModel& model,
                                   std::size_t joint);

/// One RCU console line.
struct RcuLine {
  enum class Kind : std::uint8_t { none, out, in, step, fault };
  Kind kind = Kind::none;
  std::uint16_t address = 0;  ///< out, in: a joint's register
  std::uint8_t byte = 0;      ///< out
  std::int64_t step_us = 0;   ///< step: emulated time, us
  std::size_t joint = 0;      ///< fault: 0 .. dof - 1
  hw::RcuFault fault = hw::RcuFault::joint_not_answering;
};

/// Reads an RCU console line (blank lines and # comments are Kind::none) for a robot with
/// `dof` joints. Throws io::ParseError.
RcuLine parse_rcu_line(std::string_view line, std::size_t dof);

}  // namespace rccx::tools
