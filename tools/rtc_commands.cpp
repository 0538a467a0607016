#include "rtc_commands.hpp"
#include "console_lines.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "rccx/hw/rcu.hpp"
#include "rccx/hw/simulated_arm.hpp"
#include "rccx/io/console.hpp"
#include "rccx/io/input.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/io/signals.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rtc/microbo_driver.hpp"
#include "rccx/rtc/servo_driver.hpp"
#include "rccx/rtc/session.hpp"
#include "rccx/rtc/simulated_robot.hpp"

namespace rccx::tools {

namespace {

using namespace std::chrono_literals;
using Seconds = std::chrono::duration<double>;

std::chrono::nanoseconds to_ns(double seconds) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Seconds(seconds));
}

/// The longest a control program runs or waits: beyond it a number is a typo (11.6 days).
constexpr double kMaxRunSeconds = 1e6;

double seconds_of(const std::string& text, const char* what, double lo_s = 1e-6) {
  try {
    return io::parse_seconds(text, what, lo_s, kMaxRunSeconds);
  } catch (const io::ParseError& e) {
    throw BadArgument{e.what()};
  }
}

/// What every control program takes.
struct RtcArgs {
  RobotChoice robot{"microbo"};
  std::string period;  ///< empty: the robot's usual period
  bool realtime = false;
  bool uncalibrated = false;
  std::string log;  ///< CSV of every controlled sample
};

void add_rtc_options(CLI::App& cmd, RtcArgs& a) {
  add_robot_options(cmd, a.robot);
  cmd.add_option("--period", a.period,
                 "Sample period, 0.25ms to 56ms (e.g. 1ms, 28ms); default 28ms for the Microbo "
                 "(its bus needs about 10 ms a sample), 10ms for the others")
      ->check(not_empty());
  cmd.add_flag("--realtime", a.realtime,
               "Run in real time (SCHED_FIFO when allowed) instead of simulated time, which is "
               "deterministic and runs as fast as the machine allows");
  cmd.add_flag("--uncalibrated", a.uncalibrated,
               "Start the simulated robot uncalibrated (encoders relative to power-up)");
  cmd.add_option("--log", a.log,
                 "Write every controlled sample to this CSV file: t,seg,q1..,qm1..,x,y,z,ax,ay,az "
                 "(s, rad or m; the environment's RCCX_LOG does the same for any program)")
      ->check(not_empty());
}

/// The simulated robot the options ask for, its errors turned into bad arguments.
struct SimulatedRobot : rtc::SimulatedRobot {
  explicit SimulatedRobot(const RtcArgs& a) : rtc::SimulatedRobot(make(a)) {}

 private:
  static rtc::SimulatedRobot make(const RtcArgs& a) {
    kin::RobotModel model = a.robot.model();
    rtc::SimulatedRobotOptions o;
    o.calibrated = !a.uncalibrated;
    o.clock = a.realtime ? rtc::ClockKind::real_time : rtc::ClockKind::simulated;
    if (!a.period.empty()) o.period = parse_period(a.period);
    o.log = a.log;
    const std::string name = model.name;
    const bool log_given = !a.log.empty();
    try {
      return rtc::SimulatedRobot(std::move(model), o);
    } catch (const rtc::SessionError& e) {
      throw BadArgument{fmt::format("--period: {}", e.what())};
    } catch (const rtc::LogError& e) {
      // RCCX_LOG's errors name it; --log's are named here.
      const bool environment = std::string_view(e.what()).starts_with("RCCX_LOG");
      throw BadArgument{environment || !log_given ? std::string(e.what())
                                                  : fmt::format("--log {}: {}", a.log, e.what())};
    } catch (const std::invalid_argument& e) {
      throw BadArgument{fmt::format("robot {} cannot be simulated: {}", name, e.what())};
    }
  }
};

bool revolute(const kin::Joint& j) {
  return j.type == kin::JointType::revolute;
}
/// SI to what people read: degrees, millimetres.
double shown(const kin::Joint& j, double si) {
  return revolute(j) ? math::rad_to_deg(si) : si * 1e3;
}
double from_shown(const kin::Joint& j, double value) {
  return revolute(j) ? math::deg_to_rad(value) : value * 1e-3;
}
const char* unit(const kin::Joint& j) {
  return revolute(j) ? "deg" : "mm";
}

