// A workcell as a program sees it, wherever its robots run: cell::Cell runs them all in this
// process on one clock; net::RemoteCell commands robots that `rccx serve` processes run
// (docs/NETWORK.md). A program written against Workcell& (and rccl::Arm&) runs on both:
//
//   void present(cell::Workcell& c) {
//     rccl::Arm& puma = c.robot("puma");
//     const rccl::Motion m = puma.move(c.world_goal("puma", "OVER", over_board));
//     c.robot("microbo").move(probe, c.after("puma", m.end()));
//   }
//
// What follows from the cell file alone (bases, tools, goals in the world, objects) is said
// here once; what needs the robots (their arms, events, tool frames as they move) each kind of
// cell gives. Planning-level calls only; units m, rad, s.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/cell/cell_model.hpp"
#include "rccx/rccl/arm.hpp"
#include "rccx/rccl/motion_sync.hpp"
#include "rccx/rccl/transforms.hpp"

namespace rccx::cell {

class Workcell {
 public:
  virtual ~Workcell() = default;

  /// The cell file's model: robots, bases, tools, objects, frames.
  [[nodiscard]] virtual const CellModel& model() const noexcept = 0;
  /// Starts control of every robot (a remote cell: attaches to them).
  virtual void start() = 0;
  /// Lets `d` pass (simulated time: runs those ticks).
  virtual void wait_for(std::chrono::nanoseconds d) = 0;
  /// A robot's motion API. Throws std::invalid_argument naming the cell's robots for an
  /// unknown name.
  [[nodiscard]] virtual rccl::Arm& robot(std::string_view name) = 0;
  [[nodiscard]] virtual std::vector<std::string> robot_names() const = 0;
  /// A functional transform: `leader`'s commanded T6 TOOL in the world, extrapolated to the
  /// sample's time (reference "frame:<leader>", so that a serve process resolves it).
  [[nodiscard]] virtual rccl::TransformPtr tool_frame(std::string_view leader) const = 0;
  /// An event of `robot`'s motions for another robot's motion (StartWhen::after) or the
  /// program (waitfor) to wait for.
  [[nodiscard]] virtual rccl::EventGate event(std::string_view robot, const rccl::Event& e) = 0;
  /// Waits for every gate: reached; failed when one can no longer open; timeout;
  /// session_ended when no robot's control runs.
  virtual rccl::WaitResult waitfor(const std::vector<rccl::EventGate>& gates,
                                   std::chrono::nanoseconds timeout = std::chrono::hours(24)) = 0;

  // --- From the cell file alone ------------------------------------------------------------------
  /// world <- the robot's base frame, m. Throws std::invalid_argument for an unknown robot.
  [[nodiscard]] const math::Transform& base(std::string_view robot) const;
  /// A pose given in the world expressed in the robot's base frame: base^-1 world_pose.
  [[nodiscard]] math::Transform world_to_base(std::string_view robot,
                                              const math::Transform& world_pose) const;
  /// The robot's cell tool, T6 <- tool (m; identity without one), as the constant
  /// "<robot>_TOOL" (C's mnp_tool).
  [[nodiscard]] rccl::TransformPtr tool_transform(std::string_view robot) const;
  /// The robot's base <- world as the constant "<robot>_BASE_INV" (C's mnp_base_inv).
  [[nodiscard]] rccl::TransformPtr base_inv_transform(std::string_view robot) const;
  /// A goal in the world for the robot's tool, `T6 TOOL = BASE_INV GOAL...`: `world` the
  /// goal's product in the world (another robot's tool_frame, holds, constants), or one world
  /// pose (m) as the constant `name`.
  [[nodiscard]] rccl::PositionPtr world_goal(std::string_view robot, std::string name,
                                             const std::vector<rccl::TransformPtr>& world) const;
  [[nodiscard]] rccl::PositionPtr world_goal(std::string_view robot, std::string name,
                                             const math::Transform& world_pose) const;
  /// A world-frame transform in `robot`'s base frame (base^-1 T): constant for a constant T,
  /// functional for a functional one (not sendable to a serve process: use world_goal, which
  /// keeps the frame a term of its own). Throws std::invalid_argument for hold and T6.
  [[nodiscard]] rccl::TransformPtr in_base_of(std::string_view robot,
                                              const rccl::TransformPtr& world_transform) const;
  /// The objects (by name) a motion's tool may touch (StartWhen::touch). Throws
  /// std::invalid_argument naming the cell's objects for an unknown name, or past the 64th.
  [[nodiscard]] std::uint64_t objects(const std::vector<std::string>& names) const;
  /// What move() / dwell() take to let the motion's tool touch these objects.
  [[nodiscard]] rccl::StartWhen touching(const std::vector<std::string>& names) const;
  /// What move() / dwell() take to start once `robot`'s event has happened:
  /// `microbo.move(p, cell.after("puma", m.end()))`.
  [[nodiscard]] rccl::StartWhen after(std::string_view robot, const rccl::Event& e);

 protected:
  Workcell() = default;
  Workcell(const Workcell&) = default;
  Workcell& operator=(const Workcell&) = default;

 private:
  [[nodiscard]] const CellRobot& model_robot(std::string_view name) const;
};

}  // namespace rccx::cell
