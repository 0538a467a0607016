// The newest value from one thread to another without waiting: a triple buffer. The writer
// never blocks; the reader takes the newest value published since it last looked.
//
//   rtc::detail::Latest<math::Transform> latest;
//   latest.publish(t);              // writer thread
//   if (latest.take(t)) use(t);     // reader thread
#pragma once

#include <atomic>
#include <cstdint>

namespace rccx::rtc::detail {

/// A triple buffer: one writer publishes values without waiting, one reader takes the newest.
template <class T>
class Latest {
 public:
  /// Writer: publishes v.
  void publish(const T& v) noexcept {
    buffers_[write_] = v;
    write_ = static_cast<std::uint8_t>(
        middle_.exchange(write_ | kFresh, std::memory_order_acq_rel) & kIndex);
  }
  /// Reader: the newest value into out; false when nothing new was published since last time.
  bool take(T& out) noexcept {
    if ((middle_.load(std::memory_order_acquire) & kFresh) == 0) return false;
    read_ = static_cast<std::uint8_t>(middle_.exchange(read_, std::memory_order_acq_rel) & kIndex);
    out = buffers_[read_];
    return true;
  }

 private:
  static constexpr std::uint8_t kFresh = 4, kIndex = 3;
  T buffers_[3]{};
  std::atomic<std::uint8_t> middle_{1};
  std::uint8_t write_ = 0, read_ = 2;
};

}  // namespace rccx::rtc::detail
