// The waits between RTC's tasks: "doorbells", 32-bit counters that a waker bumps after changing
// what a sleeper watches. A sleeper spins briefly (the other task usually answers within
// microseconds, and a futex wake-up costs tens of them on a virtual machine), then sleeps on
// the futex until rung or until an absolute deadline on the monotonic clock. Ringing makes the
// wake system call only when somebody sleeps. No mutex anywhere; sleepers re-check their
// condition after every return.
#pragma once

#include <atomic>
#include <cstdint>

namespace rccx::rtc::detail {

/// Monotonic clock, ns.
std::int64_t monotonic_ns() noexcept;

struct Doorbell {
  std::atomic<std::uint32_t> rings{0};
  std::atomic<std::uint32_t> sleepers{0};
  [[nodiscard]] std::uint32_t load() const noexcept {
    return rings.load(std::memory_order_seq_cst);
  }
};

/// How long a waiter spins before it sleeps, ns: longer than a hand-over between two running
/// tasks, far shorter than a sample period. Bounded by time, not by a count of `pause`s: a
/// pause takes 10 to 140 cycles by processor (18 ns on the 2-core VM of docs/PERFORMANCE.md,
/// where 4,000 of them held a core at real-time priority for 74 us at every hand-over, and
/// the network threads beside the control tasks waited for it).
inline constexpr std::int64_t kSpinNs = 20'000;

/// Waits while the bell still shows `seen` (from bell.load() before checking the condition),
/// until rung or `deadline_ns` (monotonic; <= 0: no deadline), spinning for up to `spin_ns`
/// before sleeping. Spurious returns are allowed.
void wait_while(Doorbell& bell, std::uint32_t seen, std::int64_t deadline_ns = 0,
                std::int64_t spin_ns = kSpinNs) noexcept;

/// Rings the bell: wakes everyone waiting on it.
void ring(Doorbell& bell) noexcept;

/// Sleeps until the absolute monotonic time `deadline_ns`.
void sleep_until(std::int64_t deadline_ns) noexcept;

/// a is at or after b, for sample numbers that may wrap at 2^32.
constexpr bool reached(std::uint32_t a, std::uint32_t b) noexcept {
  return static_cast<std::int32_t>(a - b) >= 0;
}

}  // namespace rccx::rtc::detail
