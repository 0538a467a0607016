// `rccx jointtest`: the thesis's `test` program, a console that commands single joints through
// Chg, one line on stdin at a time (console_lines.hpp reads the lines; ? lists the letters).
// Each letter maps to one entry of one table: what the console does with the line, and what the
// control task does with the command it sends (through a lock-free queue, in f1).
//
//   RtcArgs args;                       // --robot, --period, ... (add_rtc_options)
//   return run_jointtest(args);         // reads stdin until q, its end or Ctrl-C
#pragma once

#include "rtc_robot.hpp"

namespace rccx::tools {

/// Runs the console on the robot `a` asks for. Returns the exit code: kOk, kFailure when a line
/// was refused or control ended on the way, 128 + the signal when stopped by one.
int run_jointtest(const RtcArgs& a);

}  // namespace rccx::tools
