#include "jointtest.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <boost/lockfree/spsc_queue.hpp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <istream>
#include <memory>
#include <string>
#include <vector>

#include "console_lines.hpp"
#include "rccx/io/console.hpp"
#include "rccx/io/input.hpp"
#include "rccx/io/signals.hpp"
#include "rccx/rtc/session.hpp"

namespace rccx::tools {

namespace {

// --- The control task's side: written only in f1 and f2, never a lock --------------------------

/// The servo ramp of M.
struct ServoRamp {
  bool active = false;
  std::size_t joint = 0;
  double target = 0.0;  ///< range value
  double speed = 0.0;   ///< per second
  double at = 0.0;      ///< the last POSVEL target
  bool fresh = false;   ///< started this sample: the joint is stopped first
};

struct TestCommand;
/// What f1 does with a command: this sample's Chg (and M's ramp).
using ControlAction = void (*)(rtc::Control&, ServoRamp&, const TestCommand&) noexcept;

/// A command on its way to the control task.
struct TestCommand {
  ControlAction act = nullptr;
  rtc::Setting setting = rtc::Setting::none;  ///< a joint controller setting's
  std::uint8_t joint = 0;
  double value = 0.0;  ///< SI: a range value, or a bit number; a setting's value
  double speed = 0.0;  ///< SI, per second: for m and M
};

void move_joint(rtc::Control& c, ServoRamp& ramp, const TestCommand& cmd) noexcept {  // m
  ramp.active = false;
  c.chg().pos(cmd.joint, cmd.value, cmd.speed);
}

void start_ramp(rtc::Control& c, ServoRamp& ramp, const TestCommand& cmd) noexcept {  // M
  // Stopped where it is first: the ramp's first step is then one step from the last target,
  // also when an `m` move was under way (its target far ahead of the joint, a jump RTC would
  // refuse as too fast).
  const double here = c.how().joint[cmd.joint].range;
  ramp = {true, cmd.joint, cmd.value, cmd.speed, here, true};
  c.chg().pos(cmd.joint, here);
}

void stop_joint(rtc::Control& c, ServoRamp& ramp, const TestCommand& cmd) noexcept {  // s
  ramp.active = false;
  c.chg().pos(cmd.joint, c.how().joint[cmd.joint].range);
}

void open_hand(rtc::Control& c, ServoRamp&, const TestCommand&) noexcept {
  c.chg().hand = rtc::Request::off;
}
void close_hand(rtc::Control& c, ServoRamp&, const TestCommand&) noexcept {
  c.chg().hand = rtc::Request::on;
}
void power_off(rtc::Control& c, ServoRamp&, const TestCommand&) noexcept {
  c.chg().power = rtc::Request::off;
}
void power_on(rtc::Control& c, ServoRamp&, const TestCommand&) noexcept {
  c.chg().power = rtc::Request::on;
}
void clear_output(rtc::Control& c, ServoRamp&, const TestCommand& cmd) noexcept {
  c.chg().outputs_clear = static_cast<std::uint16_t>(1U << static_cast<unsigned>(cmd.value));
}
void set_output(rtc::Control& c, ServoRamp&, const TestCommand& cmd) noexcept {
  c.chg().outputs_set = static_cast<std::uint16_t>(1U << static_cast<unsigned>(cmd.value));
}
void change_setting(rtc::Control& c, ServoRamp&, const TestCommand& cmd) noexcept {
  c.chg().setting = {cmd.setting, cmd.joint, static_cast<std::uint16_t>(cmd.value)};
}

/// What the control task keeps: commands arrive through a lock-free queue. Shared with f1 and
/// f2, which the session holds.
struct ControlSide {
  boost::lockfree::spsc_queue<TestCommand, boost::lockfree::capacity<64>> queue;
  ServoRamp ramp;

