// cell::SeqLock: readers never see a torn value while a writer stores as fast as it can, and a
// reader is never held up by a writer stopped in the middle of a store (a middleware thread at
// a low real-time priority preempted by the control task that reads): it gets the value before.
#include "rccx/cell/seqlock.hpp"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

namespace rccx::cell {

/// A store begun and not finished, as a preempted writer leaves it.
struct SeqLockProbe {
  template <class T>
  static void begin_and_write(SeqLock<T>& lock, const T& value) {
    auto& b = lock.begin_store();
    SeqLock<T>::write_words(b, value);
  }
  template <class T>
  static void finish(SeqLock<T>& lock) {
    lock.finish_store(lock.buffers_[(lock.stores_.load() + 1) & 1U]);
  }
};

namespace {

/// Nine words that must all hold the same number: any mix of two stores shows.
struct Words {
  std::array<std::uint64_t, 9> w{};
  [[nodiscard]] bool consistent() const {
    for (const std::uint64_t x : w) {
      if (x != w[0]) return false;
    }
    return true;
  }
};

Words filled(std::uint64_t v) {
  Words x;
  x.w.fill(v);
  return x;
}

TEST(SeqLock, FalseBeforeTheFirstStoreThenTheLastValue) {
  SeqLock<Words> lock;
  Words out = filled(7);
  EXPECT_FALSE(lock.load(out));
  EXPECT_EQ(out.w[0], 7U);  // untouched
  for (std::uint64_t v = 1; v <= 5; ++v) {
    lock.store(filled(v));
    ASSERT_TRUE(lock.load(out));
    EXPECT_EQ(out.w[0], v);
    EXPECT_TRUE(out.consistent());
  }
}

TEST(SeqLock, AReaderGetsThePreviousValueWhileAStoreIsUnfinished) {
  SeqLock<Words> lock;
  lock.store(filled(1));
  lock.store(filled(2));
  SeqLockProbe::begin_and_write(lock, filled(3));  // the writer stops here
  // From another thread, bounded: a reader that waited for the writer would never return.
  std::atomic<int> state{0};  // 0 running, 1 got 2, -1 other
  std::thread reader([&] {
    Words out;
    state = lock.load(out) && out.consistent() && out.w[0] == 2 ? 1 : -1;
  });
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (state.load() == 0 && std::chrono::steady_clock::now() < until) std::this_thread::yield();
  if (state.load() == 0) {
    SeqLockProbe::finish(lock);  // lets the reader go, so that the test ends
    reader.join();
    FAIL() << "a reader waited for the unfinished store";
  }
  reader.join();
  EXPECT_EQ(state.load(), 1);
  SeqLockProbe::finish(lock);  // the writer runs again
  Words out;
  ASSERT_TRUE(lock.load(out));
  EXPECT_EQ(out.w[0], 3U);
  EXPECT_TRUE(out.consistent());
}

TEST(SeqLock, ReadersNeverSeeATornValueUnderAWriterStoringFlatOut) {
  SeqLock<Words> lock;
  lock.store(filled(1));
  std::atomic<bool> stop{false};
  std::atomic<long> torn{0}, backwards{0}, reads{0};
  std::vector<std::thread> readers;
  for (int r = 0; r < 2; ++r) {
    readers.emplace_back([&] {
      std::uint64_t last = 0;
      while (!stop.load(std::memory_order_relaxed)) {
        Words out;
        if (!lock.load(out)) continue;
        if (!out.consistent()) ++torn;
        if (out.w[0] < last) ++backwards;  // a reader never goes back to an older store
        last = out.w[0];
        ++reads;
      }
    });
  }
  for (std::uint64_t v = 2; v < 300'000; ++v) lock.store(filled(v));
  stop = true;
  for (std::thread& t : readers) t.join();
  EXPECT_EQ(torn.load(), 0);
  EXPECT_EQ(backwards.load(), 0);
  EXPECT_GT(reads.load(), 0);
}

}  // namespace
}  // namespace rccx::cell
