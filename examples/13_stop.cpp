// Example 13: RCCL's stop(ms) - a dwell between motions - on the simulated PUMA 560.
//
// The wrist goes back and forth 80 mm along y in Cartesian mode with a dwell of 0.1, 0.3, 0.6
// and 1 s (Manipulator::dwell, the C library's stop(ms)) after each motion. A dwell is never
// blended with the motions either side: the motion before it comes to rest, the arm stands for
// the dwell's time, and the motion after it starts from rest. So the arm is still for the time
// asked, rounded up to whole samples and at least 3 (docs/RCCL.md, "stop(ms)"), whatever the
// transition time.
//
// It prints, for each dwell, how long the commanded joints stood still (every sample's setpoint,
// from the trajectory generator) against that rule, and exits 1 when one differs. With
// RCCX_LOG=FILE the run is logged; docs/stop-speed.svg is `rccx plot FILE` of it:
//   RCCX_LOG=stop.csv ./build/release/examples/13_stop
//   ./build/release/tools/rccx plot stop.csv -o docs/stop-speed.svg --title "stop(ms)"
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "rccx/math/units.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/simulated_robot.hpp"

using namespace rccx;
using namespace rccx::math::literals;

int main() {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));  // PID servos, 10 ms samples
  rtc::Session& session = *robot.session;
  rccl::Manipulator arm(session);
  const double period_s = std::chrono::duration<double>(session.period()).count();

  const math::Transform home = arm.kinematics().forward(robot.model.ready());
  const auto t6 = rccl::t6();
  const auto at = [&](const char* name, double dy) {
    return rccl::Position::make(
        name, {t6}, {rccl::constant(name, {home.R, home.p + math::Vec3{0.0, dy, -20_mm}})});
  };
  const auto a = at("A", 40_mm);
  const auto b = at("B", -40_mm);

  arm.start();
  rccl::WaitResult w = arm.waitfor(arm.move(a).end());
  arm.set_mode(rccl::Mode::cartesian);
  arm.set_velocity(100_mm, 90_deg);
  constexpr std::array<double, 4> kDwells_s{0.1, 0.3, 0.6, 1.0};
  rccl::Motion last;
  for (std::size_t i = 0; i < kDwells_s.size(); ++i) {
    arm.move(i % 2 == 0 ? b : a);
    arm.dwell(kDwells_s[i]);
  }
  last = arm.move(kDwells_s.size() % 2 == 0 ? b : a);

  // Every sample's setpoint: a run of repeated setpoints between two motions is a dwell.
  std::array<double, kDwells_s.size()> still_s{};
  std::size_t found = 0;
  kin::JointVector previous = arm.generator().last_setpoint();
  double still_from = -1.0, last_t = -1.0;
  while (w == rccl::WaitResult::reached && !arm.happened(last.end())) {
    if (session.wait_for(session.period()).ended()) break;  // one sample
    const double t = arm.generator().last_setpoint_time_s();
    if (t == last_t) continue;
    last_t = t;
    const kin::JointVector& q = arm.generator().last_setpoint();
    bool still = q.size() == previous.size();
    // (A motion from rest leaves it by a rounding's worth on its first sample: 1e-16 rad.)
    for (std::size_t j = 0; still && j < q.size(); ++j)
      still = std::abs(q[j] - previous[j]) < 1e-12;
    if (still && still_from < 0.0) still_from = t - period_s;  // the sample it came to rest on
    if (!still && still_from >= 0.0) {
      // The last runs are the dwells (the arm stood before the first motion left, too).
      std::rotate(still_s.begin(), still_s.begin() + 1, still_s.end());
      still_s.back() = t - period_s - still_from;
      ++found;
      still_from = -1.0;
    }
    previous = q;
  }
  for (const auto& f : arm.failures()) fmt::print(stderr, "failed: {}\n", f.message());
  if (w != rccl::WaitResult::reached || !arm.failures().empty() || found < kDwells_s.size()) {
    fmt::print(stderr, "the motions did not run through ({} dwells seen of {})\n", found,
               kDwells_s.size());
    return 1;
  }
  bool good = true;
  fmt::print("dwell    still    the rule (ms rounded up to {:.0f} ms samples, at least 3)\n",
             period_s * 1e3);
  for (std::size_t i = 0; i < kDwells_s.size(); ++i) {
    const double rule = std::max(std::ceil(kDwells_s[i] / period_s - 1e-9), 3.0) * period_s;
    const bool ok = std::abs(still_s[i] - rule) < 1e-9;
    good = good && ok;
    fmt::print("{:5.0f} ms {:5.0f} ms {:5.0f} ms{}\n", kDwells_s[i] * 1e3, still_s[i] * 1e3,
               rule * 1e3, ok ? "" : "  DIFFERS");
  }
  return good ? 0 : 1;
}
