#include "cell_command.hpp"

#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "rccx/cell/cell.hpp"
#include "rccx/cell/cell_model.hpp"
#include "rccx/cell/load.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/io/signals.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rtc/session.hpp"

namespace rccx::tools {

namespace {

using json = nlohmann::ordered_json;

struct ShowArgs {
  std::string file;
  bool json = false;
};

double ms(std::chrono::nanoseconds t) {
  return static_cast<double>(t.count()) * 1e-6;
}

/// A value rounded to 0.1 as it will be printed, without the "-0.0" of round-off.
double tenth(double v) {
  return std::round(v * 10.0) / 10.0 + 0.0;
}

/// "x -300.0 y 0.0 z 330.2 mm, roll 180.0 pitch 0.0 yaw 0.0 deg" (Paul's RPY).
std::string pose_text(const math::Transform& T) {
  const auto rpy = T.R.to_rpy();
  return fmt::format("x {:.1f} y {:.1f} z {:.1f} mm, roll {:.1f} pitch {:.1f} yaw {:.1f} deg",
                     tenth(T.p.x * 1e3), tenth(T.p.y * 1e3), tenth(T.p.z * 1e3),
                     tenth(math::rad_to_deg(rpy[0])), tenth(math::rad_to_deg(rpy[1])),
                     tenth(math::rad_to_deg(rpy[2])));
}

json pose_json(const math::Transform& T) {
  const auto rpy = T.R.to_rpy();
  // + 0.0 turns the -0.0 of round-off into 0.
  return {{"xyz_m", {T.p.x + 0.0, T.p.y + 0.0, T.p.z + 0.0}},
          {"rpy_deg",
           {math::rad_to_deg(rpy[0]) + 0.0, math::rad_to_deg(rpy[1]) + 0.0,
            math::rad_to_deg(rpy[2]) + 0.0}}};
}

std::string shape_text(const cell::Shape& s) {
  if (s.kind == cell::ShapeKind::box) {
    return fmt::format("box {:.1f} x {:.1f} x {:.1f} mm", s.size_m.x * 1e3, s.size_m.y * 1e3,
                       s.size_m.z * 1e3);
  }
  return fmt::format("cylinder radius {:.1f} mm, height {:.1f} mm", s.radius_m * 1e3,
                     s.height_m * 1e3);
}

json shape_json(const cell::Shape& s) {
  if (s.kind == cell::ShapeKind::box) {
    return {{"shape", "box"}, {"size_m", {s.size_m.x, s.size_m.y, s.size_m.z}}};
  }
  return {{"shape", "cylinder"}, {"radius_m", s.radius_m}, {"height_m", s.height_m}};
}

int run_show(const ShowArgs& args) {
  cell::CellModel c;
  try {
    c = cell::load_cell_file(args.file);
  } catch (const cell::CellFileError& e) {
    throw BadArgument{e.what()};
  }
  const std::vector<cell::ReachOverlap> overlaps = cell::reach_overlaps(c);

  if (args.json) {
    json robots = json::array();
    for (std::size_t i = 0; i < c.robots.size(); ++i) {
      const cell::CellRobot& r = c.robots[i];
      json item{{"name", r.name},
                {"robot", r.model.name},
                {"robot_file", r.model_file.empty() ? json(nullptr) : json(r.model_file)},
                {"urdf", r.urdf_file.empty() ? json(nullptr) : json(r.urdf_file)},
                {"period_multiple", r.period_multiple},
                {"period_ms", ms(c.period(i))},
                {"base", pose_json(r.base)},
                {"reach_m", cell::reach_m(r)},
                {"link_radius_m", r.link_radius_m}};
      item["tool"] = r.tool ? pose_json(*r.tool) : json(nullptr);
      json shapes = json::array();
      for (const cell::RobotShape& k : r.shapes) {
        shapes.push_back({{"name", k.name},
                          {"frame", k.frame},
                          {"from_m", {k.from_m.x, k.from_m.y, k.from_m.z}},
                          {"to_m", {k.to_m.x, k.to_m.y, k.to_m.z}},
                          {"radius_m", k.radius_m}});
      }
      item["shapes"] = shapes;
      item["mounted_on"] = r.mounted_on.empty() ? json(nullptr) : json(r.mounted_on);
      robots.push_back(item);
    }
    json objects = json::array();
    for (const cell::CellObject& o : c.objects) {
      json item{{"name", o.name}};
      item.update(shape_json(o.shape));
      item["pose"] = pose_json(o.pose);
      item["movable"] = o.movable;
      objects.push_back(item);
    }
    json frames = json::array();
    for (const cell::CellFrame& f : c.frames) {
      frames.push_back({{"name", f.name}, {"pose", pose_json(f.pose)}});
    }
    json pairs = json::array();
    for (const cell::ReachOverlap& o : overlaps) {
      pairs.push_back({{"robots", {c.robots[o.first].name, c.robots[o.second].name}},
                       {"distance_m", o.distance_m},
                       {"depth_m", o.depth_m},
                       {"overlap", o.overlaps()},
                       {"shared_volume_m3", o.shared_volume_m3}});
    }
    fmt::print("{}\n", json{{"name", c.name},
                            {"title", c.title},
                            {"base_period_ms", ms(c.base_period)},
                            {"collision_margin_m", c.collision_margin_m},
                            {"robots", robots},
                            {"objects", objects},
                            {"frames", frames},
                            {"reach_overlaps", pairs}}
                           .dump());
    return kOk;
  }

  fmt::print("cell {} - {}\n  source: {}\n  clock: {:g} ms; collision margin {:.1f} mm\n", c.name,
             c.title, c.source, ms(c.base_period), c.collision_margin_m * 1e3);
  fmt::print("robots ({}):\n", c.robots.size());
  for (std::size_t i = 0; i < c.robots.size(); ++i) {
    const cell::CellRobot& r = c.robots[i];
    fmt::print("  {} - {}{}, period {:g} ms (x{}), reach {:.1f} mm\n    base: {}\n", r.name,
               r.model.name,
               !r.model_file.empty()  ? " (" + r.model_file + ")"
               : !r.urdf_file.empty() ? " (" + r.urdf_file + ")"
                                      : "",
               ms(c.period(i)), r.period_multiple, cell::reach_m(r) * 1e3, pose_text(r.base));
    if (r.tool) fmt::print("    tool: {}\n", pose_text(*r.tool));
    // The collision model's shapes beyond the links (docs/CELL.md), and what it stands on.
    for (const cell::RobotShape& k : r.shapes) {
      const std::string frame = k.frame == 0               ? std::string("base")
                                : k.frame == r.model.dof() ? std::string("t6")
                                                           : fmt::format("link {}", k.frame);
      fmt::print("    shape {}: {} mm long in {}, radius {:.1f} mm\n", k.name,
                 fmt::format("{:.1f}", (k.to_m - k.from_m).norm() * 1e3), frame, k.radius_m * 1e3);
    }
    if (!r.mounted_on.empty()) fmt::print("    stands on: {}\n", r.mounted_on);
  }
  if (!c.objects.empty()) fmt::print("objects ({}):\n", c.objects.size());
  for (const cell::CellObject& o : c.objects) {
    fmt::print("  {} - {}{}\n    at: {}\n", o.name, shape_text(o.shape),
               o.movable ? ", movable" : "", pose_text(o.pose));
  }
  if (!c.frames.empty()) fmt::print("frames ({}):\n", c.frames.size());
  for (const cell::CellFrame& f : c.frames) fmt::print("  {}: {}\n", f.name, pose_text(f.pose));
  if (!overlaps.empty()) fmt::print("reach overlaps (conservative spheres about each base):\n");
  for (const cell::ReachOverlap& o : overlaps) {
    const std::string pair =
        fmt::format("{} / {}", c.robots[o.first].name, c.robots[o.second].name);
    if (o.overlaps()) {
      fmt::print("  {}: bases {:.1f} mm apart, reaches overlap by {:.1f} mm, shared {:.4f} m^3\n",
                 pair, o.distance_m * 1e3, o.depth_m * 1e3, o.shared_volume_m3);
    } else {
      fmt::print("  {}: bases {:.1f} mm apart, no overlap ({:.1f} mm between the reaches)\n", pair,
                 o.distance_m * 1e3, -o.depth_m * 1e3);
    }
  }
  return kOk;
}

struct LoadArgs {
  std::string robots = "8";
  Duration period{"1ms"};
  Duration seconds{"2s"};
  std::string robot = "puma560";
  std::string spacing = "2.5";
  bool realtime = false;
  bool plant = false;
  bool one_thread = false;
  Duration spin{"0s"};
  bool json = false;
};

int run_load(const LoadArgs& a) {
  std::size_t n = 0;
  const std::chrono::nanoseconds period = a.period.value;
  const double seconds = a.seconds.seconds();
  double spacing = 0;
  const auto spin_us = std::chrono::duration_cast<std::chrono::microseconds>(a.spin.value).count();
  try {
    n = static_cast<std::size_t>(io::parse_integer(a.robots, "--robots", 1, 4096));
    spacing = io::parse_number(a.spacing, "--spacing", {1.0, 100.0, "m"});
  } catch (const io::ParseError& e) {
    throw BadArgument{e.what()};
  }
  if (a.robot != "puma560" && a.robot != "puma260") {
    throw BadArgument{fmt::format("--robot: {} is not one the load drives; give puma560 or puma260",
                                  io::quoted(a.robot))};
  }
  cell::CellOptions options;
  options.clock = a.realtime ? rtc::ClockKind::real_time : rtc::ClockKind::simulated;
  options.ideal_servo = !a.plant;
  options.one_thread = a.one_thread;
  options.spin_before_tick = std::chrono::microseconds(spin_us);
  cell::Cell c(cell::grid_cell(n, a.robot, spacing, period), options);
  if (!a.json) {
    fmt::print("cell-load: {} {} on a {:g} m grid, {} at {:g} ms, {} time, {} s\n", n, a.robot,
               spacing, a.plant ? "each on its plant" : "ideal servos",
               std::chrono::duration<double, std::milli>(period).count(),
               a.realtime ? "real" : "simulated", seconds);
    if (a.one_thread) fmt::print("both tasks on one thread\n");
  }
  cell::start_circles(c);
  const auto run_for =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(seconds));
  if (a.realtime) {
    // Real time: the tasks tick on their own; wait in period steps so Ctrl-C ends it soon.
    const auto until = std::chrono::steady_clock::now() + run_for;
    while (std::chrono::steady_clock::now() < until && io::stop_count() == 0) {
      c.wait_for(std::min<std::chrono::nanoseconds>(run_for, std::chrono::milliseconds(100)));
    }
  } else {
    c.wait_for(run_for);
  }
  const rtc::LatencyStats compute = c.group().compute();
  const rtc::LatencyStats wake = c.group().latency();
  std::size_t failed = 0;
  std::string first_failure;  // what went wrong, once: the others are alike as a rule
  for (const auto& name : c.robot_names()) {
    const auto& failures = c.robot(name).failures();
    if (failures.empty()) continue;
    if (failed++ == 0) first_failure = fmt::format("{}: {}", name, failures.front().text.data());
  }
  const rtc::Termination ended = c.session(c.robot_names().front()).termination();
  const double period_us = std::chrono::duration<double, std::micro>(period).count();
  if (a.json) {
    nlohmann::ordered_json j{{"robots", n},
                             {"period_us", period_us},
                             {"realtime", a.realtime},
                             {"one_thread", a.one_thread},
                             {"ticks", compute.wakeups},
                             {"compute_p50_us", compute.p50_us},
                             {"compute_p99_us", compute.p99_us},
                             {"compute_p999_us", compute.p999_us},
                             {"compute_max_us", compute.max_us},
                             {"wakeup_p50_us", wake.p50_us},
                             {"wakeup_p99_us", wake.p99_us},
                             {"wakeup_max_us", wake.max_us},
                             {"spin_us", spin_us},
                             {"wakeup_p999_us", wake.p999_us},
                             {"missed_deadlines", wake.missed_deadlines},
                             {"late_wakeups", wake.late_wakeups},
                             {"robots_failed", failed},
                             {"first_failure", first_failure}};
    fmt::print("{}\n", j.dump(2));
  } else {
    fmt::print(
        "cycle compute over {} ticks: p50 {:.1f} us, p99 {:.1f} us, p99.9 {:.1f} us, max {:.1f} us "
        "({:.1f} % of the period at p99; {:.2f} us a robot at p50)\n",
        compute.wakeups, compute.p50_us, compute.p99_us, compute.p999_us, compute.max_us,
        100.0 * compute.p99_us / period_us, compute.p50_us / static_cast<double>(n));
    if (a.realtime) {
      fmt::print(
          "wake-up latency: p50 {:.0f} us, p99 {:.0f} us, max {:.0f} us; missed deadlines {} (in "
          "{} "
          "wake-ups a period or more late)\n",
          wake.p50_us, wake.p99_us, wake.max_us, wake.missed_deadlines, wake.late_wakeups);
    }
    if (failed > 0) {
      fmt::print("{} robots' motions failed (see docs/CELL.md); the first, {}\n", failed,
                 first_failure);
    }
    if (ended.ended()) {
      fmt::print("control of {} ended: {} {}\n", c.robot_names().front(),
                 rtc::to_string(ended.code), ended.detail.data());
    }
  }
  return !c.finish_logs("error") || failed > 0 ? kFailure : kOk;
}

}  // namespace