void print_positions(const kin::RobotModel& m, const rtc::How& h) {
  fmt::print("t {:8.3f} s ", h.time_s);
  for (std::size_t i = 0; i < h.dof; ++i) {
    const kin::Joint& j = m.joints[i];
    fmt::print(" {} {:.3f} {}", j.name, shown(j, h.joint[i].q), unit(j));
  }
  if (!h.all_calibrated) fmt::print("  (not calibrated)");
  if (!h.power) fmt::print("  (power off)");
  fmt::print("\n");
}

void print_positions_detailed(const kin::RobotModel& m, const rtc::How& h) {
  fmt::print("t = {:.3f} s, sample {}, power {}, hand {}, outputs 0x{:04x}\n", h.time_s, h.sample,
             h.power ? "on" : "off", h.hand_closed ? "closed" : "open", h.outputs);
  for (std::size_t i = 0; i < h.dof; ++i) {
    const kin::Joint& j = m.joints[i];
    const rtc::JointHow& jh = h.joint[i];
    fmt::print("  {} {:<7} {:10.3f} {:<3}  range {:10.3f} {:<3}  speed {:9.3f} {}/s{}{}\n", i + 1,
               j.name, shown(j, jh.q), unit(j), shown(j, jh.range), unit(j), shown(j, jh.velocity),
               unit(j), jh.has(rtc::kCalibrated) ? "" : "  not calibrated",
               jh.has(rtc::kCalibrating) ? "  calibrating" : "");
  }
}

int report_termination(const rtc::Termination& t) {
  if (!t.ended()) return kOk;
  rtc::print_terminate_code(t, stderr);
  return kFailure;
}

/// The end of every control program: the session closed, the logs in place. A log that is not
/// complete (a full disk, rows dropped) makes the run a failure; a stop signal gives 128 + it.
int finish(SimulatedRobot& r, int code) {
  const std::string problem = r.finish();
  if (!problem.empty() && code == kOk) code = kFailure;
  if (io::stop_count() > 0) code = io::stop_exit_code();
  return code;
}

// ---------------------------------------------------------------------------------------------

struct ReportArgs : RtcArgs {
  std::string seconds = "2";
  std::string every = "0.5";
  bool json = false;
};

/// --every: at least one sample period, else time would never advance between reports.
double every_of(const std::string& text, const SimulatedRobot& r) {
  const double every = seconds_of(text, "--every");
  if (every < r.period_s()) {
    throw BadArgument{fmt::format(
        "--every: \"{}\" is shorter than the sample period ({:g} ms); give at least {:g}ms", text,
        r.period_s() * 1e3, r.period_s() * 1e3)};
  }
  return every;
}

int run_report(const ReportArgs& a) {
  const double seconds = seconds_of(a.seconds, "--seconds");
  seconds_of(a.every, "--every");  // its form, before the robot is made
  SimulatedRobot r(a);
  const double every = every_of(a.every, r);
  r.session->control({}, {});  // empty f1 and f2: the full cycle, nothing commanded
  const std::int64_t lines = std::max<std::int64_t>(1, std::llround(seconds / every));
  // In real time an overrun says the machine missed a deadline: count it and go on measuring.
  std::uint64_t overruns = 0;
  rtc::Termination t;
  for (std::int64_t i = 0; i < lines && !t.ended() && io::stop_count() == 0; ++i) {
    t = r.session->wait_for(to_ns(every));
    if (!a.json) print_positions(r.model, r.session->how());
    if (a.realtime && t.code == rtc::TerminateCode::overrun) {
      ++overruns;
      if (!a.json) rtc::print_terminate_code(t, stdout);
      r.session->release();
      r.session->control({}, {});
      t = {};
    }
  }
  if (!t.ended()) t = r.session->release();
  if (a.realtime) {  // the figures up to the end, even when control ended early
    const rtc::LatencyStats s = r.session->latency();
    if (a.json) {
      nlohmann::ordered_json j{{"period_us", Seconds(r.session->period()).count() * 1e6},
                               {"seconds", seconds},
                               {"wakeups", s.wakeups},
                               {"missed_deadlines", s.missed_deadlines},
                               {"p50_us", s.p50_us},
                               {"p99_us", s.p99_us},
                               {"p999_us", s.p999_us},
                               {"max_us", s.max_us},
                               {"overruns", overruns}};
      fmt::print("{}\n", j.dump(2));
    } else {
      fmt::print(
          "wake-up latency over {} ticks at {:.3f} ms: p50 {:.0f} us, p99 {:.0f} us, p99.9 "
          "{:.0f} us, max {:.0f} us; missed deadlines {}; control overruns {}\n",
          s.wakeups, r.period_s() * 1e3, s.p50_us, s.p99_us, s.p999_us, s.max_us,
          s.missed_deadlines, overruns);
    }
  }
  return finish(r, report_termination(t));
}

