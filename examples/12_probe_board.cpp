// Example 12: the Microbo probes a circuit board with a set force (the thesis's demonstration,
// 4.5, figure 4.8, with the force sensor the CVaRL cell had and the port could not use).
//
// The Microbo (on the MuJoCo plant: the arm, a wrist sensor, the board as a box) visits the
// board's test points. At each one: a joint move above it, a guarded descent (the motion ends
// when the probe presses 2 N), then compliance along the probe's axis holding the test force
// for a moment (a compliant dwell: the probe keeps its force whatever the board's height), and
// back up. It prints each point's contact height and the force held there.
// Run: ./build/release/examples/12_probe_board [--force N] [--help]
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
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

constexpr double kBoardTop_m = 0.232;  // the board's surface, base frame
constexpr double kProbeLength_m = 0.06;
constexpr double kProbeRadius_m = 0.002;
constexpr double kProbeMass_kg = 0.1;

struct Point {
  const char* name;
  double x_mm, y_mm;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "The Microbo probes a circuit board's test points with a set force (MuJoCo "
      "plant, simulated time)"};
  double force_N = 3.0;
  app.add_option("--force", force_N, "the probing force, N")->check(CLI::Range(0.5, 20.0));
  CLI11_PARSE(app, argc, argv);

  auto scene = std::make_shared<hw::Scene>();
  hw::SceneBox board;
  board.name = "board";
  board.half_size_m = {0.05, 0.06, 0.004};
  board.pose_m = Transform::translation(0.32, 0.02, kBoardTop_m - 0.004);
  scene->boxes.push_back(board);
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

  const auto probe = rccl::constant("PROBE", Transform::translation(0, 0, kProbeLength_m));
  const auto at = [&](const Point& p, double z_mm) {
    const Transform t{math::Rot3::rot_x(180_deg), {p.x_mm * 1e-3, p.y_mm * 1e-3, z_mm * 1e-3}};
    return rccl::Position::make(p.name, {rccl::t6(), probe}, {rccl::constant(p.name, t)}, probe);
  };
  const auto wait = [&](const rccl::Motion& m) {
    if (arm.waitfor(m.end()) != rccl::WaitResult::reached) {
      for (const auto& f : arm.failures()) fmt::print(stderr, "failed: {}\n", f.message());
      std::exit(1);
    }
  };

  const std::vector<Point> points = {
      {"TP1", 290, -20}, {"TP2", 290, 50}, {"TP3", 350, 50}, {"TP4", 350, -20}};
  rccl::ForceGuard touch;
  touch.kind = rccl::ForceGuard::Kind::along;
  touch.axis = 2;
  touch.threshold = 2.0;
  rccl::Compliance press;
  press.axes = 1U << 2;
  press.force[2] = force_N;
  bool good = true;
  fmt::print("point   contact z (mm)   force held (N)\n");
  for (const Point& p : points) {
    arm.set_mode(rccl::Mode::joint);
    wait(arm.move(at(p, kBoardTop_m * 1e3 + 20)));
    arm.set_mode(rccl::Mode::cartesian);
    arm.set_velocity(15_mm, 30_deg);
    arm.set_guard(touch);
    const rccl::Motion down = arm.move(at(p, kBoardTop_m * 1e3 - 15));
    wait(down);
    arm.set_guard({});
    const auto c = arm.contact(down);
    if (!c) {
      fmt::print("{}      no contact\n", p.name);
      good = false;
      continue;
    }
    arm.set_compliance(press);
    const rccl::Motion hold = arm.dwell(1.5);
    robot.session->wait_for(std::chrono::milliseconds(1200));
    const rtc::How h = robot.session->how();
    const Transform t6 = arm.kinematics().forward(h.q());
    const double f =
        -force::at_tool(probe->value(), force::external_wrench(load, t6.R, h.force.wrench))
             .force_N.z;
    wait(hold);
    arm.set_compliance({});
    wait(arm.move(at(p, kBoardTop_m * 1e3 + 20)));
    fmt::print("{}     {:8.2f}          {:6.2f}\n", p.name, c->tool_frame.p.z * 1e3, f);
    good = good && std::abs(c->tool_frame.p.z - kBoardTop_m) < 0.5e-3 &&
           std::abs(f - force_N) < 0.1 * force_N;
  }
  arm.set_mode(rccl::Mode::joint);
  wait(arm.move(arm.park()));
  fmt::print("{}\n", good ? "done" : "FAILED: a point was off");
  return good ? 0 : 1;
}
