// A value one thread writes and any thread reads without a lock (a sequence lock): the writer
// makes the counter odd, writes, makes it even; a reader copies and retries when the counter
// was odd or changed meanwhile. Neither side blocks or allocates; the writer never waits. What
// the cell uses to hand one robot's tool frame, written by the control task each sample, to
// another robot's trajectory generator (same thread) and to the planning level (move()).
//
//   cell::SeqLock<math::Transform> tool;             // any trivially copyable value
//   tool.store(T6);                                  // the one writer, every sample
//   math::Transform seen;
//   if (tool.load(seen)) ...                         // any thread; false before the first store
//
// The value is kept in atomic words so that the racing copy is defined behaviour (and
// ThreadSanitizer sees no race); release stores and acquire loads of the words order them
// against the counter (plain moves on x86; fences would do as well, but ThreadSanitizer does
// not model them).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace rccx::cell {

template <class T>
class SeqLock {
  static_assert(std::is_trivially_copyable_v<T>, "the value is copied word by word");

 public:
  /// Writer (one thread only).
  void store(const T& value) noexcept {
    std::array<std::uint64_t, kWords> w{};
    std::memcpy(w.data(), &value, sizeof(T));
    const std::uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);
    // Release: odd before any word.
    for (std::size_t i = 0; i < kWords; ++i) words_[i].store(w[i], std::memory_order_release);
    seq_.store(s + 2, std::memory_order_release);  // every word before even
  }

  /// Reader (any thread): the last value stored; false (out untouched) before the first store.
  bool load(T& out) const noexcept {
    std::array<std::uint64_t, kWords> w{};
    for (;;) {
      const std::uint64_t s0 = seq_.load(std::memory_order_acquire);
      if ((s0 & 1U) != 0) continue;  // a store is under way: it takes a few ns
      // Acquire: the words before the re-check.
      for (std::size_t i = 0; i < kWords; ++i) w[i] = words_[i].load(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) != s0) continue;
      if (s0 == 0) return false;
      std::memcpy(static_cast<void*>(&out), w.data(), sizeof(T));
      return true;
    }
  }

 private:
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;
  std::atomic<std::uint64_t> seq_{0};
  std::array<std::atomic<std::uint64_t>, kWords> words_{};
};

}  // namespace rccx::cell
