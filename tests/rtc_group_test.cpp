// Several robots on one clock (rtc::SessionGroup): each sampled at the ticks of its multiple,
// its own control and termination, a fixed number of threads whatever their number.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <dirent.h>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rccx/hw/ideal_arm.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rtc/servo_driver.hpp"
#include "rccx/rtc/session.hpp"

using namespace rccx;
using namespace std::chrono_literals;
using rtc::TerminateCode;

namespace {

/// N ideal arms and their drivers, for a group.
struct Arms {
  std::vector<std::unique_ptr<hw::IdealArm>> arms;
  std::vector<std::unique_ptr<rtc::ServoDriver>> drivers;
  explicit Arms(std::size_t n, const std::string& robot = "puma560") {
    const kin::RobotModel model = kin::builtin_robot(robot);
    for (std::size_t i = 0; i < n; ++i) {
      arms.push_back(std::make_unique<hw::IdealArm>(model));
      drivers.push_back(std::make_unique<rtc::ServoDriver>(*arms.back()));
    }
  }
};

rtc::SessionOptions clock_of(std::chrono::nanoseconds period) {
  rtc::SessionOptions o;
  o.period = period;
  o.clock = rtc::ClockKind::simulated;
  return o;
}

std::size_t threads_of_this_process() {
  std::size_t n = 0;
  for (const auto& e : std::filesystem::directory_iterator("/proc/self/task")) {
    (void)e;
    ++n;
  }
  return n;
}

}  // namespace

TEST(SessionGroup, EachRobotIsSampledAtTheTicksOfItsMultiple) {
  Arms a(2);
  rtc::SessionGroup group(clock_of(7ms));
  rtc::Session& fast = group.add(*a.drivers[0]);
  rtc::Session& slow = group.add(*a.drivers[1], 4);
  group.start();
  EXPECT_EQ(fast.period(), 7ms);
  EXPECT_EQ(slow.period(), 28ms);
  // Written only by the control task, read after the waits.
  auto fast_samples = std::make_shared<std::vector<std::uint64_t>>();
  auto slow_samples = std::make_shared<std::vector<std::uint64_t>>();
  auto slow_times = std::make_shared<std::vector<double>>();
  auto slow_period = std::make_shared<double>(0.0);
  fast.control([=](rtc::Control& c) { fast_samples->push_back(c.how().sample); }, {});
  slow.control(
      [=](rtc::Control& c) {
        slow_samples->push_back(c.how().sample);
        slow_times->push_back(c.how().time_s);
        *slow_period = c.period_s();
      },
      {});
  group.wait_for(280ms);  // 40 ticks
  fast.release();
  slow.release();
  ASSERT_GE(fast_samples->size(), 38U);
  for (std::size_t i = 1; i < fast_samples->size(); ++i) {
    EXPECT_EQ((*fast_samples)[i], (*fast_samples)[i - 1] + 1) << "the fast robot skipped a tick";
  }
  ASSERT_GE(slow_samples->size(), 9U);
  for (std::size_t i = 0; i < slow_samples->size(); ++i) {
    EXPECT_EQ(((*slow_samples)[i] - 1) % 4, 0U) << "sampled at tick " << (*slow_samples)[i];
    if (i > 0) {
      EXPECT_EQ((*slow_samples)[i], (*slow_samples)[i - 1] + 4);
      EXPECT_NEAR((*slow_times)[i] - (*slow_times)[i - 1], 0.028, 1e-9);
    }
  }
  EXPECT_DOUBLE_EQ(*slow_period, 0.028);
  // The same clock: ticks the two share carry the same time.
  EXPECT_EQ(fast.how().time_s, fast.how().time_s);
}

TEST(SessionGroup, OneRobotsFaultEndsItsControlOnlyAndTheOthersGoOn) {
  Arms a(3);
  rtc::SessionGroup group(clock_of(10ms));
  std::vector<rtc::Session*> s;
  for (auto& d : a.drivers) s.push_back(&group.add(*d));
  group.start();
  for (rtc::Session* x : s) x->control({}, {});
  group.wait_for(50ms);
  a.arms[1]->inject(hw::Fault::joint_not_answering, 2);
  group.wait_for(50ms);
  const rtc::Termination t = s[1]->termination();
  EXPECT_EQ(t.code, TerminateCode::joint_not_answering);
  EXPECT_EQ(t.joint, 3);
  EXPECT_TRUE(s[0]->controlling());
  EXPECT_TRUE(s[2]->controlling());
  const std::uint64_t before = s[0]->how().sample;
  group.wait_for(100ms);
  EXPECT_EQ(s[0]->how().sample, before + 10) << "the others' samples go on";
  for (rtc::Session* x : s) x->release();
}