  void f1(rtc::Control& c) noexcept {
    TestCommand cmd;
    while (queue.pop(cmd)) cmd.act(c, ramp, cmd);
  }
  /// M: POSVEL every sample along a ramp at the joint's velocity.
  void f2(rtc::Control& c) noexcept {
    if (!ramp.active) return;
    if (ramp.fresh) {  // this sample stops the joint (f1); the ramp starts at the next
      ramp.fresh = false;
      return;
    }
    const double step = ramp.speed * c.period_s();
    ramp.at += std::clamp(ramp.target - ramp.at, -step, step);
    c.chg().posvel(ramp.joint, ramp.at);
    if (ramp.at == ramp.target) ramp.active = false;
  }
};

// --- The console's side ------------------------------------------------------------------------

constexpr const char* kTestMenu =
    "commands (one per line; values in deg or mm, speeds per second):\n"
    "  j N     set the joint for the commands below      x    examine positions\n"
    "  m V     move joint to V at its velocity (POS)     M V  servo joint to V (POSVEL ramp)\n"
    "  v V     set the joint's velocity                  s    stop joint where it is\n"
    "  h / H   open / close the hand                     o B / O B  clear / set output bit B\n"
    "  p / P   arm power off / on                        r MS set the sample period\n"
    "  w S     wait S seconds                            q    quit\n"
    "  Microbo joint controllers (Appendix B units):\n"
    "  a N     acceleration setting (1/4 rad/s^2)       f N  speed factor (0..255)\n"
    "  k N     dynamic integration constant (0..255)    K N  static integration constant\n"
    "  V N     static zone speed (0..255)               z N  static zone size (0..255)\n"
    "  X       examine the joint's motor parameters\n"
    "  ?       this menu\n";

class Console {
 public:
  explicit Console(const RtcArgs& a);
  /// Reads and does lines until q, the end of stdin or a stop signal; the exit code.
  int run();

 private:
  /// One letter's entry: what the console does with its line and, for what is sent, what the
  /// control task does with it.
  struct Command {
    char letter;
    bool anytime;  ///< also once control has ended (reads, prints, the console's own state)
    void (Console::*handle)(const JointtestLine&, const Command&);  ///< null: nothing (blank)
    ControlAction act;     ///< f1's part of what handle sends
    rtc::Setting setting;  ///< a joint controller setting (a f k K V z X)
  };
  static const Command* command(char letter) noexcept;

  void do_line(const std::string& line);
  void start();
  /// Queues `c` for f1 and lets a sample run.
  void send(TestCommand c);
  /// Control ended (a limit, a fault): says why at once, counts it, and controls again.
  void check();
  void failed(const std::string& why);
  int end_session(int read_error);
  [[nodiscard]] static bool stopped() noexcept { return io::stop_count() != kStops; }
  [[nodiscard]] std::uint8_t joint8() const noexcept { return static_cast<std::uint8_t>(joint_); }

  // The handlers, one signature for the table.
  void select_joint(const JointtestLine& c, const Command& k);
  void set_velocity(const JointtestLine& c, const Command& k);
  void send_move(const JointtestLine& c, const Command& k);
  void send_stop(const JointtestLine& c, const Command& k);
  void send_plain(const JointtestLine& c, const Command& k);
  void send_bit(const JointtestLine& c, const Command& k);
  void send_setting(const JointtestLine& c, const Command& k);
  void read_examined();
  void examine_positions(const JointtestLine& c, const Command& k);
  void wait(const JointtestLine& c, const Command& k);
  void change_period(const JointtestLine& c, const Command& k);
  void quit(const JointtestLine& c, const Command& k);
  void menu(const JointtestLine& c, const Command& k);

