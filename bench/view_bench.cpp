// The view's cost to the sample loop (docs/PERFORMANCE.md, "The view"): the same loop without
// the view and with it attached (rccx::view::serve) and two pages connected (WebSocket clients
// in this process that read every message, as a browser's page does).
//
//   BM_ViewSimulatedLoop/view:V  a sample of simulated time on the PUMA 560 at 1 ms (its plant,
//                                f2 commanding a sine on joint 1), both tasks on one thread
//                                (SessionOptions::one_thread: the cycle's own work, no hand-overs
//                                that a loaded machine's scheduler would dominate): wall time a
//                                sample; the server drains at full speed meanwhile (its worst
//                                case: simulated time runs hundreds of times faster than real).
//   BM_ViewRealTimeCompute/view:V  the same loop in real time at 1 ms for 3 s, in a one-robot
//                                SessionGroup on one thread: the loop's computing time a tick
//                                (counters, p50 and p99 us), the measure that matters for an arm.
#include <benchmark/benchmark.h>

#include <utility>  // before Boost.Asio 1.74 (std::exchange)

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <memory>
#include <thread>
#include <vector>

#include "rccx/hw/simulated_arm.hpp"
#include "rccx/rtc/servo_driver.hpp"
#include "rccx/rtc/session.hpp"
#include "rccx/view/server.hpp"

namespace {

using namespace rccx;
using namespace std::chrono_literals;
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;

/// A page: a WebSocket client on its own thread reading every message until stopped.
class Page {
 public:
  explicit Page(std::uint16_t port) {
    ws_.next_layer().connect({asio::ip::make_address("127.0.0.1"), port});
    ws_.handshake("127.0.0.1", "/ws");
    thread_ = std::thread([this] {
      beast::flat_buffer buffer;
      beast::error_code ec;
      while (!ec) {
        ws_.read(buffer, ec);
        messages_ += ec ? 0 : 1;
        buffer.clear();
      }
    });
  }
  ~Page() {
    beast::error_code ec;
    ws_.next_layer().shutdown(asio::ip::tcp::socket::shutdown_both, ec);
    thread_.join();
  }
  [[nodiscard]] std::uint64_t messages() const { return messages_; }

 private:
  asio::io_context io_;
  websocket::stream<asio::ip::tcp::socket> ws_{io_};
  std::thread thread_;
  std::atomic<std::uint64_t> messages_{0};
};

/// f2: joint 1 on a slow sine about where it was at the start (0.05 rad, 1 rad/s).
rtc::ControlFunction sine() {
  return [start = -1.0, t0 = 0.0](rtc::Control& c) mutable {
    if (start < 0.0) start = c.how().joint[0].range, t0 = c.how().time_s;
    c.chg().posvel(0, start + 0.05 * std::sin(c.how().time_s - t0));
  };
}

struct Viewed {
  std::unique_ptr<view::Server> server;
  std::vector<std::unique_ptr<Page>> pages;

  Viewed(rtc::Session& session, bool on) {
    if (!on) return;
    view::ServeOptions o;
    o.announce = false;
    server = view::serve(session, 0, o);
    for (int i = 0; i < 2; ++i) pages.push_back(std::make_unique<Page>(server->port()));
  }
  void report(benchmark::State& state) {
    if (!server) return;
    const view::ServerStats s = server->stats();
    state.counters["pages"] = static_cast<double>(s.pages);
    state.counters["samples_sent"] = static_cast<double>(s.samples_sent);
    state.counters["samples_dropped"] = static_cast<double>(s.samples_dropped);
    std::uint64_t m = 0;
    for (const auto& p : pages) m += p->messages();
    state.counters["messages_read"] = static_cast<double>(m);
  }
  ~Viewed() {
    pages.clear();
    server.reset();
  }
};

void BM_ViewSimulatedLoop(benchmark::State& state) {
  const auto model = kin::builtin_robot("puma560");
  const auto arm = hw::make_simulated_arm(model);
  rtc::ServoDriver driver(*arm);
  rtc::SessionOptions o;
  o.period = 1ms;
  o.one_thread = true;  // the cycle's own cost, without hand-overs between threads
  rtc::Session session(driver, o);
  Viewed viewed(session, state.range(0) != 0);
  session.control({}, sine());
  session.wait_for(100ms);
  for (auto _ : state) session.wait_for(1ms);
  const rtc::Termination t = session.release();
  if (t.ended()) state.SkipWithError(std::string(rtc::describe(t.code)).c_str());
  viewed.report(state);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ViewSimulatedLoop)->ArgName("view")->Arg(0)->Arg(1)->UseRealTime();

void BM_ViewRealTimeCompute(benchmark::State& state) {
  const auto model = kin::builtin_robot("puma560");
  const auto arm = hw::make_simulated_arm(model);
  rtc::ServoDriver driver(*arm);
  rtc::SessionOptions o;
  o.period = 1ms;
  o.clock = rtc::ClockKind::real_time;
  o.one_thread = true;  // no watchdog: a tick late on a loaded machine is counted, not fatal
  rtc::SessionGroup group(o);
  rtc::Session& session = group.add(driver);
  group.start();
  Viewed viewed(session, state.range(0) != 0);
  session.control({}, sine());
  for (auto _ : state) std::this_thread::sleep_for(3s);
  const rtc::Termination t = session.release();
  if (t.ended()) state.SkipWithError(std::string(rtc::describe(t.code)).c_str());
  const rtc::LatencyStats c = group.compute();
  state.counters["compute_p50_us"] = c.p50_us;
  state.counters["compute_p99_us"] = c.p99_us;
  state.counters["compute_max_us"] = c.max_us;
  state.counters["ticks"] = static_cast<double>(c.wakeups);
  viewed.report(state);
}
BENCHMARK(BM_ViewRealTimeCompute)
    ->ArgName("view")
    ->Arg(0)
    ->Arg(1)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
