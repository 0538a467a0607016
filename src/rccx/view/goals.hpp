// The frames the program adds to the view (Server::add_frame, Server::show, the goals of an
// attached arm's moves) and which goal each queued motion goes to. Written at the planning
// level, read by the server's thread (the scene it serves, the "goal" of each sample), under one
// mutex. The arms' move observers hold it weakly: an arm that outlives the server finds it gone.
// Part of view::Server (server.cpp).
//
//   auto goals = std::make_shared<Goals>(scene);   // before any thread shares it
//   goals->show(*position, robot, motion.id);      // planning level: draw it, remember the motion
//   std::string name = goals->goal_of(robot, id);  // server thread: where sample's motion goes
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/position.hpp"
#include "rccx/view/scene.hpp"

namespace rccx::view::detail {

class Goals {
 public:
  /// The solvers and bases of the scene's robots (the solvers keep no state).
  explicit Goals(const Scene& scene);

  /// The world pose of `p`'s goal (the tool frame where the equation puts it) for `robot`,
  /// drawn and named; the same name for the same robot moves its frame. `motion` != 0: the
  /// motion that goes there.
  void show(const rccl::Position& p, std::size_t robot, std::uint64_t motion);
  /// A named frame (world <- frame) to draw.
  void add_frame(SceneFrame frame);
  /// The name of the goal motion `id` of `robot` goes to, empty when not known; forgets the
  /// motions before it (a generator runs its motions in the order of their ids). Server thread.
  std::string goal_of(std::size_t robot, std::uint64_t id);
  /// Appends the frames added so far to `frames`.
  void copy_frames(std::vector<SceneFrame>& frames) const;

 private:
  mutable std::mutex mutex_;
  std::vector<SceneFrame> frames_;
  /// Per scene robot: motion id -> index in frames_, for the motions not yet past.
  std::vector<std::map<std::uint64_t, std::size_t>> motion_frame_;
  /// Per scene robot, fixed at construction.
  std::vector<std::unique_ptr<kin::Kinematics>> kinematics_;
  std::vector<math::Transform> base_;
};

}  // namespace rccx::view::detail
