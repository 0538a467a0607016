// Example 14: a UR5e hands a bar to a Franka Panda (cells/ur5e_panda.json). Both arms come from
// their makers' descriptions (robots/ur5e.json and robots/panda.json over their URDFs, docs/
// KINEMATICS.md "Robots from URDF"), each on the MuJoCo plant built from its URDF's inertias,
// both on the cell's one clock in simulated time. The UR5e is solved in closed form (its 8
// configurations), the 7-axis Panda in closed form given joint 7, which its Cartesian lines keep
// where it was.
//
// The lesson: a goal through another robot's frame, as RCCL wrote tracking. The UR5e presents
// the bar at the hand-over point; the Panda's grip is written on the UR5e's tool,
//
//     T6 PANDA_TOOL = BASE_INV(panda) UR5E_TOOL PANDA_GRIP        UR5E_TOOL =
//     cell.tool_frame("ur5e")
//
// (PANDA_GRIP: 160 mm along the bar, turned to face back), so it closes on the bar where the
// UR5e holds it, not where the program thought it would be.
//
//   1. The UR5e, bar in hand, swings to 100 mm short of the hand-over point and moves in along
//      a line; it holds the bar there.
//   2. When that motion has ended, the Panda comes in: a joint move to 80 mm behind its grip,
//      then a line onto the grip through the UR5e's frame, and closes its hand.
//   3. Both hold the bar for a second: what this program measures.
//   4. The UR5e opens its hand and backs off along its line; once it is clear, the Panda lifts
//      the bar 150 mm; both park.
//
// Measured during the hold, at every sample, on MuJoCo's own bodies (hw::MujocoArm::body_pose):
// each arm's flange against where its commanded joints put it (holding the pose against
// gravity), and the bar's end as each gripper has it (UR5e flange TOOL, Panda flange TOOL
// PANDA_GRIP^-1): how far apart the two hands hold the one bar. Exit 1 when a motion failed,
// the collision check stopped the arms, or an arm held its pose worse than 0.5 mm; 2 for a bad
// option.
// Run: ./build/release/examples/14_handover [--cell cells/ur5e_panda.json] [--speed 0.15]
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "rccx/cell/cell.hpp"
#include "rccx/hw/mujoco_arm.hpp"
#include "rccx/io/data_files.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/position.hpp"

namespace {

using namespace rccx;
using namespace std::chrono_literals;
using namespace rccx::math::literals;

constexpr double kHoldTolerance_m = 0.5e-3;  // issue 26: each arm holds its pose within 0.5 mm
constexpr double kBarLength_m = 0.160;       // between the two grips
constexpr auto kTimeout = 60s;

/// Tool z along +x of the world (the UR5e's, pointing at the Panda), fingers' x down.
math::Transform facing_plus_x(const math::Vec3& at) {
  return {math::Rot3::rot_y(90_deg), at};
}

/// Worst of a quantity over the samples it was measured at.
struct Worst {
  double value = 0.0;
  void add(double v) { value = std::max(value, v); }
};

/// Where each robot's MuJoCo flange is, against where its commanded joints put it, and the bar's
/// -x end as each hand has it, in the world.
class Measure {
 public:
  Measure(cell::Cell& c, const math::Transform& panda_grip)
      : c_(c), grip_inverse_(panda_grip.inverse()) {
    for (const char* name : {"ur5e", "panda"}) {
      auto* mj = dynamic_cast<hw::MujocoArm*>(c.hardware(name).arm.get());
      if (mj == nullptr) {
        throw std::invalid_argument(
            fmt::format("robot {} is not on the MuJoCo plant (its robot file's \"plant\")", name));
      }
      (name[0] == 'u' ? ur_ : panda_) = mj;
    }
  }

  /// Lets `seconds` pass one tick at a time, measuring at each.
  void hold(double seconds) {
    const auto ticks =
        static_cast<long>(seconds / std::chrono::duration<double>(c_.model().base_period).count());
    for (long k = 0; k < ticks; ++k) {
      c_.wait_for(c_.model().base_period);
      ur_hold_.add(hold_error("ur5e", *ur_));
      panda_hold_.add(hold_error("panda", *panda_));
      const math::Vec3 ur_end = (flange_in_world("ur5e", *ur_) * tool("ur5e")).p;
      const math::Transform panda_hand = flange_in_world("panda", *panda_) * tool("panda");
      gap_.add((ur_end - (panda_hand * grip_inverse_).p).norm());
      ++samples_;
    }
  }

