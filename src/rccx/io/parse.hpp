// Strict reading of what people type and files hold: numbers, durations, joint numbers, lists,
// names and text. One reader for every input path (command-line options, console lines, files,
// the environment), so that every path refuses the same things with the same words:
//
//   - the whole token or nothing: "5abc", "5 ", "" and "0x10" are not numbers;
//   - finite: "inf", "nan" and "1e400" (overflow) are refused;
//   - in range, and the message gives the range with its unit;
//   - text is UTF-8 without control characters (a NUL would cut it in C and SQLite).
//
// Every error is a ParseError whose message reads `WHAT: "TEXT" PROBLEM; WHAT TO DO`.
//
//   const double v = io::parse_number(text, "v: the speed", {1e-3, 250.0, "deg/s"});
//   const std::chrono::nanoseconds p =                   // "28ms", "250us", or "0.028" (s)
//       io::parse_duration(text, "--period", io::BareUnit::seconds, 250us, 56ms);
//   const std::size_t j = io::parse_joint(text, "j: the joint", model.dof());   // "2" -> 1
//   io::check_name(name, "--name", 32);                  // letters, digits, _ - .
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace rccx::io {

/// Bad input: the message names what was read, quotes it and says what is expected.
class ParseError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A closed range of accepted values and the unit it is given in ("s", "deg", "" for none).
struct Range {
  double lo = std::numeric_limits<double>::lowest();
  double hi = std::numeric_limits<double>::max();
  std::string_view unit;
};

/// A finite decimal number ("12", "-0.5", "+3", "1e-3"), the whole of `text`, within `range`.
/// `what` names it in the error ("--seconds", "teach m: the value").
double parse_number(std::string_view text, std::string_view what, Range range = {});

/// A whole number in [lo, hi] (no fraction, no exponent, no hex).
std::int64_t parse_integer(std::string_view text, std::string_view what, std::int64_t lo,
                           std::int64_t hi);

/// A joint number 1 .. dof, returned as an index 0 .. dof - 1.
std::size_t parse_joint(std::string_view text, std::string_view what, std::size_t dof);

/// The unit a bare number of a duration is taken in.
enum class BareUnit : std::uint8_t { seconds, milliseconds };

/// A duration: a number and an optional unit, ns, us, ms, s or min ("2", "2s", "28ms", "250us",
/// "1.5min"); a bare number is in `bare` (every command-line option: seconds, the SI unit).
/// Refused outside [lo, hi]; the message says how a bare number was read.
std::chrono::nanoseconds parse_duration(std::string_view text, std::string_view what, BareUnit bare,
                                        std::chrono::nanoseconds lo, std::chrono::nanoseconds hi);

/// A duration in seconds as a double (see parse_duration), within [lo_s, hi_s].
double parse_seconds(std::string_view text, std::string_view what, double lo_s, double hi_s);

/// Comma-separated numbers ("1,0,0.5"); `count` of them unless it is 0 (any number, at least
/// one). Each as parse_number.
std::vector<double> parse_number_list(std::string_view text, std::string_view what,
                                      std::size_t count = 0, Range range = {});

/// True when `text` is well-formed UTF-8 (no overlong forms, no surrogates).
bool is_utf8(std::string_view text) noexcept;

/// Text for a note or a description: UTF-8, at most `max_bytes`, no control characters but
/// tab. Throws ParseError saying which rule failed.
void check_text(std::string_view text, std::string_view what, std::size_t max_bytes);

/// A name (of a transform, robot, frame): 1 .. max_chars of ASCII letters, digits and _ - .
void check_name(std::string_view text, std::string_view what, std::size_t max_chars);

/// The words of a console line (split at blanks, tabs and a carriage return); views into `line`.
std::vector<std::string_view> words_of(std::string_view line);

/// Throws ParseError unless `words` (a command and its arguments, at least the command) has
/// exactly `count` of them; the message names the command and shows `usage`.
void expect_words(const std::vector<std::string_view>& words, std::size_t count,
                  std::string_view usage);

/// `text` quoted for an error message: non-printable bytes as \xNN, cut after 40 characters.
std::string quoted(std::string_view text);

/// A number as people read it in a range message: 56 rather than 56.000000.
std::string shown(double value);

}  // namespace rccx::io
