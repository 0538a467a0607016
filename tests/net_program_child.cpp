// A program to kill: opens the cell across processes, starts a long joint motion of one robot,
// says "moving <motion id>" on stdout and waits to be killed (net_serve_test's lost program).
//
//   rccx_net_program_child CELL_FILE DOMAIN DETECTION_MS ROBOT
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <thread>

#include "rccx/cell/cell_model.hpp"
#include "rccx/net/remote_cell.hpp"

int main(int argc, char** argv) {
  using namespace rccx;
  if (argc != 5) {
    std::fprintf(stderr, "usage: %s CELL_FILE DOMAIN DETECTION_MS ROBOT\n", argv[0]);
    return 2;
  }
  try {
    net::NetOptions o;
    o.domain = static_cast<std::uint32_t>(std::atoi(argv[2]));
    o.interface = "lo";
    o.detection = std::chrono::milliseconds(std::atoi(argv[3]));
    o.heartbeat = o.detection / 4;
    net::RemoteOptions ro;
    ro.robots = {argv[4]};
    net::RemoteCell cell(cell::load_cell_file(argv[1]), o, ro);
    net::RemoteArm& arm = cell.robot(argv[4]);
    kin::JointVector q = arm.state().q_commanded;
    q[0] += 1.0;  // a long turn of the first joint (rad)
    q[1] += 0.3;
    const rccl::Motion m = arm.move(rccl::Position::joints("FAR", q));
    std::printf("moving %llu\n", static_cast<unsigned long long>(m.id));
    std::fflush(stdout);
    for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rccx_net_program_child: %s\n", e.what());
    return 1;
  }
}
