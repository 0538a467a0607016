#include "cell_command.hpp"

#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "rccx/cell/cell_model.hpp"
#include "rccx/math/units.hpp"

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
                {"period_multiple", r.period_multiple},
                {"period_ms", ms(c.period(i))},
                {"base", pose_json(r.base)},
                {"reach_m", cell::reach_m(r)},
                {"link_radius_m", r.link_radius_m}};
      item["tool"] = r.tool ? pose_json(*r.tool) : json(nullptr);
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
               r.model.name, r.model_file.empty() ? "" : " (" + r.model_file + ")", ms(c.period(i)),
               r.period_multiple, cell::reach_m(r) * 1e3, pose_text(r.base));
    if (r.tool) fmt::print("    tool: {}\n", pose_text(*r.tool));
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
}

}  // namespace rccx::tools
