// Example 07: an RCCL program for the PUMA 560 (simulated: PID servos on its dynamics, 10 ms).
//
// What a PUMA program sets between motions, and what it must expect:
//   - set_mode: joint mode to get somewhere, Cartesian mode to move the wrist on straight lines;
//   - set_velocity and set_transition_time: a square in the y-z plane (the wrist pointing
//     forward) twice, at 100 mm/s with 0.2 s transitions, then at 250 mm/s with 0.6 s ones
//     (rounder corners); the segment times follow from the speeds;
//   - dwell (RCCL's stop): stay where the last motion ends, here 0.5 s;
//   - set_configuration: the same position reached in four of the PUMA's eight configurations
//     (kin::Kinematics::configuration_names(): lun ... rdf = left/right arm, elbow up/down,
//     wrist no flip/flip), each in joint mode: the arm swings round; Cartesian lines keep the
//     configuration they start in;
//   - rccl::MotionError: a position out of reach, and one that the configuration asked for
//     cannot reach, are refused by move() before anything is queued; the program prints why
//     and carries on.
// It prints the measured joints in each configuration and each segment's report, as 04 does.
// Run: ./build/release/examples/07_puma560
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "rccx/math/units.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/simulated_robot.hpp"

using namespace rccx;
using namespace rccx::math::literals;

namespace {

std::string degrees(const kin::JointVector& q) {
  std::string s;
  for (double v : q) s += fmt::format(" {:7.1f}", math::rad_to_deg(v));
  return s;
}

}  // namespace

