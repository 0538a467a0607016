// Example 12: the Microbo probes a circuit board's test points with a set force: the thesis's
// demonstration (4.5, figure 4.8) with the wrist force sensor the CVaRL cell had and the port
// could not use (4.4.2).
//
// The Microbo runs on the MuJoCo plant (rccx::hw::MujocoArm: the arm, a six-axis sensor at the
// wrist, a 60 mm probe, the board as a box). At each test point:
//   1. a joint move to 20 mm above it, the probe pointing down;
//   2. a guarded descent (set_guard: the motion ends, as nextmove does, once the probe presses
//      2 N along its axis) at 2 mm/s; contact() says where the touch began;
//   3. a compliant dwell (set_compliance along the probe's z: hold --force N), the force the
//      test needs whatever the board's true height, then up again.
// It prints each point's contact height and the force held (the mean over the dwell's last
// second, and its range).
//
// What the Microbo asks of force control, beside the PUMA of example 11 (docs/FORCE.md): its
// vertical slide carries 35 kg of reflected motor inertia behind a servo of 100 rad/s, so
//   - the probe has some give (a 50 ms contact, as a spring-loaded test pin has), and the search
//     is slow (2 mm/s): the slide's momentum at 5 mm/s struck the board with 30 to 70 N;
//   - the probe axis's damping is ten times the default (30,000 N s/m): the slide and the board
//     make a stiff spring, and the default admittance oscillated against it;
//   - the slide's dry friction (15 N) makes the held force hunt around its set value (the servo's
//     integrator against stick-slip): the dwell's mean holds it, single readings vary.
// Run: ./build/release/examples/12_probe_board [--force N] [--help]
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <vector>

#include "rccx/force/tool_load.hpp"
#include "rccx/hw/mjcf.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/simulated_robot.hpp"

using namespace rccx;
using namespace rccx::math::literals;
using math::Transform;

namespace {

/// The board's top face in the Microbo's base frame, m: below the probe's tip at the ready
/// pose (T6 at 275 mm, the probe 60 mm down from it), so the arm starts clear of it.
constexpr double kBoardTop_m = 0.180;
constexpr double kProbeLength_m = 0.06;
constexpr double kProbeRadius_m = 0.002;
constexpr double kProbeMass_kg = 0.1;
/// The dwell at each point, s; the force is averaged over its last kAveraged_s.
constexpr double kDwell_s = 1.5;
constexpr double kAveraged_s = 1.0;

struct TestPoint {
  const char* name;
  double x_mm, y_mm;  ///< on the board, in the Microbo's base frame
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "The Microbo probes a circuit board's test points with a set force (MuJoCo plant, wrist "
      "force sensor, simulated time)"};
  double force_N = 3.0;
  app.add_option("--force", force_N, "the probing force, N")->check(CLI::Range(1.0, 20.0));
  CLI11_PARSE(app, argc, argv);

  auto scene = std::make_shared<hw::Scene>();
  hw::SceneBox board;
  board.name = "board";
  board.half_size_m = {0.05, 0.06, 0.004};
  board.pose_m = Transform::translation(0.32, 0.02, kBoardTop_m - board.half_size_m.z);
  scene->boxes.push_back(board);
  scene->contact_time_constant_s = 0.05;  // a spring-loaded pin's give
  scene->tool_friction = 0.2;
  scene->tool_mass_kg = kProbeMass_kg;
  scene->tool_com_m = {0, 0, kProbeLength_m / 2};
  scene->tool_length_m = kProbeLength_m;
  scene->tool_radius_m = kProbeRadius_m;

  rtc::SimulatedRobotOptions options;
  options.plant = hw::Plant::mujoco;
  options.scene = scene;
  rtc::SimulatedRobot robot(kin::builtin_robot("microbo"), options);
  rccl::Manipulator arm(*robot.session);
  arm.start();
  force::ToolLoad load;
  load.mass_kg = kProbeMass_kg;
  load.com_m = {0, 0, kProbeLength_m / 2};
  arm.set_tool_load(load);

