#include "rccx/rccl/trajectory/motion_queue.hpp"

#include "rccx/rccl/trajectory/text.hpp"

namespace rccx::rccl {

std::string_view to_string(Mode m) noexcept {
  return m == Mode::joint ? "joint" : "cartesian";
}

std::string_view to_string(EventKind k) noexcept {
  switch (k) {
    case EventKind::started:
      return "started";
    case EventKind::ended:
      return "ended";
    case EventKind::failed:
      return "failed";
    case EventKind::cancelled:
      return "cancelled";
  }
  return "?";
}

std::string_view MotionEvent::message() const noexcept {
  return {text.data()};
}

}  // namespace rccx::rccl

namespace rccx::rccl::trajectory {

std::optional<MotionEvent> MotionQueue::next_event() noexcept {
  MotionEvent e;
  if (events_.pop(e)) return e;
  return std::nullopt;
}

SegmentReport MotionQueue::report(std::uint64_t id) const noexcept {
  const SegmentReport& r = reports_[id % kReports];
  return r.id == id ? r : SegmentReport{};
}

GateState MotionQueue::gate_state(Text& why) const noexcept {
  const MotionRequest& r = *waiting_;
  for (std::size_t k = 0; k < r.gates; ++k) {
    const EventGate& g = r.after[k];
    const GateAnswer a = g.answer();
    if (a == GateAnswer::yes) continue;
    if (a == GateAnswer::not_yet) return GateState::closed;
    const std::string_view robot = g.ledger != nullptr ? g.ledger->robot() : "?";
    const char* what = g.kind == EventGate::Kind::started ? "start" : "end";
    if (g.ledger != nullptr && g.ledger->control_ended() && !g.ledger->failed(g.id)) {
      why = text("cancelled: it waited for the {} of {}'s motion {}, and {}'s control ended", what,
                 robot, g.id, robot);
    } else {
      why = text("cancelled: it waited for the {} of {}'s motion {}, which failed or was cancelled",
                 what, robot, g.id);
    }
    return GateState::cancel;
  }
  if (r.together != nullptr) {
    if (const std::string_view w = r.together->withdrawn(); !w.empty()) {
      why = text("cancelled: its joint start cannot happen: {}", w);
      return GateState::cancel;
    }
    if (const MotionLedger* lost = r.together->lost_participant(); lost != nullptr) {
      why = text("cancelled: its joint start cannot happen: {}'s control ended", lost->robot());
      return GateState::cancel;
    }
  }
  return GateState::open;
}

void MotionQueue::join() noexcept {
  joined_ = waiting_;
  waiting_.reset();
}

void MotionQueue::started() noexcept {
  waiting_.reset();
  rendezvous_ready_ = false;
}

void MotionQueue::put_back_joined() noexcept {
  if (!joined_) return;
  if (waiting_) requeued_ = waiting_;
  waiting_ = joined_;
  rendezvous_ready_ = false;
}

void MotionQueue::reset(const Text& why) noexcept {
  if (waiting_) withdraw(*waiting_, why);
  if (requeued_) withdraw(*requeued_, why);
  waiting_.reset();
  requeued_.reset();
  joined_.reset();
  rendezvous_ready_ = false;
}

void MotionQueue::emit(EventKind kind, std::uint64_t id, const SampleContext& ctx,
                       kin::IkStatus status, int joint, std::string_view text) noexcept {
  MotionEvent e;
  e.kind = kind;
  e.id = id;
  e.t_s = ctx.sample_time_s();
  e.sample = ctx.sample;
  e.status = status;
  e.joint = joint;
  io::copy_fixed(e.text, text);
  events_.push(e);  // a full event queue drops the event: the counters still tell the story
}

void MotionQueue::withdraw(const MotionRequest& r, const Text& why) noexcept {
  if (r.together == nullptr) return;
  r.together->withdraw(std::string_view(
      text("{}'s motion {} ended before it: {}", ledger_.robot(), r.id, why.data()).data()));
}

}  // namespace rccx::rccl::trajectory
