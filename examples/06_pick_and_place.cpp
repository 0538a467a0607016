// Example 06: pick and place with a tool transform and a hold transform, on the simulated Microbo.
//
// The gripper's fingertips are 100 mm along T6's approach vector: a constant TOOL on the left
// side of the equations, so that in Cartesian mode the fingertips, not T6, move on straight
// lines. Where the object is, is a hold transform OBJ (rccl::hold) that the program sets, from
// the pick location to the place location, between motions: a motion has latched OBJ's value
// by the time it starts, and keeps it. Two equations serve both places:
//
//     GET:   T6 TOOL = OBJ GRASP          the fingertips on the object, pointing down
//     OVER:  T6 TOOL = OBJ LIFT GRASP     60 mm above it (LIFT, in the object's frame)
//
// The program goes over the object in joint mode, down and up in Cartesian mode with a dwell
// for the gripper between, sets OBJ to the place location (turned 90 deg) as soon as the lift
// has started, carries the object over in joint mode, puts it down the same way and parks.
// Moves are queued and the program waits (waitfor) only where it must: before gripping and
// releasing, and before changing OBJ.
//
// The Microbo's vertical joint d2 travels 200 .. 330 mm and T6 is 100 mm above the fingertips:
// GET puts T6 at 215 / 220 mm, OVER at 275 / 280 mm.
//
// It prints each motion's report (arm.report(m)) in a table, and how far the measured
// fingertips were from the object's frame while gripping and releasing.
// Run: ./build/release/examples/06_pick_and_place
#include <fmt/format.h>

#include <string>
#include <vector>

#include "rccx/math/units.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/simulated_robot.hpp"

using namespace rccx;
using namespace rccx::math::literals;

int main() {
  rtc::SimulatedRobot robot(kin::builtin_robot("microbo"));  // the emulated RCU, 28 ms samples
  rccl::Manipulator arm(*robot.session);

  const math::Transform pick{math::Rot3::identity(), {300_mm, 120_mm, 115_mm}};
  const math::Transform place{math::Rot3::rot_z(90_deg), {350_mm, -120_mm, 120_mm}};
  const auto tool = rccl::constant("TOOL", math::Transform::translation(0, 0, 100_mm));
  const auto obj = rccl::hold("OBJ", pick);
  const auto grasp = rccl::constant("GRASP", {math::Rot3::rot_x(180_deg), {}});
  const auto lift = rccl::constant("LIFT", math::Transform::translation(0, 0, 60_mm));
  const auto t6 = rccl::t6();
  const auto get = rccl::Position::make("GET", {t6, tool}, {obj, grasp});
  const auto over = rccl::Position::make("OVER", {t6, tool}, {obj, lift, grasp});
  fmt::print("{}\n{}\n", get->describe(), over->describe());

  // Where the measured fingertips are now, against the object's frame (OBJ's planning value).
  const kin::Kinematics& kin = arm.kinematics();
  const auto fingertip_error = [&] {
    const math::Transform fingers = kin.forward(robot.session->how().q()) * tool->value();
    return (fingers.p - obj->value().p).norm();
  };

  struct Step {
    rccl::Motion motion;
    std::string what;
  };
  std::vector<Step> steps;
  const auto queue = [&](rccl::Mode mode, const rccl::PositionPtr& p, std::string what) {
    arm.set_mode(mode);
    steps.push_back({arm.move(p), std::move(what)});
    return steps.back().motion;
  };
  const auto dwell = [&](double s, std::string what) {
    steps.push_back({arm.dwell(s), std::move(what)});
    return steps.back().motion;
  };
  const auto ok = [](rccl::WaitResult w) { return w == rccl::WaitResult::reached; };

  arm.start();
  arm.set_velocity(100_mm, 90_deg);
  queue(rccl::Mode::joint, arm.park(), "park");
  queue(rccl::Mode::joint, over, "over the pick location");
  queue(rccl::Mode::cartesian, get, "down onto the object");
  // Close the gripper once the arm is still on the object (a dwell stands for it here).
  bool good = ok(arm.waitfor(steps.back().motion.end()));
  good = good && ok(arm.waitfor(dwell(0.3, "grip").end()));
  const double grip_error = fingertip_error();
  const rccl::Motion up = queue(rccl::Mode::cartesian, over, "up, holding it");
  // Once the lift has started it has latched OBJ (the pick location): OBJ may change now, and
  // the motions queued from here on go to the place location.
  good = good && ok(arm.waitfor(up.start()));
  obj->set(place);
  queue(rccl::Mode::joint, over, "over the place location");
  queue(rccl::Mode::cartesian, get, "down to place it");
  good = good && ok(arm.waitfor(steps.back().motion.end()));
  good = good && ok(arm.waitfor(dwell(0.3, "release").end()));
  const double place_error = fingertip_error();
  queue(rccl::Mode::cartesian, over, "up, empty");
  queue(rccl::Mode::joint, arm.park(), "park");
  const rccl::WaitResult w = arm.waitfor(arm.completed());
  good = good && ok(w);
  const rtc::Termination t = arm.stop_control();

  fmt::print(
      "\n seg  motion                    mode       start s   end s   T s   path error mm "
      "(cmd / measured)  approach deg\n");
  for (const Step& s : steps) {
    const rccl::SegmentReport r = arm.report(s.motion);
    fmt::print("{:4}  {:<25} {:<9} {:7.2f} {:7.2f} {:5.2f}", r.id, s.what, rccl::to_string(r.mode),
               r.start_s, r.end_s, r.duration_s);
    if (r.mode == rccl::Mode::cartesian && r.straight_samples > 0) {
      fmt::print("   {:10.4f} / {:7.3f}             {:7.3f}", r.max_commanded_path_error_m * 1e3,
                 r.max_measured_path_error_m * 1e3, math::rad_to_deg(r.max_approach_error_rad));
    }
    fmt::print("{}\n", r.failed ? "  FAILED" : "");
  }
  fmt::print(
      "\nmeasured fingertips from the object's frame: {:.3f} mm when gripping at ({:.0f}, {:.0f}, "
      "{:.0f}) mm, {:.3f} mm when releasing at ({:.0f}, {:.0f}, {:.0f}) mm\n",
      grip_error * 1e3, pick.p.x * 1e3, pick.p.y * 1e3, pick.p.z * 1e3, place_error * 1e3,
      place.p.x * 1e3, place.p.y * 1e3, place.p.z * 1e3);

  for (const rccl::MotionEvent& f : arm.failures()) {
    fmt::print(stderr, "motion {} {}: {}\n", f.id, rccl::to_string(f.kind), f.message());
  }
  if (!good || t.ended() || !arm.failures().empty()) {
    fmt::print(stderr, "waitfor(completed): {}\n", rccl::to_string(w));
    if (t.ended()) rtc::print_terminate_code(t, stderr);
    return 1;
  }
  constexpr double kPlacedWithin = 1_mm;
  if (grip_error > kPlacedWithin || place_error > kPlacedWithin) {
    fmt::print(stderr, "the fingertips missed the object by more than {:.1f} mm\n",
               kPlacedWithin * 1e3);
    return 1;
  }
  return robot.finish_logs("06_pick_and_place") ? 0 : 1;  // RCCX_LOG's log whole
}
