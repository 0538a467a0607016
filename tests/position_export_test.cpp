// The position export format (rccx db export / import): an exact round trip, and every way a
// file can differ from the format refused with PositionExportError naming the transform and
// the key, never another exception.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "rccx/math/units.hpp"
#include "rccx/rccl/position_export.hpp"

namespace {

using namespace rccx;
using namespace rccx::math::literals;
using rccl::PositionExportError;
using rccl::StoredTransform;

StoredTransform sample(const std::string& robot, const std::string& name, double x) {
  StoredTransform t;
  t.robot = robot;
  t.name = name;
  t.value = {math::Rot3::rot_x(180_deg) * math::Rot3::rot_z(0.3), {x, -0.15, 0.3}};
  t.configuration = "n";
  t.note = "über dem Tisch";
  t.created_unix_s = 1700000000;
  t.changed_unix_s = 1700000100;
  return t;
}

constexpr const char* kRows = "[1,0,0,0.1, 0,1,0,0.2, 0,0,1,0.3]";

/// An export with `transforms` as the text of its array.
std::string export_with(const std::string& transforms) {
  return std::string(R"({"rccx_position_database": 1, "units": "m, rad", "transforms": )") +
         transforms + "}";
}

std::string one(const std::string& extra, const std::string& rows = kRows) {
  return export_with(R"([{"robot": "microbo", "name": "PICK", "T_rows_m": )" + rows + extra + "}]");
}

TEST(PositionExport, RoundTripsExactly) {
  const std::vector<StoredTransform> all = {sample("microbo", "PICK", 0.325),
                                            sample("puma560", "PLACE", 0.1 + 0.2)};
  const std::string text = rccl::position_export_json(all);
  const auto back = rccl::parse_position_export(text, "t.json");
  ASSERT_EQ(back.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back[i].robot, all[i].robot);
    EXPECT_EQ(back[i].name, all[i].name);
    EXPECT_EQ(back[i].value.rows(), all[i].value.rows());  // bit for bit
    EXPECT_EQ(back[i].configuration, all[i].configuration);
    EXPECT_EQ(back[i].note, all[i].note);
    EXPECT_EQ(back[i].created_unix_s, all[i].created_unix_s);
    EXPECT_EQ(back[i].changed_unix_s, all[i].changed_unix_s);
  }
  EXPECT_EQ(rccl::position_export_json(back), text);
  // The optional keys may be left out; an empty list is an export too.
  EXPECT_EQ(rccl::parse_position_export(one(""), "t.json").at(0).note, "");
  EXPECT_TRUE(rccl::parse_position_export(export_with("[]"), "t.json").empty());
  EXPECT_TRUE(rccl::parse_position_export(R"({"rccx_position_database": 1, "transforms": []})", "t")
                  .empty());
}

struct Bad {
  std::string text;
  std::string expected;  // in the message
};