  // T6 PROBE = POINT: the probe's tip on (or above) a test point, pointing down.
  const auto probe = rccl::constant("PROBE", Transform::translation(0, 0, kProbeLength_m));
  const auto at = [&](const TestPoint& p, double z_mm) {
    const Transform t{math::Rot3::rot_x(180_deg), {p.x_mm * 1e-3, p.y_mm * 1e-3, z_mm * 1e-3}};
    return rccl::Position::make(p.name, {rccl::t6(), probe}, {rccl::constant(p.name, t)});
  };
  const auto wait = [&](const rccl::Motion& m) {
    if (arm.waitfor(m.end()) != rccl::WaitResult::reached) {
      rtc::print_terminate_code(robot.session->termination(), stderr);
      for (const auto& f : arm.failures()) fmt::print(stderr, "failed: {}\n", f.message());
      std::exit(1);
    }
  };
  // The force the probe exerts along its axis now: the reading, the probe's weight taken out,
  // carried to the tip.
  const auto probe_force_N = [&] {
    const rtc::How h = robot.session->how();
    const Transform t6 = arm.kinematics().forward(h.q());
    return -force::at_tool(probe->value(), force::external_wrench(load, t6.R, h.force.wrench))
                .force_N.z;
  };

  const std::vector<TestPoint> points = {
      {"TP1", 290, -20}, {"TP2", 290, 50}, {"TP3", 350, 50}, {"TP4", 350, -20}};
  rccl::ForceGuard touch;
  touch.kind = rccl::ForceGuard::Kind::along;
  touch.axis = 2;
  touch.threshold = 2.0;
  rccl::Compliance press;
  press.axes = 1U << 2;
  press.force[2] = force_N;
  press.damping[2] = 10 * rccl::kDefaultDamping_N_s_per_m;

  bool good = true;
  fmt::print("board top at {:.2f} mm; probing with {:.1f} N\n", kBoardTop_m * 1e3, force_N);
  fmt::print("point   contact z (mm)   force held (N): mean   range\n");
  for (const TestPoint& p : points) {
    arm.set_mode(rccl::Mode::joint);
    wait(arm.move(at(p, kBoardTop_m * 1e3 + 20)));
    arm.set_mode(rccl::Mode::cartesian);
    arm.set_velocity(2_mm, 30_deg);  // a search: slowly
    arm.set_guard(touch);
    const rccl::Motion down = arm.move(at(p, kBoardTop_m * 1e3 - 15));
    wait(down);
    arm.set_guard({});
    const auto c = arm.contact(down);
    if (!c) {
      fmt::print("{}      no contact: the board is not under this point\n", p.name);
      good = false;
      continue;
    }
    arm.set_compliance(press);
    const rccl::Motion hold = arm.dwell(kDwell_s);
    const double t0 = robot.session->how().time_s;
    double sum = 0.0, lo = 1e9, hi = -1e9;
    int n = 0;
    while (!arm.happened(hold.end())) {
      robot.session->wait_for(std::chrono::milliseconds(10));
      if (robot.session->how().time_s - t0 < kDwell_s - kAveraged_s) continue;
      const double f = probe_force_N();
      sum += f;
      lo = std::min(lo, f);
      hi = std::max(hi, f);
      ++n;
    }
    wait(hold);
    arm.set_compliance({});
    arm.set_velocity(20_mm, 30_deg);
    wait(arm.move(at(p, kBoardTop_m * 1e3 + 20)));
    const double mean = n > 0 ? sum / n : 0.0;
    fmt::print("{}     {:8.2f}          {:12.2f}   {:.2f} .. {:.2f}\n", p.name,
               c->tool_frame.p.z * 1e3, mean, lo, hi);
    good = good && std::abs(c->tool_frame.p.z - kBoardTop_m) < 0.5e-3 &&
           std::abs(mean - force_N) < 0.1 * force_N;
  }
  arm.set_mode(rccl::Mode::joint);
  wait(arm.move(arm.park()));
  fmt::print("{}\n", good ? "done: every point touched within 0.5 mm, its force held within 10 %"
                          : "FAILED: a point was off");
  return robot.finish_logs("12_probe_board") && good ? 0 : 1;  // RCCX_LOG's log whole
}
