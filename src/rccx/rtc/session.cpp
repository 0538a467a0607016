#include "rccx/rtc/session.hpp"

#include <fmt/format.h>

#include <cmath>

#include <algorithm>
#include <utility>

#include "rccx/rtc/doorbell.hpp"
#include "rccx/rtc/hangup.hpp"
#include "rccx/rtc/robot_channel.hpp"
#include "rccx/rtc/sample_clock.hpp"

namespace rccx::rtc {

using detail::monotonic_ns;

// ---------------------------------------------------------------------------------------------
// Opening and closing

Session::Session(Driver& driver, SessionOptions options)
    : driver_(driver), clock_(std::make_shared<SampleClock>(options)), owns_clock_(true) {
  open_channel(1, {}, {});
  clock_->add(*channel_);
  clock_->start();
}

Session::Session(Driver& driver, std::shared_ptr<SampleClock> clock, int multiple,
                 const std::string& name)
    : driver_(driver), clock_(std::move(clock)) {
  open_channel(multiple, name, "-" + name);
}

void Session::open_channel(int multiple, const std::string& name, const std::string& log_suffix) {
  if (driver_.model().dof() == 0 || driver_.model().dof() > kMaxJoints) {
    throw SessionError(fmt::format("robot {} has {} joints; RTC serves 1 to {}",
                                   driver_.model().name, driver_.model().dof(), kMaxJoints));
  }
  name_ = name.empty() ? driver_.model().name : name;
  const std::chrono::nanoseconds period(clock_->period_ns() * multiple);
  check_period(period);
  const LogHeader header = LogHeader::of(driver_.model(), name_, period, clock_->simulated());
  // LogError names RCCX_LOG.
  environment_log_ = SampleLog::from_environment(driver_.model(), header, log_suffix);
  channel_ = std::make_unique<RobotChannel>(driver_, *clock_, multiple, clock_->size(),
                                            environment_log_.get());
}

Session::~Session() {
  try {
    close();
  } catch (...) {  // close() only throws for misuse that a destructor cannot report
  }
}

std::chrono::nanoseconds Session::period() const noexcept {
  return channel_->period();
}

ClockKind Session::clock() const noexcept {
  return clock_->options().clock;
}

void Session::check_period(std::chrono::nanoseconds p) const {
  const double needed_s = driver_.minimum_period_s();
  const double max_ms = std::chrono::duration<double, std::milli>(kMaxPeriod).count();
  if (needed_s * 1e3 > max_ms) {  // no period serves it: the robot file must change, not the period
    throw SessionError(fmt::format(
        "robot {}: its link needs {:.1f} ms of bus time a sample, more than the longest sample "
        "period RTC serves ({:g} ms); no period can serve it: shorten the robot file's bus time "
        "(exchange_us) or its joints",
        driver_.model().name, needed_s * 1e3, max_ms));
  }
  if (std::chrono::duration<double>(p).count() < needed_s) {
    throw SessionError(fmt::format(
        "sample period {} ms is too short for robot {}: its link needs {:.1f} ms of bus time a "
        "sample; choose a period from {:.1f} to {:g} ms",
        std::chrono::duration<double, std::milli>(p).count(), driver_.model().name, needed_s * 1e3,
        std::ceil(needed_s * 1e4) / 10, max_ms));
  }
  if (p < kMinPeriod || p > kMaxPeriod) {
    using ms = std::chrono::duration<double, std::milli>;
    throw SessionError(fmt::format("sample period {} ms is outside {} .. {} ms", ms(p).count(),
                                   ms(kMinPeriod).count(), ms(kMaxPeriod).count()));
  }
}

void Session::set_period(std::chrono::nanoseconds period) {
  if (!owns_clock_) {
    throw SessionError("a robot of a group keeps the group's clock; its period cannot change");
  }
  check_period(period);
  if (controlling()) throw SessionError("the sample period can change only while not in control");
  clock_->set_period_ns(period.count());
}

void Session::close(bool power_off) {
  if (closed_) return;
  release(power_off);
  if (owns_clock_) clock_->stop_tasks();
  closed_ = true;
  if (environment_log_) log_problem_ = environment_log_->close();
}

// ---------------------------------------------------------------------------------------------
// A group

SessionGroup::SessionGroup(SessionOptions options)
    : clock_(std::make_shared<SampleClock>(options)) {
  if (options.period < kMinPeriod || options.period > kMaxPeriod) {
    using ms = std::chrono::duration<double, std::milli>;
    throw SessionError(fmt::format("the clock's period {} ms is outside {} .. {} ms",
                                   ms(options.period).count(), ms(kMinPeriod).count(),
                                   ms(kMaxPeriod).count()));
  }
}

SessionGroup::~SessionGroup() {
  for (auto& s : sessions_) {
    try {
      s->release();
    } catch (...) {
    }
  }
  clock_->stop_tasks();
  sessions_.clear();  // their logs close after the tasks have stopped
}

Session& SessionGroup::add(Driver& driver, int multiple, std::string_view name) {
  if (clock_->running()) throw SessionError("add every robot before start()");
  if (multiple < 1 || multiple > 1000) {
    throw SessionError(fmt::format("robot {}: a period multiple of {}; give 1 to 1000",
                                   driver.model().name, multiple));
  }
  auto s =
      std::unique_ptr<Session>(new Session(driver, clock_, multiple, unique_name(driver, name)));
  clock_->add(*s->channel_);
  sessions_.push_back(std::move(s));
  return *sessions_.back();
}

std::string SessionGroup::unique_name(const Driver& driver, std::string_view name) const {
  const std::string base(name.empty() ? std::string_view(driver.model().name) : name);
  const auto taken = [this](const std::string& n) {
    return std::any_of(sessions_.begin(), sessions_.end(),
                       [&n](const auto& s) { return s->name() == n; });
  };
  if (!name.empty() && taken(base)) {
    throw SessionError(
        fmt::format("a robot named \"{}\" is in the group already; give each "
                    "robot its own name",
                    base));
  }
  std::string unique = base;
  for (int k = 2; taken(unique); ++k) unique = fmt::format("{}-{}", base, k);
  return unique;
}

void SessionGroup::set_cycle_hook(std::function<void(std::uint32_t tick)> hook) {
  if (clock_->running()) throw SessionError("set the cycle hook before start()");
  clock_->set_cycle_hook(std::move(hook));
}

void SessionGroup::set_robot_hook(std::function<void(std::size_t, std::uint32_t)> hook) {
  if (clock_->running()) throw SessionError("set the robot hook before start()");
  clock_->set_robot_hook(std::move(hook));
}

void SessionGroup::start() {
  if (sessions_.empty()) throw SessionError("a group needs at least one robot: add() it first");
  clock_->start();
}

std::chrono::nanoseconds SessionGroup::period() const noexcept {
  return std::chrono::nanoseconds(clock_->period_ns());
}

LatencyStats SessionGroup::latency() const {
  return clock_->latency();
}

LatencyStats SessionGroup::compute() const {
  return clock_->compute();
}

void SessionGroup::wait_for(std::chrono::nanoseconds d) {
  if (sessions_.empty() || !clock_->running()) throw SessionError("start() the group first");
  sessions_.front()->wait_for(d);
}

// ---------------------------------------------------------------------------------------------
// Planning level

void Session::control(ControlFunction f1, ControlFunction f2) {
  if (closed_) throw SessionError("the session is closed; open a new one");
  if (!clock_->running()) throw SessionError("the group is not started: call start() first");
  channel_->prepare_control(std::move(f1), std::move(f2), static_cast<bool>(hangup_handler_));
  detail::register_for_hangup(this);
  channel_->begin_control();
}

Termination Session::release(bool power_off) {
  Termination t = channel_->release();
  detail::unregister_for_hangup(this);
  if (!clock_->running() || clock_->stopped()) return t;
  // The arm holds where it is (and powers off if asked) from the next tick on.
  channel_->request_hold(power_off);
  if (clock_->simulated()) {
    clock_->step_simulated_sample();
  } else {
    clock_->wait_tick_done();
  }
  return t;
}

void Session::terminate(TerminateCode code) noexcept {
  channel_->request_termination(code, 0);
}

bool Session::controlling() const noexcept {
  return channel_->controlling();
}

TerminateCode Session::ended_code() const noexcept {
  return channel_->ended_code();
}

Termination Session::termination() const {
  return channel_->termination();
}

How Session::how() const {
  return channel_->how();
}

LatencyStats Session::latency() const {
  return clock_->latency();
}

LatencyStats Session::compute() const {
  return clock_->compute();
}

void Session::set_tap(SampleTap* tap) noexcept {
  channel_->set_tap(tap);
}

void Session::set_log(SampleLog* log) {
  if (controlling()) throw SessionError("set the log before control()");
  channel_->set_log(log);
}

void Session::set_hangup_handler(std::function<void(Session&)> handler) {
  if (controlling()) throw SessionError("set the hang-up handler before control()");
  hangup_handler_ = std::move(handler);
}

void Session::hangup() {
  if (hangup_handler_ && controlling()) hangup_handler_(*this);
}

Termination Session::wait_for(std::chrono::nanoseconds d) {
  // A stop signal (Ctrl-C, SIGTERM) ends the wait within a period, whatever its length.
  SampleClock& clk = *clock_;
  const std::uint32_t stops = detail::hangup_count();
  const auto stopped = [&] { return detail::hangup_count() != stops; };
  if (clk.simulated()) {
    const std::int64_t until = clk.simulated_now_ns() + d.count();
    while (!stopped() && clk.simulated_now_ns() + clk.period_ns() <= until) {
      clk.step_simulated_sample();
    }
    // One more tick lets the communication task see the signal and end control.
    if (stopped() && controlling()) {
      for (int i = 0; i < channel_->multiple() && controlling(); ++i) clk.step_simulated_sample();
    }
  } else {
    const std::int64_t until = monotonic_ns() + d.count();
    for (std::int64_t now = monotonic_ns(); now < until && !stopped(); now = monotonic_ns()) {
      detail::sleep_until(std::min(until, now + clk.period_ns()));
    }
  }
  return termination();
}

Termination Session::wait_terminated(std::chrono::nanoseconds timeout) {
  SampleClock& clk = *clock_;
  const std::uint32_t stops = detail::hangup_count();
  const auto ended = [&] { return channel_->ended() || detail::hangup_count() != stops; };
  if (clk.simulated()) {
    const std::int64_t until = clk.simulated_now_ns() + timeout.count();
    while (!ended() && clk.simulated_now_ns() + clk.period_ns() <= until) {
      clk.step_simulated_sample();
    }
  } else {
    const std::int64_t deadline = monotonic_ns() + timeout.count();
    while (!ended() && monotonic_ns() < deadline) {
      const std::uint32_t seen = clk.planning_rings();
      if (ended()) break;
      clk.wait_planning(seen, std::min(deadline, monotonic_ns() + period().count()));
    }
  }
  return termination();
}

bool Session::wait_until(const std::function<bool(const How&)>& done,
                         std::chrono::nanoseconds timeout) {
  SampleClock& clk = *clock_;
  const bool simulated = clk.simulated();
  const std::int64_t start = simulated ? clk.simulated_now_ns() : monotonic_ns();
  const std::uint32_t stops = detail::hangup_count();
  std::uint64_t seen_sample = ~std::uint64_t{0};
  for (;;) {
    // A robot sampled every k-th tick has a new How only every k-th tick.
    const How h = how();
    if (h.sample != seen_sample) {
      seen_sample = h.sample;
      if (done(h)) return true;
    }
    if (channel_->ended()) return false;
    if (detail::hangup_count() != stops) return false;  // Ctrl-C, SIGTERM
    const std::int64_t now = simulated ? clk.simulated_now_ns() : monotonic_ns();
    if (now - start >= timeout.count()) return false;
    if (simulated) {
      clk.step_simulated_sample();
    } else {
      detail::sleep_until(monotonic_ns() + clk.period_ns());
    }
  }
}

}  // namespace rccx::rtc
