// The teach loop on simulated robots, driven through a stream as an operator would type:
// moving a joint, jogging the tool in pendant mode, pushing the arm in zero gravity, saving
// to the database, and RCCL's teach(trans, pos) solving and storing a transform.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "rccx/math/units.hpp"
#include "rccx/rccl/teach.hpp"
#include "rccx/rtc/simulated_robot.hpp"
#include "temp_db.hpp"

namespace {

using namespace rccx;
using namespace rccx::math::literals;

using test::TempDb;

TEST(Teach, MoveAJointExamineAndSaveByName) {
  TempDb file;
  rccl::PositionDb db(file.path);
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  std::istringstream in("m 1 30\nxd\nsave PICK\nbogus\ne\n");
  std::ostringstream out;
  const rccl::Taught t = rccl::teach_loop(arm, {in, out, &db, {}});
  EXPECT_TRUE(t.ended_by_exit);
  EXPECT_EQ(t.failed_commands, 1U) << out.str();  // "bogus"
  EXPECT_FALSE(t.ok());
  EXPECT_NEAR(t.q[0], 30_deg, 0.2_deg) << out.str();
  const auto at = out.str().find("joints ");  // xd shows it, in deg
  ASSERT_NE(at, std::string::npos) << out.str();
  EXPECT_NEAR(std::stod(out.str().substr(at + 7)), 30.0, 0.2) << out.str();
  EXPECT_NE(out.str().find("unknown command \"bogus\""), std::string::npos) << out.str();
  const auto saved = db.get("puma560", "PICK");
  ASSERT_TRUE(saved);
  EXPECT_LT((saved->value.p - t.t6.p).norm(), 1e-3);
  EXPECT_FALSE(arm.stop_control().ended());
}

TEST(Teach, PendantJogsTheToolAlongABaseAxis) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  const math::Transform before = arm.kinematics().forward(robot.session->how().q());
  std::istringstream in("p\ns 10\nz+\nz+\nx-\nq\ne\n");
  std::ostringstream out;
  const math::Transform after = rccl::teach_t6(arm, {in, out, nullptr, {}});
  EXPECT_NEAR(after.p.z - before.p.z, 0.020, 5e-4) << out.str();
  EXPECT_NEAR(after.p.x - before.p.x, -0.010, 5e-4) << out.str();
  EXPECT_NEAR(dot(after.R.a, before.R.a), 1.0, 1e-4);  // orientation kept
  EXPECT_FALSE(arm.stop_control().ended());
}

TEST(Teach, ZeroGravityLetsAPushMoveTheArmAndItStays) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  const double q1 = robot.session->how().q()[0];
  std::istringstream in("Z\npush 1 80 0.3\nz\ne\n");  // the PUMA's gears need a firm push
  std::ostringstream out;
  const kin::JointVector q = rccl::teach_angles(
      arm, {in, out, nullptr, [&](std::size_t j, double e) { robot.push(j, e); }});
  EXPECT_GT(std::abs(q[0] - q1), 1_deg) << out.str();
  // Zero gravity is off again: the arm holds, and moves on command.
  robot.session->wait_for(std::chrono::milliseconds(500));
  EXPECT_NEAR(robot.session->how().q()[0], q[0], 0.2_deg);
  EXPECT_EQ(arm.waitfor(arm.move(arm.park()).end()), rccl::WaitResult::reached);
  EXPECT_FALSE(arm.stop_control().ended());
}

// teach(OBJ, T6 TOOL = BASE OBJ): taught, solved so the equation holds at the taught T6,
// stored under OBJ; a second teach finds it in the database and asks nothing.
TEST(Teach, TeachSolvesTheTransformAndLooksItUpNextTime) {
  TempDb file;
  rccl::PositionDb db(file.path);
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  const auto t6 = rccl::t6();
  const auto tool = rccl::constant("TOOL", math::Transform::translation(0, 0, 0.1));
  const auto base = rccl::constant("BASE", math::Transform::translation(0.1, 0, -0.2));
  const auto obj = rccl::hold("OBJ");
  const auto p = rccl::Position::make("P", {t6, tool}, {base, obj}, tool);
  std::istringstream in("m 2 60\ne\n");
  std::ostringstream out;
  const math::Transform value = rccl::teach(arm, *obj, *p, {in, out, &db, {}});
  const math::Transform T6 = arm.kinematics().forward(robot.session->how().q());
  EXPECT_LT((T6 * tool->value() * (base->value() * value).inverse()).p.norm(), 1e-9);
  EXPECT_LT((p->t6_now().p - T6.p).norm(), 1e-9);
  ASSERT_TRUE(db.get("puma560", "OBJ"));
  std::istringstream nothing("");
  std::ostringstream out2;
  const math::Transform again = rccl::teach(arm, *obj, *p, {nothing, out2, &db, {}});
  EXPECT_EQ(again.p.x, value.p.x);
  EXPECT_TRUE(out2.str().empty());
  EXPECT_FALSE(arm.stop_control().ended());
}

}  // namespace

