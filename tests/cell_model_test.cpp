// The cell model and cell files (src/rccx/cell/cell_model.hpp, cells/): the shipped CVaRL cell
// loads and its circuit board is reachable by both arms, every rule of the file format refuses
// what it should with a message naming the key, the reach geometry agrees with a hand
// computation, and `rccx cell show` works on good and bad files.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <tuple>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "rccx/cell/cell.hpp"
#include "rccx/cell/cell_model.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rtc/session.hpp"

#include "shell_run.hpp"

namespace {

using namespace rccx;
using namespace std::chrono_literals;
using nlohmann::json;
namespace fs = std::filesystem;

// The cell layer repeats RTC's period range rather than link the real-time layer.
static_assert(cell::kMinPeriod == rtc::kMinPeriod);
static_assert(cell::kMaxPeriod == rtc::kMaxPeriod);

const fs::path kCvarl = fs::path(RCCX_CELLS_DIR) / "cvarl.json";

TEST(CellCvarl, Loads) {
  const cell::CellModel c = cell::load_cell_file(kCvarl);
  EXPECT_EQ(c.name, "cvarl");
  EXPECT_EQ(c.base_period, 7ms);
  ASSERT_EQ(c.robots.size(), 2U);
  EXPECT_EQ(c.robots[0].name, "puma");
  EXPECT_EQ(c.robots[0].model.name, "puma260");
  EXPECT_EQ(c.period(0), 7ms);
  EXPECT_EQ(c.robots[1].name, "microbo");
  EXPECT_EQ(c.robots[1].model.name, "microbo");
  EXPECT_EQ(c.period(1), 28ms);  // the thesis's joint-mode period
  ASSERT_NE(c.find_object("board"), nullptr);
  EXPECT_TRUE(c.find_object("board")->movable);
  ASSERT_NE(c.find_frame("board_home"), nullptr);
  EXPECT_EQ(c.find_robot("pumaa"), nullptr);
  const auto overlaps = cell::reach_overlaps(c);
  ASSERT_EQ(overlaps.size(), 1U);
  EXPECT_TRUE(overlaps[0].overlaps());
  EXPECT_GT(overlaps[0].shared_volume_m3, 0.0);
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Cell files are JSON with comments (JSONC); plain JSON is read as well: every shipped cell with
// its comments taken out loads to the same cell, and is what Python's json module reads.
TEST(CellCvarl, ShippedCellsLoadWithoutTheirCommentsTooAndPythonReadsThatText) {
  for (const fs::directory_entry& e : fs::directory_iterator(RCCX_CELLS_DIR)) {
    if (e.path().extension() != ".json") continue;
    const std::string with = read_text(e.path());
    ASSERT_NE(with.find("//"), std::string::npos) << e.path() << ": the test needs its comments";
    const std::string plain = json::parse(with, nullptr, true, /*ignore_comments=*/true).dump(2);
    EXPECT_FALSE(json::accept(with));  // strict JSON refuses the comments
    const cell::CellModel a = cell::load_cell_file(e.path());
    const cell::CellModel b = cell::parse_cell(plain, e.path().string(), e.path().parent_path());
    ASSERT_EQ(a.robots.size(), b.robots.size());
    for (std::size_t i = 0; i < a.robots.size(); ++i) {
      EXPECT_EQ(a.robots[i].name, b.robots[i].name);
      EXPECT_EQ(math::max_abs_difference(a.robots[i].base, b.robots[i].base), 0.0);
    }
    EXPECT_EQ(a.objects.size(), b.objects.size());
    const fs::path out = fs::temp_directory_path() / ("rccx_plain_" + e.path().filename().string());
    std::ofstream(out) << plain;
    const auto py = rccx::test::run_shell(
        "python3 -c 'import json,sys; json.load(open(sys.argv[1]))' " + out.string() + " 2>&1");
    EXPECT_EQ(py.exit_code, 0) << py.out;
    fs::remove(out);
  }
}

// A misspelt key is named with the known key nearest it and its line and column in the file,
// whether the key it stands for is required (else reported "missing") or optional.
TEST(CellCvarl, AMisspeltKeyIsNamedWithItsPlaceAndTheNearestKnownKey) {
  struct Typo {
    std::string key, typo;
  };
  const std::vector<Typo> typos = {
      {"robots", "robts"},
      {"base_period_ms", "base_period_sm"},
      {"collision_margin_m", "colision_margin_m"},
      {"objects", "object"},
      {"frames", "framse"},
      {"period_multiple", "period_multiplier"},
      {"link_radius_m", "link_radius_mm"},
      {"base", "bsae"},
      {"xyz_m", "xyz_mm"},
      {"rpy_deg", "rpy_dge"},
      {"movable", "moveable"},
      {"tool", "tol"},
  };
  const std::string text = read_text(kCvarl);
  for (const Typo& t : typos) {
    std::string bad = text;
    const std::size_t at = bad.find("\"" + t.key + "\":");
    ASSERT_NE(at, std::string::npos) << t.key;
    bad.replace(at + 1, t.key.size(), t.typo);
    const auto line = 1 + std::count(bad.begin(), bad.begin() + static_cast<long>(at), '\n');
    const auto column = at - bad.rfind('\n', at);
    try {
      (void)cell::parse_cell(bad, "cells/x.json", kCvarl.parent_path());
      ADD_FAILURE() << t.typo << " accepted";
    } catch (const cell::CellFileError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(fmt::format("cells/x.json:{}:{}: ", line, column), 0), 0U) << m;
      EXPECT_NE(m.find(fmt::format("unknown key \"{}\"", t.typo)), std::string::npos) << m;
      EXPECT_NE(m.find(fmt::format("did you mean \"{}\"?", t.key)), std::string::npos) << m;
    }
  }
  // Nothing near: the message lists the keys of that place instead.
  std::string bad = text;
  bad.replace(bad.find("\"collision_margin_m\""), 0, "\"zzz\": 1, ");
  try {
    (void)cell::parse_cell(bad, "cells/x.json", kCvarl.parent_path());
    ADD_FAILURE() << "zzz accepted";
  } catch (const cell::CellFileError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown key \"zzz\"; the keys here are "),
              std::string::npos)
        << e.what();
  }
}

