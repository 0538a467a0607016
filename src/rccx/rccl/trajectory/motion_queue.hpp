// What goes in and out of the sample loop: the lock-free queue of requests from the planning
// level, the request taken from it and not yet built (waiting: behind its gates or its
// rendezvous), the one joined to the running segment (put back by a nextmove) and a request put
// back in front of the queue; the events out, and the path reports. Single producer, single
// consumer each way; nothing here allocates, locks or throws.
//
//   MotionQueue queue(ledger);
//   queue.submit(request);                       // planning level
//   queue.take();                                // loop: the next request, when none waits
//   if (const MotionRequest* w = queue.waiting()) { Text why{}; queue.gate_state(why); }
//   queue.emit(EventKind::started, id, ctx);     // loop: events out
//   while (auto e = queue.next_event()) { ... }  // planning level
#pragma once

#include <array>
#include <boost/lockfree/spsc_queue.hpp>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "rccx/rccl/motion_sync.hpp"
#include "rccx/rccl/trajectory/failure.hpp"
#include "rccx/rccl/trajectory/requests.hpp"

namespace rccx::rccl::trajectory {

enum class GateState : std::uint8_t { open, closed, cancel };

class MotionQueue {
 public:
  static constexpr std::size_t kCapacity = 256;
  static constexpr std::size_t kReports = 256;

  /// `ledger`: the robot's, for its name in messages.
  explicit MotionQueue(const MotionLedger& ledger) noexcept : ledger_(ledger) {}

  // --- Planning level ----------------------------------------------------------------------------
  /// Queues a request; false when the queue is full.
  bool submit(const MotionRequest& request) noexcept { return requests_.push(request); }
  std::optional<MotionEvent> next_event() noexcept;
  /// The report of motion `id` (an empty one once kReports later motions have reused its slot).
  [[nodiscard]] SegmentReport report(std::uint64_t id) const noexcept;

  // --- Sample loop -------------------------------------------------------------------------------
  /// The request taken from the queue and not yet built, or null.
  [[nodiscard]] const MotionRequest* waiting() const noexcept {
    return waiting_ ? &*waiting_ : nullptr;
  }
  /// No request waiting, none put back.
  [[nodiscard]] bool idle() const noexcept { return !waiting_ && !requeued_; }
  /// When none waits: the request put back, else the next one queued.
  void take() noexcept {
    if (waiting_) return;
    MotionRequest r;
    if (requeued_) {
      waiting_ = requeued_;
      requeued_.reset();
      rendezvous_ready_ = false;
    } else if (requests_.pop(r)) {
      waiting_ = r;
      rendezvous_ready_ = false;
    }
  }
  /// Whether the waiting request's gates let it start now (its rendezvous apart); cancel: why
  /// says why.
  GateState gate_state(Text& why) const noexcept;
  /// The waiting request has been built and joined to the running segment.
  void join() noexcept;
  /// The waiting request has been built and begins now.
  void started() noexcept;
  /// A nextmove: the joined request starts from rest once the arm has stopped, before the one
  /// waiting.
  void put_back_joined() noexcept;
  void drop_joined() noexcept { joined_.reset(); }
  /// The waiting request has told its rendezvous it is ready.
  [[nodiscard]] bool rendezvous_ready() const noexcept { return rendezvous_ready_; }
  void set_rendezvous_ready() noexcept { rendezvous_ready_ = true; }
  /// Every request not begun (waiting, put back, queued), in order: `cancel(request)`, then
  /// withdrawn from its rendezvous with `why`.
  template <class Cancel>
  void cancel_all(const Text& why, Cancel&& cancel) noexcept;
  /// The loop starts again: the requests taken are withdrawn from their rendezvous with `why`
  /// and dropped (those queued stay).
  void reset(const Text& why) noexcept;

  void emit(EventKind kind, std::uint64_t id, const SampleContext& ctx,
            kin::IkStatus status = kin::IkStatus::ok, int joint = 0,
            std::string_view text = {}) noexcept;
  /// The report slot of motion `id`.
  [[nodiscard]] SegmentReport& report_slot(std::uint64_t id) noexcept {
    return reports_[id % kReports];
  }

 private:
  /// Cancels r's rendezvous, if it has one: r ended before it for `why`.
  void withdraw(const MotionRequest& r, const Text& why) noexcept;

  const MotionLedger& ledger_;
  boost::lockfree::spsc_queue<MotionRequest, boost::lockfree::capacity<kCapacity>> requests_;
  boost::lockfree::spsc_queue<MotionEvent, boost::lockfree::capacity<4 * kCapacity>> events_;
  std::array<SegmentReport, kReports> reports_{};
  std::optional<MotionRequest> waiting_;  ///< taken from the queue, not yet built
  /// The request the next segment was built from when it joined the running one (a nextmove
  /// puts it back), and a request put back in front of the queue.
  std::optional<MotionRequest> joined_, requeued_;
  bool rendezvous_ready_ = false;  ///< waiting_ has told its rendezvous it is ready
};

template <class Cancel>
void MotionQueue::cancel_all(const Text& why, Cancel&& cancel) noexcept {
  const auto cancel_request = [&](const MotionRequest& r) {
    cancel(r);
    withdraw(r, why);
  };
  if (waiting_) cancel_request(*waiting_);
  if (requeued_) cancel_request(*requeued_);
  waiting_.reset();
  requeued_.reset();
  joined_.reset();
  MotionRequest r;
  while (requests_.pop(r)) cancel_request(r);
}

}  // namespace rccx::rccl::trajectory