namespace {

TEST(Teach, ExamineMotorParametersOnTheMicrobo) {
  rtc::SimulatedRobot robot(kin::builtin_robot("microbo"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  std::istringstream in("X 2\ne\n");
  std::ostringstream out;
  (void)rccl::teach_loop(arm, {in, out, nullptr, {}});
  // Joint 2's parameters as robots/microbo.json gives them: proportional gain 100 first.
  EXPECT_NE(out.str().find("joint 2 motor parameters: 100 "), std::string::npos) << out.str();
  EXPECT_FALSE(arm.stop_control().ended());
}

}  // namespace

namespace {

// A refused line moves nothing: `m 1.5 10` is not joint 1 (nor 1.5 read as 1).
TEST(Teach, ARefusedLineMovesNothingAndCounts) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  const kin::JointVector before = robot.session->how().q();
  std::istringstream in("m 1.5 10\nm 1 10 20\nm 1 1e9\np\ns 1e308\nq\ne\n");
  std::ostringstream out;
  const rccl::Taught t = rccl::teach_loop(arm, {in, out, nullptr, {}});
  EXPECT_TRUE(t.ended_by_exit);
  EXPECT_EQ(t.failed_commands, 4U) << out.str();
  EXPECT_FALSE(t.ok());
  for (std::size_t j = 0; j < 6; ++j) EXPECT_NEAR(t.q[j], before[j], 0.01_deg) << j;
  EXPECT_NE(out.str().find("\"1.5\" is not a joint"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("from 0.001 to 90 deg or mm"), std::string::npos) << out.str();
  EXPECT_FALSE(t.termination.ended());
  EXPECT_FALSE(arm.stop_control().ended());
}

// Control ended by a fault: said at once with the terminate code's meaning; motion refused
// from then on; the result carries the end.
TEST(Teach, AFaultEndsControlAndMotionIsRefusedAfterIt) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  const double q1 = robot.session->how().q()[0];
  std::istringstream in("push 2 1 0.1\nm 1 30\nh\nZ\ne\n");
  std::ostringstream out;
  // The "hand" injects a joint fault instead of pushing.
  const rccl::Taught t =
      rccl::teach_loop(arm, {in, out, nullptr, [&](std::size_t, double effort) {
                               if (effort != 0.0)
                                 robot.session->terminate(rtc::TerminateCode::joint_fault);
                             }});
  EXPECT_TRUE(t.termination.ended());
  EXPECT_EQ(t.termination.code, rtc::TerminateCode::joint_fault);
  EXPECT_FALSE(t.ok());
  EXPECT_EQ(t.failed_commands, 3U) << out.str();  // m, h, Z
  EXPECT_NEAR(t.q[0], q1, 0.01_deg) << out.str();
  const std::string said = out.str();
  EXPECT_NE(said.find("control has ended (joint_fault"), std::string::npos) << said;
  EXPECT_NE(said.find("motion commands are refused; e exits"), std::string::npos) << said;
  EXPECT_EQ(said.find("hand open"), std::string::npos) << said;
  EXPECT_EQ(said.find("the arm holds"), std::string::npos) << said;
}

// A pose with a joint beyond its limits is not saved: pushed past joint 1's upper limit in zero
// gravity, the arm ends control (observed_position) and stays there.
TEST(Teach, SaveRefusesAPoseBeyondTheJointLimits) {
  TempDb file;
  rccl::PositionDb db(file.path);
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  std::istringstream in("m 1 158\nZ\npush 1 60 0.5\nsave OUT\ne\n");
  std::ostringstream out;
  const rccl::Taught t =
      rccl::teach_loop(arm, {in, out, &db, [&](std::size_t j, double e) { robot.push(j, e); }});
  ASSERT_GT(t.q[0], kin::builtin_robot("puma560").joints[0].upper) << out.str();
  EXPECT_NE(out.str().find("beyond its upper limit 160.000 deg; nothing saved"), std::string::npos)
      << out.str();
  EXPECT_FALSE(db.get("puma560", "OUT"));
  EXPECT_TRUE(t.termination.ended());
}

// A bad name is refused before anything is written.
TEST(Teach, SaveRefusesABadNameAndExtraWords) {
  TempDb file;
  rccl::PositionDb db(file.path);
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  std::istringstream in("save PICK UP\nsave P/Q\ne\n");
  std::ostringstream out;
  const rccl::Taught t = rccl::teach_loop(arm, {in, out, &db, {}});
  EXPECT_EQ(t.failed_commands, 2U) << out.str();
  EXPECT_FALSE(db.get("puma560", "PICK"));
  EXPECT_TRUE(db.list().empty());
  EXPECT_FALSE(arm.stop_control().ended());
}

}  // namespace
