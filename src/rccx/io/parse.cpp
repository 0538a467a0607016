#include "rccx/io/parse.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <system_error>

namespace rccx::io {

namespace {

std::string range_text(double lo, double hi, std::string_view unit) {
  const std::string u = unit.empty() ? "" : fmt::format(" {}", unit);
  if (lo == std::numeric_limits<double>::lowest()) return fmt::format("at most {}{}", shown(hi), u);
  if (hi == std::numeric_limits<double>::max()) return fmt::format("at least {}{}", shown(lo), u);
  return fmt::format("from {} to {}{}", shown(lo), shown(hi), u);
}

/// The number at the start of `text`; `used` is how many characters it took (0: none).
double leading_number(std::string_view text, std::size_t& used, bool& overflow) {
  overflow = false;
  used = 0;
  const std::size_t start = !text.empty() && text[0] == '+' ? 1 : 0;  // from_chars takes no '+'
  const std::string_view body = text.substr(start);
  // Only digits, a point and an exponent: from_chars would also take "inf" and "nan".
  const std::size_t first = start == 0 && !body.empty() && body[0] == '-' ? 1 : 0;
  if (first >= body.size() ||
      !(std::isdigit(static_cast<unsigned char>(body[first])) || body[first] == '.')) {
    return 0;
  }
  double value = 0;
  const auto [end, ec] =
      std::from_chars(body.data(), body.data() + body.size(), value, std::chars_format::general);
  if (end == body.data()) return 0;
  if (ec == std::errc::result_out_of_range) {
    // from_chars leaves `value` alone here: strtod tells overflow (refused) from underflow (0).
    const std::string token(body.data(), end);
    value = std::strtod(token.c_str(), nullptr);
    overflow = std::isinf(value);
  }
  used = start + static_cast<std::size_t>(end - body.data());
  return value;
}

}  // namespace

std::string quoted(std::string_view text) {
  std::string out = "\"";
  std::size_t shown_chars = 0;
  for (const char c : text) {
    if (++shown_chars > 40) {
      out += "...";
      break;
    }
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u >= 0x7f || c == '"' || c == '\\') {
      out += (c == '"' || c == '\\') ? fmt::format("\\{}", c) : fmt::format("\\x{:02x}", u);
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string shown(double value) {
  return fmt::format("{:g}", value);
}

double parse_number(std::string_view text, std::string_view what, Range range) {
  std::size_t used = 0;
  bool overflow = false;
  const double value = leading_number(text, used, overflow);
  if (text.empty()) throw ParseError(fmt::format("{}: a number is missing", what));
  if (used == 0 || used != text.size()) {
    throw ParseError(fmt::format("{}: {} is not a number; write digits, e.g. 12, -0.5 or 1e-3",
                                 what, quoted(text)));
  }
  if (overflow || !std::isfinite(value)) {
    throw ParseError(fmt::format("{}: {} is too large; give a number {}", what, quoted(text),
                                 range_text(range.lo, range.hi, range.unit)));
  }
  if (value < range.lo || value > range.hi) {
    throw ParseError(fmt::format("{}: {} is out of range; give a number {}", what, quoted(text),
                                 range_text(range.lo, range.hi, range.unit)));
  }
  return value;
}

std::int64_t parse_integer(std::string_view text, std::string_view what, std::int64_t lo,
                           std::int64_t hi) {
  if (text.empty()) throw ParseError(fmt::format("{}: a whole number is missing", what));
  std::string_view digits = text;
  if (digits[0] == '+') digits.remove_prefix(1);
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  const bool whole = !digits.empty() && end == digits.data() + digits.size() &&
                     (std::isdigit(static_cast<unsigned char>(digits[0])) || digits[0] == '-');
  if (!whole && ec != std::errc::result_out_of_range) {
    throw ParseError(fmt::format("{}: {} is not a whole number; give one from {} to {}", what,
                                 quoted(text), lo, hi));
  }
  if (ec == std::errc::result_out_of_range || value < lo || value > hi) {
    throw ParseError(fmt::format("{}: {} is out of range; give a whole number from {} to {}", what,
                                 quoted(text), lo, hi));
  }
  return value;
}

std::size_t parse_joint(std::string_view text, std::string_view what, std::size_t dof) {
  if (text.empty()) throw ParseError(fmt::format("{}: a joint number is missing", what));
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() ||
      !std::isdigit(static_cast<unsigned char>(text[0])) || value < 1 ||
      value > static_cast<std::int64_t>(dof)) {
    throw ParseError(fmt::format("{}: {} is not a joint of this robot; its joints are 1 to {}",
                                 what, quoted(text), dof));
  }
  return static_cast<std::size_t>(value - 1);
}

namespace {

/// Seconds per unit of a duration's unit ("s", "ms", ...), 0 for no unit known.
double seconds_per(std::string_view unit) {
  if (unit == "s") return 1.0;
  if (unit == "ms") return 1e-3;
  if (unit == "us") return 1e-6;
  if (unit == "ns") return 1e-9;
  if (unit == "min") return 60.0;
  return 0;
}

}  // namespace

std::chrono::nanoseconds parse_duration(std::string_view text, std::string_view what, BareUnit bare,
                                        std::chrono::nanoseconds lo, std::chrono::nanoseconds hi) {
  if (text.empty()) throw ParseError(fmt::format("{}: a duration is missing", what));
  std::size_t used = 0;
  bool overflow = false;
  const double value = leading_number(text, used, overflow);
  const std::string_view unit = used == 0 ? std::string_view{} : text.substr(used);
  const double scale = unit.empty() ? (bare == BareUnit::seconds ? 1.0 : 1e-3) : seconds_per(unit);
  const auto lo_s = std::chrono::duration<double>(lo).count();
  const auto hi_s = std::chrono::duration<double>(hi).count();
  const std::string range = lo_s >= 1.0 || hi_s >= 100.0 ? range_text(lo_s, hi_s, "s")
                                                         : range_text(lo_s * 1e3, hi_s * 1e3, "ms");
  const char* bare_is = bare == BareUnit::seconds ? "seconds" : "milliseconds";
  if (used == 0 || scale == 0) {
    throw ParseError(fmt::format(
        "{}: {} is not a duration; write a number with ns, us, ms, s or min (e.g. 2s, 28ms, "
        "250us); a bare number is {}",
        what, quoted(text), bare_is));
  }
  const double seconds = value * scale;
  if (overflow || !std::isfinite(seconds) || seconds < lo_s || seconds > hi_s) {
    // "--period 28" meant as ms is 28 s: say how a bare number is read, and the way out.
    std::string hint;
    if (unit.empty() && value > 0 && std::isfinite(value) && bare == BareUnit::seconds &&
        hi_s < 1.0) {
      hint = fmt::format(" (a bare number is seconds; for milliseconds write {}ms)", text);
    } else if (unit.empty()) {
      hint = fmt::format(" (a bare number is {})", bare_is);
    }
    throw ParseError(fmt::format("{}: {} is out of range; give a duration {}{}", what, quoted(text),
                                 range, hint));
  }
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::duration<double>(seconds));
}

double parse_seconds(std::string_view text, std::string_view what, double lo_s, double hi_s) {
  using std::chrono::duration;
  using std::chrono::nanoseconds;
  const auto lo = std::chrono::duration_cast<nanoseconds>(duration<double>(lo_s));
  const auto hi = std::chrono::duration_cast<nanoseconds>(duration<double>(hi_s));
  return duration<double>(parse_duration(text, what, BareUnit::seconds, lo, hi)).count();
}

std::vector<double> parse_number_list(std::string_view text, std::string_view what,
                                      std::size_t count, Range range) {
  std::vector<double> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    const std::string_view item = text.substr(start, comma - start);
    out.push_back(parse_number(item, fmt::format("{} (number {})", what, out.size() + 1), range));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (count != 0 && out.size() != count) {
    throw ParseError(
        fmt::format("{}: {} numbers given, {} needed (comma-separated)", what, out.size(), count));
  }
  return out;
}

bool is_utf8(std::string_view text) noexcept {
  std::size_t i = 0;
  const std::size_t n = text.size();
  while (i < n) {
    const auto c = static_cast<unsigned char>(text[i]);
    std::size_t len = 0;
    std::uint32_t cp = 0;
    if (c < 0x80) {
      ++i;
      continue;
    }
    if ((c & 0xE0) == 0xC0) {
      len = 2;
      cp = c & 0x1Fu;
    } else if ((c & 0xF0) == 0xE0) {
      len = 3;
      cp = c & 0x0Fu;
    } else if ((c & 0xF8) == 0xF0) {
      len = 4;
      cp = c & 0x07u;
    } else {
      return false;
    }
    if (i + len > n) return false;
    for (std::size_t k = 1; k < len; ++k) {
      const auto cc = static_cast<unsigned char>(text[i + k]);
      if ((cc & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (cc & 0x3Fu);
    }
    const std::uint32_t min = len == 2 ? 0x80 : len == 3 ? 0x800 : 0x10000;
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += len;
  }
  return true;
}

void check_text(std::string_view text, std::string_view what, std::size_t max_bytes) {
  if (text.size() > max_bytes) {
    throw ParseError(
        fmt::format("{}: {} bytes; at most {} are kept", what, text.size(), max_bytes));
  }
  if (!is_utf8(text)) {
    throw ParseError(
        fmt::format("{}: {} is not UTF-8 text; write it in UTF-8", what, quoted(text)));
  }
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\t') || u == 0x7f) {
      throw ParseError(fmt::format("{}: {} has a control character (\\x{:02x}); use printable text",
                                   what, quoted(text), u));
    }
  }
}

void check_name(std::string_view text, std::string_view what, std::size_t max_chars) {
  if (text.empty()) throw ParseError(fmt::format("{}: a name is missing", what));
  if (text.size() > max_chars) {
    throw ParseError(fmt::format("{}: {} has {} characters; at most {}", what, quoted(text),
                                 text.size(), max_chars));
  }
  for (const char c : text) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.') ||
        static_cast<unsigned char>(c) >= 0x80) {
      throw ParseError(
          fmt::format("{}: {} is not a name; use letters, digits and _ - . only (no spaces)", what,
                      quoted(text)));
    }
  }
}

std::vector<std::string_view> words_of(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t at = 0;
  while (at < line.size()) {
    const std::size_t begin = line.find_first_not_of(" \t\r", at);
    if (begin == std::string_view::npos) break;
    const std::size_t stop = std::min(line.find_first_of(" \t\r", begin), line.size());
    words.push_back(line.substr(begin, stop - begin));
    at = stop;
  }
  return words;
}

void expect_words(const std::vector<std::string_view>& words, std::size_t count,
                  std::string_view usage) {
  if (words.size() < count) {
    throw ParseError(fmt::format("{}: {} missing; write {}", words[0],
                                 count - words.size() == 1 ? "a value is" : "values are", usage));
  }
  if (words.size() > count) {
    throw ParseError(fmt::format("{}: {} is one word too many; write {}", words[0],
                                 quoted(words[count]), usage));
  }
}

}  // namespace rccx::io
