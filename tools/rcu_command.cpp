#include "rcu_command.hpp"

#include <fmt/format.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <istream>
#include <string>

#include "console_lines.hpp"
#include "rccx/hw/rcu.hpp"
#include "rccx/io/console.hpp"
#include "rccx/io/input.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/io/signals.hpp"

namespace rccx::tools {

namespace {

struct RcuArgs {
  RobotChoice robot{"microbo"};
  bool uncalibrated = false;
};

/// Emulated time in slices, so that Ctrl-C ends a long `step` soon. False when stopped.
bool advance(hw::Rcu& rcu, std::int64_t us, std::uint32_t stops) {
  constexpr std::int64_t kSliceUs = 10'000;
  while (us > 0) {
    if (io::stop_count() != stops) return false;
    const std::int64_t slice = std::min(us, kSliceUs);
    rcu.advance_us(slice);
    us -= slice;
  }
  return true;
}

/// One console line; false (after one line on stderr) when it cannot be done.
bool run_line(hw::Rcu& rcu, const std::string& line, std::uint32_t stops) {
  RcuLine c;
  try {
    c = parse_rcu_line(line, rcu.model().dof());
  } catch (const io::ParseError& e) {
    io::eprint("error: {}: {}\n", io::quoted(line), e.what());
    return false;
  }
  switch (c.kind) {
    case RcuLine::Kind::none:
      return true;
    case RcuLine::Kind::out:
      rcu.out(c.address, c.byte);
      return true;
    case RcuLine::Kind::in:
      fmt::print("{:02X}\n", rcu.in(c.address));
      return true;
    case RcuLine::Kind::step:
      return advance(rcu, c.step_us, stops);
    case RcuLine::Kind::fault:
      rcu.inject(c.fault, c.joint);
      return true;
  }
  return true;
}

int run_rcu(const RcuArgs& a) {
  const kin::RobotModel model = a.robot.model();
  hw::SimulatedArmOptions options;
  options.calibrated = !a.uncalibrated;
  std::unique_ptr<hw::Rcu> rcu;
  try {
    rcu = std::make_unique<hw::Rcu>(model, options);
  } catch (const std::invalid_argument& e) {
    throw BadArgument{fmt::format("robot {} has no RCU to emulate: {}", model.name, e.what())};
  }
  // Ctrl-C and SIGTERM end the console between lines or within a step, not the process.
  io::install_stop_handlers();
  // main() installed the handlers at start: a signal during the start-up (making the RCU)
  // counts too, rather than being lost while the console waits for input for ever.
  const std::uint32_t stops = 0;
  int status = kOk;
  {
    io::StopAwareInput buffer(STDIN_FILENO, stops);
    std::istream in(&buffer);
    std::string line;
    std::string too_long;  // a line refused by its length
    while (io::stop_count() == stops && io::read_line(in, line, too_long)) {
      if (!too_long.empty()) {
        io::eprint("error: {}\n", too_long);
        status = kFailure;
        continue;
      }
      if (!run_line(*rcu, line, stops)) status = kFailure;
    }
    if (buffer.error() != 0) {
      io::eprint("error: reading stdin: {}\n", std::strerror(buffer.error()));
      status = kFailure;
    }
  }
  std::fflush(stdout);
  const bool stopped = io::stop_count() != stops;
  io::restore_stop_handlers();
  if (stopped) {
    io::eprint("rccx rcu: stopped by a signal\n");
    return io::stop_exit_code();
  }
  return status;
}

}  // namespace

void add_rcu_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<RcuArgs>();
  CLI::App* cmd = app.add_subcommand(
      "rcu",
      "A register console to the emulated Microbo RCU (thesis Appendix B). Reads lines from "
      "stdin: `out ADDR BYTE` writes a register, `in ADDR` prints it (two hex digits), `step "
      "MS` lets MS milliseconds of emulated time pass (nothing else does), `fault JOINT KIND` "
      "injects joint_not_answering, encoder_error, phase_error or power_loss. Addresses and "
      "bytes in hex: joint n's data register is 5800 + 2(n-1), its command/status register "
      "one above. Only `in` prints; a line that fails prints one line on stderr and the exit "
      "code is 1.");
  add_robot_options(*cmd, args->robot);
  cmd->add_flag("--uncalibrated", args->uncalibrated,
                "Start with the joints not initialized (in stand-by), as after power-up");
  cmd->callback([args, &exit_code] { guarded(exit_code, [&] { return run_rcu(*args); }); });
}

}  // namespace rccx::tools