// ---------------------------------------------------------------------------------------------

struct CalibArgs : RtcArgs {
  std::string timeout = "120";
};

int run_calib(const CalibArgs& a) {
  const double timeout = seconds_of(a.timeout, "--timeout");
  SimulatedRobot r(a);
  const rtc::How before = r.session->how();
  fmt::print("calibrating the {} joints of {} ({}): each seeks its calibration position\n",
             r.model.dof(), r.model.title,
             before.all_calibrated ? "re-calibration" : "not calibrated");
  std::atomic<bool> sent{false};
  r.session->control(
      [&sent](rtc::Control& c) {
        if (sent.load(std::memory_order_relaxed)) return;
        for (std::size_t i = 0; i < c.how().dof; ++i) c.chg().stopcal(i);
        sent.store(true, std::memory_order_release);
      },
      {});
  const std::uint64_t start = r.session->how().sample;
  const bool done = r.session->wait_until(
      [&](const rtc::How& h) {
        if (h.sample <= start + 2) return false;
        for (std::size_t i = 0; i < h.dof; ++i) {
          if (h.joint[i].has(rtc::kCalibrating)) return false;
        }
        return h.all_calibrated;
      },
      to_ns(timeout));
  const rtc::How h = r.session->how();
  const rtc::Termination t = r.session->release();
  if (t.ended()) return finish(r, report_termination(t));
  if (!done) {
    if (io::stop_count() == 0)
      io::eprint("error: calibration did not finish within {} s\n", timeout);
    return finish(r, kFailure);
  }
  fmt::print("ALL JOINTS calibrated after {:.2f} s\n", h.time_s - before.time_s);
  print_positions_detailed(r.model, h);
  return finish(r, kOk);
}

// ---------------------------------------------------------------------------------------------

int run_limp(const RtcArgs& a) {
  SimulatedRobot r(a);
  r.session->control([](rtc::Control& c) { c.chg().power = rtc::Request::off; }, {});
  const bool off = r.session->wait_until([](const rtc::How& h) { return !h.power; }, 1s);
  const rtc::Termination t = r.session->release();
  if (t.ended()) return finish(r, report_termination(t));
  if (!off) {
    if (io::stop_count() == 0) io::eprint("error: arm power did not go off\n");
    return finish(r, kFailure);
  }
  fmt::print("arm power off: the joints are limp (held by their brakes)\n");
  print_positions(r.model, r.session->how());
  return finish(r, kOk);
}

// ---------------------------------------------------------------------------------------------

struct MarshArgs : RtcArgs {
  std::string seconds = "4";
  std::string every = "0.5";
  std::vector<std::string> pushes;
};

