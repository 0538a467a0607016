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
constexpr double kMaxRunSeconds = 1e6;

double seconds_of(const std::string& text, const char* what, double lo_s = 1e-6) {
  try {
    return io::parse_seconds(text, what, lo_s, kMaxRunSeconds);
  } catch (const io::ParseError& e) {
    throw BadArgument{e.what()};
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
  code = finish_logs(r, code);
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
}

void add_calib_command(CLI::App& app, int& exit_code) {
  auto calib = std::make_shared<CalibArgs>();
  CLI::App* calib_cmd = app.add_subcommand(
      "calib",
      std::string("Calibrate every joint (STOPCAL) and wait for ALL JOINTS (thesis calib.c).") +
          kRobotNote);
  add_rtc_options(*calib_cmd, *calib);
  calib_cmd->add_option("--timeout", calib->timeout, "Give up after this long: s, or with a unit")
      ->capture_default_str();
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
