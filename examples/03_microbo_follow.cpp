// Example 03: the Microbo's joints driven the thesis's way (section 4.4.3), on its emulated RCU.
//
// The vendor's joint law decelerates whenever it nears its target. Sent the next setpoint as
// the target every sample ("raw"), a joint stops and starts at the sample frequency. The
// thesis's follow scheme sends X = Xd + (Xd - Xm), a target always ahead, and paces the joint
// with its speed setting V = K (Xd - Xm). This program drives joint 3 (d3) along a ramp both
// ways and prints what the thesis measured: bus exchanges and time per sample, the work-area
// speed limit, tracking error and the oscillation at the sample frequency.
//
// Run: ./build/release/examples/03_microbo_follow [speed.svg]
//      (with a file name it also draws the joint's speed, raw against follow, as an SVG)
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "rccx/hw/rcu.hpp"
#include "rccx/rtc/microbo_driver.hpp"
#include "rccx/rtc/microbo_trial.hpp"

using namespace rccx;

namespace {

/// The thesis's sample: GET POSITION, SET TARGET, SET SPEED for each joint.
std::uint64_t thesis_sample_exchanges(const kin::RobotModel& model) {
  hw::Rcu rcu(model);
  hw::RcuBus bus(rcu);
  rtc::MicroboDriver driver(model, bus, rcu);
  for (std::size_t j = 0; j < model.dof(); ++j) {
    std::uint16_t e = 0;
    driver.get_word(j, hw::rcu::kGetPosition, e);
    driver.put_word(j, hw::rcu::kSetTarget, e);
    driver.put_word(j, hw::rcu::kSetSpeed, 32);
  }
  return bus.exchanges();
}

void write_svg(const std::string& path, const rtc::RampResult& raw, const rtc::RampResult& follow,
               double speed) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) {
    fmt::print(stderr, "cannot write {}\n", path);
    return;
  }
  const double window_s = 0.3;  // of the plot, from the first measured sample
  const double w = 900, h = 300, top = 2.2 * speed * 1e3;  // mm/s at the top of the plot
  const auto polyline = [&](const rtc::RampResult& r, const char* colour) {
    // One polyline per stretch between bus traffic: the gaps are where the bus was busy.
    std::string points;
    double last = -1;
    const auto flush = [&] {
      if (!points.empty()) {
        fmt::print(f, "<polyline fill='none' stroke='{}' stroke-width='1.5' points='{}'/>\n",
                   colour, points);
      }
      points.clear();
    };
    for (std::size_t i = 0; i < r.speed.size(); ++i) {
      const double t = r.speed_t[i] - r.speed_t[0];
      if (t > window_s) break;
      if (last >= 0 && t - last > 1.5e-3) flush();
      last = t;
      const double x = 60 + (w - 80) * t / window_s;
      const double y = h - 40 - (h - 60) * std::clamp(r.speed[i] * 1e3 / top, 0.0, 1.0);
      points += fmt::format("{:.1f},{:.1f} ", x, y);
    }
    flush();
  };
  fmt::print(f,
             "<svg xmlns='http://www.w3.org/2000/svg' width='{}' height='{}' "
             "font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' "
             "fill='white'/>\n",
             w, h);
  fmt::print(f,
             "<text x='60' y='16'>Microbo joint 3 speed on a {:.0f} mm/s ramp, 28 ms period, "
             "1 ms samples of the emulated plant</text>\n",
             speed * 1e3);
  fmt::print(f, "<line x1='60' y1='{0}' x2='{1}' y2='{0}' stroke='black'/>\n", h - 40, w - 20);
  fmt::print(f, "<line x1='60' y1='20' x2='60' y2='{}' stroke='black'/>\n", h - 40);
  for (int mm = 0; mm <= static_cast<int>(top); mm += 25) {
    const double y = h - 40 - (h - 60) * mm / top;
    fmt::print(f, "<text x='20' y='{:.0f}'>{}</text>\n", y + 4, mm);
  }
  fmt::print(f, "<text x='{}' y='{}'>time: {:.0f} ms (gaps: the bus at work)</text>\n", w / 2 - 100,
             h - 12, window_s * 1e3);
  fmt::print(f, "<text x='8' y='{}' transform='rotate(-90 12 {})'>mm/s</text>\n", h / 2, h / 2);
  polyline(raw, "#c0392b");
  polyline(follow, "#2471a3");
  fmt::print(f, "<text x='{}' y='36' fill='#c0392b'>raw targets</text>\n", w - 200);
  fmt::print(f, "<text x='{}' y='52' fill='#2471a3'>follow scheme</text>\n</svg>\n", w - 200);
  std::fclose(f);
  fmt::print("wrote {}\n", path);
}

}  // namespace