int run_marsh(const MarshArgs& a) {
  struct Push {
    std::size_t joint;
    double effort;
  };
  const double seconds = seconds_of(a.seconds, "--seconds");
  seconds_of(a.every, "--every");
  SimulatedRobot r(a);
  const double every = every_of(a.every, r);
  std::vector<Push> pushes;
  for (const std::string& p : a.pushes) {
    const auto colon = p.find(':');
    if (colon == std::string::npos) {
      throw BadArgument{
          fmt::format("--push: {} should be JOINT:EFFORT, e.g. 3:60 (joint 1..{}, N m or N)",
                      io::quoted(p), r.model.dof())};
    }
    try {
      const std::size_t joint =
          io::parse_joint(p.substr(0, colon), "--push: the joint", r.model.dof());
      // A hand, not a press: beyond 10 kN m the plant's integration means nothing.
      const double effort = io::parse_number(p.substr(colon + 1), "--push: the effort",
                                             {-1e4, 1e4, "N m (revolute) or N (prismatic)"});
      pushes.push_back({joint, effort});
    } catch (const io::ParseError& e) {
      throw BadArgument{e.what()};
    }
  }
  if (!pushes.empty() && !r.simulated()) {
    throw BadArgument{"--push needs simulated time (a hand cannot push a real-time simulation)"};
  }

  std::atomic<bool> leave{false};
  r.session->control(
      [&leave](rtc::Control& c) {
        c.chg().zero_gravity =
            leave.load(std::memory_order_relaxed) ? rtc::Request::off : rtc::Request::on;
      },
      {});
  fmt::print("zero gravity: the joints follow a push and stay where they are left{}\n",
             pushes.empty() ? "" : " (pushing for the first half)");
  const std::int64_t lines = std::max<std::int64_t>(1, std::llround(seconds / every));
  for (std::int64_t i = 0; i < lines && io::stop_count() == 0; ++i) {
    // Between samples of simulated time the arm is the planning level's to touch.
    const bool pushing = 2 * i < lines;
    for (const Push& p : pushes) r.push(p.joint, pushing ? p.effort : 0.0);
    const rtc::Termination t = r.session->wait_for(to_ns(every));
    print_positions(r.model, r.session->how());
    if (t.ended()) return finish(r, report_termination(t));
  }
  for (const Push& p : pushes) r.push(p.joint, 0.0);
  leave = true;
  r.session->wait_for(r.session->period() * 2);
  return finish(r, report_termination(r.session->release()));
}

// ---------------------------------------------------------------------------------------------
// jointtest: the thesis's `test` program, one command per line on stdin.

struct TestCommand {
  char letter = 0;
  std::uint8_t joint = 0;
  double value = 0.0;  ///< SI: a range value, or a bit number
  double speed = 0.0;  ///< SI, per second: for m and M
};

/// What the control task keeps for jointtest: written only in f1 and f2.
struct ServoRamp {
  bool active = false;
  std::size_t joint = 0;
  double target = 0.0;  ///< range value
  double speed = 0.0;   ///< per second
  double at = 0.0;      ///< the last POSVEL target
  bool fresh = false;   ///< started this sample: the joint is stopped first
};

/// The test program's letters for joint controller settings.
rtc::Setting setting_of(char letter) noexcept {
  switch (letter) {
    case 'a':
      return rtc::Setting::acceleration;
    case 'f':
      return rtc::Setting::speed_factor;
    case 'k':
      return rtc::Setting::dynamic_integral;
    case 'K':
      return rtc::Setting::static_integral;
    case 'V':
      return rtc::Setting::static_speed;
    case 'z':
      return rtc::Setting::static_zone;
    case 'X':
      return rtc::Setting::examine;
    default:
      return rtc::Setting::none;
  }
}

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

/// Ctrl-C and SIGTERM end the console cleanly for its whole run, in control or not.
struct StopHandlers {
  StopHandlers() noexcept { io::install_stop_handlers(); }
  ~StopHandlers() { io::restore_stop_handlers(); }
  StopHandlers(const StopHandlers&) = delete;
  StopHandlers& operator=(const StopHandlers&) = delete;
};

