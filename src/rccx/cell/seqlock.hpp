// A value one thread writes and any thread reads without a lock (a sequence lock): the writer
// makes a counter odd, writes, makes it even; a reader copies and retries when the counter was
// odd or changed meanwhile. Neither side blocks or allocates; the writer never waits. What the
// cell uses to hand one robot's tool frame, written by the control task each sample, to another
// robot's trajectory generator (same thread) and to the planning level (move()); and what the
// network layer's middleware thread uses to hand a remote robot's newest state to the control
// task.
//
//   cell::SeqLock<math::Transform> tool;             // any trivially copyable value
//   tool.store(T6);                                  // the one writer, every sample
//   math::Transform seen;
//   if (tool.load(seen)) ...                         // any thread; false before the first store
//
// Two buffers, written in turn, and a count of finished stores: a reader copies the buffer of
// the last finished store, which the writer does not touch before it has finished the next one.
// So a reader never waits for a writer that was preempted in the middle of a store (a
// middleware thread at a low real-time priority, under the control task that reads): it reads
// the value before. It retries only when the writer finished a whole store and began the next
// on the same buffer meanwhile, i.e. while the writer runs. A reader never sees an older value
// after a newer one.
//
// The value is kept in atomic words so that the racing copy is defined behaviour (and
// ThreadSanitizer sees no race); release stores and acquire loads of the words order them
// against the counters (plain moves on x86; fences would do as well, but ThreadSanitizer does
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
    Buffer& b = begin_store();
    write_words(b, value);
    finish_store(b);
  }

  /// Reader (any thread): the last value stored; false (out untouched) before the first store.
  bool load(T& out) const noexcept {
    std::array<std::uint64_t, kWords> w{};
    for (;;) {
      const std::uint64_t n = stores_.load(std::memory_order_acquire);
      if (n == 0) return false;
      const Buffer& b = buffers_[n & 1U];
      // Store n itself, finished, and nothing else: a buffer lapped by store n + 2 (under way,
      // or finished before stores_ says so) is read again from stores_, so that a reader never
      // takes a value it could later see an older one after.
      const std::uint64_t s0 = b.seq.load(std::memory_order_acquire);
      if (s0 != 2 * n) continue;
      // Acquire: the words before the re-check.
      for (std::size_t i = 0; i < kWords; ++i) w[i] = b.words[i].load(std::memory_order_acquire);
      if (b.seq.load(std::memory_order_relaxed) != s0) continue;
      std::memcpy(static_cast<void*>(&out), w.data(), sizeof(T));
      return true;
    }
  }

 private:
  friend struct SeqLockProbe;  // tests: a store begun and not finished (a preempted writer)
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;
  struct Buffer {
    std::atomic<std::uint64_t> seq{0};  ///< 2k - 1 while store k is written, 2k when finished
    std::array<std::atomic<std::uint64_t>, kWords> words{};
  };

  /// The buffer the next store (k) writes, not the one readers are sent to, marked 2k - 1.
  Buffer& begin_store() noexcept {
    const std::uint64_t k = stores_.load(std::memory_order_relaxed) + 1;
    Buffer& b = buffers_[k & 1U];
    b.seq.store(2 * k - 1, std::memory_order_relaxed);
    return b;
  }
  static void write_words(Buffer& b, const T& value) noexcept {
    std::array<std::uint64_t, kWords> w{};
    std::memcpy(w.data(), &value, sizeof(T));
    // Release: odd before any word.
    for (std::size_t i = 0; i < kWords; ++i) b.words[i].store(w[i], std::memory_order_release);
  }
  void finish_store(Buffer& b) noexcept {
    b.seq.store(b.seq.load(std::memory_order_relaxed) + 1, std::memory_order_release);  // 2k
    // Release: the buffer's words and seq before readers are sent to it.
    stores_.store(stores_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  }

  std::atomic<std::uint64_t> stores_{0};  ///< finished stores; the last is in buffers_[n & 1]
  std::array<Buffer, 2> buffers_{};
};

}  // namespace rccx::cell
