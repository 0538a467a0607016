// RobotMirror (src/rccx/net/mirror.hpp): another process's robot as its states tell it.
#include <gtest/gtest.h>

#include "rccx/net/mirror.hpp"

using namespace rccx;

namespace {

rccx_net_RobotState state(std::uint64_t instance, std::uint64_t started, std::uint64_t ended,
                          bool control_ended) {
  rccx_net_RobotState s{};
  s.instance = instance;
  s.dof = 6;
  s.started_upto = started;
  s.ended_upto = ended;
  s.control_ended = control_ended;
  s.tool.r[0] = s.tool.r[4] = s.tool.r[8] = 1.0;
  return s;
}

}  // namespace

TEST(NetMirror, AStoppedServesLastStateDoesNotEndTheRobotAnotherServeRuns) {
  net::RobotMirror m("puma");
  EXPECT_FALSE(m.apply(state(7, 3, 2, false), 1000));
  EXPECT_EQ(m.ledger.has_ended(3), rccl::GateAnswer::not_yet);
  // A serve process of the robot that stopped before this one took over says its last word
  // late: the gate on motion 3 must stay open to this instance's answer.
  EXPECT_FALSE(m.apply(state(5, 9, 9, true), 2000));
  EXPECT_FALSE(m.ledger.control_ended());
  EXPECT_EQ(m.ledger.started_upto(), 3U);
  EXPECT_EQ(m.ledger.has_ended(3), rccl::GateAnswer::not_yet);
  // This instance's own end does end it.
  EXPECT_FALSE(m.apply(state(7, 3, 2, true), 3000));
  EXPECT_EQ(m.ledger.has_ended(3), rccl::GateAnswer::never);
}

TEST(NetMirror, ARestartedServeIsANewInstanceAndItsLedgerStartsAgain) {
  net::RobotMirror m("puma");
  EXPECT_FALSE(m.apply(state(7, 3, 3, false), 1000));
  EXPECT_TRUE(m.apply(state(8, 1, 0, false), 2000));
  EXPECT_EQ(m.ledger.started_upto(), 1U);
  EXPECT_EQ(m.ledger.ended_upto(), 0U);
  EXPECT_FALSE(m.ledger.control_ended());
}