TEST(PositionExport, EveryDepartureFromTheFormatIsRefusedByName) {
  const std::vector<Bad> cases = {
      {"", "not JSON"},
      {"{", "not JSON"},
      {"[]", "not an rccx position export"},
      {"null", "not an rccx position export"},
      {R"({"transforms": []})", "no \"rccx_position_database\""},
      {R"({"rccx_position_database": 99, "transforms": []})", "written by a newer rccx"},
      {R"({"rccx_position_database": 0, "transforms": []})", "not a version this rccx reads"},
      {R"({"rccx_position_database": -1, "transforms": []})", "not a version"},
      {R"({"rccx_position_database": 1.0, "transforms": []})", "not a version"},
      {R"({"rccx_position_database": "1", "transforms": []})", "not a version"},
      {R"({"rccx_position_database": 1e400, "transforms": []})", "not JSON"},
      {R"({"rccx_position_database": 1, "transforms": null})", "\"transforms\" is a null"},
      {R"({"rccx_position_database": 1, "transforms": {}})", "\"transforms\" is an object"},
      {R"({"rccx_position_database": 1})", "\"transforms\" is missing"},
      {R"({"rccx_position_database": 1, "transforms": [], "extra": 1})", "\"extra\""},
      {R"({"rccx_position_database": 1, "units": 5, "transforms": []})", "\"units\""},
      {R"({"rccx_position_database": 1, "rccx_position_database": 1, "transforms": []})",
       "given twice"},
      {export_with("[null]"), "transforms[0]: a null, not an object"},
      {export_with("[5]"), "transforms[0]"},
      {one("", "[1,0,0,0.1, 0,1,0,0.2, 0,0,1,0.3, 7]"), "13 numbers; give exactly 12"},
      {one("", "[1,0,0,0.1, 0,1,0,0.2, 0,0,1]"), "11 numbers"},
      {one("", "[1,0,0,0.1, 0,1,0,0.2, 0,0,1,1e400]"), "not JSON"},
      {one("", "[1,0,0,0.1, 0,1,0,0.2, 0,0,1,\"0.3\"]"), "element 11 is a string"},
      {one("", "[1,0,0,0.1, 0,1,0,0.2, 0,0,1,null]"), "element 11 is a null"},
      {one("", "null"), "key \"T_rows_m\": a null"},
      {one("", "[1,0,0,0.1, 0,1,0,0.2, 0,0,2,0.3]"), "rigid"},
      {one("", "[1,0,0,0.1, 0,1,0,1e308, 0,0,1,0.3]"), "beyond 100 m"},
      {one(R"(, "colour": "red")"), "transforms[0] (\"PICK\"), key \"colour\": not a key"},
      {one(R"(, "note": "a\u0000b")"), "control character"},
      {one(R"(, "note": "a\nb")"), "control character"},
      {one(R"(, "note": 5)"), "key \"note\": a number, not a string"},
      {one(", \"note\": \"caf\xe9\""), "not JSON"},  // raw Latin-1 byte
      {one(R"(, "note": ")" + std::string(1001, 'n') + "\""), "at most 1000"},
      {one(R"(, "configuration": "l1n")"), "configuration"},
      {one(R"(, "created_unix_s": -5)"), "key \"created_unix_s\""},
      {one(R"(, "changed_unix_s": 1.5)"), "key \"changed_unix_s\""},
      {one(R"(, "changed_unix_s": 18446744073709551615)"), "key \"changed_unix_s\""},
      {one(R"(, "note": "a", "note": "b")"), "\"note\" is given twice"},
      {export_with(R"([{"robot": "microbo", "T_rows_m": [1,0,0,0,0,1,0,0,0,0,1,0]}])"),
       "key \"name\": missing"},
      {export_with(R"([{"robot": "microbo", "name": "TWO WORDS", "T_rows_m": )" +
                   std::string(kRows) + "}]"),
       "key \"name\""},
      {export_with(R"([{"robot": "", "name": "P", "T_rows_m": )" + std::string(kRows) + "}]"),
       "key \"robot\""},
      {export_with(R"([{"robot": "microbo", "name": "", "T_rows_m": )" + std::string(kRows) + "}]"),
       "empty"},
      {export_with(R"([{"robot": "microbo", "name": "P", "T_rows_m": )" + std::string(kRows) +
                   R"(}, {"robot": "microbo", "name": "P", "T_rows_m": )" + std::string(kRows) +
                   "}]"),
       "transforms[1] (\"P\") of robot \"microbo\" is also transforms[0]"},
      {std::string(100000, '[') + std::string(100000, ']'), "nested more than"},
  };
  for (const Bad& c : cases) {
    std::string message;
    try {
      (void)rccl::parse_position_export(c.text, "in.json");
      message = "(accepted)";
    } catch (const PositionExportError& e) {
      message = e.what();
    }
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "input: " << c.text.substr(0, 200) << "\nexpected: " << c.expected
        << "\nmessage:  " << message;
    EXPECT_EQ(message.rfind("in.json", 0), 0u) << message;  // names the origin first
  }
}

}  // namespace
