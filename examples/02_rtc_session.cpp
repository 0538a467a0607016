// Example 02: an RTC control session on the simulated PUMA 560.
//
// Two control functions run every 10 ms sample (thesis 2.3): f1 reads the arm's state (How)
// and f2 commands it (Chg). Here f2 swings joint 2 (the shoulder) along a half cosine by 30
// degrees and back, sending each sample's target with POSVEL so that it arrives exactly one
// period later. Then a second session asks for a target beyond joint 3's limit: the
// communication task refuses to send it, ends the session with a terminate code and leaves the
// arm holding where it is. That breach is deliberate (the program says so before and after).
//
// Time is simulated: the 4 s motion runs as fast as the machine allows, the same every run.
// Run: ./build/release/examples/02_rtc_session
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <optional>

#include "rccx/hw/simulated_arm.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rtc/servo_driver.hpp"
#include "rccx/rtc/session.hpp"

using namespace rccx;
using namespace std::chrono_literals;
using namespace rccx::math::literals;

int main() {
  fmt::print(
      "Part 1 swings joint 2 by 30 deg and back. Part 2 breaks a limit on purpose: it asks\n"
      "joint 3 for a target beyond its range, to show RTC refusing it (a terminate code, the\n"
      "arm holding). That limit breach is deliberate: its message is the lesson, and the\n"
      "example exits 0 when it comes.\n\n");
  // Below the wire: PID joint servos at 1 kHz on a plant with inertia, friction and gravity.
  const auto arm = hw::make_simulated_arm(kin::builtin_robot("puma560"));
  rtc::ServoDriver driver(*arm);
  rtc::Session session(driver, {.period = 10ms, .clock = rtc::ClockKind::simulated});

  const double swing = 30_deg;
  const double duration_s = 2.0;                  // out, then back
  std::optional<double> start_range, start_time;  // joint 2 and the clock when control starts
  double last_target = 0.0;                       // range value sent in the last sample
  double worst_lag = 0.0;  // largest |last sample's target - where the joint is now|, rad

  session.control(
      [&](rtc::Control& c) {  // f1: what happened to the last target?
        if (c.how().sample > 2) {
          worst_lag = std::max(worst_lag, std::abs(c.how().joint[1].range - last_target));
        }
      },
      [&](rtc::Control& c) {  // f2: the next target, out and back along a half cosine
        if (!start_range) {
          start_range = c.how().joint[1].range;
          start_time = c.how().time_s;
        }
        const double due = c.how().time_s + c.period_s() - *start_time;  // when it is reached
        const double phase = std::min(due / duration_s, 2.0);
        last_target = *start_range + swing * 0.5 * (1 - std::cos(math::kPi * phase));
        c.chg().posvel(1, last_target);
      });
  for (int i = 0; i < 4; ++i) {
    session.wait_for(1s);
    const rtc::How h = session.how();
    fmt::print("t = {:.2f} s  joint 2 at {:7.3f} deg  speed {:7.3f} deg/s\n", h.time_s,
               math::rad_to_deg(h.joint[1].q), math::rad_to_deg(h.joint[1].velocity));
  }
  fmt::print(
      "largest lag behind the POSVEL targets: {:.4f} deg (one encoder count is {:.4f} deg)\n",
      math::rad_to_deg(worst_lag), math::rad_to_deg(driver.model().joints[1].resolution_per_count));
  session.release();

  // A target out of range ends control: nothing is sent, the arm holds, the code says why.
  session.control([](rtc::Control& c) { c.chg().pos(2, 10.0); }, {});
  fmt::print("\nPart 2: joint 3 asked for 10 rad, beyond its range (deliberate):\n");
  const rtc::Termination t = session.wait_terminated(1s);
  rtc::print_terminate_code(t);
  session.release();
  session.close();  // RCCX_LOG's log put in place
  if (!session.log_problem().empty()) {
    fmt::print(stderr, "02_rtc_session: the sample log is lost: {}\n", session.log_problem());
    return 1;
  }
  if (t.code != rtc::TerminateCode::target_position) {
    fmt::print(stderr, "02_rtc_session: the out-of-range target was not refused\n");
    return 1;
  }
  fmt::print(
      "The limit breach above was deliberate: RTC refused the target and ended control with\n"
      "that code, as it should. Example done.\n");
  return 0;
}
