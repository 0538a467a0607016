// The C compatibility layer (compat/rccl.h, compat/rtc.h): its error paths set rtc_error and a
// message and never abort; waitfor over POS.end and `completed` on the simulated Microbo.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "rccl.h"
#include "rtc.h"

namespace {

std::string message() {
  return rtc_error_message();
}

// Each test starts with no session and no error.
class Compat : public ::testing::Test {
 protected:
  void SetUp() override {
    rtc_error = RTC_OK;
    ::unsetenv("RCCX_ROBOT");
  }
  void TearDown() override {
    rccl_close(0);  // RTC_E_SEQUENCE when no session is open
    rcclRelease(0);
  }
};

TEST_F(Compat, MakepositionWithoutEqIsNullAndSaysHowToWriteIt) {
  TRSF_PTR b = gen_tr_rot("B", 325.0, 150.0, 300.0, xunit, 180.0);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(makeposition("P", t6, b, TL, t6), nullptr);
  EXPECT_EQ(rtc_error, RTC_E_EQUATION);
  EXPECT_NE(message().find("TL before EQ"), std::string::npos) << message();
  EXPECT_NE(message().find("makeposition(\"P1\", t6, EQ, b, TL, t6)"), std::string::npos);

  rtc_error = RTC_OK;
  EXPECT_EQ(makeposition("P", t6, EQ, nullptr, TL, t6), nullptr);
  EXPECT_EQ(rtc_error, RTC_E_EQUATION);
  EXPECT_NE(message().find("NULL"), std::string::npos) << message();

  // Well formed as a list, wrong as an equation: T6 on the right side.
  rtc_error = RTC_OK;
  EXPECT_EQ(makeposition("P", b, EQ, t6, TL, b), nullptr);
  EXPECT_EQ(rtc_error, RTC_E_EQUATION);
  EXPECT_NE(message().find("position P"), std::string::npos) << message();

  rtc_error = RTC_OK;
  POS_PTR p = makeposition("P", t6, EQ, b, TL, t6);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(rtc_error, RTC_OK);
  EXPECT_STREQ(p->name, "P");
  EXPECT_EQ(p->end, 1);
}

TEST_F(Compat, BadArgumentsAreRefused) {
  const VECT zero = {0.0, 0.0, 0.0};
  EXPECT_EQ(gen_tr_rot("Z", 0.0, 0.0, 0.0, zero, 90.0), nullptr);
  EXPECT_EQ(rtc_error, RTC_E_ARGUMENT);
  EXPECT_NE(message().find("axis is zero"), std::string::npos) << message();
  EXPECT_EQ(setvel(0, 100), RTC_E_ARGUMENT);
  EXPECT_EQ(setvel(100, -1), RTC_E_ARGUMENT);
  EXPECT_EQ(setmod('x'), RTC_E_ARGUMENT);
  EXPECT_EQ(settime(0, 0), RTC_E_ARGUMENT);
  EXPECT_EQ(settime(100, -1), RTC_E_ARGUMENT);
  EXPECT_EQ(move(nullptr), RTC_E_ARGUMENT);
  POS not_made_here{0, "fake", 0};
  EXPECT_EQ(move(&not_made_here), RTC_E_ARGUMENT);
  EXPECT_EQ(setvel(100, 100), RTC_OK);  // the defaults, for the tests after this one
  EXPECT_EQ(setmod('j'), RTC_OK);
  EXPECT_EQ(settime(200, 0), RTC_OK);
}

TEST_F(Compat, CallsOutOfOrderAreSequenceErrors) {
  EXPECT_EQ(rccl_close(0), RTC_E_SEQUENCE);
  EXPECT_EQ(rccl_control(), RTC_E_SEQUENCE);
  EXPECT_EQ(move(park), RTC_E_SEQUENCE);
  EXPECT_EQ(rccl_wait_sample(), RTC_E_SEQUENCE);
  int never = 0;
  waitfor(never);  // returns: nothing runs that could make it true
  EXPECT_EQ(rtc_error, RTC_E_SEQUENCE);

  ASSERT_EQ(rccl_open("microbo", 0), RTC_OK) << message();
  EXPECT_EQ(rccl_open("microbo", 0), RTC_E_SEQUENCE);
  EXPECT_EQ(move(park), RTC_E_SEQUENCE);  // before rccl_control
  ASSERT_EQ(rccl_control(), RTC_OK);
  EXPECT_EQ(rccl_control(), RTC_E_SEQUENCE);
  // The refused move() makes the session fail, for programs that check only rccl_close().
  EXPECT_EQ(rccl_close(0), RTC_E_SEQUENCE);
  EXPECT_NE(message().find("1 call(s) to queue a motion were refused"), std::string::npos)
      << message();
  EXPECT_EQ(rccl_close(0), RTC_E_SEQUENCE);  // closed all the same
  EXPECT_NE(message().find("no session is open"), std::string::npos) << message();
}

TEST_F(Compat, UnknownRobotAndBadPeriod) {
  EXPECT_EQ(rccl_open("no_such_robot", 0), RTC_E_ROBOT);
  EXPECT_NE(message().find("microbo"), std::string::npos) << message();  // lists the known
  ::setenv("RCCX_ROBOT", "no_such_robot", 1);
  EXPECT_EQ(rccl_open(nullptr, 0), RTC_E_ROBOT);
  ::unsetenv("RCCX_ROBOT");
  EXPECT_EQ(rccl_open(nullptr, 1000), RTC_E_OPEN);
  EXPECT_EQ(rccl_open(nullptr, -1), RTC_E_ARGUMENT);
}

TEST_F(Compat, WaitforEndAndCompletedOnTheSimulatedMicrobo) {
  TRSF_PTR b = gen_tr_rot("B", 325.0, 150.0, 300.0, xunit, 180.0);
  TRSF_PTR c = gen_tr_rot("C", 325.0, -150.0, 300.0, xunit, 180.0);
  TRSF_PTR far = gen_tr_rot("FAR", 3000.0, 0.0, 300.0, xunit, 180.0);
  POS_PTR p1 = makeposition("P1", t6, EQ, b, TL, t6);
  POS_PTR p2 = makeposition("P2", t6, EQ, c, TL, t6);
  POS_PTR unreachable = makeposition("FAR", t6, EQ, far, TL, t6);
  ASSERT_NE(p1, nullptr);
  ASSERT_NE(p2, nullptr);
  ASSERT_NE(unreachable, nullptr);

  ASSERT_EQ(rccl_open(nullptr, 0), RTC_OK) << message();
  ASSERT_EQ(rccl_control(), RTC_OK) << message();
  EXPECT_EQ(park->end, 1);
  EXPECT_EQ(completed, 1);

  ASSERT_EQ(move(park), RTC_OK) << message();
  EXPECT_EQ(park->end, 0);  // at once: nothing ran yet
  EXPECT_EQ(completed, 0);
  waitfor(park->end);
  EXPECT_EQ(park->end, 1);
  EXPECT_EQ(completed, 1);

  ASSERT_EQ(move(p1), RTC_OK) << message();
  waitfor(p1->end);
  ASSERT_EQ(setmod('c'), RTC_OK);
  ASSERT_EQ(move(p2), RTC_OK) << message();  // along the window's top edge
  ASSERT_EQ(move(p1), RTC_OK) << message();  // and back: joined by a transition
  EXPECT_EQ(p1->end, 0);
  EXPECT_EQ(p2->end, 0);
  waitfor(completed);
  EXPECT_EQ(p1->end, 1);
  EXPECT_EQ(p2->end, 1);
  EXPECT_EQ(setmod('j'), RTC_OK);

  rtc_error = RTC_OK;
  EXPECT_EQ(rccl_close(0), RTC_OK) << message();
  EXPECT_EQ(rtc_error, RTC_OK);
  EXPECT_EQ(park->end, 1);

  // A goal out of reach is refused at move(), queuing nothing; rccl_close() reports it.
  ASSERT_EQ(rccl_open(nullptr, 0), RTC_OK) << message();
  ASSERT_EQ(rccl_control(), RTC_OK) << message();
  EXPECT_EQ(move(unreachable), RTC_E_UNREACHABLE);
  EXPECT_NE(message().find("FAR"), std::string::npos) << message();
  EXPECT_EQ(unreachable->end, 1);
  EXPECT_EQ(completed, 1);
  EXPECT_EQ(rccl_close(0), RTC_E_UNREACHABLE);
  EXPECT_NE(message().find("position FAR cannot be reached"), std::string::npos) << message();
}

}  // namespace

