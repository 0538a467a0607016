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

/// Room for up to `capacity` samples of T (its Cyclone type `type`) taken off a reader, made
/// once: Cyclone deserializes in place, and a sequence's buffer it allocates for the first
/// sample that fills it is reused by later takes (freed with the inbox), so takes allocate
/// nothing once each slot has seen its longest sample.
template <class T>
class Inbox {
 public:
  Inbox(const dds_topic_descriptor_t& type, std::size_t capacity)
      : type_(&type), buf_(capacity), ptrs_(capacity), info_(capacity) {
    for (std::size_t i = 0; i < capacity; ++i) ptrs_[i] = &buf_[i];
  }
  ~Inbox() {
    for (T& s : buf_) dds_sample_free(&s, type_, DDS_FREE_CONTENTS);
  }
  Inbox(const Inbox&) = delete;
  Inbox& operator=(const Inbox&) = delete;
  /// Takes up to capacity() samples of `reader`: how many (0 on an error), in info() order
  /// (invalid ones: instance state changes). Fewer than capacity(): the reader is empty.
  int take(dds_entity_t reader) {
    const dds_return_t n = dds_take(reader, ptrs_.data(), info_.data(), buf_.size(),
                                    static_cast<std::uint32_t>(buf_.size()));
    return n < 0 ? 0 : static_cast<int>(n);
  }
  [[nodiscard]] int capacity() const noexcept { return static_cast<int>(buf_.size()); }
  [[nodiscard]] const T& operator[](int i) const { return buf_[static_cast<std::size_t>(i)]; }
  [[nodiscard]] bool valid(int i) const { return info_[static_cast<std::size_t>(i)].valid_data; }

 private:
  const dds_topic_descriptor_t* type_;
  std::vector<T> buf_;
  std::vector<void*> ptrs_;
  std::vector<dds_sample_info_t> info_;
};

}  // namespace rccx::net::detail
