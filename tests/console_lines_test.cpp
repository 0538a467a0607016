// The console line readers, table-driven: each line is either read as the command it names or
// refused with a message that says what is wrong (the substring given).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "console_lines.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/math/units.hpp"
#include "rccx/rccl/teach.hpp"

namespace {

using namespace rccx;
using Kind = rccl::TeachCommand::Kind;

struct TeachCase {
  const char* line;
  bool pendant;
  Kind kind;          ///< when accepted
  const char* error;  ///< nullptr: accepted; else a substring of the message
};

TEST(ConsoleLines, TeachLinesAreReadWholeAndInRange) {
  const kin::RobotModel puma = kin::builtin_robot("puma560");
  const std::vector<TeachCase> cases = {
      {"", false, Kind::none, nullptr},
      {"  \t\r", false, Kind::none, nullptr},
      {"m 1 20", false, Kind::move_joint, nullptr},
      {"m 1 20\r", false, Kind::move_joint, nullptr},  // a line from a Windows file
      {"m 1.5 10", false, Kind::none, "is not a joint of this robot; its joints are 1 to 6"},
      {"m 7 10", false, Kind::none, "its joints are 1 to 6"},
      {"m 0 10", false, Kind::none, "its joints are 1 to 6"},
      {"m 1 5abc", false, Kind::none, "\"5abc\" is not a number"},
      {"m 1 500", false, Kind::none, "give a number from -160 to 160 deg"},
      {"m 1 nan", false, Kind::none, "is not a number"},
      {"m 1 1e400", false, Kind::none, "too large"},
      {"m 1", false, Kind::none, "a value is missing"},
      {"m 1 10 20", false, Kind::none, "\"20\" is one word too many"},
      {"push 1 80 0.3", false, Kind::push, nullptr},
      {"push 1 80 300ms", false, Kind::push, nullptr},
      {"push 1 inf 1", false, Kind::none, "is not a number"},
      {"push 1 1e6 1", false, Kind::none, "give a number from -1000 to 1000 N m or N"},
      {"push 1 1 1e5", false, Kind::none, "from 0.001 to 600 s"},
      {"push 1 1 0", false, Kind::none, "out of range"},
      {"push 1 1 -1", false, Kind::none, "out of range"},
      {"save PICK", false, Kind::save, nullptr},
      {"save PICK UP", false, Kind::none, "\"UP\" is one word too many"},
      {"save P!CK", false, Kind::none, "save: the name"},
      {"save", false, Kind::none, "a value is missing"},
      {"save AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA", false, Kind::none, "at most 32"},
      {"X 2", false, Kind::motor_parameters, nullptr},
      {"X", false, Kind::none, "missing"},
      {"xd", false, Kind::examine_deg, nullptr},
      {"xd now", false, Kind::none, "one word too many"},
      {"e", false, Kind::exit, nullptr},
      {"e 1", false, Kind::none, "one word too many"},
      {"Z", false, Kind::zero_gravity_on, nullptr},
      {"bogus", false, Kind::none, "unknown command \"bogus\""},
      {"m\x01 1 2", false, Kind::none, "\\x01"},
      {"1+", false, Kind::none, "unknown command"},  // only in pendant mode
      // pendant mode
      {"1+", true, Kind::jog_joint, nullptr},
      {"6-", true, Kind::jog_joint, nullptr},
      {"7+", true, Kind::none, "its joints are 1 to 6"},
      {"1.5+", true, Kind::none, "its joints are 1 to 6"},
      {"rz-", true, Kind::turn_tool, nullptr},
      {"x+", true, Kind::jog_tool, nullptr},
      {"rw+", true, Kind::none, "is not a pendant command"},
      {"x+ 3", true, Kind::none, "one word too many"},
      {"+", true, Kind::none, "is not a pendant command"},
      {"s 2", true, Kind::set_step, nullptr},
      {"s 1e308", true, Kind::none, "from 0.001 to 90 deg or mm"},
      {"s 0", true, Kind::none, "out of range"},
      {"s -5", true, Kind::none, "out of range"},
      {"s", true, Kind::none, "missing"},
      {"q", true, Kind::leave_pendant, nullptr},
      {"e", true, Kind::exit, nullptr},
  };
  for (const TeachCase& c : cases) {
    SCOPED_TRACE(c.line);
    if (c.error == nullptr) {
      EXPECT_EQ(rccl::parse_teach_command(c.line, puma, c.pendant).kind, c.kind);
    } else {
      try {
        (void)rccl::parse_teach_command(c.line, puma, c.pendant);
        ADD_FAILURE() << "accepted";
      } catch (const io::ParseError& e) {
        EXPECT_NE(std::string(e.what()).find(c.error), std::string::npos) << e.what();
      }
    }
  }
}

TEST(ConsoleLines, TeachValuesAreInSiAndTheJointIsAnIndex) {
  const kin::RobotModel microbo = kin::builtin_robot("microbo");
  const rccl::TeachCommand m = rccl::parse_teach_command("m 1 20", microbo, false);
  EXPECT_EQ(m.joint, 0U);
  EXPECT_NEAR(m.value, math::deg_to_rad(20), 1e-12);
  // The Microbo's joint 3 is prismatic: mm.
  const double lower_mm = microbo.joints[2].lower * 1e3;
  const rccl::TeachCommand d =
      rccl::parse_teach_command(fmt::format("m 3 {}", lower_mm + 1), microbo, false);
  EXPECT_NEAR(d.value, microbo.joints[2].lower + 1e-3, 1e-9);
  const rccl::TeachCommand push = rccl::parse_teach_command("push 2 -5 250ms", microbo, false);
  EXPECT_EQ(push.joint, 1U);
  EXPECT_EQ(push.value, -5.0);
  EXPECT_NEAR(push.seconds, 0.25, 1e-12);
  EXPECT_EQ(rccl::parse_teach_command("save PICK", microbo, false).name, "PICK");
  const rccl::TeachCommand jog = rccl::parse_teach_command("ry-", microbo, true);
  EXPECT_EQ(jog.axis, 1U);
  EXPECT_EQ(jog.sign, -1);
}

struct JointtestCase {
  const char* line;
  char letter;        ///< when accepted
  const char* error;  ///< nullptr: accepted
};

TEST(ConsoleLines, JointtestLinesAreReadWholeAndInRange) {
  const kin::RobotModel puma = kin::builtin_robot("puma560");
  const std::vector<JointtestCase> cases = {
      {"", '\0', nullptr},
      {"j 2", 'j', nullptr},
      {"j 2.5", '\0', "its joints are 1 to 6"},
      {"j 9", '\0', "its joints are 1 to 6"},
      {"m 60", 'm', nullptr},
      {"m 500", 'm', nullptr},  // beyond the limit on purpose: RTC's limit check answers
      {"m 5abc", '\0', "\"5abc\" is not a number"},
      {"m 1e308", '\0', "out of range"},
      {"M inf", '\0', "is not a number"},
      {"m", '\0', "a value is missing"},
      {"v 20", 'v', nullptr},
      {"v 0", '\0', "out of range"},
      {"v -5", '\0', "out of range"},
      {"v 1e9", '\0', "deg/s"},
      {"w 3", 'w', nullptr},
      {"w 500ms", 'w', nullptr},
      {"w 1e10", '\0', "out of range; give a duration from 0 to 1e+06 s"},
      {"w -1", '\0', "out of range"},
      {"w", '\0', "missing"},
      {"r 28", 'r', nullptr},
      {"r 250us", 'r', nullptr},
      {"r 0.1", '\0', "0.25 to 56 ms"},
      {"r 100", '\0', "0.25 to 56 ms"},
      {"o 3", 'o', nullptr},
      {"O 16", '\0', "from 0 to 15"},
      {"O 3.5", '\0', "not a whole number"},
      {"a 65535", 'a', nullptr},
      {"a 65536", '\0', "from 0 to 65535"},
      {"k 40", 'k', nullptr},
      {"k 300", '\0', "from 0 to 255"},
      {"k 40.5", '\0', "not a whole number"},
      {"s", 's', nullptr},
      {"s 3", '\0', "one word too many"},
      {"q", 'q', nullptr},
      {"q now", '\0', "one word too many"},
      {"zz", '\0', "unknown command \"zz\""},
      {"Y", '\0', "unknown command \"Y\""},
  };
  for (const JointtestCase& c : cases) {
    SCOPED_TRACE(c.line);
    if (c.error == nullptr) {
      EXPECT_EQ(tools::parse_jointtest_line(c.line, puma, 1).letter, c.letter);
    } else {
      try {
        (void)tools::parse_jointtest_line(c.line, puma, 1);
        ADD_FAILURE() << "accepted";
      } catch (const io::ParseError& e) {
        EXPECT_NE(std::string(e.what()).find(c.error), std::string::npos) << e.what();
      }
    }
  }
  EXPECT_EQ(tools::parse_jointtest_line("r 28", puma, 0).duration, std::chrono::milliseconds(28));
  EXPECT_EQ(tools::parse_jointtest_line("w 2", puma, 0).duration, std::chrono::seconds(2));
  EXPECT_EQ(tools::parse_jointtest_line("j 3", puma, 0).joint, 2U);
}

struct RcuCase {
  const char* line;
  tools::RcuLine::Kind kind;
  const char* error;
};

TEST(ConsoleLines, RcuLinesAreReadWholeAndInRange) {
  using K = tools::RcuLine::Kind;
  const std::vector<RcuCase> cases = {
      {"", K::none, nullptr},
      {"# comment", K::none, nullptr},
      {"in 5805", K::in, nullptr},
      {"in 580b", K::in, nullptr},
      {"in 5900", K::none, "5800 to 580B"},
      {"in 0x5805", K::none, "5800 to 580B"},
      {"in +5805", K::none, "5800 to 580B"},
      {"in 5805 1", K::none, "one word too many"},
      {"out 5805 04", K::out, nullptr},
      {"out 5800 1FF", K::none, "00 to FF"},
      {"out 5800 -1", K::none, "00 to FF"},
      {"step 0.1", K::step, nullptr},
      {"step 5abc", K::none, "\"5abc\" is not a number"},
      {"step -1", K::none, "out of range"},
      {"step 1e10", K::none, "out of range"},
      {"step nan", K::none, "is not a number"},
      {"fault 2 encoder_error", K::fault, nullptr},
      {"fault 7 encoder_error", K::none, "the joint must be 1 to 6"},
      {"fault 1.0 encoder_error", K::none, "the joint must be 1 to 6"},
      {"fault 1 gremlins", K::none, "the fault must be"},
      {"bogus", K::none, "unknown command"},
  };
  for (const RcuCase& c : cases) {
    SCOPED_TRACE(c.line);
    if (c.error == nullptr) {
      EXPECT_EQ(tools::parse_rcu_line(c.line, 6).kind, c.kind);
    } else {
      try {
        (void)tools::parse_rcu_line(c.line, 6);
        ADD_FAILURE() << "accepted";
      } catch (const io::ParseError& e) {
        EXPECT_NE(std::string(e.what()).find(c.error), std::string::npos) << e.what();
      }
    }
  }
  const tools::RcuLine out = tools::parse_rcu_line("out 580B ff", 6);
  EXPECT_EQ(out.address, 0x580B);
  EXPECT_EQ(out.byte, 0xFF);
  EXPECT_EQ(tools::parse_rcu_line("step 0.1", 6).step_us, 100);
  EXPECT_EQ(tools::parse_rcu_line("fault 2 power_loss", 6).joint, 1U);
}

}  // namespace
