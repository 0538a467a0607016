// Output that never throws and never hides a failure: error messages go to stderr with one
// write(2) each (a closed or full stderr is ignored, as nothing else can be done), and
// standard output is checked once at the end (a full disk or a closed pipe changes the exit
// code).
//
//   io::eprint("{}: cannot read {}\n", program, file);   // one write(2), never throws
//   fmt::print("{} samples\n", n);                        // stdout as usual, then at the end:
//   if (std::string why; !io::flush_stdout(why)) return 1;   // something was lost: why says
#pragma once

#include <fmt/format.h>

#include <string_view>

namespace rccx::io {

/// Writes `text` to stderr; never throws, retries EINTR, ignores a failing stderr.
void error_text(std::string_view text) noexcept;

/// fmt-formatted error_text.
template <typename... Args>
void eprint(fmt::format_string<Args...> format, Args&&... args) noexcept {
  try {
    error_text(fmt::format(format, std::forward<Args>(args)...));
  } catch (...) {  // formatting can only fail for lack of memory: say nothing rather than abort
  }
}

/// Flushes stdout; false (with errno's reason in `why`) when anything written to it was lost.
bool flush_stdout(std::string& why) noexcept;

}  // namespace rccx::io
