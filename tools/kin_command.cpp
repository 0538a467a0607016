#include "kin_command.hpp"

#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pose_options.hpp"
#include "rccx/io/console.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/seven_axis_kinematics.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/position_db.hpp"

namespace rccx::tools {

namespace {

using json = nlohmann::ordered_json;

std::string unit_of(const kin::Joint& j) {
  return j.type == kin::JointType::revolute ? "rad" : "m";
}

/// Joint values given by the user (each token strict: whole, finite), in rad/m, or in deg/m
/// when `degrees` is set. With `within_limits` each must lie within its joint's limits.
kin::JointVector joints_from(const std::vector<std::string>& values, const kin::Kinematics& k,
                             bool degrees, const char* what, bool within_limits = false) {
  if (values.size() != k.dof()) {
    throw BadArgument{fmt::format("{}: robot {} has {} joints, got {} values", what, k.model().name,
                                  k.dof(), values.size())};
  }
  kin::JointVector q(k.dof());
  for (std::size_t i = 0; i < k.dof(); ++i) {
    const kin::Joint& j = k.model().joints[i];
    const bool revolute = j.type == kin::JointType::revolute;
    const bool deg = degrees && revolute;
    const std::string name = fmt::format("{} (joint {})", what, i + 1);
    // Beyond a few turns (or a kilometre) a value is a typo, not a pose.
    const double big = deg ? 3600.0 : (revolute ? 20 * math::kPi : 1e3);
    const std::string unit = deg ? "deg" : unit_of(j);  // outlives the Range's view of it
    io::Range range{-big, big, unit};
    if (within_limits) {
      range.lo = deg ? math::rad_to_deg(j.lower) : j.lower;
      range.hi = deg ? math::rad_to_deg(j.upper) : j.upper;
    }
    const double v = io::parse_number(values[i], name, range);
    q[i] = deg ? math::deg_to_rad(v) : v;
  }
  return q;
}

void warn_outside_limits(const kin::Kinematics& k, const kin::JointVector& q) {
  for (std::size_t i = 0; i < k.dof(); ++i) {
    const kin::Joint& j = k.model().joints[i];
    if (q[i] < j.lower || q[i] > j.upper) {
      io::eprint("warning: joint {} ({}) = {} {} is outside its limits [{}, {}]\n", i + 1, j.name,
                 q[i], unit_of(j), j.lower, j.upper);
    }
  }
}

json to_json(const kin::JointVector& q) {
  return json(std::vector<double>(q.begin(), q.end()));
}

std::string format_joints(const kin::Kinematics& k, const kin::JointVector& q) {
  std::string out;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const kin::Joint& j = k.model().joints[i];
    const bool revolute = j.type == kin::JointType::revolute;
    out += fmt::format("  {:>7} = {:>12.9f} {:<3}  ({:.4f} {})\n", j.name, q[i], unit_of(j),
                       revolute ? math::rad_to_deg(q[i]) : q[i] * 1e3, revolute ? "deg" : "mm");
  }
  return out;
}

std::string format_transform(const math::Transform& T) {
  std::string out = "          n            o            a            p (m)\n";
  for (int r = 0; r < 4; ++r) {
    out += fmt::format("  {:>12.9f} {:>12.9f} {:>12.9f} {:>12.9f}\n", T(r, 0), T(r, 1), T(r, 2),
                       T(r, 3));
  }
  return out;
}

// ---- rccx kin fk ----

struct FkArgs {
  RobotChoice robot{"microbo"};  // the default of every rccx command
  std::vector<std::string> q;
  bool degrees = false;
  bool json = false;
};

int run_fk(const FkArgs& args) {
  const auto k = args.robot.load();
  const kin::JointVector q = joints_from(args.q, *k, args.degrees, "joint values");
  warn_outside_limits(*k, q);
  const math::Transform T = k->forward(q);
  if (args.json) {
    json rows = json::array();
    for (int r = 0; r < 4; ++r) rows.push_back({T(r, 0), T(r, 1), T(r, 2), T(r, 3)});
    fmt::print("{}\n", json{{"robot", k->model().name}, {"q", to_json(q)}, {"T", rows}}.dump());
    return kOk;
  }
  fmt::print("{} ({})\njoints:\n{}", k->model().name, k->model().title, format_joints(*k, q));
  if (!k->configuration_names().empty()) {
    fmt::print("configuration: {}\n", k->configuration_name(k->configuration_of(q)));
  }
  fmt::print("T6:\n{}", format_transform(T));
  return kOk;
}

// ---- rccx kin ik ----

struct IkArgs {
  RobotChoice robot{"microbo"};
  PoseArgs pose;
  std::string config;
  std::string near;
  std::optional<double> redundant;
  bool degrees = false;
  bool all = false;
  bool json = false;
};

int run_ik(const IkArgs& args) {
  const auto k = args.robot.load();
  // Within the position database's bound: no robot reaches beyond it, and a larger value is a
  // typo (exit 2, not "unreachable").
  const math::Transform pose = pose_from(args.pose, rccl::kMaxPosition_m);
  kin::IkOptions options;
  if (!args.config.empty()) {
    const auto names = k->configuration_names();
    if (names.empty()) {
      throw BadArgument{fmt::format(
          "--config: robot {} is solved numerically and has no named configurations; use --near",
          k->model().name)};
    }
    options.configuration = k->find_configuration(args.config);
    if (!options.configuration) {
      std::string list;
      for (auto n : names) list += std::string(list.empty() ? "" : ", ") + std::string(n);
      throw BadArgument{fmt::format("--config: robot {} has no configuration \"{}\"; use one of {}",
                                    k->model().name, args.config, list)};
    }
  }
  if (!args.near.empty()) {
    std::vector<std::string> near;
    std::size_t start = 0;
    for (;;) {
      const std::size_t comma = args.near.find(',', start);
      near.push_back(args.near.substr(start, comma - start));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    // The joints to stay near: a pose of the arm, so within its limits.
    options.near = joints_from(near, *k, args.degrees, "--near", true);
  }

  if (args.redundant) {
    if (dynamic_cast<const kin::SevenAxisKinematics*>(k.get()) == nullptr) {
      throw BadArgument{fmt::format(
          "--redundant: robot {} is not a 7-axis arm solved given joint 7 (such as the Panda "
          "from robots/panda.urdf); leave it out",
          k->model().name)};
    }
    options.redundant = args.degrees ? math::deg_to_rad(*args.redundant) : *args.redundant;
  }

  const bool named = !k->configuration_names().empty();
  auto config_name = [&](const kin::IkResult& r) {
    return named ? std::string(k->configuration_name(r.configuration)) : std::string("dh");
  };
  auto report_singularity = [&](const kin::IkResult& r) {
    if (r.singularity != kin::Singularity::none) {
      io::eprint("note: {} singularity; a joint left free by it was taken from {}\n",
                 kin::to_string(r.singularity), options.near ? "--near" : "the ready pose");
    }
  };

  if (args.all) {
    kin::IkSolutions all = k->inverse_all(pose, options);
    if (options.configuration && all.count > 0) {  // --all with --config: that one only
      std::size_t kept = 0;
      for (std::size_t i = 0; i < all.count; ++i) {
        if (all.items[i].configuration == *options.configuration) all.items[kept++] = all.items[i];
      }
      if (kept == 0) all.status = kin::IkStatus::joint_limits;
      all.count = kept;
    }
    if (all.count == 0) {
      io::eprint("{}: {}\n", k->model().name, kin::describe(all.status));
      return kUnreachable;
    }
    if (args.json) {
      json list = json::array();
      for (const auto& r : all.solutions()) {
        list.push_back({{"config", config_name(r)}, {"q", to_json(r.q)}});
      }
      fmt::print("{}\n", json{{"robot", k->model().name}, {"solutions", list}}.dump());
    } else {
      fmt::print("{} ({}): {} solution(s) within limits\n", k->model().name, k->model().title,
                 all.count);
      for (const auto& r : all.solutions()) {
        fmt::print("configuration {}:\n{}", config_name(r), format_joints(*k, r.q));
      }
    }
    for (const auto& r : all.solutions()) report_singularity(r);
    return kOk;
  }

  const kin::IkResult r = k->inverse(pose, options);
  if (!r) {
    io::eprint("{}: {}\n", k->model().name, kin::describe(r.status));
    return kUnreachable;
  }
  report_singularity(r);
  if (args.json) {
    fmt::print(
        "{}\n",
        json{{"robot", k->model().name}, {"q", to_json(r.q)}, {"config", config_name(r)}}.dump());
  } else {
    fmt::print("{} ({}), configuration {}:\n{}", k->model().name, k->model().title, config_name(r),
               format_joints(*k, r.q));
  }
  return kOk;
}

// ---- rccx kin robots ----

int run_robots(bool as_json) {
  json list = json::array();
  for (const std::string& name : kin::builtin_robot_names()) {
    const kin::RobotModel model = kin::builtin_robot(name);
    const auto k = kin::make_kinematics(model);
    if (!as_json) {
      fmt::print("{} - {} ({} solver, {} joints)\n  source: {}\n", model.name, model.title,
                 kin::to_string(model.solver), model.dof(), model.source);
      if (!k->configuration_names().empty()) {
        std::string names;
        for (auto n : k->configuration_names()) names += " " + std::string(n);
        fmt::print("  configurations:{}\n", names);
      }
    }
    json joints = json::array();
    for (const kin::Joint& j : model.joints) {
      const bool revolute = j.type == kin::JointType::revolute;
      if (as_json) {
        joints.push_back({{"name", j.name},
                          {"type", kin::to_string(j.type)},
                          {"lower", j.lower},
                          {"upper", j.upper},
                          {"unit", unit_of(j)},
                          {"resolution_per_count", j.resolution_per_count}});
      } else if (revolute) {
        fmt::print("  {:>7}  revolute   {:>9.3f} .. {:>8.3f} deg   {:.4f} deg/count\n", j.name,
                   math::rad_to_deg(j.lower), math::rad_to_deg(j.upper),
                   math::rad_to_deg(j.resolution_per_count));
      } else {
        fmt::print("  {:>7}  prismatic  {:>9.4f} .. {:>8.4f} m     {:.4f} mm/count\n", j.name,
                   j.lower, j.upper, j.resolution_per_count * 1e3);
      }
    }
    if (as_json) {
      list.push_back({{"name", model.name},
                      {"title", model.title},
                      {"solver", kin::to_string(model.solver)},
                      {"joints", joints}});
    }
  }
  if (as_json) fmt::print("{}\n", list.dump());
  return kOk;
}

}  // namespace

void add_kin_command(CLI::App& app, int& exit_code) {
  CLI::App* kin = app.add_subcommand(
      "kin",
      "Forward and inverse kinematics. Joint values are those of each robot's model: rad for "
      "revolute joints, m for prismatic ones; poses are T6 (wrist frame) in the base frame, m.");
  kin->require_subcommand(1);

  auto fk = std::make_shared<FkArgs>();
  CLI::App* fk_cmd = kin->add_subcommand("fk", "Forward kinematics: T6 for given joint values");
  add_robot_options(*fk_cmd, fk->robot);
  fk_cmd->add_option("q", fk->q, "Joint values q1 ... qN (rad or m; with --deg, deg or m)")
      ->required()
      ->allow_extra_args();
  fk_cmd->add_flag("--deg", fk->degrees, "Revolute joint values are in degrees (prismatic stay m)");
  fk_cmd->add_flag("--json", fk->json,
                   "Print {\"robot\":..,\"q\":[rad|m],\"T\":[[4 numbers] x 4 rows]}");
  fk_cmd->callback([fk, &exit_code] { guarded(exit_code, [&] { return run_fk(*fk); }); });

  auto ik = std::make_shared<IkArgs>();
  CLI::App* ik_cmd = kin->add_subcommand(
      "ik",
      "Inverse kinematics: joint values within limits for a T6 pose, given as --T or as --xyz "
      "and --rpy. Exit code 3 when the pose cannot be reached (the reason goes to stderr), 2 "
      "for bad arguments");
  add_robot_options(*ik_cmd, ik->robot);
  add_pose_options(*ik_cmd, ik->pose, "T6 (wrist frame) in the base frame");
  CLI::Option* config_opt = ik_cmd->add_option(
      "--config", ik->config,
      "Configuration to solve for: PUMA l|r (arm) u|d (elbow) n|f (wrist), e.g. lun; Microbo n|f "
      "(wrist)");
  CLI::Option* near_opt = ik_cmd->add_option(
      "--near", ik->near,
      "Comma-separated joint values (rad or m; with --deg, deg or m) to stay closest to; "
      "default: the robot's ready pose; within the joint limits");
  config_opt->excludes(near_opt);
  ik_cmd->add_option("--redundant", ik->redundant,
                     "A 7-axis arm solved given joint 7 (the Panda): hold joint 7 at this value "
                     "(rad; with --deg, deg); without it, joint 7 starts from --near's (or the "
                     "ready pose's) and moves only as far as it must");
  ik_cmd->add_flag("--all", ik->all, "Print every configuration's solution within limits");
  ik_cmd->add_flag("--deg", ik->degrees,
                   "--near and --redundant are in degrees for revolute joints");
  ik_cmd->add_flag("--json", ik->json,
                   "Print {\"robot\":..,\"q\":[..],\"config\":..}, or with --all "
                   "{\"robot\":..,\"solutions\":[{\"config\":..,\"q\":[..]},...]}");
  ik_cmd->callback([ik, &exit_code] { guarded(exit_code, [&] { return run_ik(*ik); }); });

  auto robots_json = std::make_shared<bool>(false);
  CLI::App* robots_cmd = kin->add_subcommand(
      "robots", "List the shipped robots with their joint types, limits and encoder resolution");
  robots_cmd->add_flag("--json", *robots_json, "Print a JSON array (limits in rad or m)");
  robots_cmd->callback(
      [robots_json, &exit_code] { guarded(exit_code, [&] { return run_robots(*robots_json); }); });
}

}  // namespace rccx::tools