// Figure 4.8's demonstration: both arms work on the board. Every point of its top face on a
// 5 x 5 grid, and 50 mm above each, with the tool pointing down and turned four ways about
// the vertical, must solve within the joint limits for each robot, in its own base frame.
TEST(CellCvarl, BoardIsReachableByBothRobots) {
  const cell::CellModel c = cell::load_cell_file(kCvarl);
  const cell::CellObject& board = *c.find_object("board");
  ASSERT_EQ(board.shape.kind, cell::ShapeKind::box);
  const math::Vec3 half = board.shape.size_m * 0.5;
  for (const cell::CellRobot& robot : c.robots) {
    const auto k = kin::make_kinematics(robot.model);
    const math::Transform tool = robot.tool.value_or(math::Transform::identity());
    int solved = 0;
    for (int ix = 0; ix <= 4; ++ix) {
      for (int iy = 0; iy <= 4; ++iy) {
        for (const double above_m : {0.0, 0.05}) {
          for (const double turn_deg : {0.0, 90.0, 180.0, -90.0}) {
            const math::Vec3 on_face{-half.x + half.x * ix / 2.0, -half.y + half.y * iy / 2.0,
                                     half.z + above_m};
            // Tool down: a = -z of the world; turned about the vertical by turn_deg.
            const math::Transform goal{
                math::Rot3::rot_z(math::deg_to_rad(turn_deg)) * math::Rot3::rot_x(math::kPi),
                board.pose * on_face};
            const math::Transform t6 = robot.base.inverse_times(goal) * tool.inverse();
            const kin::IkResult r = k->inverse(t6);
            ASSERT_TRUE(r) << robot.name << " at board point (" << ix << ", " << iy << ") + "
                           << above_m << " m, turned " << turn_deg
                           << " deg: " << kin::describe(r.status);
            EXPECT_LT(math::max_abs_difference(k->forward(r.q), t6), 1e-9) << robot.name;
            ++solved;
          }
        }
      }
    }
    EXPECT_EQ(solved, 5 * 5 * 2 * 4);
  }
}

// ---- bad cell files ----

json valid_cell() {
  return json::parse(R"({
    "name": "t", "title": "test cell", "source": "tests", "base_period_ms": 7,
    "collision_margin_m": 0.01,
    "robots": [
      {"name": "a", "robot": "puma260", "base": {"xyz_m": [0, 0, 0]}, "period_multiple": 1,
       "link_radius_m": 0.05},
      {"name": "b", "robot": "microbo", "base": {"xyz_m": [0.5, 0, 0], "rpy_deg": [180, 0, 0]},
       "period_multiple": 4, "link_radius_m": [0.1, 0.1, 0.1, 0.1, 0.1, 0.1],
       "tool": {"xyz_m": [0, 0, 0.1]}}
    ],
    "objects": [
      {"name": "table", "shape": "box", "size_m": [1, 1, 0.04], "pose": {"xyz_m": [0, 0, -0.02]}},
      {"name": "post", "shape": "cylinder", "radius_m": 0.02, "height_m": 0.3,
       "pose": {"rows_m": [1, 0, 0, 0.2, 0, 1, 0, 0.2, 0, 0, 1, 0.15]}}
    ],
    "frames": [{"name": "home", "pose": {"xyz_m": [0.2, 0, 0.1]}, "note": "a place"}]
  })");
}

/// Robot b of valid_cell(), parsed.
cell::CellRobot valid_model() {
  return cell::parse_cell(valid_cell().dump(), "good.json", {}).robots[1];
}

struct BadRow {
  std::function<void(json&)> change;
  std::string says;  ///< a part of the message (the key)
};