  /// main() installed the handlers at start: a signal during the start-up counts too.
  static constexpr std::uint32_t kStops = 0;
  const io::ScopedStopHandlers handlers_;
  SimulatedRobot r_;
  const kin::RobotModel& m_;
  std::shared_ptr<ControlSide> control_ = std::make_shared<ControlSide>();
  std::size_t joint_ = 0;
  std::vector<double> velocity_;  ///< per joint, SI per second
  int status_ = kOk;
  bool quit_ = false;
};

const Console::Command* Console::command(char letter) noexcept {
  using S = rtc::Setting;
  using C = Console;
  // clang-format off
  static constexpr Command kTable[] = {
      // letter anytime handler                f1's action     setting
      {'\0',   true,    nullptr,                nullptr,        S::none},  // a blank line
      {'j',    true,    &C::select_joint,       nullptr,        S::none},
      {'v',    true,    &C::set_velocity,       nullptr,        S::none},
      {'x',    true,    &C::examine_positions,  nullptr,        S::none},
      {'q',    true,    &C::quit,               nullptr,        S::none},
      {'?',    true,    &C::menu,               nullptr,        S::none},
      {'m',    false,   &C::send_move,          move_joint,     S::none},
      {'M',    false,   &C::send_move,          start_ramp,     S::none},
      {'s',    false,   &C::send_stop,          stop_joint,     S::none},
      {'h',    false,   &C::send_plain,         open_hand,      S::none},
      {'H',    false,   &C::send_plain,         close_hand,     S::none},
      {'p',    false,   &C::send_plain,         power_off,      S::none},
      {'P',    false,   &C::send_plain,         power_on,       S::none},
      {'o',    false,   &C::send_bit,           clear_output,   S::none},
      {'O',    false,   &C::send_bit,           set_output,     S::none},
      {'w',    false,   &C::wait,               nullptr,        S::none},
      {'r',    false,   &C::change_period,      nullptr,        S::none},
      {'a',    false,   &C::send_setting,       change_setting, S::acceleration},
      {'f',    false,   &C::send_setting,       change_setting, S::speed_factor},
      {'k',    false,   &C::send_setting,       change_setting, S::dynamic_integral},
      {'K',    false,   &C::send_setting,       change_setting, S::static_integral},
      {'V',    false,   &C::send_setting,       change_setting, S::static_speed},
      {'z',    false,   &C::send_setting,       change_setting, S::static_zone},
      {'X',    false,   &C::send_setting,       change_setting, S::examine},
  };
  // clang-format on
  for (const Command& k : kTable) {
    if (k.letter == letter) return &k;
  }
  return nullptr;  // parse_jointtest_line knows every letter above and no other
}

Console::Console(const RtcArgs& a) : r_(a), m_(r_.model), velocity_(m_.dof()) {
  // Ctrl-C ends the program (the arm holds) rather than control: the loop sees the stop count.
  r_.session->set_hangup_handler([](rtc::Session&) {});
  start();
  for (std::size_t i = 0; i < m_.dof(); ++i)
    velocity_[i] = rtc::kDefaultSpeedFraction * m_.joints[i].max_velocity;
}

int Console::run() {
  fmt::print("jointtest on {} ({} joints), {} time, period {:.3f} ms. ? for the menu.\n", m_.title,
             m_.dof(), r_.simulated() ? "simulated" : "real", r_.period_s() * 1e3);
  io::StopAwareInput buffer(STDIN_FILENO, kStops);  // ends a wait for a line on Ctrl-C / SIGTERM
  std::istream input(&buffer);
  std::string line;
  std::string too_long;  // a line refused by its length
  while (!quit_ && !stopped() && io::read_line(input, line, too_long)) {
    if (!too_long.empty()) {
      failed(too_long);
      continue;
    }
    do_line(line);
  }
  return end_session(buffer.error());
}

void Console::do_line(const std::string& line) {
  JointtestLine c;
  try {
    c = parse_jointtest_line(line, m_, joint_);
  } catch (const io::ParseError& e) {
    failed(e.what());
    return;
  }
  const Command* k = command(c.letter);
  if (!r_.session->controlling() && (k == nullptr || !k->anytime)) {
    failed(fmt::format("{}: control has ended and could not be restarted; q quits", c.letter));
    return;
  }
  if (k != nullptr && k->handle != nullptr) (this->*k->handle)(c, *k);
  check();
}

void Console::start() {
  r_.session->control([control = control_](rtc::Control& c) { control->f1(c); },
                      [control = control_](rtc::Control& c) { control->f2(c); });
}

void Console::send(TestCommand c) {
  // Without control nobody empties the queue: give up rather than wait for ever.
  while (!control_->queue.push(c)) {
    if (!r_.session->controlling() || stopped()) return;
    r_.session->wait_for(r_.session->period());
  }
  r_.session->wait_for(r_.session->period());  // simulated time: let the command take effect
}

void Console::check() {
  const rtc::Termination t = r_.session->termination();
  if (!t.ended()) return;
  std::fflush(stdout);
  rtc::print_terminate_code(t, stdout);
  status_ = kFailure;
  r_.session->release();
  if (stopped()) return;
  try {
    start();
    fmt::print("control restarted\n");
  } catch (const rtc::SessionError& e) {
    std::fflush(stdout);
    io::eprint("control could not be restarted: {}\n", e.what());
  }
}

void Console::failed(const std::string& why) {
  std::fflush(stdout);  // the error after what came before it
  io::eprint("{}\n", why);
  status_ = kFailure;
}

int Console::end_session(int read_error) {
  const rtc::Termination end = r_.session->release();
  if (end.ended()) {
    rtc::print_terminate_code(end, stdout);
    status_ = kFailure;
  }
  if (read_error != 0) failed(fmt::format("reading stdin: {}", std::strerror(read_error)));
  std::fflush(stdout);
  status_ = finish_logs(r_, status_);  // a lost log makes the run a failure
  if (stopped()) {
    fmt::print("stopped by a signal: control released, the arm holds\n");
    std::fflush(stdout);
    return io::stop_exit_code();
  }
  return status_;
}

// --- The handlers --------------------------------------------------------------------------------

void Console::select_joint(const JointtestLine& c, const Command&) {
  joint_ = c.joint;
  fmt::print("joint {} ({})\n", joint_ + 1, m_.joints[joint_].name);
}

void Console::set_velocity(const JointtestLine& c, const Command&) {
  const kin::Joint& jm = m_.joints[joint_];
  velocity_[joint_] = from_shown(jm, c.value);
  fmt::print("joint {} velocity {:.3f} {}/s\n", joint_ + 1, shown(jm, velocity_[joint_]), unit(jm));
}

void Console::send_move(const JointtestLine& c, const Command& k) {  // m, M
  const kin::Joint& jm = m_.joints[joint_];
  send({k.act, k.setting, joint8(), from_shown(jm, c.value) - jm.lower, velocity_[joint_]});
}

void Console::send_stop(const JointtestLine&, const Command& k) {
  send({k.act, k.setting, joint8(), 0, 0});
}

void Console::send_plain(const JointtestLine&, const Command& k) {  // h, H, p, P
  send({k.act, k.setting, 0, 0, 0});
}

void Console::send_bit(const JointtestLine& c, const Command& k) {  // o, O
  send({k.act, k.setting, 0, c.value, 0});
}

void Console::send_setting(const JointtestLine& c, const Command& k) {
  if (!r_.rcu) {
    failed(fmt::format("{}: {} has no Microbo joint controllers (thesis Appendix B)", k.letter,
                       m_.name));
    return;
  }
  send({k.act, k.setting, joint8(), c.value, 0});
  if (k.setting == rtc::Setting::examine) return read_examined();
  fmt::print("joint {} {} {}\n", joint_ + 1, rtc::to_string(k.setting), c.value);
}

/// X's answer: the joint's motor parameters, read during the next sample.
void Console::read_examined() {
  r_.session->wait_for(r_.session->period());
  const rtc::How h = r_.session->how();
  if (h.examined_joint != static_cast<int>(joint_)) {
    failed(fmt::format("X: joint {} did not answer", joint_ + 1));
    return;
  }
  fmt::print("joint {} motor parameters:", joint_ + 1);
  for (const std::uint8_t b : h.motor_parameters) fmt::print(" {}", b);
  fmt::print("\n");
}

void Console::examine_positions(const JointtestLine&, const Command&) {
  print_positions_detailed(m_, r_.session->how());
}

void Console::wait(const JointtestLine& c, const Command&) {
  r_.session->wait_for(c.duration);  // ends early on a stop signal or when control ends
}

void Console::change_period(const JointtestLine& c, const Command&) {
  try {
    r_.session->release();
    r_.session->set_period(c.duration);
    start();
    fmt::print("sample period {:.3f} ms\n", r_.period_s() * 1e3);
  } catch (const rtc::SessionError& e) {
    failed(fmt::format("r: {}", e.what()));
    try {
      start();  // control again at the period it had
    } catch (const rtc::SessionError&) {
    }
  }
}

void Console::quit(const JointtestLine&, const Command&) {
  quit_ = true;
}

void Console::menu(const JointtestLine&, const Command&) {
  fmt::print("{}", kTestMenu);
}

}  // namespace

int run_jointtest(const RtcArgs& a) {
  Console console(a);
  return console.run();
}

}  // namespace rccx::tools