int run_jointtest(const RtcArgs& a) {
  const StopHandlers handlers;
  SimulatedRobot r(a);
  const kin::RobotModel& m = r.model;
  auto queue =
      std::make_shared<boost::lockfree::spsc_queue<TestCommand, boost::lockfree::capacity<64>>>();
  auto ramp = std::make_shared<ServoRamp>();

  // The control task's side: commands arrive through a lock-free queue, never a lock.
  const auto f1 = [queue, ramp](rtc::Control& c) {
    TestCommand cmd;
    while (queue->pop(cmd)) {
      switch (cmd.letter) {
        case 'm':
          ramp->active = false;
          c.chg().pos(cmd.joint, cmd.value, cmd.speed);
          break;
        case 'M': {
          // Stopped where it is first: the ramp's first step is then one step from the last
          // target, also when an `m` move was under way (its target far ahead of the joint, a
          // jump RTC would refuse as too fast).
          const double here = c.how().joint[cmd.joint].range;
          *ramp = {true, cmd.joint, cmd.value, cmd.speed, here, true};
          c.chg().pos(cmd.joint, here);
          break;
        }
        case 's':
          ramp->active = false;
          c.chg().pos(cmd.joint, c.how().joint[cmd.joint].range);
          break;
        case 'h':
          c.chg().hand = rtc::Request::off;
          break;
        case 'H':
          c.chg().hand = rtc::Request::on;
          break;
        case 'o':
          c.chg().outputs_clear =
              static_cast<std::uint16_t>(1U << static_cast<unsigned>(cmd.value));
          break;
        case 'O':
          c.chg().outputs_set = static_cast<std::uint16_t>(1U << static_cast<unsigned>(cmd.value));
          break;
        case 'p':
          c.chg().power = rtc::Request::off;
          break;
        case 'P':
          c.chg().power = rtc::Request::on;
          break;
        default:
          if (const rtc::Setting s = setting_of(cmd.letter); s != rtc::Setting::none) {
            c.chg().setting = {s, cmd.joint, static_cast<std::uint16_t>(cmd.value)};
          }
          break;
      }
    }
  };
  // M: POSVEL every sample along a ramp at the joint's velocity.
  const auto f2 = [ramp](rtc::Control& c) {
    if (!ramp->active) return;
    if (ramp->fresh) {  // this sample stops the joint (f1); the ramp starts at the next
      ramp->fresh = false;
      return;
    }
    const double step = ramp->speed * c.period_s();
    ramp->at += std::clamp(ramp->target - ramp->at, -step, step);
    c.chg().posvel(ramp->joint, ramp->at);
    if (ramp->at == ramp->target) ramp->active = false;
  };
  // Ctrl-C ends the program (the arm holds) rather than control: the loop sees the stop count.
  r.session->set_hangup_handler([](rtc::Session&) {});
  // main() installed the handlers at start: a signal during the start-up counts too.
  const std::uint32_t stops = 0;
  const auto stopped = [] { return io::stop_count() != stops; };
  const auto start = [&] { r.session->control(f1, f2); };
  start();

  std::size_t joint = 0;
  std::vector<double> velocity(m.dof());
  for (std::size_t i = 0; i < m.dof(); ++i)
    velocity[i] = rtc::kDefaultSpeedFraction * m.joints[i].max_velocity;
  int status = kOk;
  const auto send = [&](TestCommand c) {
    // Without control nobody empties the queue: give up rather than wait for ever.
    while (!queue->push(c)) {
      if (!r.session->controlling() || stopped()) return;
      r.session->wait_for(r.session->period());
    }
    r.session->wait_for(r.session->period());  // simulated time: let the command take effect
  };
  // Control ended (a limit, a fault): say why at once, count it, and control again.
  const auto check = [&] {
    const rtc::Termination t = r.session->termination();
    if (!t.ended()) return;
    std::fflush(stdout);
    rtc::print_terminate_code(t, stdout);
    status = kFailure;
    r.session->release();
    if (stopped()) return;
    try {
      start();
      fmt::print("control restarted\n");
    } catch (const rtc::SessionError& e) {
      std::fflush(stdout);
      io::eprint("control could not be restarted: {}\n", e.what());
    }
  };
  const auto failed = [&](const std::string& why) {
    std::fflush(stdout);  // the error after what came before it
    io::eprint("{}\n", why);
    status = kFailure;
  };

  fmt::print("jointtest on {} ({} joints), {} time, period {:.3f} ms. ? for the menu.\n", m.title,
             m.dof(), r.simulated() ? "simulated" : "real", r.period_s() * 1e3);
  io::StopAwareInput buffer(STDIN_FILENO, stops);  // ends a wait for a line on Ctrl-C / SIGTERM
  std::istream input(&buffer);
  std::string line;
  std::string too_long;  // a line refused by its length
  bool quit = false;
  while (!quit && !stopped() && io::read_line(input, line, too_long)) {
    if (!too_long.empty()) {
      failed(too_long);
      continue;
    }
    JointtestLine c;
    try {
      c = parse_jointtest_line(line, m, joint);
    } catch (const io::ParseError& e) {
      failed(e.what());
      continue;
    }
    const char letter = c.letter;
    const kin::Joint& jm = m.joints[joint];
    if (!r.session->controlling() && letter != 'x' && letter != '?' && letter != 'q' &&
        letter != 'j' && letter != 'v' && letter != '\0') {
      failed(fmt::format("{}: control has ended and could not be restarted; q quits", letter));
      continue;
    }
    switch (letter) {
      case '\0':
        break;
      case 'j':
        joint = c.joint;
        fmt::print("joint {} ({})\n", joint + 1, m.joints[joint].name);
        break;
      case 'v':
        velocity[joint] = from_shown(jm, c.value);
        fmt::print("joint {} velocity {:.3f} {}/s\n", joint + 1, shown(jm, velocity[joint]),
                   unit(jm));
        break;
      case 'm':
      case 'M':
        send({letter, static_cast<std::uint8_t>(joint), from_shown(jm, c.value) - jm.lower,
              velocity[joint]});
        break;
      case 's':
        send({'s', static_cast<std::uint8_t>(joint), 0, 0});
        break;
      case 'h':
      case 'H':
      case 'p':
      case 'P':
        send({letter, 0, 0, 0});
        break;
      case 'o':
      case 'O':
        send({letter, 0, c.value, 0});
        break;
      case 'x':
        print_positions_detailed(m, r.session->how());
        break;
      case 'w':
        r.session->wait_for(c.duration);  // ends early on a stop signal or when control ends
        break;
      case 'r':
        try {
          r.session->release();
          r.session->set_period(c.duration);
          start();
          fmt::print("sample period {:.3f} ms\n", r.period_s() * 1e3);
        } catch (const rtc::SessionError& e) {
          failed(fmt::format("r: {}", e.what()));
          try {
            start();  // control again at the period it had
          } catch (const rtc::SessionError&) {
          }
        }
        break;
      case 'a':
      case 'f':
      case 'k':
      case 'K':
      case 'V':
      case 'z':
      case 'X': {
        if (!r.rcu) {
          failed(fmt::format("{}: {} has no Microbo joint controllers (thesis Appendix B)", letter,
                             m.name));
          break;
        }
        send({letter, static_cast<std::uint8_t>(joint), c.value, 0});
        if (letter == 'X') {
          r.session->wait_for(r.session->period());  // read during the next sample
          const rtc::How h = r.session->how();
          if (h.examined_joint != static_cast<int>(joint)) {
            failed(fmt::format("X: joint {} did not answer", joint + 1));
            break;
          }
          fmt::print("joint {} motor parameters:", joint + 1);
          for (const std::uint8_t b : h.motor_parameters) fmt::print(" {}", b);
          fmt::print("\n");
        } else {
          fmt::print("joint {} {} {}\n", joint + 1, rtc::to_string(setting_of(letter)), c.value);
        }
        break;
      }
      case 'q':
        quit = true;
        break;
      case '?':
        fmt::print("{}", kTestMenu);
        break;
      default:  // parse_jointtest_line knows every letter above and no other
        break;
    }
    check();
  }
  const rtc::Termination end = r.session->release();
  if (end.ended()) {
    rtc::print_terminate_code(end, stdout);
    status = kFailure;
  }
  if (buffer.error() != 0) failed(fmt::format("reading stdin: {}", std::strerror(buffer.error())));
  if (stopped()) {
    fmt::print("stopped by a signal: control released, the arm holds\n");
    std::fflush(stdout);
    return io::stop_exit_code();
  }
  return status;
}

}  // namespace