TEST(CellFile, ShapesAndMountingLoad) {
  json j = valid_cell();
  j["robots"][1]["shapes"] = json::array({{{"name", "hand"},
                                           {"frame", "t6"},
                                           {"from_m", {0, 0, 0}},
                                           {"to_m", {0, 0, 0.05}},
                                           {"radius_m", 0.02}},
                                          {{"name", "slide_tail"},
                                           {"frame", 3},
                                           {"from_m", {0, 0, 0}},
                                           {"to_m", {0, 0, -0.1}},
                                           {"radius_m", 0.03},
                                           {"note", "behind the column"}},
                                          {{"name", "plinth"},
                                           {"frame", "base"},
                                           {"from_m", {0, 0, 0}},
                                           {"to_m", {0, 0, 0.1}},
                                           {"radius_m", 0.1}}});
  j["robots"][1]["mounted_on"] = "table";
  const cell::CellModel c = cell::parse_cell(j.dump(), "good.json", {});
  ASSERT_EQ(c.robots[1].shapes.size(), 3U);
  EXPECT_EQ(c.robots[1].shapes[0].frame, 6U);
  EXPECT_EQ(c.robots[1].shapes[1].frame, 3U);
  EXPECT_EQ(c.robots[1].shapes[2].frame, 0U);
  EXPECT_DOUBLE_EQ(c.robots[1].shapes[1].to_m.z, -0.1);
  EXPECT_EQ(c.robots[1].mounted_on, "table");
  // Shapes in T6 replace the default tool capsule; without them the tool gets one.
  EXPECT_EQ(cell::Cell::shapes_of(c.robots[1]).size(), 3U);
  const std::vector<cell::RobotShape> tool = cell::Cell::shapes_of(valid_model());
  ASSERT_EQ(tool.size(), 1U);
  EXPECT_EQ(tool[0].name, "tool");
  EXPECT_DOUBLE_EQ(tool[0].to_m.z, 0.1);
  EXPECT_DOUBLE_EQ(tool[0].radius_m, 0.1);
}

TEST(CellFile, ARobotInsideAnObjectIsRefusedSayingWhatToDo) {
  // The Microbo's base joint and column start on the table top: inside the table unless the
  // cell says it stands there.
  json j = valid_cell();
  j["robots"][0]["base"]["xyz_m"] = {0, 0, 0.3};  // the PUMA's shoulder above the table
  try {
    cell::Cell c(cell::parse_cell(j.dump(), "t.json", {}));
    ADD_FAILURE() << "a robot standing inside the table was accepted";
  } catch (const cell::CellFileError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("robot b's link 1 lies 100.0 mm inside object table"), std::string::npos) << m;
    EXPECT_NE(m.find("\"mounted_on\": \"table\""), std::string::npos) << m;
  }
  j["robots"][1]["mounted_on"] = "table";
  EXPECT_NO_THROW(cell::Cell(cell::parse_cell(j.dump(), "t.json", {})));
  // A part that is not the base's stays refused, mounted or not: the post through the arm.
  j["objects"][1]["pose"] = {{"xyz_m", {0.5 - 0.325, 0, 0.275}}};
  try {
    cell::Cell c(cell::parse_cell(j.dump(), "t.json", {}));
    ADD_FAILURE() << "an arm through a post was accepted";
  } catch (const cell::CellFileError& e) {
    EXPECT_NE(std::string(e.what()).find("inside object post"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("mounted_on"), std::string::npos) << e.what();
  }
}

TEST(CellFile, ValidTestCellLoads) {
  const cell::CellModel c = cell::parse_cell(valid_cell().dump(), "good.json", {});
  EXPECT_EQ(c.robots[0].link_radius_m.size(), 6U);
  EXPECT_EQ(c.objects[1].shape.kind, cell::ShapeKind::cylinder);
  EXPECT_DOUBLE_EQ(c.objects[1].pose.p.z, 0.15);
  EXPECT_NEAR(c.robots[1].base.R.n.x, -1.0, 1e-15);  // Paul's roll turns about z
}

