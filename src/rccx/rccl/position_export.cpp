#include "rccx/rccl/position_export.hpp"

#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <utility>

namespace rccx::rccl {
namespace {

using json = nlohmann::ordered_json;

constexpr std::string_view kVersionKey = "rccx_position_database";
constexpr std::array<std::string_view, 3> kTopKeys = {kVersionKey, "units", "transforms"};
constexpr std::array<std::string_view, 7> kTransformKeys = {
    "robot", "name", "T_rows_m", "configuration", "note", "created_unix_s", "changed_unix_s"};
/// The format is 4 levels deep (object, array, object, array); anything much deeper is not an
/// export, and refusing it early keeps a hostile file from costing memory and stack.
constexpr int kMaxDepth = 16;
constexpr std::size_t kMaxUnits = 1000;

/// "an object", "a string": the JSON type of `j` with its article, for messages.
std::string kind(const json& j) {
  const std::string_view t = j.type_name();
  return fmt::format("{} {}", t == "object" || t == "array" ? "an" : "a", t);
}

/// What the parser callback refuses (a repeated key, too deep); turned into the error below.
struct Refused {
  std::string message;
};

template <class Keys>
std::string key_list(const Keys& keys) {
  std::string out;
  for (const std::string_view k : keys) out += fmt::format("{}{}", out.empty() ? "" : ", ", k);
  return out;
}

template <class Keys>
bool known(const Keys& keys, std::string_view key) {
  for (const std::string_view k : keys) {
    if (k == key) return true;
  }
  return false;
}

/// Parses `text`, refusing repeated keys in an object (the JSON library would keep the last
/// one silently) and nesting deeper than kMaxDepth.
json parse_strict(std::string_view text, std::string_view origin) {
  std::vector<std::set<std::string>> keys;  // one set per open object
  const auto callback = [&](int depth, json::parse_event_t event, json& parsed) {
    if (depth > kMaxDepth) {
      throw Refused{fmt::format("nested more than {} deep; an export is 4 levels deep", kMaxDepth)};
    }
    switch (event) {
      case json::parse_event_t::object_start:
        keys.emplace_back();
        break;
      case json::parse_event_t::object_end:
        if (!keys.empty()) keys.pop_back();
        break;
      case json::parse_event_t::key:
        if (!keys.empty() && !keys.back().insert(parsed.get<std::string>()).second) {
          throw Refused{fmt::format("key {} is given twice in one object; give it once",
                                    io::quoted(parsed.get<std::string>()))};
        }
        break;
      default:
        break;
    }
    return true;
  };
  try {
    return json::parse(text.begin(), text.end(), callback, true, false);
  } catch (const Refused& r) {
    throw PositionExportError(fmt::format("{}: {}", origin, r.message));
  } catch (const json::exception& e) {
    // Syntax errors, invalid UTF-8, a number too large for a double (1e400).
    throw PositionExportError(fmt::format(
        "{}: not JSON ({}); give an export written by `rccx db export`", origin, e.what()));
  }
}

/// The transform at `index` while it is read: errors name it and the key.
class Entry {
 public:
  Entry(const json& j, std::size_t index, std::string_view origin)
      : j_(j), index_(index), origin_(origin) {
    if (j.is_object()) {
      if (const auto n = j.find("name"); n != j.end() && n->is_string()) {
        name_ = n->get<std::string>();
      }
    }
  }

  [[noreturn]] void fail(std::string_view key, std::string_view problem) const {
    const std::string who = name_ ? fmt::format(" ({})", io::quoted(*name_)) : "";
    const std::string k = key.empty() ? "" : fmt::format(", key \"{}\"", key);
    throw PositionExportError(
        fmt::format("{}: transforms[{}]{}{}: {}", origin_, index_, who, k, problem));
  }

  /// The string at `key`; `fallback` when the key is absent and `fallback` is given.
  [[nodiscard]] std::string string(std::string_view key,
                                   const std::optional<std::string>& fallback) const {
    const auto it = j_.find(key);
    if (it == j_.end()) {
      if (fallback) return *fallback;
      fail(key, "missing; every transform has robot, name and T_rows_m");
    }
    if (!it->is_string()) fail(key, fmt::format("{}, not a string", kind(*it)));
    return it->get<std::string>();
  }

  [[nodiscard]] std::int64_t seconds(std::string_view key) const {
    const auto it = j_.find(key);
    if (it == j_.end()) return 0;
    const bool whole = it->is_number_integer();
    const bool fits =
        whole && (it->is_number_unsigned()
                      ? it->get<std::uint64_t>() <=
                            static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())
                      : it->get<std::int64_t>() >= 0);
    if (!fits) {
      fail(key, fmt::format("{} is not a time; give whole seconds since 1970, 0 or more",
                            it->dump(-1, ' ', false, json::error_handler_t::replace)));
    }
    return it->get<std::int64_t>();
  }

  [[nodiscard]] math::Transform rows() const {
    const auto it = j_.find("T_rows_m");
    if (it == j_.end()) fail("T_rows_m", "missing; give the 12 numbers of the transform");
    if (!it->is_array()) fail("T_rows_m", fmt::format("{}, not an array", kind(*it)));
    if (it->size() != 12) {
      fail("T_rows_m", fmt::format("{} numbers; give exactly 12 (r11,r12,r13,px,r21,...,r33,pz; m)",
                                   it->size()));
    }
    std::array<double, 12> v{};
    for (std::size_t i = 0; i < 12; ++i) {
      const json& e = (*it)[i];
      if (!e.is_number()) {
        fail("T_rows_m", fmt::format("element {} is {}, not a number", i, kind(e)));
      }
      v[i] = e.get<double>();
    }
    return math::Transform::from_rows(v);
  }

