// Wake-up latency of the communication task in real time: how late each tick's thread woke
// after its absolute deadline, in a fixed histogram (1 us bins up to 20 ms) written by the
// communication task without allocating, read by the planning level.
//
//   rtc::Session session(driver, {.period = 1ms, .clock = rtc::ClockKind::real_time});
//   session.control(f1, f2);
//   session.wait_for(10s);
//   const rtc::LatencyStats s = session.latency();   // p99_us, max_us, missed_deadlines
//
// Inside, the communication task calls LatencyHistogram::record(late_ns) every tick.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>

namespace rccx::rtc {

struct LatencyStats {
  std::uint64_t wakeups = 0;  ///< ticks measured
  /// Deadlines missed: the ticks skipped because a wake-up came a period or more late (a stall
  /// of k periods counts k).
  std::uint64_t missed_deadlines = 0;
  /// Wake-ups a period or more late (a stall of k periods counts 1): what cyclictest's
  /// histogram shows as latencies of an interval or more.
  std::uint64_t late_wakeups = 0;
  double p50_us = 0.0, p99_us = 0.0, p999_us = 0.0, max_us = 0.0;
};

class LatencyHistogram {
 public:
  static constexpr std::size_t kBins = 20'000;  ///< 1 us each; the last one takes the rest

  LatencyHistogram();
  /// Communication task: one wake-up `late_ns` after its deadline.
  void record(std::int64_t late_ns) noexcept;
  /// A wake-up so late that `ticks` deadlines passed (one late wake-up).
  void record_missed(std::uint64_t ticks) noexcept;
  void reset() noexcept;
  [[nodiscard]] LatencyStats stats() const;

 private:
  std::unique_ptr<std::array<std::atomic<std::uint32_t>, kBins>> bins_;
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::uint64_t> missed_{0};
  std::atomic<std::uint64_t> late_{0};
  std::atomic<std::int64_t> max_ns_{0};
};

}  // namespace rccx::rtc