void add_cell_command(CLI::App& app, int& exit_code) {
  CLI::App* cell_cmd = app.add_subcommand(
      "cell",
      "Workcells: several robots on one clock, with the objects and named frames around "
      "them (cells/README.md)");
  cell_cmd->require_subcommand(1);

  auto show = std::make_shared<ShowArgs>();
  CLI::App* show_cmd = cell_cmd->add_subcommand(
      "show",
      "Prints a cell file: each robot (its model, period in ms, base position in mm and "
      "Paul's roll-pitch-yaw in deg, reach in mm), the objects and frames (mm, deg), and where "
      "the robots' reach spheres overlap (depth in mm, shared volume in m^3, a seeded "
      "estimate). Exit code 2 for a file that cannot be used");
  show_cmd->add_option("file", show->file, "Cell file (JSON, see cells/README.md)")->required();
  show_cmd->add_flag("--json", show->json,
                     "Print JSON in SI units (keys say them: _m, _m3, _ms, _deg)");
  show_cmd->callback([show, &exit_code] { guarded(exit_code, [&] { return run_show(*show); }); });

  auto load = std::make_shared<LoadArgs>();
  CLI::App* load_cmd = app.add_subcommand(
      "cell-load",
      "Drives N simulated PUMAs on one clock (a square grid, each tracking a 20 mm circle in "
      "Cartesian mode through a functional transform, collision checks on) and prints the "
      "cycle's computing time (from the communication task's wake-up to the end of the control "
      "cycle) in percentiles, and in real time the wake-up latency and missed deadlines");
  load_cmd->add_option("--robots", load->robots, "How many robots (1 to 4096)")
      ->capture_default_str();
  add_period_option(*load_cmd, load->period, "The clock's period (0.25ms to 56ms)");
  add_duration_option(*load_cmd, "--seconds", load->seconds, std::chrono::milliseconds(1),
                      std::chrono::hours(1), "How long to run, up to 1 h");
  load_cmd->add_option("--robot", load->robot, "puma560 or puma260")->capture_default_str();
  load_cmd->add_option("--spacing", load->spacing, "Grid spacing, m")->capture_default_str();
  load_cmd->add_flag("--realtime", load->realtime,
                     "Real time (SCHED_FIFO when allowed) instead of simulated time");
  load_cmd->add_flag("--plant", load->plant,
                     "Each robot on the PUMA's PID and plant instead of an ideal servo");
  load_cmd->add_flag("--one-thread", load->one_thread,
                     "Both tasks on one thread (no hand-overs between processors; no watchdog "
                     "for a hung control function)");
  add_duration_option(*load_cmd, "--spin", load->spin, std::chrono::nanoseconds(0),
                      std::chrono::milliseconds(1),
                      "Real time: spin this long before each tick instead of sleeping through "
                      "it (0 to 1ms, e.g. 50us)");
  load_cmd->add_flag("--json", load->json, "Print the figures as JSON (us)");
  load_cmd->callback([load, &exit_code] { guarded(exit_code, [&] { return run_load(*load); }); });
}

}  // namespace rccx::tools
