#include "rtc_commands.hpp"

#include "jointtest.hpp"
#include "rtc_robot.hpp"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "rccx/io/console.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/io/signals.hpp"
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
constexpr auto kMaxRun = std::chrono::seconds(1'000'000);
constexpr auto kMinRun = std::chrono::microseconds(1);

CLI::Option* add_run_option(CLI::App& cmd, const std::string& name, Duration& d,
                            const std::string& help) {
  return add_duration_option(cmd, name, d, kMinRun, kMaxRun, help)->capture_default_str();
}

/// Waits until the samples' time is `t_s` (from the session's start), to the nearest sample:
/// the waits aim at absolute times, so their rounding to whole samples does not add up (30 s
/// in 0.5 s reports is 30 s, not 60 waits each rounded down), and the last report is at the
/// sample nearest --seconds.
rtc::Termination wait_to(const SimulatedRobot& r, double t_s) {
  const double left = t_s - r.session->how().time_s;
  if (left < r.period_s() / 2) return r.session->termination();
  return r.session->wait_for(to_ns(left + r.period_s() / 2));
}

int report_termination(const rtc::Termination& t) {
  if (!t.ended()) return kOk;
  rtc::print_terminate_code(t, stderr);
  return kFailure;
}

/// The end of every control program: the session closed, the logs in place. A log that is not
/// complete (a full disk, rows dropped) makes the run a failure; a stop signal gives 128 + it.
int finish(SimulatedRobot& r, int code) {
  code = finish_logs(r, code);
  if (io::stop_count() > 0) code = io::stop_exit_code();
  return code;
}

// ---------------------------------------------------------------------------------------------

struct ReportArgs : RtcArgs {
  Duration seconds{"2s"};
  Duration every{"0.5s"};
  bool json = false;
};

/// --every: at least one sample period, else time would never advance between reports.
double every_of(const Duration& every, const SimulatedRobot& r) {
  if (every.seconds() < r.period_s()) {
    throw BadArgument{fmt::format(
        "--every: \"{}\" is shorter than the sample period ({:g} ms); give at least {:g}ms",
        every.text, r.period_s() * 1e3, r.period_s() * 1e3)};
  }
  return every.seconds();
}

/// The times of the reports, one at a time: every `every` seconds, and the end of the run, which
/// is `seconds` however long `every` is. Not a list: a long run with a short interval
/// (`--seconds 1e6 --every 10ms`) must not hold every time in memory before it starts.
class ReportTimes {
 public:
  ReportTimes(double seconds, double every) : seconds_(seconds), every_(every) {}
  /// The next report's time (s) into `at`; false once the end of the run has been given.
  bool next(double& at) {
    if (last_given_) return false;
    ++k_;
    last_given_ = !(k_ * every_ < seconds_ - 1e-9);
    at = last_given_ ? seconds_ : k_ * every_;
    return true;
  }

 private:
  double seconds_;
  double every_;
  double k_ = 0.0;
  bool last_given_ = false;
};

/// A real-time report measures on after control ends with an overrun (the machine missed a
/// deadline): it says so and restarts control; the run then fails (exit 1) at the end.
bool restart_after_overrun(SimulatedRobot& r, rtc::Termination& t, std::uint64_t& restarts) {
  if (r.simulated() || t.code != rtc::TerminateCode::overrun) return false;
  ++restarts;
  io::eprint("report: control ended at t = {:.3f} s: {} ({}); restarting control (restart {})\n",
             t.time_s, rtc::to_string(t.code), t.detail.data(), restarts);
  r.session->release();
  r.session->control({}, {});
  t = {};
  return true;
}

