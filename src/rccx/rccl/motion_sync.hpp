// Synchronisation between robots (thesis 5.2, Multi-RCCL): a motion that starts only once
// events of other robots have happened, and motions of several robots that start in the same
// sample and, on request, end in the same sample.
//
//   MotionLedger   what a generator has done with its motions (started / ended / failed up to
//                  which id, whether its control ended), in atomics any thread may read. Every
//                  generator keeps its own; a cell keeps a copy per robot that it refreshes after
//                  each tick, so that a motion gated on it starts in the sample after the event
//                  whatever order the robots are stepped in.
//   EventGate      one event of one ledger: motion `id` started, or ended.
//   Rendezvous     n participants' motions that start together (and end together when asked):
//                  each reports ready with its planned duration; when all are, the start is
//                  set to the next sample all of them share, and the common duration to the
//                  slowest one's, rounded up to that shared period.
//   StartWhen      what a queued motion waits for: gates (all of them) and a rendezvous.
//
// Everything the sample loop calls here is noexcept and allocation-free.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace rccx::rccl {

/// What a gate asks of a ledger.
enum class GateAnswer : std::uint8_t {
  yes,      ///< the event happened
  not_yet,  ///< it may still happen
  never,    ///< it cannot happen any more: its motion failed or was cancelled, or control ended
};

/// A generator's record of its motions, readable from any thread.
class MotionLedger {
 public:
  static constexpr std::size_t kFailures = 16;  ///< failure ranges remembered
  static constexpr std::size_t kName = 32;

  explicit MotionLedger(std::string_view robot = {}) noexcept { set_robot(robot); }
  MotionLedger(const MotionLedger&) = delete;
  MotionLedger& operator=(const MotionLedger&) = delete;

  /// The robot's name, for messages (truncated to kName - 1 characters). Before use only.
  void set_robot(std::string_view robot) noexcept;
  [[nodiscard]] std::string_view robot() const noexcept { return {name_.data()}; }

  // --- The writer (one thread: the generator's loop, or a cell's control task) --------------
  void mark_started(std::uint64_t id) noexcept;
  void mark_ended(std::uint64_t id) noexcept;
  /// Motions from..to failed or were cancelled (to >= from); ended (and started) up to `to`.
  void mark_failed(std::uint64_t from, std::uint64_t to) noexcept;
  /// The robot's control ended (true): nothing it has not done will happen; or runs again.
  void set_control_ended(bool ended) noexcept;
  /// Makes this a copy of `live` and returns true when anything changed (the copy's writer
  /// only; `live` may be written meanwhile by the same thread only).
  bool copy_from(const MotionLedger& live) noexcept;
  /// Forgets everything (a new control session).
  void clear() noexcept;

  // --- Readers (any thread) ---------------------------------------------------------------------
  [[nodiscard]] std::uint64_t started_upto() const noexcept {
    return started_.load(std::memory_order_acquire);
  }
  [[nodiscard]] std::uint64_t ended_upto() const noexcept {
    return ended_.load(std::memory_order_acquire);
  }
  [[nodiscard]] bool control_ended() const noexcept {
    return control_ended_.load(std::memory_order_acquire);
  }
  /// True when motion `id` failed or was cancelled, as far as the ranges remembered tell.
  [[nodiscard]] bool failed(std::uint64_t id) const noexcept;
  /// The newest failure ranges, newest first, into from[0 .. n) and to[0 .. n) (unused: 0);
  /// returns how many were written. What a serve process sends in its RobotState.
  std::size_t newest_failures(std::uint64_t* from, std::uint64_t* to, std::size_t n) const noexcept;
  [[nodiscard]] GateAnswer has_started(std::uint64_t id) const noexcept;
  [[nodiscard]] GateAnswer has_ended(std::uint64_t id) const noexcept;
  /// Changes so far (the copy's cue).
  [[nodiscard]] std::uint64_t version() const noexcept {
    return version_.load(std::memory_order_acquire);
  }

 private:
  void bump() noexcept { version_.fetch_add(1, std::memory_order_acq_rel); }

  std::array<char, kName> name_{};
  std::atomic<std::uint64_t> started_{0}, ended_{0}, version_{0};
  std::atomic<bool> control_ended_{false};
  /// Failure ranges, newest at failures_ - 1 (mod kFailures).
  std::array<std::atomic<std::uint64_t>, kFailures> failed_from_{}, failed_to_{};
  std::atomic<std::uint32_t> failures_{0};
  std::uint64_t copied_version_ = ~std::uint64_t{0};  ///< copy_from's writer only
};