TEST(CellFile, BadFilesNameTheKey) {
  const auto robot = [](json& j, std::size_t i) -> json& { return j["robots"][i]; };
  const auto probe = [](json frame) {
    return json{{"name", "probe"},
                {"frame", frame},
                {"from_m", {0, 0, 0}},
                {"to_m", {0, 0, 0.1}},
                {"radius_m", 0.005}};
  };
  const std::vector<BadRow> rows = {
      {[](json& j) { j.erase("robots"); }, "missing \"robots\""},
      {[](json& j) { j["robots"] = json::array(); }, "\"robots\" has 0"},
      {[](json& j) {
         j["robots"] = json::array();
         j["robots"].get_ref<json::array_t&>().resize(1025, 1);
       },
       "\"robots\" has 1025"},
      {[](json& j) { j["robots"] = json::object(); }, "\"robots\" must be a list"},
      {[](json& j) { j["base_period_s"] = 0.007; }, "unknown key \"base_period_s\""},
      {[](json& j) { j["base_period_ms"] = 0.1; }, "\"base_period_ms\" is 0.1"},
      {[](json& j) { j["base_period_ms"] = 57; }, "\"base_period_ms\" is 57"},
      {[](json& j) { j["base_period_ms"] = "7"; }, "\"base_period_ms\" must be a number"},
      {[](json& j) { j.erase("base_period_ms"); }, "missing \"base_period_ms\""},
      {[](json& j) { j["collision_margin_m"] = -0.1; }, "\"collision_margin_m\""},
      {[](json& j) { j["collision_margin_m"] = 2; }, "\"collision_margin_m\""},
      {[](json& j) { j["name"] = "my cell"; }, "\"name\""},
      {[](json& j) { j["title"] = "tab\x01"; }, "\"title\""},
      {[](json& j) {
         j["notes"] = json::array({"fine", 3});
       },
       "\"notes\" must be text"},
      {[](json& j) { j["notes"] = "bell\x07"; }, "\"notes\""},
      {[&](json& j) { robot(j, 1)["period_multiple"] = 0; }, "\"period_multiple\" is 0"},
      {[&](json& j) { robot(j, 1)["period_multiple"] = 1001; }, "\"period_multiple\" is 1001"},
      {[&](json& j) { robot(j, 1)["period_multiple"] = 2.5; },
       "\"period_multiple\" must be a whole"},
      {[&](json& j) { robot(j, 1)["period_multiple"] = -3; }, "\"period_multiple\" is -3"},
      {[&](json& j) { robot(j, 1)["period_multiple"] = 9; },
       "\"period_multiple\" 9 makes its period 63 ms"},
      {[&](json& j) { robot(j, 1)["name"] = "a"; }, "robot names must be unique"},
      {[&](json& j) { robot(j, 0)["name"] = "pu ma"; }, "robot 1: \"name\""},
      {[&](json& j) { robot(j, 0)["robot_file"] = "x.json"; }, "give one of \"robot\""},
      {[&](json& j) { robot(j, 0)["urdf"] = "x.urdf"; }, "give one of \"robot\""},
      {[&](json& j) { robot(j, 0).erase("robot"); }, "give one of \"robot\""},
      {[&](json& j) { robot(j, 0)["tip_link"] = "tool0"; },
       "\"base_link\" and \"tip_link\" choose a URDF's chain: give them with \"urdf\""},
      {[&](json& j) {
         robot(j, 0).erase("robot");
         robot(j, 0)["urdf"] = "r.urdf";
       },
       "\"urdf\" needs the cell to be read from a file"},
      {[&](json& j) { robot(j, 0)["robot"] = "puma600"; }, "\"robot\": no robot named"},
      {[&](json& j) {
         robot(j, 0).erase("robot");
         robot(j, 0)["robot_file"] = "r.json";
       },
       "\"robot_file\" needs the cell to be read from a file"},
      {[&](json& j) { robot(j, 0)["bass"] = 1; }, "unknown key \"bass\""},
      {[&](json& j) { robot(j, 0).erase("base"); }, "missing \"base\""},
      {[&](json& j) {
         robot(j, 0)["base"]["xyz_m"] = {101, 0, 0};
       },
       "\"xyz_m\" [1] is 101"},
      {[&](json& j) {
         robot(j, 0)["base"]["xyz_m"] = {1, 0};
       },
       "\"xyz_m\" must be 3 numbers"},
      {[&](json& j) {
         robot(j, 0)["base"]["xyz_mm"] = {1, 0, 0};
       },
       "unknown key \"xyz_mm\""},
      {[&](json& j) {
         robot(j, 0)["base"]["rpy_deg"] = {400, 0, 0};
       },
       "\"rpy_deg\" [1] is 400"},
      {[&](json& j) {
         robot(j, 0)["base"] = {{"rows_m", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2, 0}}};
       },
       "\"rows_m\": the rotation"},
      {[&](json& j) {
         robot(j, 0)["base"] = {{"rows_m", {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}}};
       },
       "\"rows_m\": the rotation"},  // a mirror
      {[&](json& j) { robot(j, 0)["base"]["rows_m"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}; },
       "not both"},
      {[&](json& j) {
         robot(j, 1)["link_radius_m"] = {0.1, 0.1, 0.1, 0.1, 0.1};
       },
       "\"link_radius_m\" has 5 values"},
      {[&](json& j) { robot(j, 0)["link_radius_m"] = 0; }, "\"link_radius_m\" is 0"},
      {[&](json& j) { robot(j, 0)["link_radius_m"] = -0.1; }, "\"link_radius_m\" is -0.1"},
      {[&](json& j) { robot(j, 0)["link_radius_m"] = 1.5; }, "\"link_radius_m\""},
      {[&](json& j) { robot(j, 0)["link_radius_m"] = "thin"; }, "\"link_radius_m\" must be"},
      {[&](json& j) {
         robot(j, 1)["tool"] = {{"xyz_m", {0, 0, 1e9}}};
       },
       "\"xyz_m\" [3]"},
      {[&](json& j) { robot(j, 1)["note"] = 5; }, "\"note\" must be a string"},
      {[](json& j) { j["objects"][0]["shape"] = "sphere"; }, "\"shape\" is \"sphere\""},
      {[](json& j) {
         j["objects"][0]["size_m"] = {1, -1, 1};
       },
       "\"size_m\" is -1"},
      {[](json& j) {
         j["objects"][0]["size_m"] = {1, 0, 1};
       },
       "\"size_m\" is 0"},
      {[](json& j) { j["objects"][0]["radius_m"] = 1; }, "unknown key \"radius_m\""},
      {[](json& j) { j["objects"][1].erase("height_m"); }, "missing \"height_m\""},
      {[](json& j) { j["objects"][1]["radius_m"] = 0; }, "\"radius_m\" is 0"},
      {[](json& j) { j["objects"][1]["name"] = "table"; }, "object 1's already"},
      {[](json& j) { j["objects"][0]["movable"] = "yes"; }, "\"movable\" must be true or false"},
      {[](json& j) { j["objects"][0]["note"] = "bell\x07"; }, "\"note\""},
      {[](json& j) { j["objects"] = {1}; }, "object 1: expected an object"},
      {[](json& j) { j["frames"][0]["name"] = "post"; }, "object and frame names must be unique"},
      {[](json& j) { j["frames"][0].erase("pose"); }, "missing \"pose\""},
      {[](json& j) {
         j["frames"][0]["pose"]["xyz_m"] = {0, "1", 0};
       },
       "\"xyz_m\" [2] must be a number"},
      {[](json& j) { j["frames"][0]["name"] = std::string(33, 'f'); }, "at most 32"},
      // The collision model's shapes and mounting (issue 30).
      {[&](json& j) { robot(j, 1)["shapes"] = json::object(); }, "\"shapes\" must be a list"},
      {[&](json& j) { robot(j, 1)["shapes"] = {probe(json("t7"))}; }, "\"frame\" must be"},
      {[&](json& j) { robot(j, 1)["shapes"] = {probe(json(7))}; }, "\"frame\" is 7; 1 to 6"},
      {[&](json& j) { robot(j, 1)["shapes"] = {probe(json(0))}; }, "\"frame\" is 0; 1 to 6"},
      {[&](json& j) {
         json p = probe(json("t6"));
         p["radius_m"] = -0.01;
         robot(j, 1)["shapes"] = {p};
       },
       "\"radius_m\" is -0.01"},
      {[&](json& j) {
         json p = probe(json("t6"));
         p["to_m"] = {0, 0};
         robot(j, 1)["shapes"] = {p};
       },
       "\"to_m\" must be 3 numbers"},
      {[&](json& j) {
         json p = probe(json("t6"));
         p["length_m"] = 0.1;
         robot(j, 1)["shapes"] = {p};
       },
       "unknown key \"length_m\""},
      {[&](json& j) {
         robot(j, 1)["shapes"] = {probe(json("t6")), probe(json("base"))};
       },
       "shape names must be unique"},
      {[&](json& j) {
         json p = probe(json("base"));
         p["name"] = "my probe";
         robot(j, 1)["shapes"] = {p};
       },
       "shape 1: \"name\""},
      {[&](json& j) {
         robot(j, 1)["shapes"] = json::array();
         for (int k = 0; k < 17; ++k) {
           json p = probe(json("t6"));
           p["name"] = "p" + std::to_string(k);
           robot(j, 1)["shapes"].push_back(p);
         }
       },
       "at most 16"},
      {[&](json& j) { robot(j, 1)["mounted_on"] = "tabel"; },
       "\"mounted_on\" names no object of the cell: \"tabel\"; its objects: table, post"},
  };
  for (std::size_t i = 0; i < rows.size(); ++i) {
    json j = valid_cell();
    rows[i].change(j);
    try {
      (void)cell::parse_cell(j.dump(), "bad.json", {});
      ADD_FAILURE() << "row " << i + 1 << " was accepted; should say: " << rows[i].says;
    } catch (const cell::CellFileError& e) {
      const std::string message = e.what();
      // The file's name first (then an unknown key's line and column).
      EXPECT_EQ(message.rfind("bad.json:", 0), 0U) << "row " << i + 1 << ": " << message;
      EXPECT_NE(message.find(rows[i].says), std::string::npos)
          << "row " << i + 1 << "\nshould say: " << rows[i].says << "\nsaid: " << message;
    }
  }
}