  /// Runs a check of PositionDb, naming the transform in its error.
  template <class F>
  void check(std::string_view key, F&& f) const {
    try {
      f();
    } catch (const DatabaseError& e) {
      // The check names the transform too: once is enough.
      std::string_view m = e.what();
      const std::string prefix = fmt::format("transform {}: ", io::quoted(name_.value_or("")));
      if (m.substr(0, prefix.size()) == prefix) m.remove_prefix(prefix.size());
      fail(key, m);
    }
  }

 private:
  const json& j_;
  std::size_t index_;
  std::string_view origin_;
  std::optional<std::string> name_;
};

StoredTransform read_transform(const json& j, std::size_t index, std::string_view origin) {
  const Entry e(j, index, origin);
  if (!j.is_object()) {
    e.fail("", fmt::format("{}, not an object with robot, name and T_rows_m", kind(j)));
  }
  for (const auto& [key, value] : j.items()) {
    if (!known(kTransformKeys, key)) {
      e.fail(key,
             fmt::format("not a key of a transform; the keys are {}", key_list(kTransformKeys)));
    }
  }
  StoredTransform t;
  t.robot = e.string("robot", std::nullopt);
  e.check("robot", [&] { PositionDb::check_robot_name(t.robot); });
  t.name = e.string("name", std::nullopt);
  e.check("name", [&] { PositionDb::check_name(t.name); });
  t.value = e.rows();
  t.configuration = e.string("configuration", std::string());
  t.note = e.string("note", std::string());
  t.created_unix_s = e.seconds("created_unix_s");
  t.changed_unix_s = e.seconds("changed_unix_s");
  e.check("", [&] { PositionDb::check(t); });  // configuration, note, rigid
  return t;
}

json to_json(const StoredTransform& t) {
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

/// Pretty-printed; bytes that are not UTF-8 (a row written by another program) become U+FFFD
/// instead of an exception.
std::string dump(const json& j) {
  return j.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
}

}  // namespace

std::vector<StoredTransform> parse_position_export(std::string_view json_text,
                                                   std::string_view origin) {
  const json j = parse_strict(json_text, origin);
  if (!j.is_object()) {
    throw PositionExportError(fmt::format(
        "{}: {}, not an rccx position export (an object with \"{}\" and \"transforms\")", origin,
        kind(j), kVersionKey));
  }
  for (const auto& [key, value] : j.items()) {
    if (!known(kTopKeys, key)) {
      throw PositionExportError(fmt::format("{}: key {} is not one of an export; the keys are {}",
                                            origin, io::quoted(key), key_list(kTopKeys)));
    }
  }
  const auto version = j.find(kVersionKey);
  if (version == j.end()) {
    throw PositionExportError(fmt::format(
        "{}: not an rccx position export (no \"{}\" key); give a file written by `rccx db "
        "export`",
        origin, kVersionKey));
  }
  const std::string shown = version->dump(-1, ' ', false, json::error_handler_t::replace);
  if (version->is_number_unsigned() &&
      version->get<std::uint64_t>() > static_cast<std::uint64_t>(PositionDb::kSchemaVersion)) {
    throw PositionExportError(fmt::format(
        "{}: \"{}\" is {}: written by a newer rccx (this one reads version {}); use a newer "
        "rccx",
        origin, kVersionKey, io::quoted(shown), PositionDb::kSchemaVersion));
  }
  if (!version->is_number_integer() || version->get<std::int64_t>() != PositionDb::kSchemaVersion) {
    throw PositionExportError(
        fmt::format("{}: \"{}\" is {}, not a version this rccx reads; give {}", origin, kVersionKey,
                    io::quoted(shown), PositionDb::kSchemaVersion));
  }
  if (const auto units = j.find("units"); units != j.end()) {
    if (!units->is_string()) {
      throw PositionExportError(
          fmt::format("{}: \"units\" is {}, not a string", origin, kind(*units)));
    }
    try {
      io::check_text(units->get<std::string>(), fmt::format("{}: \"units\"", origin), kMaxUnits);
    } catch (const io::ParseError& e) {
      throw PositionExportError(e.what());
    }
  }
  const auto list = j.find("transforms");
  if (list == j.end() || !list->is_array()) {
    throw PositionExportError(
        fmt::format("{}: \"transforms\" is {}; give an array of transforms (it may be empty: [])",
                    origin, list == j.end() ? "missing" : kind(*list)));
  }
  std::vector<StoredTransform> out;
  out.reserve(list->size());
  std::map<std::pair<std::string, std::string>, std::size_t> seen;  // (robot, name) -> index
  for (std::size_t i = 0; i < list->size(); ++i) {
    out.push_back(read_transform((*list)[i], i, origin));
    const StoredTransform& t = out.back();
    if (const auto [it, added] = seen.emplace(std::pair(t.robot, t.name), i); !added) {
      throw PositionExportError(
          fmt::format("{}: transforms[{}] ({}) of robot {} is also transforms[{}]; give each "
                      "(robot, name) once",
                      origin, i, io::quoted(t.name), io::quoted(t.robot), it->second));
    }
  }
  return out;
}

std::string position_export_json(const std::vector<StoredTransform>& all) {
  json j;
  j[std::string(kVersionKey)] = PositionDb::kSchemaVersion;
  j["units"] = "m, rad; T_rows_m: the top three rows of the 4x4 transform, row by row";
  j["transforms"] = json::array();
  for (const StoredTransform& t : all) j["transforms"].push_back(to_json(t));
  return dump(j);
}

std::string position_json(const StoredTransform& t) {
  return dump(to_json(t));
}

}  // namespace rccx::rccl
