// Text into a fixed buffer, never allocating or throwing: what the sample loop uses for the
// messages it leaves behind (a stop's reason, a failed motion's why, a limit's details).
//
//   std::array<char, 96> why{};
//   io::format_fixed(why, "joint {} at {:.3f} rad", 2, q);   // cut at 95 characters, NUL ended
//   io::copy_fixed(why, some_view);
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>
#include <string_view>
#include <utility>

#include <fmt/format.h>

namespace rccx::io {

/// Copies `text` into `to`, cut to N - 1 characters and NUL-terminated; returns what was kept.
template <std::size_t N>
std::string_view copy_fixed(std::array<char, N>& to, std::string_view text) noexcept {
  static_assert(N > 0);
  const std::size_t n = std::min(text.size(), N - 1);
  if (n > 0) std::memcpy(to.data(), text.data(), n);  // an empty view may hold no pointer
  to[n] = '\0';
  return {to.data(), n};
}

/// Formats into `to`, cut to N - 1 characters and NUL-terminated; returns what was written.
/// fmt allocates nothing when formatting numbers and strings into a bounded output; should a
/// formatter throw all the same, the text is left empty (a message matters less than the stop
/// it reports).
template <std::size_t N, class... Args>
std::string_view format_fixed(std::array<char, N>& to, fmt::format_string<Args...> f,
                              Args&&... args) noexcept {
  static_assert(N > 0);
  try {
    const auto r = fmt::format_to_n(to.data(), N - 1, f, std::forward<Args>(args)...);
    const std::size_t n = std::min(r.size, N - 1);
    to[n] = '\0';
    return {to.data(), n};
  } catch (...) {
    to[0] = '\0';
    return {};
  }
}

}  // namespace rccx::io
