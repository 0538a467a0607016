// RTC benchmarks: the cost of one full sample cycle (communication task, control task and the
// planning level stepping simulated time) on the simulated PUMA 560, beside its parts: the
// driver and servo simulation alone, and one thread hand-off with our futex doorbells against
// the textbook mutex + condition variable (the peer).
#include <benchmark/benchmark.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "rccx/hw/simulated_arm.hpp"
#include "rccx/rtc/doorbell.hpp"
#include "rccx/rtc/servo_driver.hpp"
#include "rccx/rtc/session.hpp"

namespace {

using namespace rccx;
using namespace std::chrono_literals;

/// One full cycle: the planning level lets a 1 ms sample pass; the communication task reads the
/// arm (one 1 kHz servo tick of the PUMA plant), checks limits, hands How over; the control task
/// runs the empty f1, hands Chg back, runs the empty f2 and kicks the watchdog.
void BM_RtcCycle(benchmark::State& state) {
  const auto model = kin::builtin_robot("puma560");
  const auto arm = hw::make_simulated_arm(model);
  rtc::ServoDriver driver(*arm);
  rtc::SessionOptions o;
  o.period = 1ms;
  o.clock = rtc::ClockKind::simulated;
  rtc::Session session(driver, o);
  session.control([](rtc::Control&) {}, [](rtc::Control&) {});
  for (auto _ : state) session.wait_for(1ms);
  const rtc::Termination t = session.release();
  if (t.ended()) state.SkipWithError(std::string(rtc::describe(t.code)).c_str());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RtcCycle)->UseRealTime();

/// The work of a cycle without RTC: read the arm (advancing the plant 1 ms) and send a hold.
void BM_DriverReadSend(benchmark::State& state) {
  const auto model = kin::builtin_robot("puma560");
  const auto arm = hw::make_simulated_arm(model);
  rtc::ServoDriver driver(*arm);
  rtc::How how;
  rtc::JointCommands commands{};
  double t = 0;
  for (auto _ : state) {
    t += 1e-3;
    driver.read(t, how);
    benchmark::DoNotOptimize(how);
    driver.send(commands);
  }
}
BENCHMARK(BM_DriverReadSend);

/// A round trip between two threads with RTC's doorbells (spin, then futex).
void BM_DoorbellRoundTrip(benchmark::State& state) {
  rtc::detail::Doorbell ping, pong;
  std::atomic<bool> stop{false};
  std::thread other([&] {
    std::uint32_t seen = 0;
    for (;;) {
      while (ping.load() == seen) rtc::detail::wait_while(ping, seen);
      if (stop.load()) return;
      seen = ping.load();
      rtc::detail::ring(pong);
    }
  });
  std::uint32_t seen = 0;
  for (auto _ : state) {
    rtc::detail::ring(ping);
    while (pong.load() == seen) rtc::detail::wait_while(pong, seen);
    seen = pong.load();
  }
  stop = true;
  rtc::detail::ring(ping);
  other.join();
}
BENCHMARK(BM_DoorbellRoundTrip)->UseRealTime();

/// The peer: the same round trip with std::mutex and std::condition_variable.
void BM_CondvarRoundTrip(benchmark::State& state) {
  std::mutex m;
  std::condition_variable cv;
  std::uint64_t ping = 0, pong = 0;
  bool stop = false;
  std::thread other([&] {
    std::uint64_t seen = 0;
    std::unique_lock lock(m);
    for (;;) {
      cv.wait(lock, [&] { return stop || ping != seen; });
      if (stop) return;
      seen = ping;
      ++pong;
      cv.notify_all();
    }
  });
  std::uint64_t seen = 0;
  for (auto _ : state) {
    std::unique_lock lock(m);
    ++ping;
    cv.notify_all();
    cv.wait(lock, [&] { return pong != seen; });
    seen = pong;
  }
  {
    std::lock_guard lock(m);
    stop = true;
  }
  cv.notify_all();
  other.join();
}
BENCHMARK(BM_CondvarRoundTrip)->UseRealTime();

}  // namespace