void print_latency(const ReportArgs& a, const SimulatedRobot& r, std::uint64_t restarts) {
  const rtc::LatencyStats s = r.session->latency();
  if (a.json) {
    nlohmann::ordered_json j{{"period_us", Seconds(r.session->period()).count() * 1e6},
                             {"seconds", a.seconds.seconds()},
                             {"wakeups", s.wakeups},
                             {"missed_deadlines", s.missed_deadlines},
                             {"p50_us", s.p50_us},
                             {"p99_us", s.p99_us},
                             {"p999_us", s.p999_us},
                             {"max_us", s.max_us},
                             {"overruns", restarts}};
    fmt::print("{}\n", j.dump(2));
    return;
  }
  fmt::print(
      "wake-up latency over {} ticks at {:.3f} ms: p50 {:.0f} us, p99 {:.0f} us, p99.9 "
      "{:.0f} us, max {:.0f} us; missed deadlines {}; control overruns {}\n",
      s.wakeups, r.period_s() * 1e3, s.p50_us, s.p99_us, s.p999_us, s.max_us, s.missed_deadlines,
      restarts);
}

int run_report(const ReportArgs& a) {
  if (a.json && !a.realtime) {
    throw BadArgument{
        "--json prints the wake-up latency figures, which only a real-time run has; add "
        "--realtime (simulated time prints the joint positions as text)"};
  }
  SimulatedRobot r(a);
  const double every = every_of(a.every, r);
  r.session->control({}, {});  // empty f1 and f2: the full cycle, nothing commanded
  std::uint64_t restarts = 0;
  rtc::Termination t;
  ReportTimes times(a.seconds.seconds(), every);
  for (double at = 0.0; times.next(at);) {
    if (t.ended() || io::stop_count() != 0) break;
    t = wait_to(r, at);
    if (!a.json) print_positions(r.model, r.session->how());
    restart_after_overrun(r, t, restarts);
  }
  if (!t.ended()) t = r.session->release();
  if (a.realtime) print_latency(a, r, restarts);  // up to the end, even when control ended early
  const int code = report_termination(t);
  if (restarts > 0)
    io::eprint("report: control was restarted {} time{} after overruns\n", restarts,
               restarts == 1 ? "" : "s");
  return finish(r, restarts > 0 ? kFailure : code);
}

// ---------------------------------------------------------------------------------------------

struct CalibArgs : RtcArgs {
  Duration timeout{"120s"};
};

int run_calib(const CalibArgs& a) {
  const double timeout = a.timeout.seconds();
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
      a.timeout.value);
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
  Duration seconds{"4s"};
  Duration every{"0.5s"};
  std::vector<std::string> pushes;
};

int run_marsh(const MarshArgs& a) {
  struct Push {
    std::size_t joint;
    double effort;
  };
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
  const double seconds = a.seconds.seconds();
  ReportTimes times(seconds, every);
  for (double at = 0.0; times.next(at);) {
    if (io::stop_count() != 0) break;
    // Between samples of simulated time the arm is the planning level's to touch.
    const bool pushing = at - every < seconds / 2;
    for (const Push& p : pushes) r.push(p.joint, pushing ? p.effort : 0.0);
    const rtc::Termination t = wait_to(r, at);
    print_positions(r.model, r.session->how());
    if (t.ended()) return finish(r, report_termination(t));
  }
  for (const Push& p : pushes) r.push(p.joint, 0.0);
  leave = true;
  r.session->wait_for(r.session->period() * 2);
  return finish(r, report_termination(r.session->release()));
}

/// What every control program's help says of the robot it runs on.
constexpr const char* kRobotNote =
    " Runs on a simulated robot (rccx::hw): the Microbo (default) through its emulated RCU, "
    "registers and bus; the PUMA 560/260 with PID joint servos; any other robot file with an "
    "ideal servo.";

