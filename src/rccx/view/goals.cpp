#include "rccx/view/goals.hpp"

#include <algorithm>
#include <utility>

namespace rccx::view::detail {

Goals::Goals(const Scene& scene) {
  for (const SceneRobot& r : scene.robots) {
    kinematics_.push_back(kin::make_kinematics(r.model));
    base_.push_back(r.base);
    motion_frame_.emplace_back();
  }
}

void Goals::show(const rccl::Position& p, std::size_t robot, std::uint64_t motion) {
  math::Transform goal;
  if (p.in_joints()) {
    goal = kinematics_.at(robot)->forward(p.joint_values());
  } else if (p.fixed()) {
    goal = p.t6_now();
  } else {
    goal = p.t6_at({});
  }
  SceneFrame f{p.name(), base_.at(robot) * goal * p.tool_now(), p.describe(),
               static_cast<int>(robot)};
  std::lock_guard lock(mutex_);
  const auto same = std::find_if(frames_.begin(), frames_.end(), [&](const SceneFrame& g) {
    return g.robot == f.robot && g.name == f.name;
  });
  const std::size_t index = static_cast<std::size_t>(same - frames_.begin());
  if (same == frames_.end()) {
    frames_.push_back(std::move(f));
  } else {
    *same = std::move(f);
  }
  if (motion != 0) motion_frame_.at(robot)[motion] = index;
}

void Goals::add_frame(SceneFrame frame) {
  std::lock_guard lock(mutex_);
  frames_.push_back(std::move(frame));
}

std::string Goals::goal_of(std::size_t robot, std::uint64_t id) {
  if (id == 0) return {};
  std::lock_guard lock(mutex_);
  auto& m = motion_frame_[robot];
  m.erase(m.begin(), m.lower_bound(id));
  const auto it = m.find(id);
  return it == m.end() ? std::string() : frames_[it->second].name;
}

void Goals::copy_frames(std::vector<SceneFrame>& frames) const {
  std::lock_guard lock(mutex_);
  frames.insert(frames.end(), frames_.begin(), frames_.end());
}

}  // namespace rccx::view::detail