void add_rtc_commands(CLI::App& app, int& exit_code) {
  const char* robot_note =
      " Runs on a simulated robot (rccx::hw): the Microbo (default) through its emulated RCU, "
      "registers and bus; the PUMA 560/260 with PID joint servos; any other robot file with an "
      "ideal servo.";

  auto report = std::make_shared<ReportArgs>();
  CLI::App* report_cmd = app.add_subcommand(
      "report", std::string("Report joint positions (deg, mm) every --every seconds (thesis "
                            "report.c); with --realtime also the wake-up latency of the "
                            "communication task.") +
                    robot_note);
  add_rtc_options(*report_cmd, *report);
  report_cmd
      ->add_option("--seconds", report->seconds,
                   "How long to run: s, or with a unit (500ms); up to 1e6 s")
      ->capture_default_str();
  report_cmd
      ->add_option("--every", report->every,
                   "Time between reports: s, or with a unit; at least one sample period")
      ->capture_default_str();
  report_cmd->add_flag("--json", report->json, "Print only the latency figures, as JSON");
  report_cmd->callback(
      [report, &exit_code] { guarded(exit_code, [&] { return run_report(*report); }); });

  auto calib = std::make_shared<CalibArgs>();
  CLI::App* calib_cmd = app.add_subcommand(
      "calib",
      std::string("Calibrate every joint (STOPCAL) and wait for ALL JOINTS (thesis calib.c).") +
          robot_note);
  add_rtc_options(*calib_cmd, *calib);
  calib_cmd->add_option("--timeout", calib->timeout, "Give up after this long: s, or with a unit")
      ->capture_default_str();
  calib_cmd->callback(
      [calib, &exit_code] { guarded(exit_code, [&] { return run_calib(*calib); }); });

  auto limp = std::make_shared<RtcArgs>();
  CLI::App* limp_cmd =
      app.add_subcommand("limp", std::string("Turn arm power off (thesis limp.c).") + robot_note);
  add_rtc_options(*limp_cmd, *limp);
  limp_cmd->callback([limp, &exit_code] { guarded(exit_code, [&] { return run_limp(*limp); }); });

  auto marsh = std::make_shared<MarshArgs>();
  CLI::App* marsh_cmd = app.add_subcommand(
      "marsh", std::string("Zero gravity: the joints follow a push and stay (thesis marsh.c).") +
                   robot_note);
  add_rtc_options(*marsh_cmd, *marsh);
  marsh_cmd
      ->add_option("--seconds", marsh->seconds,
                   "How long to run: s, or with a unit (500ms); up to 1e6 s")
      ->capture_default_str();
  marsh_cmd
      ->add_option("--every", marsh->every,
                   "Time between reports: s, or with a unit; at least one sample period")
      ->capture_default_str();
  marsh_cmd->add_option("--push", marsh->pushes,
                        "JOINT:EFFORT - a simulated hand pushes joint JOINT (1-based) with EFFORT "
                        "N m or N for the first half of the run; repeatable");
  marsh_cmd->callback(
      [marsh, &exit_code] { guarded(exit_code, [&] { return run_marsh(*marsh); }); });

  auto test = std::make_shared<RtcArgs>();
  CLI::App* test_cmd = app.add_subcommand(
      "jointtest",
      std::string("Command single joints through Chg, one command per line on stdin, with the "
                  "letters of the thesis's test program (? lists them; w S waits S seconds).") +
          robot_note);
  add_rtc_options(*test_cmd, *test);
  test_cmd->callback(
      [test, &exit_code] { guarded(exit_code, [&] { return run_jointtest(*test); }); });

  CLI::App* codes_cmd =
      app.add_subcommand("codes", "List RTC's terminate codes and their meanings");
  codes_cmd->callback([&exit_code] {
    rtc::print_terminate_codes(stdout);
    exit_code = kOk;
  });
}

}  // namespace rccx::tools