TEST(CellFile, BadTextIsRefused) {
  for (const std::string text :
       {"", "name = cvarl", "[]", "{\"base_period_ms\": 1e400}", "{\"name\": \"caf\xe9\"}"}) {
    EXPECT_THROW((void)cell::parse_cell(text, "bad.json", {}), cell::CellFileError) << text;
  }
}

TEST(CellFile, RobotFilesAreFoundBesideTheCell) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("rccx-cell-{}", getpid());
  fs::create_directories(dir / "robots");
  std::ofstream(dir / "robots" / "arm.json") << R"({"name": "arm", "title": "t", "source": "s",
    "solver": "dh", "joints": [{"name": "j1", "type": "revolute", "a_m": 0.4, "alpha_deg": 0,
    "lower_deg": -90, "upper_deg": 90, "resolution_deg_per_count": 0.01, "ready_deg": 0,
    "max_velocity_deg_per_s": 90}]})";
  json j = valid_cell();
  j["robots"][0].erase("robot");
  j["robots"][0]["robot_file"] = "robots/arm.json";
  std::ofstream(dir / "cell.json") << j.dump();
  const cell::CellModel c = cell::load_cell_file(dir / "cell.json");
  EXPECT_EQ(c.robots[0].model.name, "arm");
  EXPECT_EQ(c.robots[0].model_file, "robots/arm.json");
  EXPECT_DOUBLE_EQ(cell::reach_m(c.robots[0]), 0.4);
  // A robot file that is not there: the message names the key and the file.
  j["robots"][0]["robot_file"] = "robots/gone.json";
  std::ofstream(dir / "cell.json") << j.dump();
  try {
    (void)cell::load_cell_file(dir / "cell.json");
    ADD_FAILURE() << "a missing robot file was accepted";
  } catch (const cell::CellFileError& e) {
    EXPECT_NE(std::string(e.what()).find("\"robot_file\""), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("gone.json"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)cell::load_cell_file(dir / "none.json"), cell::CellFileError);
  EXPECT_THROW((void)cell::load_cell_file(dir), cell::CellFileError);  // a directory
  fs::remove_all(dir);
}

