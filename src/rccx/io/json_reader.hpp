// One strict reader for the JSON objects of rccx's files (robot files, their RCU section, cell
// files): key by key, so that every error names where it is ("cvarl: robot 2: \"base\": ..."),
// and so that an unknown key (a typo such as "upper_mm") is refused instead of silently ignored,
// naming the known key nearest it ("unknown key \"robts\"; did you mean \"robots\"?"), also
// when the typo leaves a required key missing ("missing \"robots\" (unknown key \"robts\": did
// you mean \"robots\"?)").
// Errors are thrown as `Error` (each file kind has its own exception type), built from one
// string. Header-only: the file readers include nlohmann/json themselves.
//
//   io::JsonObjectReader<kin::RobotFileError> r(joint_json, "puma560: joint 2");
//   const std::string name = r.name("name");         // printable, at most 32 bytes
//   const double a_m = r.number("a_m", 100.0);       // finite, |a_m| <= 100
//   const double d_m = r.number_or("d_m", 0.0, 100.0);   // optional, 0 when missing
//   r.no_unknown_keys();                             // "puma560: joint 2: unknown key ..."
#pragma once

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>

#include "rccx/io/parse.hpp"
#include "rccx/io/spelling.hpp"

namespace rccx::io {

template <class Error>
class JsonObjectReader {
 public:
  using json = nlohmann::json;

  /// `default_limit`: the largest magnitude number(key) accepts. Every key has a unit: beyond a
  /// million of it a value is a typo, and would overflow the solvers' arithmetic.
  JsonObjectReader(const json& object, std::string where, double default_limit = 1e6)
      : object_(object), where_(std::move(where)), default_limit_(default_limit) {
    if (!object_.is_object()) fail("expected an object");
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(fmt::format("{}: {}", where_, what));
  }

  bool has(const std::string& key) {
    used_.insert(key);
    return object_.contains(key);
  }

  const json& get(const std::string& key) {
    if (!has(key)) {
      // A required key missing is most often a misspelt one: name that, not only the absence.
      for (const auto& item : object_.items()) {
        if (!used_.contains(item.key()) && !nearest_word(item.key(), std::array{key}).empty()) {
          fail(fmt::format("missing \"{}\" (unknown key \"{}\": did you mean \"{}\"?)", key,
                           item.key(), key));
        }
      }
      fail(fmt::format("missing \"{}\"", key));
    }
    return object_.at(key);
  }

  std::string string(const std::string& key) {
    const json& v = get(key);
    if (!v.is_string()) fail(fmt::format("\"{}\" must be a string", key));
    return v.get<std::string>();
  }
  std::string string_or(const std::string& key) { return has(key) ? string(key) : std::string(); }
  /// A name: UTF-8, printable, at most `max_bytes`.
  std::string name(const std::string& key, std::size_t max_bytes = 32) {
    return checked(key, [&](const std::string& s, const std::string& what) {
      check_name(s, what, max_bytes);
    });
  }
  /// Free text for people: UTF-8, at most `max_bytes`.
  std::string text(const std::string& key, std::size_t max_bytes = 4096) {
    return checked(key, [&](const std::string& s, const std::string& what) {
      check_text(s, what, max_bytes);
    });
  }

  /// A finite number no larger than `limit` in magnitude; `what` names it in errors.
  double number(const json& v, const std::string& what, double limit) const {
    if (!v.is_number()) fail(fmt::format("{} must be a number", what));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(fmt::format("{} must be finite", what));
    if (std::abs(d) > limit) {
      fail(fmt::format("{} is {:g}; at most {:g} in magnitude", what, d, limit));
    }
    return d;
  }
  double number(const std::string& key, double limit) {
    return number(get(key), fmt::format("\"{}\"", key), limit);
  }
  double number(const std::string& key) { return number(key, default_limit_); }
  double number_or(const std::string& key, double fallback) {
    return has(key) ? number(key) : fallback;
  }
  double number_or(const std::string& key, double fallback, double limit) {
    return has(key) ? number(key, limit) : fallback;
  }
  double positive(const std::string& key) {
    const double d = number(key);
    if (!(d > 0)) fail(fmt::format("\"{}\" must be > 0", key));
    return d;
  }
  double non_negative_or(const std::string& key, double fallback) {
    const double d = number_or(key, fallback);
    if (d < 0) fail(fmt::format("\"{}\" must not be negative", key));
    return d;
  }
  /// N numbers, each as number().
  template <std::size_t N>
  std::array<double, N> numbers(const std::string& key, double limit) {
    const json& v = get(key);
    if (!v.is_array() || v.size() != N) fail(fmt::format("\"{}\" must be {} numbers", key, N));
    std::array<double, N> out{};
    for (std::size_t i = 0; i < N; ++i) {
      out[i] = number(v[i], fmt::format("\"{}\" [{}]", key, i + 1), limit);
    }
    return out;
  }

  /// A whole number in [lo, hi] (also beyond int64 on the unsigned side: refused, not wrapped).
  std::int64_t integer(const std::string& key, std::int64_t lo, std::int64_t hi) {
    const json& v = get(key);
    if (!v.is_number_integer()) fail(fmt::format("\"{}\" must be a whole number", key));
    const bool fits = v.is_number_unsigned()
                          ? v.get<std::uint64_t>() <= static_cast<std::uint64_t>(hi) &&
                                static_cast<std::int64_t>(v.get<std::uint64_t>()) >= lo
                          : v.get<std::int64_t>() >= lo && v.get<std::int64_t>() <= hi;
    if (!fits) fail(fmt::format("\"{}\" is {}; {} to {}", key, v.dump(), lo, hi));
    return v.is_number_unsigned() ? static_cast<std::int64_t>(v.get<std::uint64_t>())
                                  : v.get<std::int64_t>();
  }
  std::int64_t integer_or(const std::string& key, std::int64_t lo, std::int64_t hi,
                          std::int64_t fallback) {
    return has(key) ? integer(key, lo, hi) : fallback;
  }

  bool boolean(const std::string& key) {
    const json& v = get(key);
    if (!v.is_boolean()) fail(fmt::format("\"{}\" must be true or false", key));
    return v.get<bool>();
  }

  /// Refuses a key no read asked for, naming the nearest asked-for key, else every one.
  void no_unknown_keys() const {
    for (const auto& item : object_.items()) {
      if (used_.contains(item.key())) continue;
      const std::string near = nearest_word(item.key(), used_);
      fail(near.empty()
               ? fmt::format("unknown key \"{}\"; the keys here are {}", item.key(),
                             fmt::join(used_, ", "))
               : fmt::format("unknown key \"{}\"; did you mean \"{}\"?", item.key(), near));
    }
  }

  [[nodiscard]] const std::string& where() const { return where_; }

 private:
  template <class Check>
  std::string checked(const std::string& key, Check check) {
    const std::string s = string(key);
    try {
      check(s, fmt::format("\"{}\"", key));
    } catch (const ParseError& e) {
      fail(e.what());
    }
    return s;
  }

  const json& object_;
  std::string where_;
  double default_limit_;
  std::set<std::string> used_;
};

}  // namespace rccx::io
