#include "rccx/rtc/latency.hpp"

#include <algorithm>

namespace rccx::rtc {

LatencyHistogram::LatencyHistogram()
    : bins_(std::make_unique<std::array<std::atomic<std::uint32_t>, kBins>>()) {
  reset();
}

void LatencyHistogram::record(std::int64_t late_ns) noexcept {
  const std::int64_t ns = std::max<std::int64_t>(late_ns, 0);
  const auto bin = std::min<std::size_t>(static_cast<std::size_t>(ns / 1000), kBins - 1);
  (*bins_)[bin].fetch_add(1, std::memory_order_relaxed);
  count_.fetch_add(1, std::memory_order_relaxed);
  if (ns > max_ns_.load(std::memory_order_relaxed)) max_ns_.store(ns, std::memory_order_relaxed);
}

void LatencyHistogram::record_missed(std::uint64_t ticks) noexcept {
  missed_.fetch_add(ticks, std::memory_order_relaxed);
  late_.fetch_add(1, std::memory_order_relaxed);
}

void LatencyHistogram::reset() noexcept {
  for (auto& b : *bins_) b.store(0, std::memory_order_relaxed);
  count_.store(0);
  missed_.store(0);
  late_.store(0);
  max_ns_.store(0);
}

LatencyStats LatencyHistogram::stats() const {
  LatencyStats s;
  s.wakeups = count_.load(std::memory_order_relaxed);
  s.missed_deadlines = missed_.load(std::memory_order_relaxed);
  s.late_wakeups = late_.load(std::memory_order_relaxed);
  s.max_us = static_cast<double>(max_ns_.load(std::memory_order_relaxed)) / 1000.0;
  if (s.wakeups == 0) return s;
  // Percentiles at the upper edge of their bin: never reported better than measured.
  const auto at = [&](double fraction) {
    const auto wanted = static_cast<std::uint64_t>(fraction * static_cast<double>(s.wakeups));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBins; ++i) {
      seen += (*bins_)[i].load(std::memory_order_relaxed);
      if (seen > wanted) return std::min(static_cast<double>(i + 1), s.max_us);
    }
    return s.max_us;
  };
  s.p50_us = at(0.50);
  s.p99_us = at(0.99);
  s.p999_us = at(0.999);
  return s;
}

}  // namespace rccx::rtc
