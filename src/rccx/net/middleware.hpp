// What the serve process's and the program's middleware threads share: their identity, their
// priority, and taking samples off a reader. Internal to src/rccx/net (not installed API).
#pragma once

#include <dds/dds.h>

#include <cstdint>
#include <vector>

namespace rccx::net::detail {

/// A random participant instance (never 0): a restarted process is a new instance.
[[nodiscard]] std::uint64_t random_instance();

/// The middleware thread decides that a peer is lost within the detection time, so it runs
/// above ordinary threads when the process may (SCHED_FIFO at the lowest priority, below the
/// control tasks'); otherwise as it is. It sleeps whenever nothing is pending, and each pass
/// does a bounded amount of work, so it cannot starve others.
void raise_priority() noexcept;

[[nodiscard]] inline double ms_of(std::int64_t ns) noexcept {
  return static_cast<double>(ns) * 1e-6;
}

/// Takes up to buf.size() samples of `reader` into `buf` (ptrs and info as large); returns how
/// many were taken (0 on an error), in `info` order (invalid ones: instance state changes).
template <class T>
int take(dds_entity_t reader, std::vector<T>& buf, std::vector<void*>& ptrs,
         std::vector<dds_sample_info_t>& info) {
  for (std::size_t i = 0; i < buf.size(); ++i) ptrs[i] = &buf[i];
  const dds_return_t n = dds_take(reader, ptrs.data(), info.data(), buf.size(),
                                  static_cast<std::uint32_t>(buf.size()));
  return n < 0 ? 0 : static_cast<int>(n);
}

}  // namespace rccx::net::detail