int main(int argc, char** argv) {
  const kin::RobotModel model = kin::builtin_robot("microbo");
  const hw::RcuConfig config = hw::rcu_config(model);

  fmt::print("Bus (thesis 4.4.3: 6 joints x 3 commands x 6 exchanges = 108, ~8 ms)\n");
  const auto thesis = thesis_sample_exchanges(model);
  fmt::print("  get position, set target, set speed:  {} exchanges, {:.1f} ms\n", thesis,
             static_cast<double>(thesis) * config.exchange_us * 1e-3);

  fmt::print("\nWork-area speed limit of joint 3 (thesis: 173 mm/s at 56 ms, 346 at 28 ms)\n");
  {
    hw::Rcu rcu(model);
    hw::RcuBus bus(rcu);
    rtc::MicroboDriver driver(model, bus, rcu);
    for (const double T : {0.056, 0.028}) {
      const double zone = config.joints[2].lower_threshold * model.joints[2].resolution_per_count;
      fmt::print(
          "  {:.0f} ms: zone {:.0f} counts -> {:.0f} mm/s; commanded at most {:.0f} mm/s "
          "(top speed {:.0f})\n",
          T * 1e3, static_cast<double>(config.joints[2].lower_threshold), zone / T * 1e3,
          driver.velocity_limit(2, T) * 1e3, model.joints[2].max_velocity * 1e3);
    }
  }

  fmt::print("\nJoint 3 on a ramp: follow scheme against raw targets\n");
  fmt::print("  {:>6} {:>9} {:>7} | {:>13} {:>9} {:>14} | {:>10}\n", "period", "speed", "scheme",
             "error (counts)", "(mm)", "ripple at 1/T", "exchanges");
  rtc::RampResult plot_raw, plot_follow;
  for (const double T : {0.028, 0.056}) {
    for (const double v : {0.025, 0.050, 0.100}) {
      for (const auto scheme : {rtc::TargetScheme::raw, rtc::TargetScheme::follow}) {
        rtc::RampTrial trial;
        trial.scheme = scheme;
        trial.joint = 2;
        trial.speed = v;
        trial.period_s = T;
        const rtc::RampResult r = rtc::run_ramp_trial(model, trial);
        fmt::print(
            "  {:>4.0f}ms {:>5.0f}mm/s {:>7} | {:>6.0f} max {:>4.0f} {:>9.3f} {:>9.1f} mm/s | "
            "{:>10}\n",
            T * 1e3, v * 1e3, scheme == rtc::TargetScheme::raw ? "raw" : "follow",
            r.mean_error_counts(), r.max_error_counts(), r.mean_error_counts() * r.count * 1e3,
            r.amplitude_at(1.0 / T) * 1e3, r.exchanges_per_sample);
        if (T == 0.028 && v == 0.050)
          (scheme == rtc::TargetScheme::raw ? plot_raw : plot_follow) = r;
      }
    }
  }
  fmt::print(
      "  (error: |Xd - Xm| at the sample instants after 0.5 s; ripple: the joint speed's\n"
      "   component at the sample frequency, from 1 ms samples of the emulated plant)\n");
  if (argc > 1) write_svg(argv[1], plot_raw, plot_follow, 0.050);
  return 0;
}
