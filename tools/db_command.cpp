#include "db_command.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "rccx/math/units.hpp"
#include "rccx/rccl/position_db.hpp"

namespace rccx::tools {
namespace {

using json = nlohmann::ordered_json;

struct DbArgs {
  std::string file;
  std::string robot;
  std::string name;
  std::string pattern = "*";
  std::vector<double> T;
  std::string configuration;
  std::string note;
  std::string path;  // export / import file ("-": stdout / stdin)
};

json to_json(const rccl::StoredTransform& t) {
  json j;
  j["robot"] = t.robot;
  j["name"] = t.name;
  j["T_rows_m"] = t.value.rows();
  j["configuration"] = t.configuration;
  j["note"] = t.note;
  j["created_unix_s"] = t.created_unix_s;
  j["changed_unix_s"] = t.changed_unix_s;
  return j;
}

rccl::StoredTransform from_json(const json& j) {
  rccl::StoredTransform t;
  t.robot = j.at("robot").get<std::string>();
  t.name = j.at("name").get<std::string>();
  t.value = math::Transform::from_rows(j.at("T_rows_m").get<std::array<double, 12>>());
  t.configuration = j.value("configuration", "");
  t.note = j.value("note", "");
  t.created_unix_s = j.value("created_unix_s", std::int64_t{0});
  t.changed_unix_s = j.value("changed_unix_s", std::int64_t{0});
  return t;
}

void print(const rccl::StoredTransform& t) {
  const auto rpy = t.value.R.to_rpy();
  fmt::print("{} {}: x {:.3f} y {:.3f} z {:.3f} mm, roll {:.3f} pitch {:.3f} yaw {:.3f} deg{}{}\n",
             t.robot, t.name, t.value.p.x * 1e3, t.value.p.y * 1e3, t.value.p.z * 1e3,
             math::rad_to_deg(rpy[0]), math::rad_to_deg(rpy[1]), math::rad_to_deg(rpy[2]),
             t.configuration.empty() ? "" : ", configuration " + t.configuration,
             t.note.empty() ? "" : " (" + t.note + ")");
}

int run(const std::string& what, const DbArgs& a) {
  using rccl::PositionDb;
  const std::string file = database_file(a.file);
  try {
    if (what == "list") {
      PositionDb db(file, PositionDb::Open::existing);
      for (const auto& t : db.list(a.robot, a.pattern)) print(t);
    } else if (what == "show") {
      PositionDb db(file, PositionDb::Open::existing);
      const auto t = db.get(a.robot, a.name);
      if (!t) throw BadArgument{fmt::format("{} has no {} for robot {}", file, a.name, a.robot)};
      print(*t);
      fmt::print("{}\n", to_json(*t).dump(2));
    } else if (what == "put") {
      if (a.T.size() != 12) {
        throw BadArgument{
            fmt::format("--T takes 12 numbers (r11,r12,r13,px,...,r33,pz in m), "
                        "got {}",
                        a.T.size())};
      }
      rccl::StoredTransform t;
      t.robot = a.robot;
      t.name = a.name;
      std::array<double, 12> rows{};
      std::copy(a.T.begin(), a.T.end(), rows.begin());
      t.value = math::Transform::from_rows(rows);
      t.configuration = a.configuration;
      t.note = a.note;
      PositionDb db(file);
      if (const auto old = db.get(a.robot, a.name)) t.created_unix_s = old->created_unix_s;
      db.put(t);
    } else if (what == "rm") {
      PositionDb db(file, PositionDb::Open::existing);
      if (!db.remove(a.robot, a.name)) {
        throw BadArgument{fmt::format("{} has no {} for robot {}", file, a.name, a.robot)};
      }
    } else if (what == "export") {
      PositionDb db(file, PositionDb::Open::existing);
      json j;
      j["rccx_position_database"] = PositionDb::kSchemaVersion;
      j["units"] = "m, rad; T_rows_m: the top three rows of the 4x4 transform, row by row";
      j["transforms"] = json::array();
      for (const auto& t : db.list(a.robot)) j["transforms"].push_back(to_json(t));
      if (a.path.empty() || a.path == "-") {
        std::cout << j.dump(2) << "\n";
      } else {
        std::ofstream out(a.path);
        out << j.dump(2) << "\n";
        if (!out) throw BadArgument{fmt::format("cannot write {}", a.path)};
      }
    } else if (what == "import") {
      json j;
      try {
        if (a.path == "-") {
          j = json::parse(std::cin);
        } else {
          std::ifstream in(a.path);
          if (!in) throw BadArgument{fmt::format("cannot read {}", a.path)};
          j = json::parse(in);
        }
        std::vector<rccl::StoredTransform> all;
        for (const json& t : j.at("transforms")) all.push_back(from_json(t));
        PositionDb db(file);
        db.put(all);  // all or nothing
        fmt::print(stderr, "imported {} transforms into {}\n", all.size(), file);
      } catch (const json::exception& e) {
        throw BadArgument{fmt::format("{}: not an rccx position export ({}); nothing imported",
                                      a.path, e.what())};
      }
    }
  } catch (const rccl::DatabaseError& e) {
    fmt::print(stderr, "rccx db: {}\n", e.what());
    return kFailure;
  }
  return kOk;
}

}  // namespace

void add_db_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<DbArgs>();
  CLI::App* db = app.add_subcommand(
      "db",
      "The position database (SQLite): named transforms per robot, for programs and equations. "
      "The file is --db, else $RCCX_DB, else ./rccx.db. Export / import as JSON (m, rad) to "
      "keep positions in version control or edit them off-line.");
  db->add_option("--db", args->file, "Database file");
  db->require_subcommand(1);
  const auto robot_name = [&](CLI::App* c, bool name_required) {
    c->add_option("--robot", args->robot, "The robot the transform belongs to")->required();
    auto* n = c->add_option("name", args->name, "Transform name (1 to 32 characters)");
    if (name_required) n->required();
  };
  CLI::App* list = db->add_subcommand("list", "Lists transforms (all robots unless --robot)");
  list->add_option("--robot", args->robot, "Only this robot's");
  list->add_option("pattern", args->pattern, "Name pattern (glob: *, ?)")->capture_default_str();
  CLI::App* show = db->add_subcommand("show", "Prints one transform (mm, deg, and as JSON)");
  robot_name(show, true);
  CLI::App* put = db->add_subcommand("put", "Stores a transform (replacing one of that name)");
  robot_name(put, true);
  put->add_option("--T", args->T, "r11,r12,r13,px,r21,r22,r23,py,r31,r32,r33,pz (m)")
      ->delimiter(',')
      ->required();
  put->add_option("--config", args->configuration, "The arm configuration it is for");
  put->add_option("--note", args->note, "A note");
  CLI::App* rm = db->add_subcommand("rm", "Removes a transform");
  robot_name(rm, true);
  CLI::App* exp = db->add_subcommand("export", "Writes every transform as JSON");
  exp->add_option("--robot", args->robot, "Only this robot's");
  exp->add_option("file", args->path, "Output file (default: standard output)");
  CLI::App* imp = db->add_subcommand("import", "Reads a JSON export: all transforms or none");
  imp->add_option("file", args->path, "Input file (- for standard input)")->required();
  for (CLI::App* c : {list, show, put, rm, exp, imp}) {
    const std::string what = c->get_name();
    c->callback([args, what, &exit_code] { guarded(exit_code, [&] { return run(what, *args); }); });
  }
}

}  // namespace rccx::tools
