// The view's sample feed: the tap on each robot's sample loop, and what the server's thread
// makes of what it taps. The communication task copies a fixed-size sample into a lock-free
// single-producer queue every 1/rate s of sample time (RobotTap::on_sample, decimated in the
// loop, so the copy costs nothing the other samples); it never waits, locks or allocates, and a
// full queue drops the sample (counted). Every tick the server's thread drains the queues
// (drain()), computes the tool frame and its speed, names the goal, keeps a history for pages
// that open late, and hands the new frames to the page sockets. Part of view::Server.
//
//   SampleFeed feed(scene, options.rate_hz, options.history, goals);
//   session.set_tap(&feed.tap(0));               // the loop side, scene robot 0
//   std::vector<nlohmann::json> fresh = feed.drain();  // server thread, every tick
#pragma once

#include <array>
#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <vector>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rtc/session.hpp"
#include "rccx/view/goals.hpp"
#include "rccx/view/scene.hpp"

namespace rccx::view::detail {

/// One tapped sample: fixed size, copied in the loop.
struct TapSample {
  double t_s = 0.0;
  std::int32_t segment = 0;
  std::uint8_t dof = 0;
  std::array<double, kin::kMaxJoints> q{};   ///< commanded, rad / m
  std::array<double, kin::kMaxJoints> qm{};  ///< measured, rad / m
  std::array<double, kin::kMaxJoints> qd{};  ///< measured speed, rad/s / m/s
};

/// What the communication task calls. Lock-free, allocation-free.
class RobotTap final : public rtc::SampleTap {
 public:
  explicit RobotTap(double interval_s) : interval_s_(interval_s) {}

  void on_sample(const rtc::How& how, const kin::JointVector& commanded,
                 std::int32_t segment) noexcept override;
  bool pop(TapSample& s) noexcept { return queue_.pop(s); }
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(); }

 private:
  double interval_s_;
  double next_t_s_ = -std::numeric_limits<double>::infinity();
  double last_t_s_ = -std::numeric_limits<double>::infinity();
  boost::lockfree::spsc_queue<TapSample, boost::lockfree::capacity<1024>> queue_;
  std::atomic<std::uint64_t> dropped_{0};
};

class SampleFeed {
 public:
  /// At most this many samples a robot a tick go to the pages (see drain()).
  static constexpr std::size_t kPerTick = 3;

  /// A tap for every robot of `scene`, made now, before the server's thread runs (attaching
  /// only hands it over), sampling every 1 / rate_hz s; `history` frames kept a robot.
  SampleFeed(const Scene& scene, double rate_hz, std::size_t history, std::shared_ptr<Goals> goals);

  [[nodiscard]] RobotTap& tap(std::size_t robot) { return *robots_.at(robot).tap; }
  /// Takes what the taps queued since the last tick: per robot, the frames that go on to the
  /// pages (as the page reads them: r, t, seg, q, qm, qd, p, v, goal). Server thread.
  std::vector<nlohmann::json> drain();
  /// The frames kept of `robot` for the pages that open late. Server thread.
  [[nodiscard]] const std::deque<nlohmann::json>& history(std::size_t robot) const {
    return robots_[robot].history;
  }
  /// The last frame of every robot (`robot` >= 0: of that one), as an array.
  [[nodiscard]] nlohmann::json latest(int robot) const;
  [[nodiscard]] std::size_t robots() const noexcept { return robots_.size(); }
  [[nodiscard]] std::uint64_t samples_sent() const noexcept { return samples_sent_.load(); }
  [[nodiscard]] std::uint64_t samples_dropped() const noexcept;

 private:
  struct Robot {
    std::unique_ptr<RobotTap> tap;
    std::unique_ptr<kin::Kinematics> kinematics;
    math::Transform base;  ///< world <- base
    math::Transform tool = math::Transform::identity();
    bool has_last = false;
    double last_t = 0.0;                 ///< s
    math::Vec3 last_p;                   ///< m, world
    std::deque<nlohmann::json> history;  ///< server thread only
    nlohmann::json latest;               ///< guarded by state_mutex_
  };
  /// The frame of sample `s` of robot `r`: its tool's place and speed, and its goal.
  nlohmann::json frame_of(std::size_t r, const TapSample& s);

  std::vector<Robot> robots_;
  std::size_t history_;
  std::shared_ptr<Goals> goals_;
  std::vector<TapSample> popped_;   ///< drain()'s, kept between ticks
  mutable std::mutex state_mutex_;  ///< latest (server thread vs planning level)
  std::atomic<std::uint64_t> samples_sent_{0};
};

}  // namespace rccx::view::detail