TEST(CellFile, UrdfRobotsAreFoundBesideTheCellWithTheirChainAndCapsules) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("rccx-cell-urdf-{}", getpid());
  fs::create_directories(dir / "robots");
  // Two links 0.3 m and 0.2 m, a 0.1 m flange past the last joint; the first link has a
  // collision cylinder, and a branch (the "camera") makes the tip a choice.
  std::ofstream(dir / "robots" / "arm.urdf") << R"(<robot name="arm">
    <link name="base"/>
    <link name="l1"><collision><origin xyz="0 0 0.15"/>
      <geometry><cylinder radius="0.04" length="0.3"/></geometry></collision></link>
    <link name="l2"/><link name="flange"/><link name="camera"/>
    <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
      <axis xyz="0 0 1"/><limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
    <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.3"/>
      <axis xyz="0 1 0"/><limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
    <joint name="f" type="fixed"><parent link="l2"/><child link="flange"/><origin xyz="0.2 0 0.1"/></joint>
    <joint name="c" type="fixed"><parent link="l1"/><child link="camera"/><origin xyz="0.05 0 0"/></joint>
  </robot>)";
  json j = valid_cell();
  j["robots"][0].erase("robot");
  j["robots"][0].erase("link_radius_m");
  j["robots"][0].erase("shapes");
  j["robots"][0]["urdf"] = "robots/arm.urdf";
  j["robots"][0]["tip_link"] = "flange";
  std::ofstream(dir / "cell.json") << j.dump();
  const cell::CellModel c = cell::load_cell_file(dir / "cell.json");
  const cell::CellRobot& r = c.robots[0];
  EXPECT_EQ(r.model.geometry, kin::Geometry::chain);
  EXPECT_EQ(r.urdf_file, "robots/arm.urdf");
  ASSERT_EQ(r.model.dof(), 2U);
  EXPECT_TRUE(r.link_radius_m.empty());  // the URDF's capsule stands for the links
  ASSERT_EQ(r.model.collision.capsules.size(), 1U);
  // By hand: 0.3 m to joint 2, then |(0.2, 0, 0.1)| to the flange, plus the tool.
  const double tool = r.tool ? r.tool->p.norm() : 0.0;
  EXPECT_NEAR(cell::reach_m(r), 0.3 + std::hypot(0.2, 0.1) + tool, 1e-15);
  // Bad input: a link not there, a missing file, each named after the robot's place.
  for (const auto& [key, value, says] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {"tip_link", "nope", "no link named 'nope'"},
           {"urdf", "robots/gone.urdf", "gone.urdf"}}) {
    json bad = j;
    bad["robots"][0][key] = value;
    std::ofstream(dir / "cell.json") << bad.dump();
    try {
      (void)cell::load_cell_file(dir / "cell.json");
      ADD_FAILURE() << key << " " << value << " was accepted";
    } catch (const cell::CellFileError& e) {
      EXPECT_NE(std::string(e.what()).find("robot 1: \"urdf\""), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  }
  // Without the tip the tree branches: the reader lists the leaves.
  json branching = j;
  branching["robots"][0].erase("tip_link");
  std::ofstream(dir / "cell.json") << branching.dump();
  try {
    (void)cell::load_cell_file(dir / "cell.json");
    ADD_FAILURE() << "a branching URDF without a tip was accepted";
  } catch (const cell::CellFileError& e) {
    EXPECT_NE(std::string(e.what()).find("camera, flange"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(CellFile, TheShippedUr5eAndPandaCellReads) {
  const cell::CellModel c = cell::load_cell_file(RCCX_CELLS_DIR "/ur5e_panda.json");
  ASSERT_EQ(c.robots.size(), 2U);
  for (const cell::CellRobot& r : c.robots) {
    EXPECT_EQ(r.model.geometry, kin::Geometry::chain) << r.name;
    EXPECT_FALSE(r.model.collision.capsules.empty()) << r.name;
    EXPECT_TRUE(r.model.collision.mesh_links.empty()) << r.name;
  }
  EXPECT_EQ(c.robots[0].model.dof(), 6U);
  EXPECT_EQ(c.robots[1].model.dof(), 7U);
}

// ---- cells built in code, and their geometry ----

kin::Joint joint(kin::JointType type, double a_m, double d_m, double lower, double upper) {
  kin::Joint j;
  j.name = "j";
  j.type = type;
  j.dh.a_m = a_m;
  j.dh.d_m = d_m;
  j.lower = lower;
  j.upper = upper;
  j.resolution_per_count = 1e-4;
  j.ready = 0.5 * (lower + upper);
  j.max_velocity = 1.0;
  return j;
}

/// Two simple arms a metre apart: A, two revolute links (a 0.3, d 0.1; a 0.2): reach
/// 0.3 + 0.1 + 0.2 = 0.6 m. B, a revolute link (a 0.1, d 0.2) and a prismatic joint at d 0.05
/// travelling -0.1 .. 0.3 m (its farthest |d| 0.35), with a tool offset (0.03, 0.04, 0) (0.05):
/// reach 0.1 + 0.2 + 0.35 + 0.05 = 0.7 m.
cell::CellModel two_arms() {
  cell::CellModel c;
  c.name = "two";
  c.base_period = 4ms;
  cell::CellRobot a;
  a.name = "a";
  a.model.name = "arm_a";
  a.model.joints = {joint(kin::JointType::revolute, 0.3, 0.1, -1, 1),
                    joint(kin::JointType::revolute, 0.2, 0.0, -1, 1)};
  a.link_radius_m = {0.05, 0.04};
  cell::CellRobot b;
  b.name = "b";
  b.model.name = "arm_b";
  b.model.joints = {joint(kin::JointType::revolute, -0.1, 0.2, -1, 1),
                    joint(kin::JointType::prismatic, 0.0, 0.05, -0.1, 0.3)};
  b.link_radius_m = {0.05, 0.04};
  b.base = math::Transform::translation(0.6, 0.8, 0.0);  // 1.0 m from A
  b.tool = math::Transform::translation(0.03, 0.04, 0.0);
  b.period_multiple = 2;
  c.robots = {a, b};
  return c;
}

/// The volume common to two spheres (a lens), for checking the sampled estimate.
double lens_volume_m3(double r1, double r2, double d) {
  const double h = r1 + r2 - d;
  return std::numbers::pi * h * h * (d * d + 2 * d * (r1 + r2) - 3 * (r1 - r2) * (r1 - r2)) /
         (12 * d);
}

TEST(CellGeometry, ReachAndOverlapAgreeWithAHandComputation) {
  cell::CellModel c = two_arms();
  EXPECT_NO_THROW(cell::validate(c));
  EXPECT_NEAR(cell::reach_m(c.robots[0]), 0.6, 1e-12);
  EXPECT_NEAR(cell::reach_m(c.robots[1]), 0.7, 1e-12);
  EXPECT_EQ(c.period(1), 8ms);

  const auto overlaps = cell::reach_overlaps(c);
  ASSERT_EQ(overlaps.size(), 1U);
  EXPECT_NEAR(overlaps[0].distance_m, 1.0, 1e-12);
  EXPECT_NEAR(overlaps[0].depth_m, 0.3, 1e-12);
  // The lens: pi 0.3^2 (1 + 2.6 - 3 x 0.01) / 12 = 0.08412 m^3. 20000 samples in the 1.2 m
  // cube hit it with p = 0.049: one standard deviation is 0.0026 m^3.
  const double exact = lens_volume_m3(0.6, 0.7, 1.0);
  EXPECT_NEAR(exact, std::numbers::pi * 0.09 * 3.57 / 12, 1e-12);
  EXPECT_NEAR(overlaps[0].shared_volume_m3, exact, 4 * 0.0026);
  // Deterministic: the same cell gives the same numbers.
  EXPECT_EQ(cell::reach_overlaps(c)[0].shared_volume_m3, overlaps[0].shared_volume_m3);
  EXPECT_NEAR(cell::shared_volume_m3(0.6, 0.7, 1.0, 400000, 7), exact,
              4 * 0.0026 / std::sqrt(20.0));
  // One sphere inside the other: the smaller one's volume.
  EXPECT_NEAR(cell::shared_volume_m3(0.1, 1.0, 0.2, 200000, 1), 4.0 / 3 * std::numbers::pi * 1e-3,
              2e-4);

  // A third arm 2 m away meets neither: depth is the (negative) gap, no volume.
  cell::CellRobot far = c.robots[0];
  far.name = "far";
  far.base = math::Transform::translation(-2.0, 0, 0);
  c.robots.push_back(far);
  const auto three = cell::reach_overlaps(c);
  ASSERT_EQ(three.size(), 3U);
  EXPECT_EQ(three[1].first, 0U);
  EXPECT_EQ(three[1].second, 2U);
  EXPECT_FALSE(three[1].overlaps());
  EXPECT_NEAR(three[1].depth_m, 1.2 - 2.0, 1e-12);
  EXPECT_EQ(three[1].shared_volume_m3, 0.0);
}

TEST(CellGeometry, ValidateRefusesWhatAFileWould) {
  const auto refused = [](const std::function<void(cell::CellModel&)>& change,
                          const std::string& says) {
    cell::CellModel c = two_arms();
    change(c);
    try {
      cell::validate(c, "code");
      ADD_FAILURE() << "accepted; should say " << says;
    } catch (const cell::CellFileError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  refused([](cell::CellModel& c) { c.robots.clear(); }, "\"robots\" has 0");
  refused([](cell::CellModel& c) { c.base_period = 100us; }, "\"base_period_ms\" is 0.1");
  refused([](cell::CellModel& c) { c.robots[1].period_multiple = 20; }, "makes its period 80 ms");
  refused([](cell::CellModel& c) { c.robots[1].name = "a"; }, "unique");
  refused([](cell::CellModel& c) { c.robots[0].link_radius_m.pop_back(); }, "\"link_radius_m\"");
  refused([](cell::CellModel& c) { c.robots[0].base.p.x = std::nan(""); }, "\"base\"");
  refused([](cell::CellModel& c) { c.robots[0].base.R.n = {2, 0, 0}; }, "\"base\": the rotation");
  refused([](cell::CellModel& c) { c.robots[1].tool->R.a = {0, 0, -1}; }, "\"tool\": the rotation");
  refused([](cell::CellModel& c) { c.collision_margin_m = INFINITY; }, "\"collision_margin_m\"");
  refused(
      [](cell::CellModel& c) {
        c.frames.push_back({"x", {}, ""});
        c.objects.push_back({"x", {}, {}, false, ""});
      },
      "\"size_m\" is 0");
  refused(
      [](cell::CellModel& c) {
        c.objects.push_back({"x", {cell::ShapeKind::box, {1, 1, 1}, 0, 0}, {}, false, ""});
        c.frames.push_back({"x", {}, ""});
      },
      "frame 1 \"x\": \"name\" \"x\" is object 1's already");
}

// ---- rccx cell show ----

using CommandRun = rccx::test::ShellRun;

CommandRun run(const std::string& args, bool with_stderr = true) {
  return rccx::test::rccx_run(args, with_stderr);
}

TEST(CellCli, ShowListsBothRobots) {
  const CommandRun r = run("cell show " + kCvarl.string());
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("puma - puma260, period 7 ms"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("microbo - microbo, period 28 ms (x4)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("board_home"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("puma / microbo: bases"), std::string::npos) << r.out;

  const CommandRun j = run("cell show --json " + kCvarl.string(), false);
  ASSERT_EQ(j.exit_code, 0) << j.out;
  const json doc = json::parse(j.out);
  ASSERT_EQ(doc["robots"].size(), 2U);
  EXPECT_EQ(doc["robots"][1]["period_ms"], 28.0);
  EXPECT_EQ(doc["reach_overlaps"][0]["overlap"], true);
}

TEST(CellCli, BadFilesExitWithTwo) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("rccx-cell-cli-{}", getpid());
  fs::create_directories(dir);
  json j = valid_cell();
  j["robots"][1]["period_multiple"] = 0;
  std::ofstream(dir / "bad.json") << j.dump();
  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {"cell show " + (dir / "bad.json").string(), "\"period_multiple\" is 0"},
           {"cell show " + (dir / "none.json").string(), "none.json"},
           {"cell show " + dir.string(), "directory"},
           {"cell show", "file is required"}}) {
    const CommandRun r = run(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.out;
    EXPECT_EQ(r.out.rfind("error: ", 0), 0U) << args << "\n" << r.out;
    EXPECT_NE(r.out.find(says), std::string::npos) << args << "\nshould say " << says << "\n"
                                                   << r.out;
  }
  fs::remove_all(dir);
}

}  // namespace
