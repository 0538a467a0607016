// Example 11: force on a PUMA 560 whose wrist has a six-axis sensor (simulated by MuJoCo: the
// arm, a table and the tool touching it; rccx::hw::MujocoArm).
//
// What the Microbo port of 1986 had to leave out (thesis 4.4.2), in three steps:
//   1. touch: a guarded move down (set_guard: end the motion, as nextmove does, once the tool
//      presses 5 N along its z) finds the table; contact() says where the touch began, and
//      update_from_contact() writes its height into the transform TABLE (the world model);
//   2. wipe: compliance along the tool's z (set_compliance: hold 5 N there) while the motion
//      runs along x: the arm follows the table whatever its true height, pressing steadily;
//   3. leave: lock again (Compliance{}) and go up.
// The tool's weight (0.4 kg) is taken out of the readings with set_tool_load; the force the
// program prints is the sensor's reading compensated and carried to the tool tip.
// Run: ./build/release/examples/11_touch_and_wipe [--table-mm Z] [--force N] [--help]
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "rccx/force/tool_load.hpp"
#include "rccx/hw/mjcf.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/simulated_robot.hpp"

using namespace rccx;
using namespace rccx::math::literals;
using math::Transform;

namespace {

constexpr double kToolLength_m = 0.10;
constexpr double kToolRadius_m = 0.008;
constexpr double kToolMass_kg = 0.4;

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Touch a table with a guarded move, then wipe along it holding a force (PUMA 560 "
      "on the MuJoCo plant, simulated time)"};
  double table_mm = -203.0;
  double press_N = 5.0;
  app.add_option("--table-mm", table_mm,
                 "where the table's top really is, mm below the shoulder (the program believes "
                 "-200 and finds out)")
      ->check(CLI::Range(-300.0, -150.0));
  app.add_option("--force", press_N, "the force to hold while wiping, N")
      ->check(CLI::Range(1.0, 40.0));
  CLI11_PARSE(app, argc, argv);

  auto scene = std::make_shared<hw::Scene>();
  hw::SceneBox table;
  table.name = "table";
  table.half_size_m = {0.40, 0.40, 0.02};
  table.pose_m = Transform::translation(0.45, 0.0, table_mm * 1e-3 - 0.02);
  table.friction = 0.2;
  scene->boxes.push_back(table);
  // A tool with some give (a 20 ms contact, MuJoCo's default, not steel on steel) and modest
  // friction: what force control through position servos sampled at 10 ms wants (FORCE.md).
  scene->contact_time_constant_s = 0.02;
  scene->tool_friction = 0.2;
  scene->tool_mass_kg = kToolMass_kg;
  scene->tool_com_m = {0, 0, kToolLength_m / 2};
  scene->tool_length_m = kToolLength_m;
  scene->tool_radius_m = kToolRadius_m;

  rtc::SimulatedRobotOptions options;
  options.plant = hw::Plant::mujoco;
  options.scene = scene;
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"), options);
  rccl::Manipulator arm(*robot.session);
  arm.start();
  force::ToolLoad load;
  load.mass_kg = kToolMass_kg;
  load.com_m = {0, 0, kToolLength_m / 2};
  arm.set_tool_load(load);

  // T6 TOOL = TABLE SPOT: SPOT a point above, on or along the table, the tool pointing down.
  const auto tool = rccl::constant("TOOL", Transform::translation(0, 0, kToolLength_m));
  const auto table_frame = rccl::hold("TABLE", Transform::translation(0, 0, -0.200));
  const auto spot = [&](const char* name, double x_mm, double y_mm, double z_mm) {
    const Transform s{math::Rot3::rot_x(180_deg), {x_mm * 1e-3, y_mm * 1e-3, z_mm * 1e-3}};
    return rccl::Position::make(name, {rccl::t6(), tool}, {table_frame, rccl::constant(name, s)});
  };
  const auto above = spot("ABOVE", 400, 100, 30);
  const auto into = spot("INTO", 400, 100, -30);  // 30 mm below where the table is believed

  const auto wait = [&](const rccl::Motion& m) {
    const rccl::WaitResult w = arm.waitfor(m.end());
    if (w != rccl::WaitResult::reached) {
      fmt::print(stderr, "waitfor: {}\n", rccl::to_string(w));
      for (const auto& f : arm.failures()) fmt::print(stderr, "  {}\n", f.message());
      std::exit(1);
    }
  };

  // 1. Touch.
  wait(arm.move(above));
  arm.set_mode(rccl::Mode::cartesian);
  arm.set_velocity(5_mm, 30_deg);  // a search: slowly (FORCE.md)
  rccl::ForceGuard guard;
  guard.kind = rccl::ForceGuard::Kind::along;
  guard.axis = 2;  // the tool's z
  guard.threshold = 5.0;
  arm.set_guard(guard);
  const rccl::Motion down = arm.move(into);
  wait(down);
  arm.set_guard({});
  const auto touch = arm.contact(down);
  if (!touch) {
    fmt::print(stderr, "no contact: the table is not where the program looked\n");
    return 1;
  }
  const auto on_table = spot("ON", 400, 100, 0);
  arm.update_from_contact(down, table_frame, on_table);
  fmt::print("touched at z = {:.2f} mm (the table's top is at {:.2f} mm): TABLE updated\n",
             touch->tool_frame.p.z * 1e3, table_mm);

  // 2. Wipe 150 mm along x, pressing.
  rccl::Compliance press;
  press.axes = 1U << 2;
  press.force[2] = press_N;
  arm.set_compliance(press);
  arm.set_velocity(20_mm, 30_deg);
  const rccl::Motion wipe = arm.move(spot("ALONG", 550, 100, 0));
  double lo = 1e9, hi = -1e9, sum = 0.0;
  int n = 0;
  const double t0 = robot.session->how().time_s;
  while (!arm.happened(wipe.end())) {
    robot.session->wait_for(std::chrono::milliseconds(10));
    const rtc::How h = robot.session->how();
    const Transform t6 = arm.kinematics().forward(h.q());
    const double f =
        -force::at_tool(tool->value(), force::external_wrench(load, t6.R, h.force.wrench))
             .force_N.z;
    if (h.time_s - t0 > 1.0) {  // after the first second: steady
      lo = std::min(lo, f);
      hi = std::max(hi, f);
      sum += f;
      ++n;
    }
  }
  wait(wipe);
  fmt::print("wiped 150 mm holding {:.1f} N: measured {:.2f} N on average, {:.2f} .. {:.2f} N\n",
             press_N, n > 0 ? sum / n : 0.0, lo, hi);

  // 3. Leave.
  arm.set_compliance({});
  wait(arm.move(spot("UP", 550, 100, 50)));
  arm.set_mode(rccl::Mode::joint);
  wait(arm.move(arm.park()));
  const bool good = std::abs(touch->tool_frame.p.z * 1e3 - table_mm) < 0.5 && n > 0 &&
                    std::abs(sum / n - press_N) < 0.1 * press_N;
  fmt::print("{}\n", good ? "done" : "FAILED: the touch or the force was off");
  return robot.finish_logs("11_touch_and_wipe") && good ? 0 : 1;  // RCCX_LOG's log whole
}
