#include "rccx/rccl/motion_sync.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace rccx::rccl {

// --- MotionLedger --------------------------------------------------------------------------------

void MotionLedger::set_robot(std::string_view robot) noexcept {
  const std::size_t n = std::min(robot.size(), kName - 1);
  std::copy_n(robot.data(), n, name_.data());
  name_[n] = '\0';
}

void MotionLedger::mark_started(std::uint64_t id) noexcept {
  if (id <= started_.load(std::memory_order_relaxed)) return;
  started_.store(id, std::memory_order_release);
  bump();
}

void MotionLedger::mark_ended(std::uint64_t id) noexcept {
  if (id <= ended_.load(std::memory_order_relaxed)) return;
  ended_.store(id, std::memory_order_release);
  bump();
}

void MotionLedger::mark_failed(std::uint64_t from, std::uint64_t to) noexcept {
  const std::uint32_t k = failures_.load(std::memory_order_relaxed);
  // The range first, then the count that makes it visible.
  failed_from_[k % kFailures].store(from, std::memory_order_relaxed);
  failed_to_[k % kFailures].store(std::max(from, to), std::memory_order_relaxed);
  failures_.store(k + 1, std::memory_order_release);
  if (to > started_.load(std::memory_order_relaxed)) started_.store(to, std::memory_order_release);
  if (to > ended_.load(std::memory_order_relaxed)) ended_.store(to, std::memory_order_release);
  bump();
}

void MotionLedger::set_control_ended(bool ended) noexcept {
  if (control_ended_.exchange(ended, std::memory_order_acq_rel) == ended) return;
  bump();
}

bool MotionLedger::copy_from(const MotionLedger& live) noexcept {
  const std::uint64_t v = live.version();
  if (v == copied_version_) return false;
  copied_version_ = v;
  const std::uint32_t n = live.failures_.load(std::memory_order_acquire);
  const std::uint32_t first = n > kFailures ? n - static_cast<std::uint32_t>(kFailures) : 0U;
  for (std::uint32_t k = first; k < n; ++k) {
    failed_from_[k % kFailures].store(live.failed_from_[k % kFailures].load(),
                                      std::memory_order_relaxed);
    failed_to_[k % kFailures].store(live.failed_to_[k % kFailures].load(),
                                    std::memory_order_relaxed);
  }
  failures_.store(n, std::memory_order_release);
  started_.store(live.started_upto(), std::memory_order_release);
  ended_.store(live.ended_upto(), std::memory_order_release);
  // A copy's own "control ended" (set by its owner) is kept.
  if (live.control_ended()) control_ended_.store(true, std::memory_order_release);
  bump();
  return true;
}

void MotionLedger::clear() noexcept {
  started_.store(0, std::memory_order_release);
  ended_.store(0, std::memory_order_release);
  failures_.store(0, std::memory_order_release);
  control_ended_.store(false, std::memory_order_release);
  bump();
}

bool MotionLedger::failed(std::uint64_t id) const noexcept {
  const std::uint32_t n = failures_.load(std::memory_order_acquire);
  const std::uint32_t first = n > kFailures ? n - static_cast<std::uint32_t>(kFailures) : 0U;
  for (std::uint32_t k = n; k > first; --k) {
    const std::size_t i = (k - 1) % kFailures;
    if (id >= failed_from_[i].load(std::memory_order_relaxed) &&
        id <= failed_to_[i].load(std::memory_order_relaxed)) {
      return true;
    }
  }
  return false;
}

std::size_t MotionLedger::newest_failures(std::uint64_t* from, std::uint64_t* to,
                                          std::size_t n) const noexcept {
  const std::uint32_t count = failures_.load(std::memory_order_acquire);
  std::size_t written = 0;
  for (std::uint32_t k = count; k > 0 && written < n && written < kFailures; --k, ++written) {
    const std::size_t i = (k - 1) % kFailures;
    from[written] = failed_from_[i].load(std::memory_order_relaxed);
    to[written] = failed_to_[i].load(std::memory_order_relaxed);
  }
  for (std::size_t i = written; i < n; ++i) from[i] = to[i] = 0;
  return written;
}

GateAnswer MotionLedger::has_started(std::uint64_t id) const noexcept {
  if (id == 0) return GateAnswer::yes;  // nothing to wait for
  if (failed(id)) return GateAnswer::never;
  if (started_upto() >= id) return GateAnswer::yes;
  return control_ended() ? GateAnswer::never : GateAnswer::not_yet;
}

GateAnswer MotionLedger::has_ended(std::uint64_t id) const noexcept {
  if (id == 0) return GateAnswer::yes;
  if (failed(id)) return GateAnswer::never;
  if (ended_upto() >= id) return GateAnswer::yes;
  return control_ended() ? GateAnswer::never : GateAnswer::not_yet;
}

