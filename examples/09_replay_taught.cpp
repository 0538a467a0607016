// Example 09: load positions by name from the database and move through them.
//
// The transforms example 08 taught (A, B, C for the PUMA 560) come back as constant
// transforms of equations, T6 = A and so on, and the arm visits them in Cartesian mode, then
// parks. A name missing from the database is a clear error, before anything moves.
// Run: ./build/release/examples/09_replay_taught [FILE]     (after 08_teach; FILE: taught.db)
#include <fmt/format.h>

#include <string>

#include "rccx/rccl/manipulator.hpp"
#include "rccx/rccl/position_db.hpp"
#include "rccx/rtc/simulated_robot.hpp"

using namespace rccx;

int main(int argc, char** argv) {
  const std::string file = argc > 1 ? argv[1] : "taught.db";
  try {
    const rccl::PositionDb db(file, rccl::PositionDb::Open::existing);
    const auto t6 = rccl::t6();
    std::vector<rccl::PositionPtr> route;
    for (const char* name : {"A", "B", "C", "A"}) {
      route.push_back(rccl::Position::make(name, {t6}, {db.constant("puma560", name)}));
    }
    rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
    rccl::Manipulator arm(*robot.session);
    arm.start();
    arm.waitfor(arm.move(route.front()).end());  // joint mode to the first
    arm.set_mode(rccl::Mode::cartesian);
    std::vector<rccl::Motion> motions;
    for (std::size_t i = 1; i < route.size(); ++i) motions.push_back(arm.move(route[i]));
    const rccl::WaitResult w = arm.waitfor(arm.completed());
    arm.set_mode(rccl::Mode::joint);
    arm.waitfor(arm.move(arm.park()).end());
    for (std::size_t i = 0; i < motions.size(); ++i) {
      const rccl::SegmentReport r = arm.report(motions[i]);
      fmt::print("to {}: {:.2f} s, measured tool within {:.3f} mm of the line\n",
                 route[i + 1]->name(), r.end_s - r.start_s, r.max_measured_path_error_m * 1e3);
    }
    for (const auto& f : arm.failures()) fmt::print(stderr, "{}\n", f.message());
    const bool ok = w == rccl::WaitResult::reached && !arm.stop_control().ended();
    return robot.finish_logs("09_replay_taught") && ok ? 0 : 1;  // RCCX_LOG's log whole
  } catch (const rccl::DatabaseError& e) {
    fmt::print(stderr, "{}\n(run 08_teach first)\n", e.what());
    return 1;
  }
}