int main() {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  const kin::Kinematics& kin = arm.kinematics();

  // The wrist centre (T6: the PUMA's d6 is 0) at the corners of a 300 x 150 mm square in the
  // plane x = 450 mm, the approach vector pointing forward (+x).
  const math::Rot3 forward = math::Rot3::rot_y(90_deg);
  const auto t6 = rccl::t6();
  const auto corner = [&](const char* name, double x_mm, double y_mm, double z_mm) {
    const math::Transform T{forward, {x_mm * 1e-3, y_mm * 1e-3, z_mm * 1e-3}};
    return rccl::Position::make(name, {t6}, {rccl::constant(name, T)});
  };
  const auto a = corner("A", 450, -150, 200), b = corner("B", 450, 150, 200),
             c = corner("C", 450, 150, 50), d = corner("D", 450, -150, 50);
  const auto far = corner("FAR", 1200, 0, 200);  // the arm reaches about 0.9 m

  struct Step {
    rccl::Motion motion;
    std::string what;
  };
  std::vector<Step> steps;
  const auto move = [&](const rccl::PositionPtr& p, std::string what) {
    steps.push_back({arm.move(p), std::move(what)});
    return steps.back().motion;
  };
  bool good = true;
  const auto wait = [&](const rccl::Event& e) {
    const rccl::WaitResult w = arm.waitfor(e);
    if (w != rccl::WaitResult::reached) fmt::print(stderr, "waitfor: {}\n", rccl::to_string(w));
    good = good && w == rccl::WaitResult::reached;
  };

  arm.start();
  arm.set_velocity(200_mm, 90_deg);  // joint moves too take their time from these
  move(arm.park(), "park");
  arm.set_configuration("run");  // right arm, elbow up, no flip: the one park is in
  move(a, "A");
  wait(arm.completed());

  // The square twice: queued at once, joined by transitions.
  arm.set_mode(rccl::Mode::cartesian);
  const std::vector<std::pair<double, double>> rounds = {{100, 0.2}, {250, 0.6}};  // mm/s, s
  for (const auto& [speed_mm, transition_s] : rounds) {
    arm.set_velocity(speed_mm * 1e-3, 90_deg);
    arm.set_transition_time(transition_s);
    for (const auto& p : {b, c, d, a})
      move(p, fmt::format("{} at {:.0f} mm/s", p->name(), speed_mm));
  }
  arm.set_transition_time(0.2);
  steps.push_back({arm.dwell(0.5), "dwell 0.5 s"});
  wait(arm.completed());

  // One position, four configurations: joint mode, each solved in the configuration asked for.
  arm.set_mode(rccl::Mode::joint);
  arm.set_velocity(200_mm, 90_deg);
  fmt::print(
      "A in four configurations: measured joints theta1 .. theta6 (deg), the wrist centre's "
      "error\n");
  for (const char* name : {"lun", "ldn", "luf", "run"}) {
    arm.set_configuration(name);
    const rccl::Motion m = move(a, fmt::format("A in {}", name));
    wait(m.end());
    robot.session->wait_for(std::chrono::milliseconds(100));  // let the servos settle
    const kin::JointVector q = robot.session->how().q();
    const double off = (kin.forward(q).p - a->t6_now().p).norm();
    fmt::print("  {}: measured in {}:{}   {:.3f} mm from A\n", name,
               kin.configuration_name(kin.configuration_of(q)), degrees(q), off * 1e3);
  }

  // Positions move() refuses: nothing is queued, the arm carries on with the program.
  int refused = 0;
  const auto try_move = [&](const rccl::PositionPtr& p, const char* configuration) {
    try {
      arm.set_configuration(configuration);
      move(p, p->name());
      fmt::print("  {} in '{}' was queued - it should not have been\n", p->name(), configuration);
    } catch (const rccl::MotionError& e) {
      ++refused;
      fmt::print("  MotionError: {}\n", e.what());
    }
  };
  fmt::print("\npositions the arm cannot take:\n");
  try_move(b, "lun");  // B is on the right of the shoulder: a left arm cannot get there
  try_move(far, "");   // '' keeps the present configuration
  move(arm.park(), "park");
  wait(arm.completed());
  const rtc::Termination t = arm.stop_control();

  fmt::print(
      "\n seg  motion              mode       start s   end s   T s   path error mm (cmd / "
      "measured)  top speed mm/s\n");
  for (const Step& s : steps) {
    const rccl::SegmentReport r = arm.report(s.motion);
    fmt::print("{:4}  {:<19} {:<9} {:7.2f} {:7.2f} {:5.2f}", r.id, s.what, rccl::to_string(r.mode),
               r.start_s, r.end_s, r.duration_s);
    if (r.mode == rccl::Mode::cartesian && r.straight_samples > 0) {
      fmt::print("   {:10.4f} / {:7.3f}             {:6.1f}", r.max_commanded_path_error_m * 1e3,
                 r.max_measured_path_error_m * 1e3, r.peak_tool_speed_m_per_s * 1e3);
    } else if (r.mode == rccl::Mode::cartesian) {
      fmt::print("   (all transition: no straight part to judge)");
    }
    fmt::print("{}\n", r.failed ? "  FAILED" : "");
  }

  // The two rounds of the square: steps 2 .. 5 and 6 .. 9.
  fmt::print("\nthe square, twice round:\n");
  for (std::size_t i = 0; i < rounds.size(); ++i) {
    const rccl::SegmentReport first = arm.report(steps[2 + 4 * i].motion);
    const rccl::SegmentReport last = arm.report(steps[5 + 4 * i].motion);
    double worst = 0.0;
    for (std::size_t k = 2 + 4 * i; k <= 5 + 4 * i; ++k) {
      worst = std::max(worst, arm.report(steps[k].motion).max_measured_path_error_m);
    }
    fmt::print(
        "  at {:.0f} mm/s with {:.1f} s transitions: {:.2f} s round, measured wrist centre within "
        "{:.3f} mm of the edges\n",
        rounds[i].first, rounds[i].second, last.end_s - first.start_s, worst * 1e3);
  }

  for (const rccl::MotionEvent& f : arm.failures()) {
    fmt::print(stderr, "motion {} {}: {}\n", f.id, rccl::to_string(f.kind), f.message());
  }
  if (!good || t.ended() || !arm.failures().empty() || refused != 2) {
    if (t.ended()) rtc::print_terminate_code(t, stderr);
    return 1;
  }
  return robot.finish_logs("07_puma560") ? 0 : 1;  // RCCX_LOG's log whole
}