TEST(SessionGroup, ReleaseAndControlOneRobotWhileTheOthersRun) {
  Arms a(2);
  rtc::SessionGroup group(clock_of(10ms));
  rtc::Session& r0 = group.add(*a.drivers[0]);
  rtc::Session& r1 = group.add(*a.drivers[1]);
  group.start();
  auto n0 = std::make_shared<std::atomic<int>>(0);
  auto n1 = std::make_shared<std::atomic<int>>(0);
  r0.control([n0](rtc::Control&) { ++*n0; }, {});
  r1.control([n1](rtc::Control&) { ++*n1; }, {});
  group.wait_for(100ms);
  EXPECT_FALSE(r0.release().ended());
  const int at_release = *n0;
  group.wait_for(100ms);
  EXPECT_EQ(*n0, at_release) << "a released robot's functions ran";
  EXPECT_GE(*n1, 19);
  r0.control([n0](rtc::Control&) { ++*n0; }, {});
  group.wait_for(100ms);
  EXPECT_GE(*n0, at_release + 9);
  r0.release();
  r1.release();
}

TEST(SessionGroup, ACycleThatOverrunsEndsEveryRobotInIt) {
  Arms a(2);
  rtc::SessionGroup group(clock_of(10ms));
  rtc::Session& r0 = group.add(*a.drivers[0]);
  rtc::Session& r1 = group.add(*a.drivers[1]);
  group.start();
  // 6 ms each: alone each fits its 10 ms, together the cycle takes 12 ms.
  r0.control({}, [](rtc::Control& c) { c.spend(6ms); });
  group.wait_for(50ms);
  EXPECT_TRUE(r0.controlling());
  r1.control({}, [](rtc::Control& c) { c.spend(6ms); });
  group.wait_for(50ms);
  EXPECT_EQ(r0.termination().code, TerminateCode::overrun);
  EXPECT_EQ(r1.termination().code, TerminateCode::overrun);
  r0.release();
  r1.release();
}

TEST(SessionGroup, ThreadsDoNotGrowWithTheNumberOfRobots) {
  Arms small(2), large(64);
  const std::size_t before = threads_of_this_process();
  std::size_t with_two = 0, with_many = 0;
  {
    rtc::SessionGroup g(clock_of(1ms));
    for (auto& d : small.drivers) g.add(*d);
    g.start();
    for (std::size_t i = 0; i < g.size(); ++i) g[i].control({}, {});
    g.wait_for(20ms);
    with_two = threads_of_this_process() - before;
    for (std::size_t i = 0; i < g.size(); ++i) g[i].release();
  }
  {
    rtc::SessionGroup g(clock_of(1ms));
    for (auto& d : large.drivers) g.add(*d);
    g.start();
    for (std::size_t i = 0; i < g.size(); ++i) g[i].control({}, {});
    g.wait_for(20ms);
    with_many = threads_of_this_process() - before;
    for (std::size_t i = 0; i < g.size(); ++i) EXPECT_TRUE(g[i].controlling());
    for (std::size_t i = 0; i < g.size(); ++i) g[i].release();
  }
  EXPECT_EQ(with_many, with_two);
  // The two tasks and the Ctrl-C watcher (ThreadSanitizer adds one of its own).
  EXPECT_LE(with_many, 4U);
}

TEST(SessionGroup, EachRobotHasItsOwnEnvironmentLog) {
  const std::filesystem::path dir = ::testing::TempDir();
  const std::string base = (dir / "group_env_log.csv").string();
  Arms a(1, "puma560");
  Arms b(1, "stanford");
  ::setenv("RCCX_LOG", base.c_str(), 1);
  {
    rtc::SessionGroup group(clock_of(10ms));
    rtc::Session& p = group.add(*a.drivers[0]);
    rtc::Session& q = group.add(*b.drivers[0], 2);
    ::unsetenv("RCCX_LOG");
    group.start();
    p.control({}, {});
    q.control({}, {});
    group.wait_for(100ms);
    p.release();
    q.release();
  }
  for (const auto& [name, rows] : {std::pair{"puma560", 10}, std::pair{"stanford", 5}}) {
    const auto file = dir / ("group_env_log-" + std::string(name) + ".csv");
    std::ifstream in(file);
    ASSERT_TRUE(in.good()) << file;
    std::string line;
    int n = -2;  // the header line and the column line
    while (std::getline(in, line)) ++n;
    EXPECT_NEAR(n, rows, 1) << file;
    std::filesystem::remove(file);
  }
}

