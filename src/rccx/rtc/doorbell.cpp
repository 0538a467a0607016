#include "rccx/rtc/doorbell.hpp"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <ctime>

namespace rccx::rtc::detail {

namespace {
timespec to_timespec(std::int64_t ns) noexcept {
  return {static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
}
// std::atomic<uint32_t> is a plain 32-bit word: the futex may sleep on it, as libstdc++'s own
// atomic wait does.
std::uint32_t* word_of(const std::atomic<std::uint32_t>& a) noexcept {
  static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t));
  return const_cast<std::uint32_t*>(reinterpret_cast<const std::uint32_t*>(&a));
}
}  // namespace

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

namespace {
inline void cpu_relax() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}
}  // namespace

void wait_while(Doorbell& bell, std::uint32_t seen, std::int64_t deadline_ns,
                std::int64_t spin_ns) noexcept {
  if (spin_ns > 0) {
    const std::int64_t until = monotonic_ns() + spin_ns;
    do {
      // A look at the clock (vDSO, tens of ns) every few pauses.
      for (int i = 0; i < 16; ++i) {
        if (bell.rings.load(std::memory_order_acquire) != seen) return;
        cpu_relax();
      }
    } while (monotonic_ns() < until);
  }
  // Counted as a sleeper before the last look, so that a ring after that look sees us
  // (both sides sequentially consistent).
  bell.sleepers.fetch_add(1, std::memory_order_seq_cst);
  if (bell.rings.load(std::memory_order_seq_cst) == seen) {
    if (deadline_ns > 0) {
      const timespec ts = to_timespec(deadline_ns);
      // FUTEX_WAIT_BITSET takes an absolute CLOCK_MONOTONIC deadline.
      syscall(SYS_futex, word_of(bell.rings), FUTEX_WAIT_BITSET | FUTEX_PRIVATE_FLAG, seen, &ts,
              nullptr, FUTEX_BITSET_MATCH_ANY);
    } else {
      syscall(SYS_futex, word_of(bell.rings), FUTEX_WAIT | FUTEX_PRIVATE_FLAG, seen, nullptr,
              nullptr, 0);
    }
  }
  bell.sleepers.fetch_sub(1, std::memory_order_seq_cst);
}

void ring(Doorbell& bell) noexcept {
  bell.rings.fetch_add(1, std::memory_order_seq_cst);
  if (bell.sleepers.load(std::memory_order_seq_cst) != 0) {
    syscall(SYS_futex, word_of(bell.rings), FUTEX_WAKE | FUTEX_PRIVATE_FLAG, INT_MAX, nullptr,
            nullptr, 0);
  }
}

void sleep_until(std::int64_t deadline_ns) noexcept {
  const timespec ts = to_timespec(deadline_ns);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace rccx::rtc::detail