// --- Rendezvous ----------------------------------------------------------------------------------

Rendezvous::Rendezvous(std::size_t participants, bool end_together,
                       std::vector<const MotionLedger*> ledgers)
    : n_(participants), end_together_(end_together), ledgers_(std::move(ledgers)) {
  if (participants < 1 || participants > kMaxParticipants) {
    throw std::invalid_argument("a rendezvous takes 1 to 64 participants");
  }
  if (!ledgers_.empty() && ledgers_.size() != participants) {
    throw std::invalid_argument("a rendezvous needs one ledger per participant, or none");
  }
  for (std::size_t i = 0; i < kMaxParticipants; ++i) {
    duration_[i].store(-1.0, std::memory_order_relaxed);
    now_ns_[i].store(0, std::memory_order_relaxed);
    period_ns_[i].store(0, std::memory_order_relaxed);
  }
}

void Rendezvous::ready(std::size_t slot, double now_s, double duration_s,
                       double period_s) noexcept {
  if (slot >= n_ || start_s() >= 0.0 || broken_.load(std::memory_order_acquire)) return;
  now_ns_[slot].store(std::llround(now_s * 1e9), std::memory_order_relaxed);
  period_ns_[slot].store(std::max<std::int64_t>(1, std::llround(period_s * 1e9)),
                         std::memory_order_relaxed);
  duration_[slot].store(std::max(duration_s, 0.0), std::memory_order_release);
  std::int64_t latest_ns = 0, widest_ns = 1, common_ns = 1;
  double longest_s = 0.0;
  for (std::size_t i = 0; i < n_; ++i) {
    const double d = duration_[i].load(std::memory_order_acquire);
    if (d < 0.0) return;  // someone is not ready yet
    longest_s = std::max(longest_s, d);
    const std::int64_t p = period_ns_[i].load(std::memory_order_relaxed);
    latest_ns = std::max(latest_ns, now_ns_[i].load(std::memory_order_relaxed));
    widest_ns = std::max(widest_ns, p);
    common_ns = std::lcm(common_ns, p);
  }
  // The first sample after the latest "ready" at which every participant is sampled: each is
  // sampled at its own now + multiples of its period (a cell's robots share their first tick).
  std::int64_t widest_now = 0;
  for (std::size_t i = 0; i < n_; ++i) {
    if (period_ns_[i].load(std::memory_order_relaxed) == widest_ns) {
      widest_now = now_ns_[i].load(std::memory_order_relaxed);
      break;
    }
  }
  std::int64_t start_ns = widest_now + widest_ns;
  while (start_ns <= latest_ns) start_ns += widest_ns;
  const auto shared = [&](std::int64_t t) {
    for (std::size_t i = 0; i < n_; ++i) {
      const std::int64_t p = period_ns_[i].load(std::memory_order_relaxed);
      if ((t - now_ns_[i].load(std::memory_order_relaxed)) % p != 0) return false;
    }
    return true;
  };
  for (std::int64_t tries = common_ns / widest_ns + 1; tries > 0 && !shared(start_ns); --tries) {
    start_ns += widest_ns;
  }
  // Ending in one sample: a duration every participant's samples fall on.
  const double common_s = static_cast<double>(common_ns) * 1e-9;
  duration_s_.store(end_together_ ? std::ceil(longest_s / common_s - 1e-9) * common_s : 0.0,
                    std::memory_order_release);
  double expected = -1.0;
  start_s_.compare_exchange_strong(expected, static_cast<double>(start_ns) * 1e-9,
                                   std::memory_order_acq_rel);
}

void Rendezvous::withdraw(std::string_view why) noexcept {
  if (start_s() >= 0.0 || broken_.exchange(true, std::memory_order_acq_rel)) return;
  const std::size_t n = std::min(why.size(), why_.size() - 1);
  std::copy_n(why.data(), n, why_.data());
  why_[n] = '\0';
  why_set_.store(true, std::memory_order_release);
}

std::string_view Rendezvous::withdrawn() const noexcept {
  if (!why_set_.load(std::memory_order_acquire)) {
    return broken_.load(std::memory_order_acquire) ? std::string_view("a participant withdrew")
                                                   : std::string_view();
  }
  return {why_.data()};
}

const MotionLedger* Rendezvous::lost_participant() const noexcept {
  if (start_s() >= 0.0) return nullptr;
  for (const MotionLedger* l : ledgers_) {
    if (l != nullptr && l->control_ended()) return l;
  }
  return nullptr;
}

std::size_t Rendezvous::slot_of(const MotionLedger* ledger) const noexcept {
  for (std::size_t i = 0; i < ledgers_.size(); ++i) {
    if (ledgers_[i] == ledger) return i;
  }
  return n_;
}

}  // namespace rccx::rccl