TEST_F(Compat, TheCellsRobotHandlesRefuseWhatCannotWork) {
  EXPECT_EQ(rcclCreate("puma", 0), nullptr);
  EXPECT_EQ(rtc_error, RTC_E_SEQUENCE);
  EXPECT_EQ(rccl_cell_open("/nonexistent/cell.json"), RTC_E_ROBOT);
  EXPECT_NE(message().find("/nonexistent/cell.json"), std::string::npos) << message();
  ASSERT_EQ(rccl_cell_open(nullptr), RTC_OK) << message();  // the shipped CVaRL cell
  EXPECT_EQ(rccl_open("microbo", 0), RTC_E_SEQUENCE);
  EXPECT_EQ(rcclCreate("scara", 0), nullptr);
  EXPECT_EQ(rtc_error, RTC_E_ROBOT);
  EXPECT_NE(message().find("puma, microbo"), std::string::npos) << message();
  MANIP* puma = rcclCreate("puma", 0);
  MANIP* mbo = rcclCreate("microbo", 0);
  ASSERT_NE(puma, nullptr);
  ASSERT_NE(mbo, nullptr);
  EXPECT_EQ(rcclCreate("puma", 0), puma) << "one handle per robot";
  EXPECT_EQ(mnp_move(puma, mnp_park(puma)), RTC_E_SEQUENCE) << "before rcclStart";
  ASSERT_EQ(rcclStart(), RTC_OK) << message();
  EXPECT_EQ(mnp_setvel(nullptr, 10.0, 10.0), RTC_E_ARGUMENT);
  EXPECT_EQ(mnp_setmod(puma, 'x'), RTC_E_ARGUMENT);
  EXPECT_EQ(mnp_after(mbo, puma, 1, RCCL_END), RTC_E_ARGUMENT) << "puma has queued nothing";
  EXPECT_NE(message().find("mnp_last_motion"), std::string::npos) << message();
  EXPECT_EQ(move(park), RTC_E_SEQUENCE) << "the one-robot move() names no robot";
  EXPECT_NE(message().find("mnp_move"), std::string::npos) << message();
  EXPECT_EQ(rccl_together(0, puma, reinterpret_cast<MANIP*>(&rtc_error), nullptr), RTC_E_ARGUMENT);
  // What a motion may touch: the cell's objects, named; a typo is refused naming them.
  EXPECT_EQ(mnp_touch(mbo, "board, tabel"), RTC_E_ARGUMENT);
  EXPECT_NE(message().find("no object \"tabel\"; its objects: table, xy_stage, board"),
            std::string::npos)
      << message();
  EXPECT_EQ(mnp_touch(nullptr, "board"), RTC_E_ARGUMENT);
  EXPECT_EQ(mnp_touch(mbo, "board,xy_stage"), RTC_OK) << message();
  EXPECT_EQ(mnp_touch(mbo, ""), RTC_OK) << "none, as every motion starts";
  // A hand-off: the Microbo's park waits for the PUMA's park to end.
  ASSERT_EQ(mnp_move(puma, mnp_park(puma)), RTC_OK) << message();
  const int a = mnp_last_motion(puma);
  ASSERT_EQ(mnp_after(mbo, puma, a, RCCL_END), RTC_OK) << message();
  ASSERT_EQ(mnp_move(mbo, mnp_park(mbo)), RTC_OK) << message();
  const int b = mnp_last_motion(mbo);
  waitfor(mnp_ended(puma, a));
  EXPECT_EQ(mnp_started(mbo, b), 0);
  waitfor(mnp_completed(mbo));
  EXPECT_EQ(mnp_ended(mbo, b), 1);
  EXPECT_EQ(completed, 1);
  const int refused_code = rcclRelease(0);
  // The refused calls above are reported at the end, like rccl_close's.
  EXPECT_EQ(refused_code, RTC_E_SEQUENCE) << message();
  EXPECT_EQ(mnp_move(puma, mnp_park(puma)), RTC_E_ARGUMENT) << "handles die with the cell";
}