namespace {

/// The lines of a log: the header line, the column line, then the rows.
std::vector<std::string> lines_of(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

/// Column `k` (0: t) of a CSV row.
double column(const std::string& row, std::size_t k) {
  std::size_t pos = 0;
  for (std::size_t i = 0; i < k; ++i) pos = row.find(',', pos) + 1;
  return std::stod(row.substr(pos));
}

}  // namespace

TEST(SessionGroup, TwoRobotsOfOneModelLogTwoFilesEachWithItsOwnRows) {
  const std::filesystem::path dir = ::testing::TempDir();
  const std::string base = (dir / "twins.csv").string();
  Arms a(3, "puma560");
  ::setenv("RCCX_LOG", base.c_str(), 1);
  {
    rtc::SessionGroup group(clock_of(10ms));
    rtc::Session& left = group.add(*a.drivers[0], 1, "left");
    rtc::Session& right = group.add(*a.drivers[1], 2, "right");
    rtc::Session& third = group.add(*a.drivers[2]);  // no name: its model's
    EXPECT_THROW(group.add(*a.drivers[2], 1, "left"), rtc::SessionError) << "a name twice";
    ::unsetenv("RCCX_LOG");
    EXPECT_EQ(third.name(), "puma560");
    group.start();
    double q2 = 0.0;
    left.control(
        [&q2](rtc::Control& c) {  // only the left arm's joint 2 moves: 1 mrad a sample
          if (q2 == 0.0) q2 = c.how().joint[1].range;
          c.chg().posvel(1, q2 += 0.001);
        },
        {});
    right.control({}, {});
    third.control({}, {});
    group.wait_for(200ms);
  }
  std::map<std::string, std::vector<std::string>> logs;
  for (const char* name : {"left", "right", "puma560"}) {
    const auto file = dir / fmt::format("twins-{}.csv", name);
    logs[name] = lines_of(file);
    ASSERT_GT(logs[name].size(), 4U) << file;
    const auto header = rtc::LogHeader::parse(logs[name][0]);
    ASSERT_TRUE(header) << logs[name][0];
    EXPECT_EQ(header->robot, "puma560");
    EXPECT_EQ(header->name, name) << "each file's header names its robot";
    std::filesystem::remove(file);
  }
  EXPECT_FALSE(std::filesystem::exists(base)) << "no file for the group as a whole";
  EXPECT_EQ(rtc::LogHeader::parse(logs["right"][0])->period_ns, 20'000'000);
  // Every 10 ms sample of the left arm, every other one of the right: each file its own rows.
  EXPECT_NEAR(static_cast<double>(logs["left"].size() - 2), 20, 1);
  EXPECT_NEAR(static_cast<double>(logs["right"].size() - 2), 10, 1);
  const auto& l = logs["left"];
  const auto& r = logs["right"];
  EXPECT_GT(column(l.back(), 3) - column(l[2], 3), 0.015) << "the left arm's joint 2 moved";
  EXPECT_NEAR(column(r.back(), 3), column(r[2], 3), 1e-9) << "the right arm's did not";
}

TEST(SessionGroup, MisuseIsRefusedWithAReason) {
  Arms a(1);
  rtc::SessionGroup group(clock_of(10ms));
  EXPECT_THROW(group.start(), rtc::SessionError);  // no robot
  rtc::Session& s = group.add(*a.drivers[0]);
  EXPECT_THROW(s.control({}, {}), rtc::SessionError);  // not started
  EXPECT_THROW(group.add(*a.drivers[0], 0), rtc::SessionError);
  EXPECT_THROW(group.add(*a.drivers[0], 9), rtc::SessionError);  // 90 ms: beyond 56 ms
  group.start();
  EXPECT_THROW(group.add(*a.drivers[0]), rtc::SessionError);  // after start
  EXPECT_THROW(s.set_period(20ms), rtc::SessionError);
  EXPECT_THROW(rtc::SessionGroup(clock_of(100ms)), rtc::SessionError);
}

TEST(SessionGroup, TheCycleHookSeesEveryRobotsChgOfItsTick) {
  Arms a(2);
  rtc::SessionGroup group(clock_of(10ms));
  rtc::Session& r0 = group.add(*a.drivers[0]);
  rtc::Session& r1 = group.add(*a.drivers[1], 2);
  // Written by the control task only: f2 of each robot, then the hook, in the same tick.
  auto last_f2 = std::make_shared<std::array<std::uint64_t, 2>>();
  auto hooked = std::make_shared<std::vector<std::array<std::uint64_t, 3>>>();
  group.set_cycle_hook([=](std::uint32_t tick) {
    hooked->push_back({tick, (*last_f2)[0], (*last_f2)[1]});
  });
  group.start();
  r0.control({}, [=](rtc::Control& c) { (*last_f2)[0] = c.how().sample; });
  r1.control({}, [=](rtc::Control& c) { (*last_f2)[1] = c.how().sample; });
  group.wait_for(100ms);
  r0.release();
  r1.release();
  ASSERT_GE(hooked->size(), 8U);
  for (const auto& [tick, s0, s1] : *hooked) {
    EXPECT_EQ(s0, tick) << "robot 0's f2 of this tick ran before the hook";
    if ((tick - 1) % 2 == 0) {
      EXPECT_EQ(s1, tick) << "robot 1 is due at odd ticks";
    }
  }
}

TEST(SessionGroup, OneThreadRunsTheSameCyclesAsTwoTasks) {
  // The same commands on both: every robot's measured joints, sample by sample, identical; a
  // release and a fault in between act the same.
  const auto run = [](bool one_thread) {
    Arms a(3);
    rtc::SessionOptions o = clock_of(10ms);
    o.one_thread = one_thread;
    rtc::SessionGroup group(o);
    std::vector<rtc::Session*> s;
    for (auto& d : a.drivers) s.push_back(&group.add(*d));
    auto trace = std::make_shared<std::vector<double>>();  // the control functions' only
    group.set_cycle_hook([trace](std::uint32_t tick) { trace->push_back(tick); });
    group.start();
    for (std::size_t i = 0; i < s.size(); ++i) {
      s[i]->control(
          [i](rtc::Control& c) {
            // Joint 1 at 0.2 rad/s per robot index, one period ahead.
            c.chg().motion[0] = {rtc::SetMode::posvel,
                                 c.how().joint[0].range + 0.002 * static_cast<double>(i + 1), 0.0};
          },
          [trace](rtc::Control& c) {
            trace->push_back(c.how().joint[0].q);
            trace->push_back(c.how().time_s);
          });
    }
    group.wait_for(100ms);
    s[1]->release();
    group.wait_for(50ms);
    a.arms[2]->inject(hw::Fault::joint_not_answering, 1);
    group.wait_for(50ms);
    std::vector<double> ends;
    for (rtc::Session* x : s) ends.push_back(static_cast<double>(x->termination().code));
    ends.push_back(static_cast<double>(s[0]->how().sample));
    for (rtc::Session* x : s) x->release();
    return std::make_pair(*trace, ends);
  };
  const auto two = run(false);
  const auto one = run(true);
  ASSERT_GT(two.first.size(), 40U);
  EXPECT_EQ(one.first, two.first);
  EXPECT_EQ(one.second, two.second);
  EXPECT_EQ(two.second[2], static_cast<double>(TerminateCode::joint_not_answering));
}

TEST(SessionGroup, OneThreadStillEndsACycleThatOverruns) {
  Arms a(2);
  rtc::SessionOptions o = clock_of(10ms);
  o.one_thread = true;
  rtc::SessionGroup group(o);
  rtc::Session& r0 = group.add(*a.drivers[0]);
  rtc::Session& r1 = group.add(*a.drivers[1]);
  group.start();
  r0.control({}, [](rtc::Control& c) { c.spend(6ms); });
  r1.control({}, [](rtc::Control& c) { c.spend(6ms); });
  group.wait_for(50ms);
  EXPECT_EQ(r0.termination().code, TerminateCode::overrun);
  EXPECT_EQ(r1.termination().code, TerminateCode::overrun);
  r0.release();
  r1.release();
}

TEST(SessionGroup, OneThreadInRealTimeTakesALateTickAsNoSpeedViolation) {
  // One thread in real time: a stall of several periods makes the next tick come late. The
  // sample's time is its nominal one (a period after the last), so a setpoint planned along
  // How::time_s steps one period's worth: joint 1 at half its top speed stays within it (a step
  // over the 5 periods of the stall would be 2.5 times the top speed).
  Arms a(1);
  rtc::SessionOptions o;
  o.clock = rtc::ClockKind::real_time;
  o.real_time_scheduling = false;  // a test must not take a core from the others
  o.period = 2ms;
  o.one_thread = true;
  rtc::SessionGroup group(o);
  rtc::Session& s = group.add(*a.drivers[0]);
  group.start();
  const double top = kin::builtin_robot("puma560").joints[0].max_velocity;
  std::atomic<bool> stall{false};
  double start_range = -1.0, start_t = 0.0;
  s.control(
      [&](rtc::Control& c) {
        const rtc::How& h = c.how();
        if (start_range < 0.0) {
          start_range = h.joint[0].range;
          start_t = h.time_s;
        }
        c.chg().posvel(0, start_range + 0.5 * top * (h.time_s - start_t));
      },
      [&](rtc::Control& c) {
        if (stall.exchange(false)) c.spend(9ms);  // busy: the next ticks come late
      });
  std::this_thread::sleep_for(40ms);
  stall = true;
  std::this_thread::sleep_for(60ms);
  EXPECT_GE(group.latency().missed_deadlines, 3U);
  EXPECT_GE(group.latency().late_wakeups, 1U);
  EXPECT_LE(group.latency().late_wakeups, group.latency().missed_deadlines);
  EXPECT_FALSE(s.termination().ended())
      << rtc::to_string(s.termination().code) << ": " << s.termination().detail_view();
  s.release();
}
