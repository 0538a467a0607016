// Example 05: a conveyor tracked by a functional transform, on the simulated PUMA 560.
//
// An object rides a conveyor belt along y at 40 mm/s. Where the wrist must be is the equation
//
//     T6 = CONV OBJ GRASP
//
// CONV is a functional transform (rccl::functional): a function of the sample's time that the
// trajectory generator evaluates every sample, here the belt's travel, 40 mm/s x t along y. OBJ
// is where the object was on the belt at t = 0, GRASP how the wrist meets it (pointing down at
// 45 deg, away from the robot). The arm goes above the belt in joint mode, then moves in
// Cartesian mode onto the moving object: the goal moves during the motion, and once the motion
// has ended the generator keeps following it. The program lets the arm ride along for 3 s, then
// parks it in joint mode.
//
// It prints the tracking lag: at every sample of those 3 s, the distance between the measured
// wrist centre (forward kinematics of the joints the arm reports, How::q()) and the object at
// the same instant, max and mean in mm, and how much of it is along the belt.
// Run: ./build/release/examples/05_conveyor
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "rccx/math/units.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/simulated_robot.hpp"

using namespace rccx;
using namespace rccx::math::literals;

int main() {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));  // PID servos, 10 ms samples
  rtc::Session& session = *robot.session;
  rccl::Manipulator arm(session);

  // The belt: the object's frame moves along y at 40 mm/s from t = 0 (the session's clock).
  constexpr double kBeltSpeed = 40_mm;  // per second
  const auto belt = [](double t_s) { return math::Transform::translation(0, kBeltSpeed * t_s, 0); };
  const auto conv = rccl::functional("CONV", [belt](const rccl::SampleContext& c) {
    return belt(c.t_s);  // runs in the sample loop: no blocking, no allocation
  });
  const math::Transform obj_at_0 = math::Transform::translation(450_mm, -250_mm, -250_mm);
  const auto obj = rccl::constant("OBJ", obj_at_0);
  const math::Rot3 pointing = math::Rot3::rot_y(-45_deg) * math::Rot3::rot_x(180_deg);
  const auto grasp = rccl::constant("GRASP", {pointing, {}});
  const auto t6 = rccl::t6();
  const auto on_belt = rccl::Position::make("ON_BELT", {t6}, {conv, obj, grasp});
  // A fixed point 100 mm above the belt to start from: T6 = OVER GRASP.
  const auto over = rccl::constant("OVER", math::Transform::translation(450_mm, -50_mm, -150_mm));
  const auto above_belt = rccl::Position::make("ABOVE_BELT", {t6}, {over, grasp});
  fmt::print("{}: belt at {:.0f} mm/s along y\n", on_belt->describe(), kBeltSpeed * 1e3);

  arm.start();
  std::vector<rccl::Motion> motions;
  motions.push_back(arm.move(above_belt));  // joint mode
  rccl::WaitResult w = arm.waitfor(motions.back().end());

  arm.set_mode(rccl::Mode::cartesian);
  arm.set_velocity(100_mm, 100_deg);  // per second, in both modes: 2.5 times the belt's speed
  motions.push_back(arm.move(on_belt));
  if (w == rccl::WaitResult::reached) w = arm.waitfor(motions.back().end());
  const double caught_s = session.how().time_s;

  // The motion has ended; the generator keeps the wrist on the object. Measure every sample.
  const kin::Kinematics& kin = arm.kinematics();
  double lag_max = 0.0, lag_max_s = 0.0, lag_sum = 0.0, along_max = 0.0;
  double settled_max = 0.0;  // from 0.5 s on, once the arm has settled after the catch
  double y_start = 0.0, y_end = 0.0;
  int samples = 0;
  while (w == rccl::WaitResult::reached && session.how().time_s < caught_s + 3.0) {
    if (session.wait_for(session.period()).ended()) break;  // one sample
    const rtc::How h = session.how();
    const math::Vec3 wrist = kin.forward(h.q()).p;            // measured
    const math::Vec3 object = (belt(h.time_s) * obj_at_0).p;  // where it is at that instant
    const double lag = (wrist - object).norm();
    if (lag > lag_max) {
      lag_max = lag;
      lag_max_s = h.time_s;
    }
    lag_sum += lag;
    if (h.time_s >= caught_s + 0.5) settled_max = std::max(settled_max, lag);
    along_max = std::max(along_max, std::abs(object.y - wrist.y));
    if (samples++ == 0) y_start = object.y;
    y_end = object.y;
  }

  arm.set_mode(rccl::Mode::joint);
  motions.push_back(arm.move(arm.park()));
  if (w == rccl::WaitResult::reached) w = arm.waitfor(motions.back().end());
  const rtc::Termination t = arm.stop_control();

  fmt::print("\n seg  mode       start s   end s   T s   to\n");
  const char* names[] = {"ABOVE_BELT", "ON_BELT (the moving object)", "park"};
  for (std::size_t i = 0; i < motions.size(); ++i) {
    const rccl::SegmentReport r = arm.report(motions[i]);
    fmt::print("{:4}  {:<9} {:7.2f} {:7.2f} {:5.2f}   {}{}\n", r.id, rccl::to_string(r.mode),
               r.start_s, r.end_s, r.duration_s, names[i], r.failed ? "  FAILED" : "");
  }
  const double lag_mean = samples > 0 ? lag_sum / samples : 0.0;
  fmt::print(
      "\ntracking for {:.2f} s ({} samples) from t = {:.2f} s, the object from y = {:.0f} mm",
      samples * robot.period_s(), samples, caught_s, y_start * 1e3);
  fmt::print(" to {:.0f} mm\n  measured wrist centre to the object: max {:.3f} mm", y_end * 1e3,
             lag_max * 1e3);
  fmt::print(" (at t = {:.2f} s), mean {:.3f} mm\n", lag_max_s, lag_mean * 1e3);
  fmt::print(
      "  along the belt at most {:.3f} mm; 0.5 s after the catch and on: at most {:.3f} mm\n",
      along_max * 1e3, settled_max * 1e3);

  for (const rccl::MotionEvent& f : arm.failures()) {
    fmt::print(stderr, "motion {} {}: {}\n", f.id, rccl::to_string(f.kind), f.message());
  }
  if (w != rccl::WaitResult::reached || t.ended() || !arm.failures().empty()) {
    fmt::print(stderr, "waitfor: {}\n", rccl::to_string(w));
    if (t.ended()) rtc::print_terminate_code(t, stderr);
    return 1;
  }
  constexpr double kLagBound = 2_mm;  // a PID servo following 40 mm/s
  if (samples < 250 || lag_max > kLagBound) {
    fmt::print(stderr, "tracking: {} samples, lag {:.3f} mm (expected >= 250 and <= {:.1f} mm)\n",
               samples, lag_max * 1e3, kLagBound * 1e3);
    return 1;
  }
  return robot.finish_logs("05_conveyor") ? 0 : 1;  // RCCX_LOG's log whole
}