/// One event of a robot's motions, as other motions may wait for it.
struct EventGate {
  enum class Kind : std::uint8_t { started, ended };
  const MotionLedger* ledger = nullptr;  ///< kept alive by its owner (the cell) while in use
  Kind kind = Kind::ended;
  std::uint64_t id = 0;

  [[nodiscard]] GateAnswer answer() const noexcept {
    if (ledger == nullptr) return GateAnswer::never;
    return kind == Kind::started ? ledger->has_started(id) : ledger->has_ended(id);
  }
};

/// The motions of several robots that start in the same sample, and optionally end in the
/// same sample (the faster ones slowed to the slowest). Made for a fixed number of
/// participants; each joins with one motion (StartWhen::together, a slot of its own). One use
/// only: make a new one for the next joint start.
class Rendezvous {
 public:
  static constexpr std::size_t kMaxParticipants = 64;

  /// `ledgers` (optional, one per participant, may be null): a participant whose control ends
  /// before the start breaks the rendezvous.
  Rendezvous(std::size_t participants, bool end_together,
             std::vector<const MotionLedger*> ledgers = {});
  Rendezvous(const Rendezvous&) = delete;
  Rendezvous& operator=(const Rendezvous&) = delete;

  [[nodiscard]] std::size_t participants() const noexcept { return n_; }
  [[nodiscard]] bool end_together() const noexcept { return end_together_; }

  // --- The sample loop -------------------------------------------------------------------------
  /// Participant `slot` is ready to start at sample time `now_s` (s, the tick's time): its
  /// motion lasts `duration_s` from its start to rest, and it is sampled every `period_s`.
  /// When it is the last one, the start is set. Idempotent until the start is set.
  void ready(std::size_t slot, double now_s, double duration_s, double period_s) noexcept;
  /// A participant cannot take part (its motion failed, was halted or cancelled; `why` says
  /// whose, truncated): the others' motions are cancelled with it when they look.
  void withdraw(std::string_view why) noexcept;
  /// The start (tick time, s) once every participant is ready, else a negative number.
  [[nodiscard]] double start_s() const noexcept { return start_s_.load(std::memory_order_acquire); }
  /// The common duration from start to rest (s, end_together), once started.
  [[nodiscard]] double duration_s() const noexcept {
    return duration_s_.load(std::memory_order_acquire);
  }
  /// Why a participant withdrew (empty: none did).
  [[nodiscard]] std::string_view withdrawn() const noexcept;
  /// A participant whose control ended before the start (nullptr: none).
  [[nodiscard]] const MotionLedger* lost_participant() const noexcept;
  /// The participant `ledger` stands for, or participants() when it is none of them.
  [[nodiscard]] std::size_t slot_of(const MotionLedger* ledger) const noexcept;
  /// The ledger of the robot that takes place `slot` (nullptr when not known).
  [[nodiscard]] const MotionLedger* participant(std::size_t slot) const noexcept {
    return slot < ledgers_.size() ? ledgers_[slot] : nullptr;
  }

 private:
  std::size_t n_;
  bool end_together_;
  std::vector<const MotionLedger*> ledgers_;
  std::array<std::atomic<double>, kMaxParticipants> duration_{};  ///< < 0: not ready
  std::array<std::atomic<std::int64_t>, kMaxParticipants> now_ns_{}, period_ns_{};
  std::atomic<double> start_s_{-1.0}, duration_s_{0.0};
  std::atomic<bool> broken_{false}, why_set_{false};
  std::array<char, 160> why_{};
};

/// What a queued motion waits for before it starts (Manipulator::move / dwell): every gate has
/// happened, and (when `together` is set) every participant of the rendezvous is ready.
struct StartWhen {
  static constexpr std::size_t kMaxGates = 4;
  std::vector<EventGate> after;
  std::shared_ptr<Rendezvous> together;
  std::size_t slot = 0;  ///< this motion's place in `together`
  /// The cell's objects this motion's tool may touch (cell::Cell::objects): nothing else may
  /// be touched. MotionSettings::may_touch.
  std::uint64_t touch = 0;
};

}  // namespace rccx::rccl
