#include "rccx/view/sample_feed.hpp"

#include <algorithm>
#include <span>
#include <string>
#include <utility>

namespace rccx::view::detail {

using json = nlohmann::json;

void RobotTap::on_sample(const rtc::How& how, const kin::JointVector& commanded,
                         std::int32_t segment) noexcept {
  if (how.time_s + 1e-9 < next_t_s_ && how.time_s >= last_t_s_) return;  // decimated
  last_t_s_ = how.time_s;
  next_t_s_ = how.time_s + interval_s_;
  TapSample s;
  s.t_s = how.time_s;
  s.segment = segment;
  s.dof = how.dof;
  for (std::size_t i = 0; i < how.dof; ++i) {
    s.q[i] = commanded[i];
    s.qm[i] = how.joint[i].q;
    s.qd[i] = how.joint[i].velocity;
  }
  if (!queue_.push(s)) dropped_.fetch_add(1, std::memory_order_relaxed);
}

SampleFeed::SampleFeed(const Scene& scene, double rate_hz, std::size_t history,
                       std::shared_ptr<Goals> goals)
    : history_(history), goals_(std::move(goals)) {
  for (const SceneRobot& r : scene.robots) {
    Robot rs;
    rs.kinematics = kin::make_kinematics(r.model);
    rs.tap = std::make_unique<RobotTap>(1.0 / rate_hz);
    rs.base = r.base;
    if (r.tool) rs.tool = *r.tool;
    robots_.push_back(std::move(rs));
  }
}

std::vector<json> SampleFeed::drain() {
  std::vector<json> per_robot(robots_.size(), json::array());
  for (std::size_t r = 0; r < robots_.size(); ++r) {
    Robot& rs = robots_[r];
    // What came since the last tick. Simulated time runs many times faster than the clock
    // on the wall: then only a few of them, evenly spaced and the newest among them, go on
    // (a page takes about the rate a second; the server's work stays as small as in real
    // time, and so does what it takes from the processors the loop runs on).
    popped_.clear();
    TapSample one;
    while (rs.tap->pop(one)) popped_.push_back(one);
    samples_sent_.fetch_add(popped_.size(), std::memory_order_relaxed);
    const std::size_t every = (popped_.size() + kPerTick - 1) / kPerTick;
    for (std::size_t k = 0; k < popped_.size(); ++k) {
      if ((popped_.size() - 1 - k) % std::max<std::size_t>(every, 1) != 0) continue;
      json f = frame_of(r, popped_[k]);
      rs.history.push_back(f);
      while (rs.history.size() > history_) rs.history.pop_front();
      per_robot[r].push_back(std::move(f));
    }
    if (!per_robot[r].empty()) {
      std::lock_guard lock(state_mutex_);
      rs.latest = per_robot[r].back();
    }
  }
  return per_robot;
}

json SampleFeed::frame_of(std::size_t r, const TapSample& s) {
  Robot& rs = robots_[r];
  kin::JointVector q(std::span<const double>(s.q.data(), s.dof));
  const math::Transform pose = rs.base * rs.kinematics->forward(q) * rs.tool;
  double speed = 0.0;
  if (rs.has_last && s.t_s > rs.last_t) {
    speed = (pose.p - rs.last_p).norm() / (s.t_s - rs.last_t);
  }
  rs.has_last = true;
  rs.last_t = s.t_s;
  rs.last_p = pose.p;
  json f = {{"r", r},
            {"t", s.t_s},
            {"seg", s.segment},
            {"q", std::vector<double>(s.q.begin(), s.q.begin() + s.dof)},
            {"qm", std::vector<double>(s.qm.begin(), s.qm.begin() + s.dof)},
            {"qd", std::vector<double>(s.qd.begin(), s.qd.begin() + s.dof)},
            {"p", {pose.p.x, pose.p.y, pose.p.z}},
            {"v", speed}};
  if (std::string goal = goals_->goal_of(r, static_cast<std::uint64_t>(std::max(0, s.segment)));
      !goal.empty()) {
    f["goal"] = std::move(goal);
  }
  return f;
}

json SampleFeed::latest(int robot) const {
  json out = json::array();
  std::lock_guard lock(state_mutex_);
  for (std::size_t r = 0; r < robots_.size(); ++r) {
    if (robot >= 0 && static_cast<int>(r) != robot) continue;
    out.push_back(robots_[r].latest);
  }
  return out;
}

std::uint64_t SampleFeed::samples_dropped() const noexcept {
  std::uint64_t dropped = 0;
  for (const Robot& r : robots_) dropped += r.tap->dropped();
  return dropped;
}

}  // namespace rccx::view::detail