void add_report_command(CLI::App& app, int& exit_code) {
  auto report = std::make_shared<ReportArgs>();
  CLI::App* report_cmd = app.add_subcommand(
      "report", std::string("Report joint positions (deg, mm) every --every seconds (thesis "
                            "report.c); with --realtime also the wake-up latency of the "
                            "communication task.") +
                    kRobotNote);
  add_rtc_options(*report_cmd, *report);
  add_run_option(*report_cmd, "--seconds", report->seconds,
                 "How long to run, up to 1e6 s; the last report is at its end");
  add_run_option(*report_cmd, "--every", report->every,
                 "Time between reports, at least one sample period; longer than --seconds: "
                 "one report, at the end");
  report_cmd->add_flag("--json", report->json,
                       "With --realtime: print only the latency figures, as JSON (refused "
                       "without --realtime)");
  report_cmd->callback(
      [report, &exit_code] { guarded(exit_code, [&] { return run_report(*report); }); });
}

void add_calib_command(CLI::App& app, int& exit_code) {
  auto calib = std::make_shared<CalibArgs>();
  CLI::App* calib_cmd = app.add_subcommand(
      "calib",
      std::string("Calibrate every joint (STOPCAL) and wait for ALL JOINTS (thesis calib.c).") +
          kRobotNote);
  add_rtc_options(*calib_cmd, *calib);
  add_run_option(*calib_cmd, "--timeout", calib->timeout, "Give up after this long");
  calib_cmd->callback(
      [calib, &exit_code] { guarded(exit_code, [&] { return run_calib(*calib); }); });
}

void add_limp_command(CLI::App& app, int& exit_code) {
  auto limp = std::make_shared<RtcArgs>();
  CLI::App* limp_cmd =
      app.add_subcommand("limp", std::string("Turn arm power off (thesis limp.c).") + kRobotNote);
  add_rtc_options(*limp_cmd, *limp);
  limp_cmd->callback([limp, &exit_code] { guarded(exit_code, [&] { return run_limp(*limp); }); });
}

void add_marsh_command(CLI::App& app, int& exit_code) {
  auto marsh = std::make_shared<MarshArgs>();
  CLI::App* marsh_cmd = app.add_subcommand(
      "marsh", std::string("Zero gravity: the joints follow a push and stay (thesis marsh.c).") +
                   kRobotNote);
  add_rtc_options(*marsh_cmd, *marsh);
  add_run_option(*marsh_cmd, "--seconds", marsh->seconds, "How long to run, up to 1e6 s");
  add_run_option(*marsh_cmd, "--every", marsh->every,
                 "Time between reports, at least one sample period");
  marsh_cmd->add_option("--push", marsh->pushes,
                        "JOINT:EFFORT - a simulated hand pushes joint JOINT (1-based) with EFFORT "
                        "N m or N for the first half of the run; repeatable");
  marsh_cmd->callback(
      [marsh, &exit_code] { guarded(exit_code, [&] { return run_marsh(*marsh); }); });
}

void add_jointtest_command(CLI::App& app, int& exit_code) {
  auto test = std::make_shared<RtcArgs>();
  CLI::App* test_cmd = app.add_subcommand(
      "jointtest",
      std::string("Command single joints through Chg, one command per line on stdin, with the "
                  "letters of the thesis's test program (? lists them; w S waits S seconds).") +
          kRobotNote);
  add_rtc_options(*test_cmd, *test);
  test_cmd->callback(
      [test, &exit_code] { guarded(exit_code, [&] { return run_jointtest(*test); }); });
}

void add_codes_command(CLI::App& app, int& exit_code) {
  CLI::App* codes_cmd =
      app.add_subcommand("codes", "List RTC's terminate codes and their meanings");
  codes_cmd->callback([&exit_code] {
    rtc::print_terminate_codes(stdout);
    exit_code = kOk;
  });
}

}  // namespace

void add_rtc_commands(CLI::App& app, int& exit_code) {
  add_report_command(app, exit_code);
  add_calib_command(app, exit_code);
  add_limp_command(app, exit_code);
  add_marsh_command(app, exit_code);
  add_jointtest_command(app, exit_code);
  add_codes_command(app, exit_code);
}

}  // namespace rccx::tools
