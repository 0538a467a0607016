// Example 04: the thesis's window washer (section 2.4.3), in C++, on the simulated Microbo.
//
// Four constant transforms B, C, D, E put the tool at the corners of a 300 x 50 mm "window" in
// the y-z plane, pointing down at the table (rotated 180 deg about x). Four position equations
// T6 = B ... T6 = E. The program moves to park and to the first corner in joint mode, then goes
// round the window three times in Cartesian mode, 5 mm/s and 10 deg/s faster each time: the
// twelve moves are queued at once and the trajectory generator joins them with transitions.
// Then back to park in joint mode.
//
// It prints what the arm did: each segment's times, and how far the commanded and the measured
// tool point strayed from the straight edge (outside the corner transitions). With RCCX_LOG=FILE
// it reads its log back and prints the worst path error `rccx plot FILE` shows: the measured tool
// from the commanded path at every sample, the corner blends included (so larger).
// Run: ./build/release/examples/04_washer          (examples/washer.c is the 1986 text in C)
//
// With --view[=PORT] (`make demo-view`) it runs at the pace of the wall clock and serves the view
// (rccx::view) on 127.0.0.1:PORT (8080): open the address it prints to watch the arm, the window's
// corners (P1 .. P4, each drawn as the arm is sent there, the running one marked), the tool path
// and the plots; it serves until Ctrl-C once the washer is done.
#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

#include "rccx/io/parse.hpp"
#include "rccx/io/signals.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/simulated_robot.hpp"
#include "rccx/view/plot.hpp"
#include "rccx/view/run_log.hpp"
#include "rccx/view/server.hpp"

using namespace rccx;
using namespace rccx::math::literals;

/// The worst path error of the run as `rccx plot` reads it from the log (view::path_errors_m).
static void print_logged_path_error(const char* file, const kin::RobotModel& model) {
  try {
    const std::vector<double> e = view::path_errors_m(view::load_run_log(file), model);
    fmt::print(
        "log {}: worst path error {:.3f} mm (measured tool from the commanded path, every "
        "sample, corner blends included: what rccx plot shows)\n",
        file, *std::max_element(e.begin(), e.end()) * 1e3);
  } catch (const view::RunLogError& err) {
    fmt::print(stderr, "04_washer: {}\n", err.what());
  }
}

