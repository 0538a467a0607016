#include "rcu_command.hpp"

#include <fmt/format.h>

#include <iostream>
#include <optional>
#include <sstream>
#include <string>

#include "rccx/hw/rcu.hpp"

namespace rccx::tools {

namespace {

std::optional<unsigned long> parse_hex(const std::string& word, unsigned long max) {
  if (word.empty() || word.size() > 6) return std::nullopt;
  std::size_t used = 0;
  unsigned long v = 0;
  try {
    v = std::stoul(word, &used, 16);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != word.size() || v > max) return std::nullopt;
  return v;
}

std::optional<hw::RcuFault> parse_fault(const std::string& word) {
  for (const auto f : {hw::RcuFault::joint_not_answering, hw::RcuFault::encoder_error,
                       hw::RcuFault::phase_error, hw::RcuFault::power_loss}) {
    if (word == hw::to_string(f)) return f;
  }
  return std::nullopt;
}

struct RcuArgs {
  RobotChoice robot{"microbo"};
  bool uncalibrated = false;
};

/// One console line; false (after one line on stderr) when it cannot be done.
bool run_line(hw::Rcu& rcu, const std::string& line) {
  std::istringstream in(line);
  std::string verb, a, b, extra;
  in >> verb >> a >> b >> extra;
  const auto fail = [&](const std::string& why) {
    fmt::print(stderr, "error: \"{}\": {}\n", line, why);
    return false;
  };
  if (!extra.empty()) return fail("too many words");
  const auto address = [&](const std::string& w) -> std::optional<std::uint16_t> {
    const auto v = parse_hex(w, 0xffff);
    const std::size_t n = rcu.model().dof();
    if (!v || *v < hw::kRcuBase || *v >= hw::kRcuBase + 2 * n) return std::nullopt;
    return static_cast<std::uint16_t>(*v);
  };
  const std::string registers =
      fmt::format("{:04X} to {:04X} (hex)", hw::kRcuBase, hw::kRcuBase + 2 * rcu.model().dof() - 1);
  if (verb == "out") {
    const auto addr = address(a);
    const auto value = parse_hex(b, 0xff);
    if (!addr) return fail("the address must be one of the joints' registers, " + registers);
    if (!value) return fail("the byte must be 00 to FF (hex)");
    rcu.out(*addr, static_cast<std::uint8_t>(*value));
    return true;
  }
  if (verb == "in") {
    const auto addr = address(a);
    if (!addr || !b.empty()) return fail("write: in ADDR, with ADDR one of " + registers);
    fmt::print("{:02X}\n", rcu.in(*addr));
    return true;
  }
  if (verb == "step") {
    double ms = 0;
    try {
      ms = std::stod(a);
    } catch (const std::exception&) {
      ms = -1;
    }
    if (!(ms >= 0) || ms > 3.6e6 || !b.empty()) return fail("write: step MS, with MS >= 0");
    rcu.advance_us(std::llround(ms * 1000));
    return true;
  }
  if (verb == "fault") {
    const auto joint = parse_hex(a, 8);
    const auto kind = parse_fault(b);
    if (!joint || *joint < 1 || *joint > rcu.model().dof()) {
      return fail(fmt::format("the joint must be 1 to {}", rcu.model().dof()));
    }
    if (!kind) {
      return fail(
          "the fault must be joint_not_answering, encoder_error, phase_error or "
          "power_loss");
    }
    rcu.inject(*kind, *joint - 1);
    return true;
  }
  return fail("unknown command; use out ADDR BYTE, in ADDR, step MS or fault JOINT KIND");
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
  int status = kOk;
  std::string line;
  while (std::getline(std::cin, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    if (!run_line(*rcu, line)) status = kFailure;
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