  void print() const {
    fmt::print("hold, {} samples of {} ms on MuJoCo's bodies:\n", samples_,
               std::chrono::duration<double, std::milli>(c_.model().base_period).count());
    fmt::print("  UR5e flange from its commanded pose:  worst {:.4f} mm\n", ur_hold_.value * 1e3);
    fmt::print("  Panda flange from its commanded pose: worst {:.4f} mm\n",
               panda_hold_.value * 1e3);
    fmt::print("  the bar's end as each hand holds it:  worst {:.4f} mm apart\n", gap_.value * 1e3);
  }
  [[nodiscard]] bool held() const {
    return samples_ > 0 && ur_hold_.value <= kHoldTolerance_m &&
           panda_hold_.value <= kHoldTolerance_m;
  }

 private:
  [[nodiscard]] math::Transform tool(const char* robot) const {
    const cell::CellRobot& r = *c_.model().find_robot(robot);
    return r.tool ? *r.tool : math::Transform::identity();
  }
  [[nodiscard]] math::Transform flange_in_world(const char* robot, const hw::MujocoArm& mj) const {
    return c_.model().find_robot(robot)->base * mj.body_pose("tool");
  }
  /// |MuJoCo's flange - FK(the joints the servos are commanded to)|, in the robot's base.
  [[nodiscard]] double hold_error(const char* robot, const hw::MujocoArm& mj) const {
    const kin::Kinematics& k = c_.robot(robot).kinematics();
    kin::JointVector setpoint(k.dof());
    for (std::size_t j = 0; j < k.dof(); ++j) setpoint[j] = mj.setpoint(j);
    return (mj.body_pose("tool").p - k.forward(setpoint).p).norm();
  }

