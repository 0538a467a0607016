#include "rccx/rtc/robot_channel.hpp"

#include <fmt/format.h>

#include <thread>

#include "rccx/io/fixed_text.hpp"
#include "rccx/rtc/doorbell.hpp"
#include "rccx/rtc/hangup.hpp"
#include "rccx/rtc/sample_clock.hpp"

namespace rccx::rtc {

RobotChannel::RobotChannel(Driver& driver, SampleClock& clock, int multiple, std::size_t index,
                           SampleLog* log)
    : driver_(driver), clock_(clock), multiple_(multiple), index_(index), log_(log) {
  control_.channel_ = this;
}

std::chrono::nanoseconds RobotChannel::period() const noexcept {
  return std::chrono::nanoseconds(clock_.period_ns() * multiple_);
}

bool RobotChannel::simulated() const noexcept {
  return clock_.simulated();
}

// ---------------------------------------------------------------------------------------------
// The planning level

void RobotChannel::prepare_control(ControlFunction f1, ControlFunction f2, bool user_hangup) {
  const std::uint32_t p = phase_.load(std::memory_order_acquire);
  if (p == kControlling) throw SessionError("control is already active: release() it first");
  if (p != kIdle) {
    throw SessionError(
        fmt::format("the last control session ended ({}); call release() before control() again",
                    to_string(termination_.code)));
  }
  clock_.wait_control_idle();
  f1_ = std::move(f1);
  f2_ = std::move(f2);
  control_.chg_ = Chg{};
  control_.message_ = {};
  requested_code_.store(0);
  user_hangup_.store(user_hangup);
  generation_.fetch_add(1, std::memory_order_relaxed);
}

void RobotChannel::begin_control() noexcept {
  phase_.store(kControlling, std::memory_order_seq_cst);
  clock_.ring_communication();
}

Termination RobotChannel::release() {
  bool ended = false;
  for (;;) {
    std::uint32_t p = phase_.load(std::memory_order_seq_cst);
    if (p == kIdle) break;
    if (p == kControlling) {
      if (phase_.compare_exchange_strong(p, kIdle, std::memory_order_seq_cst)) break;
      continue;
    }
    if (p == kEnded) {
      ended = true;
      break;
    }
    std::this_thread::yield();  // kEnding: the communication task is writing the termination
  }
  clock_.ring_control();
  clock_.ring_communication();
  Termination t = ended ? ended_termination() : Termination{};
  if (!ended) {
    clock_.wait_control_idle();
    t.message = control_.message_;
  }
  phase_.store(kIdle, std::memory_order_seq_cst);
  return t;
}

void RobotChannel::request_hold(bool power_off) noexcept {
  pending_.fetch_or(kPendingHold | (power_off ? kPendingPowerOff : 0U));
}

void RobotChannel::request_termination(TerminateCode code, int joint) noexcept {
  std::int32_t none = 0;
  if (requested_code_.compare_exchange_strong(none, static_cast<std::int32_t>(code))) {
    requested_joint_.store(joint);
  }
}

bool RobotChannel::controlling() const noexcept {
  return phase_.load(std::memory_order_acquire) == kControlling;
}

bool RobotChannel::ended() const noexcept {
  return phase_.load(std::memory_order_seq_cst) == kEnded;
}

TerminateCode RobotChannel::ended_code() const noexcept {
  // The termination is written while kEnding and not again until the next control().
  if (phase_.load(std::memory_order_acquire) != kEnded) return TerminateCode::none;
  return termination_.code;
}

Termination RobotChannel::ended_termination() const {
  clock_.wait_control_idle();
  Termination t = termination_;
  t.message = control_.message_;
  return t;
}

Termination RobotChannel::termination() const {
  if (!ended()) return {};
  return ended_termination();
}

How RobotChannel::how() const {
  std::lock_guard lock(snapshot_mutex_);
  latest_.take(snapshot_);
  return snapshot_;
}

void RobotChannel::set_tap(SampleTap* tap) noexcept {
  tap_.store(tap);
  if (tap != nullptr) return;
  while (tap_busy_.load()) std::this_thread::yield();
}

// ---------------------------------------------------------------------------------------------
// The communication task

bool RobotChannel::communication_cycle(std::uint32_t k, std::int64_t tick_ns) noexcept {
  carry_out_pending();
  if (!due(k)) return false;
  read_arm(k, tick_ns);
  bool handed = false;
  if (phase_.load(std::memory_order_seq_cst) == kControlling) handed = controlled_cycle(k);
  if (!handed) latest_.publish(comm_.how);  // a handed How is published once its Chg is applied
  return handed;
}

bool RobotChannel::due(std::uint32_t k) const noexcept {
  return multiple_ == 1 || (k - 1) % static_cast<std::uint32_t>(multiple_) == 0;
}

// Requests from release() are carried out at the next tick, whether or not the robot is due.
void RobotChannel::carry_out_pending() noexcept {
  const std::uint32_t pending = pending_.exchange(0, std::memory_order_acq_rel);
  if ((pending & kPendingHold) != 0) driver_.hold();
  if ((pending & kPendingPowerOff) != 0) driver_.set_power(false);
}

void RobotChannel::read_arm(std::uint32_t k, std::int64_t tick_ns) noexcept {
  How& h = comm_.how;
  comm_.k = k;
  comm_.tick_ns = tick_ns;
  const double t = static_cast<double>(tick_ns) * 1e-9;
  driver_.read(t, h);
  h.sample = k;
  h.time_s = t;
  const auto& joints = driver_.model().joints;
  for (std::size_t i = 0; i < h.dof; ++i) h.joint[i].range = h.joint[i].q - joints[i].lower;
}

bool RobotChannel::controlled_cycle(std::uint32_t k) noexcept {
  start_afresh_if_new();
  if (comm_.ended) return false;
  if (const std::optional<Stop> stop = first_stop()) {
    end(*stop);
    return false;
  }
  hand_how_over(k);
  return true;
}

// A new control session (control() bumped the generation): its state starts afresh.
void RobotChannel::start_afresh_if_new() noexcept {
  Comm& c = comm_;
  const std::uint32_t generation = generation_.load(std::memory_order_relaxed);
  if (generation == c.generation) return;
  c.generation = generation;
  c.hangups_seen = detail::hangup_count();
  c.power_expected = c.how.power;
  c.ended = false;
  c.chg = Chg{};
  c.targets.has = {};
}

// The checks of a controlled sample, in order (sample_checks.hpp): the first stop ends control.
std::optional<Stop> RobotChannel::first_stop() noexcept {
  Comm& c = comm_;
  const std::int64_t period_ns = period().count();
  EndRequests requests;
  requests.code = static_cast<TerminateCode>(requested_code_.exchange(0));
  requests.joint = requested_joint_.load();
  requests.hangups = detail::hangup_count();
  requests.user_hangup = user_hangup_.load(std::memory_order_relaxed);
  if (auto stop = check_requests(requests, c.hangups_seen)) return stop;
  if (auto stop = check_faults(c.how, c.power_expected, driver_)) return stop;
  if (auto stop = check_force(c.how.force, c.chg.checking)) return stop;
  return check_observed_limits(c.how, driver_, period_ns, c.chg.checking);
}

void RobotChannel::hand_how_over(std::uint32_t k) noexcept {
  // This robot's How for the control task; the clock hands every robot's over at once. (One
  // thread: f1 reads the communication task's own, run_f1_in_place.)
  if (!clock_.one_thread()) how_ = comm_.how;
  in_cycle_.store(k, std::memory_order_relaxed);
}

bool RobotChannel::still_controlling() const noexcept {
  return !comm_.ended && phase_.load(std::memory_order_seq_cst) == kControlling;
}

void RobotChannel::take_chg(std::uint32_t k, bool in_time) noexcept {
  if (in_cycle_.load(std::memory_order_relaxed) != k) return;
  if (still_controlling()) {
    if (in_time) {
      comm_.chg = chg_;
      apply_taken();
    } else {
      end(make_stop(TerminateCode::overrun, 0,
                    "f1 of sample {} did not hand Chg over within its period", k));
    }
  }
  latest_.publish(comm_.how);  // with the flags the Chg set
}

void RobotChannel::end_overrun(std::uint32_t cycle, std::uint32_t k, std::int64_t tick_ns,
                               const Stop& stop) noexcept {
  if (in_cycle_.load(std::memory_order_relaxed) != cycle || !still_controlling()) return;
  comm_.k = k;  // found at this tick
  comm_.tick_ns = tick_ns;
  end(stop);
}

void RobotChannel::apply_taken() noexcept {
  Comm& c = comm_;
  const double period_s = std::chrono::duration<double>(period()).count();
  if (apply_requests(c.chg)) {
    JointCommands commands{};
    if (const std::optional<Stop> stop =
            to_joint_commands(c.chg, driver_, period_s, c.how, c.targets, commands)) {
      end(*stop);
    } else {
      driver_.send(commands);
    }
  }
  log_sample();
  tap_sample();
}

bool RobotChannel::apply_requests(const Chg& chg) noexcept {
  if (chg.power == Request::on) {
    if (!driver_.set_power(true)) {
      end(make_stop(TerminateCode::power_failure, 0, "arm power could not be turned on"));
      return false;
    }
    comm_.power_expected = true;
  } else if (chg.power == Request::off) {
    driver_.set_power(false);
    comm_.power_expected = false;
  }
  const How& h = comm_.how;
  if (chg.hand != Request::none) driver_.set_hand_closed(chg.hand == Request::on);
  if (chg.zero_gravity != Request::none) driver_.set_zero_gravity(chg.zero_gravity == Request::on);
  if (chg.setting.what != Setting::none && chg.setting.joint < h.dof) driver_.apply(chg.setting);
  if (chg.outputs_set != 0 || chg.outputs_clear != 0) {
    driver_.set_outputs(
        static_cast<std::uint16_t>((h.outputs | chg.outputs_set) & ~chg.outputs_clear));
  }
  return true;
}

void RobotChannel::log_sample() noexcept {
  SampleLog* log = log_.load(std::memory_order_acquire);
  if (log == nullptr) return;
  const How& h = comm_.how;
  LogRow row;
  row.t_s = h.time_s;
  row.segment = comm_.chg.segment;
  row.measured = h.q();
  row.commanded = comm_.targets.commanded(row.measured);
  log->push(row, simulated());  // simulated time waits for the writer: no row is lost
}

void RobotChannel::tap_sample() noexcept {
  if (tap_.load(std::memory_order_relaxed) == nullptr) return;
  // set_tap(nullptr) waits while tap_busy: busy is raised before the pointer is read again
  // (sequentially consistent, as the detaching side's store and load are).
  tap_busy_.store(true);
  if (SampleTap* tap = tap_.load()) {
    const How& h = comm_.how;
    tap->on_sample(h, comm_.targets.commanded(h.q()), comm_.chg.segment);
  }
  tap_busy_.store(false, std::memory_order_release);
}

void RobotChannel::end(const Stop& stop) noexcept {
  Comm& c = comm_;
  c.ended = true;
  std::uint32_t expected = kControlling;
  if (!phase_.compare_exchange_strong(expected, kEnding, std::memory_order_seq_cst)) return;
  Termination& t = termination_;
  t = Termination{};
  t.code = stop.code;
  t.joint = stop.joint;
  t.sample = c.k;
  t.time_s = static_cast<double>(c.tick_ns) * 1e-9;
  io::copy_fixed(t.detail, stop.detail_view());
  if (powers_down(stop.code)) {
    driver_.set_power(false);
  } else {
    driver_.hold();
  }
  c.power_expected = false;
  phase_.store(kEnded, std::memory_order_seq_cst);
  clock_.ring_control();
  clock_.ring_planning();
}

void RobotChannel::prefetch() const noexcept {
  __builtin_prefetch(this, 1, 3);
  __builtin_prefetch(&comm_, 1, 3);
  __builtin_prefetch(&control_, 1, 3);
}

// ---------------------------------------------------------------------------------------------
// The control task

bool RobotChannel::in_cycle(std::uint32_t k) const noexcept {
  return in_cycle_.load(std::memory_order_relaxed) == k &&
         phase_.load(std::memory_order_seq_cst) == kControlling;
}

void RobotChannel::run_f1_on(const How& how) noexcept {
  Control& ctl = control_;
  ctl.how_ = how;
  ctl.period_s_ = std::chrono::duration<double>(period()).count();
  ctl.spent_ns_ = 0;
  run_guarded(f1_);
}

void RobotChannel::run_f1() noexcept {
  run_f1_on(how_);
  chg_ = control_.chg_;
}

void RobotChannel::run_f1_in_place(std::uint32_t k) noexcept {
  // What the two tasks do for this robot (run_f1, take_chg), without the copies between them.
  if (in_cycle(k)) {
    run_f1_on(comm_.how);
    if (still_controlling()) {
      comm_.chg = control_.chg_;
      apply_taken();
    }
  }
  latest_.publish(comm_.how);  // with the flags the Chg set
}

std::int64_t RobotChannel::run_f2() noexcept {
  Control& ctl = control_;
  ctl.chg_.clear_commands();
  run_guarded(f2_);
  return ctl.spent_ns_;
}

// A control function that throws ends this robot's control with `control_exception`, its
// message as rtc_message; nothing escapes into the control task.
void RobotChannel::run_guarded(ControlFunction& f) noexcept {
  if (!f) return;
  Control& ctl = control_;
  try {
    f(ctl);
  } catch (const std::exception& e) {
    ctl.message(e.what());
    request_termination(TerminateCode::control_exception, 0);
  } catch (...) {
    ctl.message("unknown exception");
    request_termination(TerminateCode::control_exception, 0);
  }
}

// ---------------------------------------------------------------------------------------------
// Control (what f1 and f2 see)

void Control::terminate(TerminateCode code) noexcept {
  channel_->request_termination(code, 0);
}

void Control::message(std::string_view text) noexcept {
  io::copy_fixed(message_, text);
}

void Control::spend(std::chrono::nanoseconds d) noexcept {
  if (channel_->simulated()) {
    spent_ns_ += d.count();
    return;
  }
  const std::int64_t until = detail::monotonic_ns() + d.count();
  while (detail::monotonic_ns() < until) {
  }
}

}  // namespace rccx::rtc