int main(int argc, char** argv) {
  int view_port = -1;  // no view
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    try {
      if (arg == "--view") {
        view_port = 8080;
      } else if (arg.starts_with("--view=")) {
        view_port = static_cast<int>(io::parse_integer(arg.substr(7), "--view", 0, 65535));
      } else {
        throw io::ParseError(fmt::format("unknown argument {}", io::quoted(arg)));
      }
    } catch (const io::ParseError& e) {
      fmt::print(stderr, "04_washer: {}; usage: 04_washer [--view[=PORT]]\n", e.what());
      return 2;
    }
  }
  const bool viewed = view_port >= 0;
  if (viewed) io::install_stop_handlers();
  // The emulated RCU, 28 ms samples, in simulated time (deterministic; paced to the clock on the
  // wall when watched, so that the eye can follow, see wait below).
  rtc::SimulatedRobot robot(kin::builtin_robot("microbo"));
  rccl::Manipulator arm(*robot.session);
  std::unique_ptr<view::Server> view;
  if (viewed) {
    try {
      // The arm's view: each position moved to is drawn, named, and the running one marked.
      view = view::serve(arm, static_cast<std::uint16_t>(view_port));
    } catch (const view::ViewError& e) {
      fmt::print(stderr, "04_washer: {}\n", e.what());
      return 2;
    }
  }

  // Translations from the robot's origin to the 4 corners; the tool points at the table.
  const auto corner = [](const char* name, double y_mm, double z_mm) {
    return rccl::constant(name, {math::Rot3::rot_x(180_deg), {0.325, y_mm * 1e-3, z_mm * 1e-3}});
  };
  const auto b = corner("B", 150, 300), c = corner("C", -150, 300), d = corner("D", -150, 250),
             e = corner("E", 150, 250);
  const auto t6 = rccl::t6();
  const auto p1 = rccl::Position::make("P1", {t6}, {b});
  const auto p2 = rccl::Position::make("P2", {t6}, {c});
  const auto p3 = rccl::Position::make("P3", {t6}, {d});
  const auto p4 = rccl::Position::make("P4", {t6}, {e});

  // waitfor; when watched, simulated time goes at the wall clock's pace: a sample, then its period
  // of sleep (real time would do as well on a quiet machine, but a busy one may overrun).
  const auto wait = [&](const rccl::Event& event) {
    if (!viewed) return arm.waitfor(event);
    const auto period = robot.session->period();
    for (;;) {
      const rccl::WaitResult r = arm.waitfor(event, period);
      if (r != rccl::WaitResult::timeout || io::stop_count() > 0) return r;
      std::this_thread::sleep_for(period);
    }
  };

  arm.start();
  double tvel_mm = 100, rvel_deg = 100;
  arm.set_velocity(tvel_mm * 1e-3, math::deg_to_rad(rvel_deg));
  std::vector<rccl::Motion> motions;
  motions.push_back(arm.move(arm.park()));
  wait(motions.back().end());
  motions.push_back(arm.move(p1));
  wait(motions.back().end());

  arm.set_mode(rccl::Mode::cartesian);
  std::vector<double> round_speed;
  for (int i = 0; i < 3; ++i) {
    fmt::print("round {}: setvel {} mm/s along the path, {} deg/s turning\n", i + 1, tvel_mm,
               rvel_deg);
    round_speed.push_back(tvel_mm);
    for (const auto& p : {p2, p3, p4, p1}) motions.push_back(arm.move(p));
    tvel_mm += 5;
    rvel_deg += 10;
    arm.set_velocity(tvel_mm * 1e-3, math::deg_to_rad(rvel_deg));
  }
  const rccl::WaitResult w = wait(arm.completed());

  arm.set_mode(rccl::Mode::joint);
  motions.push_back(arm.move(arm.park()));
  wait(motions.back().end());
  const rtc::Termination t = arm.stop_control();

  fmt::print(
      "\n seg  mode       start s   end s   T s   path error mm (cmd / measured)  "
      "approach deg  top speed mm/s\n");
  std::vector<double> round_error(3, 0.0);
  double worst_approach_deg = 0.0;
  for (std::size_t i = 0; i < motions.size(); ++i) {
    const rccl::SegmentReport r = arm.report(motions[i]);
    const bool cart = r.mode == rccl::Mode::cartesian;
    fmt::print("{:4}  {:<9} {:7.2f} {:7.2f} {:5.2f}", r.id, rccl::to_string(r.mode), r.start_s,
               r.end_s, r.duration_s);
    if (cart && r.straight_samples == 0) {
      fmt::print("   (all transition: no straight part to judge)");
    } else if (cart) {
      fmt::print("   {:10.4f} / {:7.3f}             {:7.3f}        {:6.1f}",
                 r.max_commanded_path_error_m * 1e3, r.max_measured_path_error_m * 1e3,
                 math::rad_to_deg(r.max_approach_error_rad), r.peak_tool_speed_m_per_s * 1e3);
      const std::size_t round = (i - 2) / 4;
      round_error[round] = std::max(round_error[round], r.max_measured_path_error_m * 1e3);
      worst_approach_deg = std::max(worst_approach_deg, math::rad_to_deg(r.max_approach_error_rad));
    }
    fmt::print("{}\n", r.failed ? "  FAILED" : "");
  }
  fmt::print("\nthe window, three times round:\n");
  for (std::size_t i = 0; i < 3; ++i) {
    fmt::print("  round {} at {:.0f} mm/s: measured tool point within {:.3f} mm of the edges\n",
               i + 1, round_speed[i], round_error[i]);
  }
  const double total_s = arm.report(motions.back()).end_s - arm.report(motions.front()).start_s;
  fmt::print(
      "\nwasher: {} segments in {:.2f} s, the window followed 3 times at {:.0f}/{:.0f}/{:.0f} "
      "mm/s, measured tool within {:.3f} mm of the straight edges (corner blends excluded), "
      "approach error {:.3f} deg\n",
      motions.size(), total_s, round_speed[0], round_speed[1], round_speed[2],
      *std::max_element(round_error.begin(), round_error.end()), worst_approach_deg);
  for (const rccl::MotionEvent& f : arm.failures()) {
    fmt::print(stderr, "motion {} {}: {}\n", f.id, rccl::to_string(f.kind), f.message());
  }
  const bool failed = w != rccl::WaitResult::reached || t.ended() || !arm.failures().empty();
  if (failed) rtc::print_terminate_code(t, stderr);
  if (view && io::stop_count() == 0) {
    fmt::print("\nthe view stays at {} until Ctrl-C\n", view->url());
    std::fflush(stdout);
    while (io::stop_count() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const bool logged = robot.finish_logs("04_washer");  // RCCX_LOG's log whole
  if (const char* log = std::getenv("RCCX_LOG"); logged && log != nullptr && *log != '\0') {
    print_logged_path_error(log, robot.model);
  }
  return failed || !logged ? 1 : 0;
}