  cell::Cell& c_;
  math::Transform grip_inverse_;
  hw::MujocoArm* ur_ = nullptr;
  hw::MujocoArm* panda_ = nullptr;
  Worst ur_hold_, panda_hold_, gap_;
  long samples_ = 0;
};

int run(cell::Cell& c, double speed_m_per_s) {
  const cell::CellFrame* handover = c.model().find_frame("handover");
  if (handover == nullptr || c.model().find_robot("ur5e") == nullptr ||
      c.model().find_robot("panda") == nullptr) {
    fmt::print(stderr, "14_handover: the cell needs robots ur5e and panda and a frame handover\n");
    return 2;
  }
  // The bar lies along x, its centre on the hand-over frame; the UR5e's hand at its -x end.
  const math::Vec3 centre = handover->pose.p;
  const math::Transform ur_at = facing_plus_x(centre - math::Vec3{kBarLength_m / 2, 0, 0});
  const math::Transform ur_short = facing_plus_x(centre - math::Vec3{kBarLength_m / 2 + 0.1, 0, 0});
  // The Panda's hand at the +x end, facing back (half a turn about the hand's x).
  const math::Transform panda_grip{math::Rot3::rot_x(180_deg), {0, 0, kBarLength_m}};
  const math::Transform panda_back = panda_grip * math::Transform::translation(0, 0, -0.080);
  // Where the Panda takes the bar: 150 mm up (the hand's x is down).
  const math::Transform panda_aside =
      ur_at * panda_grip * math::Transform::translation(-0.150, 0.0, 0.0);

  Measure measure(c, panda_grip);  // throws for a robot not on MuJoCo
  c.start();
  rccl::Arm& ur = c.robot("ur5e");
  rccl::Arm& panda = c.robot("panda");

  const auto ur_short_p = c.world_goal("ur5e", "UR_SHORT", ur_short);
  const auto ur_present = c.world_goal("ur5e", "UR_PRESENT", ur_at);
  const auto ur_frame = c.tool_frame("ur5e");
  const auto panda_back_p =
      c.world_goal("panda", "PANDA_BACK", {ur_frame, rccl::constant("BACK", panda_back)});
  const auto panda_grip_p =
      c.world_goal("panda", "PANDA_GRIP", {ur_frame, rccl::constant("GRIP", panda_grip)});
  // Where the Panda swings to first, in joints' terms: its grip's approach as the program
  // expects the UR5e to present the bar (a constant: joint moves go to fixed goals).
  const auto panda_near = c.world_goal("panda", "PANDA_NEAR", ur_at * panda_back);
  const auto panda_aside_p = c.world_goal("panda", "PANDA_ASIDE", panda_aside);
  fmt::print("{}\n", panda_grip_p->describe());

  bool good = true;
  const auto wait = [&](rccl::Arm& arm, const rccl::Event& e, const char* what) {
    if (!good) return;
    const rccl::WaitResult w = arm.waitfor(e, kTimeout);
    if (w == rccl::WaitResult::reached) return;
    good = false;
    fmt::print(stderr, "14_handover: {}: {}\n", what, rccl::to_string(w));
  };

  // 1. The UR5e presents the bar.
  ur.set_velocity(speed_m_per_s, 60_deg);
  panda.set_velocity(speed_m_per_s, 60_deg);
  ur.set_hand(true);
  ur.move(ur_short_p);
  ur.set_mode(rccl::Mode::cartesian);
  const rccl::Motion present = ur.move(ur_present);

  // 2. The Panda comes in once the bar is there, onto the UR5e's frame. Its swing is queued now
  // and starts at the sample after the UR5e's motion ends; the lines through the UR5e's frame
  // are queued once the bar is there (a goal is checked for reach as it is when queued).
  panda.move(panda_near, c.after("ur5e", present.end()));
  wait(ur, present.end(), "the UR5e's presentation");
  panda.set_mode(rccl::Mode::cartesian);
  panda.move(panda_back_p);
  // The last 80 mm slowly: the hands come within 70 mm of each other (their capsules), and the
  // collision check's braking allowance grows with speed.
  panda.set_velocity(0.02, 20_deg);
  const rccl::Motion grip = panda.move(panda_grip_p);
  // Once it holds the bar, the Panda stops following the UR5e's frame (an arm at rest after a
  // motion to a moving goal keeps tracking it, as RCCL's did): the grip's pose as a constant.
  const auto panda_hold = c.world_goal("panda", "PANDA_HOLD", ur_at * panda_grip);
  const rccl::Motion still = panda.move(panda_hold);
  wait(panda, grip.end(), "the Panda's grip");
  panda.set_hand(true);
  wait(panda, still.end(), "the Panda's hold");

  // 3. Both hold the bar.
  if (good) measure.hold(1.0);

  // 4. The UR5e lets go and backs off; the Panda carries the bar aside; both park.
  ur.set_hand(false);
  ur.set_velocity(0.02, 20_deg);  // slowly out of the Panda's hand too
  const rccl::Motion back_off = ur.move(ur_short_p, c.after("panda", still.end()));
  ur.set_velocity(speed_m_per_s, 60_deg);
  panda.set_velocity(speed_m_per_s, 60_deg);
  panda.move(panda_aside_p, c.after("ur5e", back_off.end()));
  ur.set_mode(rccl::Mode::joint);
  ur.move(ur.park());
  panda.set_mode(rccl::Mode::joint);
  panda.move(panda.park());
  wait(ur, rccl::Arm::completed(), "the UR5e's motions");
  wait(panda, rccl::Arm::completed(), "the Panda's motions");

  measure.print();
  std::size_t failures = 0;
  for (rccl::Arm* arm : {&ur, &panda}) {
    for (const rccl::MotionEvent& f : arm->failures()) {
      fmt::print(stderr, "14_handover: {}: motion {} {} at {:.3f} s{}{}\n",
                 arm == &ur ? "UR5e" : "Panda", f.id, rccl::to_string(f.kind), f.t_s,
                 f.message().empty() ? "" : ": ", f.message());
      ++failures;
    }
  }
  fmt::print("collision stops: {}\n", c.collision_stops());
  if (!good || failures > 0 || c.collision_stops() > 0) {
    fmt::print(stderr, "14_handover: the hand-over did not run through\n");
    return 1;
  }
  if (!measure.held()) {
    fmt::print(stderr, "14_handover: an arm held its pose worse than {:.1f} mm\n",
               kHoldTolerance_m * 1e3);
    return 1;
  }
  fmt::print("the bar changed hands\n");
  return c.finish_logs("14_handover") ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "A UR5e hands a bar to a Franka Panda (cells/ur5e_panda.json), both from their URDFs on "
      "MuJoCo plants, in simulated time; measures how well each arm holds its pose against "
      "gravity during the hand-over."};
  std::string cell_path;
  double speed = 0.15;
  app.add_option("--cell", cell_path,
                 "the cell file (default: cells/ur5e_panda.json under $RCCX_DATA_DIR, else the "
                 "installed share/rccx or the source tree)")
      ->check(CLI::ExistingFile);
  app.add_option("--speed", speed, "tool speed of every motion, m/s")
      ->check(CLI::Range(0.02, 0.5))
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    if (cell_path.empty()) cell_path = io::find_data_file("cells/ur5e_panda.json").string();
  } catch (const io::DataFileError& e) {
    std::fprintf(stderr, "14_handover: %s, or give --cell FILE\n", e.what());
    return 2;
  }
  try {
    const std::unique_ptr<cell::Cell> c = cell::Cell::load(cell_path);
    return run(*c, speed);
  } catch (const std::exception& e) {  // a bad cell file, a robot that cannot be simulated
    std::fprintf(stderr, "14_handover: %s\n", e.what());
    return 2;
  }
}
