#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "rccx/hw/rcu.hpp"
#include "rccx/kinematics/robot_model.hpp"

namespace {

using namespace rccx;
namespace rcu = hw::rcu;

// Appendix B.4's put_cmd, put_dat and get_dat over a bus: a status poll before every access.
struct Master {
  hw::Bus& bus;
  std::size_t joint = 0;
  int polls = 20;

  bool ready(std::uint8_t mask, bool set) {
    for (int i = 0; i < polls; ++i) {
      const bool s = (bus.in(hw::rcu_command_register(joint)) & mask) != 0;
      if (s == set) return true;
    }
    return false;
  }
  bool cmd(std::uint8_t c) {
    if (!ready(hw::kIbe, false)) return false;
    bus.out(hw::rcu_command_register(joint), c);
    return true;
  }
  bool put(std::uint8_t d) {
    if (!ready(hw::kIbe, false)) return false;
    bus.out(hw::rcu_data_register(joint), d);
    return true;
  }
  bool get(std::uint8_t& d) {
    if (!ready(hw::kObf, true)) return false;
    d = bus.in(hw::rcu_data_register(joint));
    return true;
  }
  bool put_word(std::uint8_t c, std::uint16_t w) {
    return cmd(c) && put(static_cast<std::uint8_t>(w & 0xFF)) &&
           put(static_cast<std::uint8_t>(w >> 8));
  }
  bool get_word(std::uint8_t c, std::uint16_t& w) {
    std::uint8_t lo = 0, hi = 0;
    const bool ok = cmd(c) && get(lo) && get(hi);
    w = static_cast<std::uint16_t>(lo | (hi << 8));
    return ok;
  }
  bool get_byte(std::uint8_t c, std::uint8_t& b) { return cmd(c) && get(b); }
  /// Waits until the joint took the last byte (a write command acts then).
  bool taken() { return ready(hw::kIbe, false); }
  std::uint16_t word(std::uint8_t c) {
    std::uint16_t w = 0;
    EXPECT_TRUE(get_word(c, w));
    return w;
  }
  std::uint8_t byte(std::uint8_t c) {
    std::uint8_t b = 0;
    EXPECT_TRUE(get_byte(c, b));
    return b;
  }
};

const kin::RobotModel& microbo() {
  static const kin::RobotModel m = kin::builtin_robot("microbo");
  return m;
}

double now_s(const hw::Rcu& rcu) {
  return static_cast<double>(rcu.time_us()) * 1e-6;
}

hw::SimulatedArmOptions uncalibrated() {
  hw::SimulatedArmOptions o;
  o.calibrated = false;
  return o;
}

/// The register P's frame of a joint: absolute counts minus its areas.
std::int64_t p_counts(const hw::Rcu& rcu, std::size_t j) {
  return rcu.absolute_counts(j) - 50000LL * rcu.work_area(j);
}

std::uint16_t low16(std::int64_t v) {
  return static_cast<std::uint16_t>(v & 0xFFFF);
}

// ---------------------------------------------------------------------------------------------
// The robot file's RCU block

kin::RobotModel with_hardware(const std::function<void(nlohmann::json&)>& edit) {
  kin::RobotModel m = microbo();
  nlohmann::json h = nlohmann::json::parse(m.hardware_json);
  edit(h);
  m.hardware_json = h.dump();
  return m;
}

std::string config_error(const kin::RobotModel& m) {
  try {
    (void)hw::rcu_config(m);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(RcuConfig, MicroboBlockMeetsTheConstraints) {
  const hw::RcuConfig c = hw::rcu_config(microbo());
  ASSERT_EQ(c.joints.size(), 6U);
  EXPECT_EQ(c.exchange_us, 75.0);
  for (std::size_t j = 0; j < 6; ++j) {
    const kin::Joint& joint = microbo().joints[j];
    const hw::RcuJointConfig& r = c.joints[j];
    const double res = joint.resolution_per_count;
    SCOPED_TRACE(joint.name);
    // Hard stops just beyond the limits; INITIALIZE seeks the lower one.
    EXPECT_NEAR(r.lower_stop, joint.lower - r.hard_stop_margin, 1e-12);
    EXPECT_NEAR(r.upper_stop, joint.upper + r.hard_stop_margin, 1e-12);
    EXPECT_EQ(r.calibration_position, r.lower_stop);
    // Appendix B.2's defaults; the top speed is a 16-bit setting the speed cap allows.
    EXPECT_EQ(r.default_speed, 32);
    EXPECT_EQ(r.default_acceleration, 1);
    const double top = joint.max_velocity / res / 1e3 / r.counts_per_ms_per_speed_unit;
    EXPECT_LT(top, 65535.0);
    EXPECT_LE(top, 256.0 * r.motor_parameters[hw::motor::kMaximumSpeed]);
    EXPECT_EQ(r.lower_threshold, 7450);
    EXPECT_EQ(r.upper_threshold, 57550);
    // Counts from stop to stop, A = initialize_counts at the lower stop.
    const double a_lo = r.initialize_counts;
    const double a_limit_lo = a_lo + (joint.lower - r.lower_stop) / res;
    const double a_limit_hi = a_lo + (joint.upper - r.lower_stop) / res;
    const double a_hi = a_lo + (r.upper_stop - r.lower_stop) / res;
    if (j == 0 || j == 2) {
      EXPECT_TRUE(r.work_areas);
      EXPECT_GT(a_limit_hi - a_limit_lo, 65535.0);  // needs work areas
      EXPECT_GT(r.initialize_counts, r.lower_threshold);
      EXPECT_LT(r.initialize_counts, r.upper_threshold);
      EXPECT_LT(a_hi, 65535.0 + 50000.0 * 127);
    } else {
      EXPECT_FALSE(r.work_areas);
      EXPECT_GE(a_limit_lo, 200.0);  // margin inside the register at both limits
      EXPECT_LE(a_limit_hi, 65535.0 - 200.0);
      EXPECT_GE(a_lo, 0.0);  // and even at the stops
      EXPECT_LE(a_hi, 65535.0);
    }
    EXPECT_GT(r.inertia, 0.0);
    EXPECT_GT(r.max_effort, std::abs(r.gravity_effort));
    EXPECT_GE(r.follow_acceleration, 32);  // full stiffness while following
  }
  EXPECT_LT(c.joints[1].gravity_effort, -50.0);  // d2 carries the arm
}

TEST(RcuConfig, RefusesWhatItCannotUseNamingTheKey) {
  kin::RobotModel none = microbo();
  none.hardware_json.clear();
  EXPECT_NE(config_error(none).find("hardware"), std::string::npos);
  EXPECT_THROW(hw::Rcu{none}, std::invalid_argument);

  const auto joint3 = [](const std::function<void(nlohmann::json&)>& f) {
    return with_hardware([&](nlohmann::json& h) { f(h["rcu"]["joints"][2]); });
  };
  EXPECT_NE(config_error(joint3([](auto& j) { j["inertia_kg_m2"] = 1.0; })).find("inertia_kg_m2"),
            std::string::npos);  // a revolute unit on a prismatic joint is unknown
  EXPECT_NE(config_error(joint3([](auto& j) {
              j.erase("counts_per_motor_turn");
            })).find("\"counts_per_motor_turn\""),
            std::string::npos);
  EXPECT_NE(config_error(joint3([](auto& j) { j["work_areas"] = false; })).find("work_areas"),
            std::string::npos);
  EXPECT_NE(
      config_error(joint3([](auto& j) { j["calibrate_at"] = "middle"; })).find("calibrate_at"),
      std::string::npos);
  EXPECT_NE(config_error(joint3([](auto& j) {
              j["motor_parameters"]["static_zone_x4_counts"] = 256;
            })).find("static_zone_x4_counts"),
            std::string::npos);
  EXPECT_NE(config_error(joint3([](auto& j) { j["motor_parameters"]["typo"] = 1; })).find("typo"),
            std::string::npos);
  EXPECT_NE(config_error(joint3([](auto& j) {
              j["counts_per_motor_turn"] = 50;
            })).find("counts_per_motor_turn"),
            std::string::npos);  // 200 mm/s would need a setting beyond 16 bits
  EXPECT_NE(config_error(joint3([](auto& j) { j["initialize_counts"] = 5000; })).find("thresholds"),
            std::string::npos);
  EXPECT_NE(config_error(with_hardware([](auto& h) { h["rcu"]["joints"].erase(5); })).find("6"),
            std::string::npos);
  EXPECT_NE(config_error(with_hardware([](auto& h) { h["pendant"] = 1; })).find("pendant"),
            std::string::npos);
  // d2 with the default 2 mm stops does not fit its register from stop to stop.
  EXPECT_NE(config_error(with_hardware([](auto& h) {
              h["rcu"]["joints"][1].erase("hard_stop_margin_mm");
            })).find("beyond the 16-bit register"),
            std::string::npos);
}

TEST(RcuCommands, DataBytesAndNamesFollowAppendixB) {
  const std::vector<std::pair<std::uint8_t, int>> table{
      {0x00, 1},  {0x02, 2},  {0x04, 2},  {0x06, 2}, {0x08, 2}, {0x0A, 2},  {0x0C, -2}, {0x0E, -16},
      {0x10, -2}, {0x12, -2}, {0x14, -2}, {0x16, 0}, {0x18, 0}, {0x1A, 0},  {0x1C, -2}, {0x1E, 0},
      {0x22, -2}, {0x24, 1},  {0x26, -1}, {0x28, 0}, {0x2A, 1}, {0x2C, -1}, {0x2E, 2},  {0x30, -2}};
  int commands = 0;
  for (int code = 0; code < 256; ++code) {
    const auto c = static_cast<std::uint8_t>(code);
    const auto it = std::find_if(table.begin(), table.end(), [&](auto& e) { return e.first == c; });
    if (it == table.end()) {
      EXPECT_EQ(rcu::data_bytes(c), -128) << code;
      EXPECT_TRUE(rcu::name(c).empty()) << code;
    } else {
      ++commands;
      EXPECT_EQ(rcu::data_bytes(c), it->second) << code;
      EXPECT_FALSE(rcu::name(c).empty()) << code;
    }
  }
  EXPECT_EQ(commands, 24);
  EXPECT_EQ(rcu::name(rcu::kGetStatus), "GET JOINT STATUS");
  EXPECT_EQ(rcu::name(rcu::kChangeWorkArea), "CHANGE WORK AREA");
}

// ---------------------------------------------------------------------------------------------
// The handshake, register by register

TEST(RcuHandshake, ServiceTimeSetsIbeThenObf) {
  hw::Rcu rcu(microbo());
  const std::uint16_t status = hw::rcu_command_register(2);
  const std::uint16_t data = hw::rcu_data_register(2);
  EXPECT_EQ(status, 0x5805);
  EXPECT_EQ(data, 0x5804);
  EXPECT_EQ(rcu.in(status), 0);  // idle: IBE and OBF clear
  rcu.out(status, rcu::kGetPosition);
  EXPECT_EQ(rcu.in(status), hw::kIbe);
  rcu.advance_us(hw::kRcuServiceTime_us - 1);
  EXPECT_EQ(rcu.in(status), hw::kIbe);
  rcu.advance_us(1);
  EXPECT_EQ(rcu.in(status), hw::kObf);  // taken, first byte out
  const std::uint16_t e = low16(p_counts(rcu, 2));
  EXPECT_EQ(rcu.in(data), e & 0xFF);
  EXPECT_EQ(rcu.in(status), 0);
  EXPECT_EQ(rcu.in(data), e & 0xFF);  // OBF clear: the stale byte, and no side effect
  rcu.advance_us(hw::kRcuServiceTime_us - 1);
  EXPECT_EQ(rcu.in(status), 0);
  rcu.advance_us(1);
  EXPECT_EQ(rcu.in(status), hw::kObf);
  EXPECT_EQ(rcu.in(data), e >> 8);
  rcu.advance_us(1000);
  EXPECT_EQ(rcu.in(status), 0);  // nothing more to give
  EXPECT_EQ(rcu.lost_bytes(2), 0U);
}

TEST(RcuHandshake, AByteWrittenWhileIbeIsSetIsLost) {
  hw::Rcu rcu(microbo(), uncalibrated());  // stays in stand-by: the target just sits there
  const std::uint16_t cmd = hw::rcu_command_register(0);
  const std::uint16_t data = hw::rcu_data_register(0);
  rcu.out(cmd, rcu::kSetTarget);
  rcu.out(data, 0x11);  // too early: lost
  EXPECT_EQ(rcu.lost_bytes(0), 1U);
  rcu.advance_us(hw::kRcuServiceTime_us);
  rcu.out(data, 0x34);
  rcu.out(cmd, rcu::kStop);  // lost too (it would have abandoned the command)
  EXPECT_EQ(rcu.lost_bytes(0), 2U);
  rcu.advance_us(hw::kRcuServiceTime_us);
  rcu.out(data, 0x12);
  rcu.advance_us(hw::kRcuServiceTime_us);
  hw::RcuBus bus(rcu);
  Master m{bus, 0};
  EXPECT_EQ(m.word(rcu::kGetTarget), 0x1234);
  EXPECT_EQ(rcu.lost_bytes(0), 2U);
  EXPECT_EQ(rcu.lost_bytes(1), 0U);
}

TEST(RcuHandshake, UnknownCodesAndStrayBytesAreIgnored) {
  hw::Rcu rcu(microbo(), uncalibrated());
  hw::RcuBus bus(rcu);
  Master m{bus, 3};
  const std::uint16_t target = m.word(rcu::kGetTarget);
  for (int code : {0x20, 0x01, 0x32, 0xFF}) EXPECT_TRUE(m.cmd(static_cast<std::uint8_t>(code)));
  EXPECT_TRUE(m.put(0x55));                           // no command waits for data
  EXPECT_EQ(bus.in(hw::rcu_command_register(3)), 0);  // no answer either
  EXPECT_EQ(m.word(rcu::kGetTarget), target);
  EXPECT_EQ(m.word(rcu::kGetVelocity), 32);
  // A new command abandons one still waiting for data.
  EXPECT_TRUE(m.cmd(rcu::kSetSpeed) && m.put(0x40));
  EXPECT_EQ(m.word(rcu::kGetVelocity), 32);
  EXPECT_EQ(bus.in(0x5800 + 2 * 6), 0xFF);  // no seventh joint
  bus.out(0x5800 + 2 * 6, 0x00);
  EXPECT_EQ(bus.in(0x57FF), 0xFF);
  EXPECT_EQ(rcu.lost_bytes(3), 0U);
}

TEST(RcuHandshake, SixJointsThreeCommandsIs108ExchangesAnd8Point1Ms) {
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  const std::int64_t t0 = rcu.time_us();
  std::array<std::uint16_t, 6> position{};
  for (std::size_t j = 0; j < 6; ++j) {
    Master m{bus, j, 1};  // one poll: the joint must be ready at once
    ASSERT_TRUE(m.get_word(rcu::kGetPosition, position[j])) << j;
    ASSERT_TRUE(m.put_word(rcu::kSetTarget, position[j])) << j;
    ASSERT_TRUE(m.put_word(rcu::kSetSpeed, 100)) << j;
  }
  EXPECT_EQ(bus.exchanges(), 108U);
  EXPECT_DOUBLE_EQ(bus.bus_time_us(), 8100.0);
  EXPECT_EQ(rcu.time_us() - t0, 8100);
  for (std::size_t j = 0; j < 6; ++j) {
    Master m{bus, j};
    EXPECT_EQ(m.word(rcu::kGetTarget), position[j]);
    EXPECT_EQ(m.word(rcu::kGetVelocity), 100);
    EXPECT_EQ(rcu.lost_bytes(j), 0U);
  }
  bus.reset_counters();
  EXPECT_EQ(bus.exchanges(), 0U);
  bus.sync(1.0);
  EXPECT_EQ(rcu.time_us(), 1000000);
}

// ---------------------------------------------------------------------------------------------
// Every command

TEST(RcuCommands, SettingsReadBackAndToleranceMode) {
  hw::Rcu rcu(microbo(), uncalibrated());  // stand-by: nothing moves
  hw::RcuBus bus(rcu);
  Master m{bus, 4};
  EXPECT_EQ(m.byte(rcu::kGetStatus), hw::kStatusInPosition);  // at its power-up target
  EXPECT_EQ(m.word(rcu::kGetPosition), 0);                    // an incremental encoder starts at 0
  EXPECT_EQ(m.word(rcu::kGetVelocity), 32);
  EXPECT_EQ(m.word(rcu::kGetAcceleration), 1);
  EXPECT_EQ(m.word(rcu::kGetTolerance), 1);
  EXPECT_TRUE(m.put_word(rcu::kSetAcceleration, 0x1234));
  EXPECT_TRUE(m.put_word(rcu::kSetSpeed, 0xBEEF));
  EXPECT_TRUE(m.put_word(rcu::kSetTolerance, 10));
  EXPECT_TRUE(m.put_word(rcu::kSetTarget, 6));
  EXPECT_EQ(m.word(rcu::kGetAcceleration), 0x1234);
  EXPECT_EQ(m.word(rcu::kGetVelocity), 0xBEEF);
  EXPECT_EQ(m.word(rcu::kGetTolerance), 10);
  EXPECT_EQ(m.word(rcu::kGetTarget), 6);
  EXPECT_TRUE(rcu.standby(4));            // not initialized: a position command does not wake it
  EXPECT_EQ(m.byte(rcu::kGetStatus), 0);  // 6 counts off: not within +-1
  EXPECT_TRUE(m.cmd(rcu::kToleranceModeOn));
  EXPECT_EQ(m.byte(rcu::kGetStatus), hw::kStatusToleranceMode | hw::kStatusInPosition);
  EXPECT_TRUE(m.put_word(rcu::kSetTolerance, 5));
  EXPECT_EQ(m.byte(rcu::kGetStatus), hw::kStatusToleranceMode);
  EXPECT_TRUE(m.cmd(rcu::kToleranceModeOff));
  EXPECT_EQ(m.byte(rcu::kGetStatus), 0);
  EXPECT_TRUE(m.put_word(rcu::kSetTarget, 65535));  // -1: within +-1 only if wrapped, it is not
  EXPECT_EQ(m.byte(rcu::kGetStatus), 0);
}

TEST(RcuCommands, RamPointerBytesWordsAndMotorParameters) {
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  Master m{bus, 1};
  // The default pointer is at the software version.
  EXPECT_EQ(m.byte(rcu::kReadRamByte), hw::kRcuSoftwareVersion & 0xFF);
  EXPECT_EQ(m.word(rcu::kReadRamWord), hw::kRcuSoftwareVersion);
  // The motor parameters of the robot file are in RAM.
  const auto& defaults = rcu.config().joints[1].motor_parameters;
  for (std::size_t i = 0; i < 16; ++i) {
    ASSERT_TRUE(m.put_word(rcu::kSetRamPointer,
                           static_cast<std::uint16_t>(hw::kRcuRamMotorParameters + i)));
    EXPECT_EQ(m.byte(rcu::kReadRamByte), defaults[i]) << i;
  }
  // 0EH writes all 16, and RAM reads show them.
  ASSERT_TRUE(m.cmd(rcu::kSetMotorParameters));
  for (std::uint8_t i = 0; i < 16; ++i) ASSERT_TRUE(m.put(static_cast<std::uint8_t>(0xA0 + i)));
  ASSERT_TRUE(m.put_word(rcu::kSetRamPointer, hw::kRcuRamMotorParameters + 4));
  EXPECT_EQ(m.word(rcu::kReadRamWord), 0xA5A4);
  // Byte and word writes; the pointer is taken modulo the RAM size and does not move.
  ASSERT_TRUE(m.put_word(rcu::kSetRamPointer, 0x0100));
  ASSERT_TRUE(m.cmd(rcu::kWriteRamByte) && m.put(0xAB));
  EXPECT_EQ(m.byte(rcu::kReadRamByte), 0xAB);
  ASSERT_TRUE(m.put_word(rcu::kWriteRamWord, 0x1234));
  EXPECT_EQ(m.word(rcu::kReadRamWord), 0x1234);
  ASSERT_TRUE(m.put_word(rcu::kSetRamPointer, 0x0100 + hw::kRcuRamSize));
  EXPECT_EQ(m.byte(rcu::kReadRamByte), 0x34);
  ASSERT_TRUE(m.put_word(rcu::kSetRamPointer, 0x0101));
  EXPECT_EQ(m.byte(rcu::kReadRamByte), 0x12);
  EXPECT_EQ(rcu.lost_bytes(1), 0U);
}

TEST(RcuCommands, TheLawReadsItsParametersFromRam) {
  // A sensor error tolerance of 0 written into RAM faults the joint as soon as it lags.
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  Master m{bus, 3};
  const std::uint16_t e = m.word(rcu::kGetPosition);
  ASSERT_TRUE(m.put_word(rcu::kSetAcceleration, rcu.config().joints[3].follow_acceleration));
  ASSERT_TRUE(m.put_word(rcu::kSetSpeed, 2000));
  ASSERT_TRUE(m.put_word(rcu::kSetTarget, static_cast<std::uint16_t>(e - 2000)));
  bus.sync(0.3);
  EXPECT_EQ(m.byte(rcu::kGetStatus) & hw::kStatusFault, 0);
  ASSERT_TRUE(m.put_word(rcu::kSetRamPointer,
                         hw::kRcuRamMotorParameters + hw::motor::kSensorErrorTolerance));
  ASSERT_TRUE(m.cmd(rcu::kWriteRamByte) && m.put(0));
  ASSERT_TRUE(m.put_word(rcu::kSetTarget, static_cast<std::uint16_t>(e + 2000)));
  bus.sync(0.6);
  EXPECT_EQ(m.byte(rcu::kGetStatus) & hw::kStatusFault, hw::kStatusFault);
  EXPECT_TRUE(rcu.standby(3));
}

/// Moves joint j to `target` (P's frame) with the follow acceleration and `speed`, and waits.
void move_to(hw::Rcu& rcu, hw::RcuBus& bus, std::size_t j, std::uint16_t target,
             std::uint16_t speed, double seconds) {
  Master m{bus, j};
  ASSERT_TRUE(m.put_word(rcu::kSetAcceleration, rcu.config().joints[j].follow_acceleration));
  ASSERT_TRUE(m.put_word(rcu::kSetSpeed, speed));
  ASSERT_TRUE(m.put_word(rcu::kSetTarget, target));
  bus.sync(now_s(rcu) + seconds);
}

/// Mean speed of joint j from 0.1 s to 0.4 s from now, in counts/ms.
double cruise_speed(hw::Rcu& rcu, std::size_t j) {
  rcu.advance_us(100000);
  const std::int64_t a = rcu.absolute_counts(j);
  rcu.advance_us(300000);
  return std::abs(static_cast<double>(rcu.absolute_counts(j) - a)) / 300.0;
}

TEST(RcuCommands, SpeedFactorScalesTheSpeedSetting) {
  const std::size_t j = 2;
  std::array<double, 2> measured{};
  for (int run = 0; run < 2; ++run) {
    hw::Rcu rcu(microbo());
    hw::RcuBus bus(rcu);
    Master m{bus, j};
    EXPECT_EQ(m.byte(rcu::kReadSpeedFactor), hw::kRcuDefaultSpeedFactor);
    if (run == 1) {
      ASSERT_TRUE(m.cmd(rcu::kWriteSpeedFactor) && m.put(50));
      EXPECT_EQ(m.byte(rcu::kReadSpeedFactor), 50);
    }
    const std::uint16_t e = m.word(rcu::kGetPosition);
    move_to(rcu, bus, j, static_cast<std::uint16_t>(e - 15000), 3000, 0.0);
    measured[static_cast<std::size_t>(run)] = cruise_speed(rcu, j);
    // The speed setting in counts: 3000 x 0.009947 = 29.8 counts/ms at 100 %.
    const double expected =
        3000 * rcu.config().joints[j].counts_per_ms_per_speed_unit * (run == 0 ? 1.0 : 0.5);
    EXPECT_NEAR(measured[static_cast<std::size_t>(run)], expected, 0.03 * expected) << run;
  }
}

TEST(RcuCommands, StandbyHoldsByTheBrakeUntilAPositionCommand) {
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  Master m{bus, 1};
  EXPECT_TRUE(rcu.standby(1));  // the power-up state
  const double q0 = rcu.true_position()[1];
  bus.sync(1.0);
  EXPECT_EQ(rcu.true_position()[1], q0);  // d2's weight is held by the brake
  const std::uint16_t e = m.word(rcu::kGetPosition);
  ASSERT_TRUE(m.put_word(rcu::kSetTarget, e) &&
              m.taken());  // initialized: a position command wakes it
  EXPECT_FALSE(rcu.standby(1));
  ASSERT_TRUE(m.cmd(rcu::kStandby) && m.taken());
  EXPECT_TRUE(rcu.standby(1));
  rcu.set_external_effort(1, 200.0);  // a push the brake (600 N) holds
  bus.sync(2.0);
  EXPECT_EQ(m.word(rcu::kGetPosition), e);
  rcu.set_external_effort(1, 0.0);
  // At the default speed and acceleration (1 rad/s, 1/4 rad/s^2 of the motor: 0.32 counts/ms
  // reached at 8e-5 counts/ms^2) 500 counts would take 4 s.
  ASSERT_TRUE(m.put_word(rcu::kSetAcceleration, 64));
  ASSERT_TRUE(m.put_word(rcu::kSetSpeed, 1000));
  ASSERT_TRUE(m.put_word(rcu::kSetTarget, static_cast<std::uint16_t>(e + 500)));
  bus.sync(3.0);
  EXPECT_FALSE(rcu.standby(1));
  EXPECT_NEAR(m.word(rcu::kGetPosition), e + 500, 20);
}

TEST(RcuCommands, StopSetsTheTargetWhereTheJointIs) {
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  Master m{bus, 2};
  const std::uint16_t e = m.word(rcu::kGetPosition);
  move_to(rcu, bus, 2, static_cast<std::uint16_t>(e - 30000), 5000, 0.3);
  const double v = std::abs(rcu.true_velocity()[2]);
  EXPECT_GT(v, 0.03);  // moving at about 5000 x 0.0099 counts/ms = 64 mm/s
  ASSERT_TRUE(m.cmd(rcu::kStop));
  const auto at_stop = static_cast<std::uint16_t>(p_counts(rcu, 2));  // within 25 us of it
  bus.sync(now_s(rcu) + 1.0);
  const std::uint16_t target = m.word(rcu::kGetTarget);
  EXPECT_NEAR(target, at_stop, 5);
  // It stops within the distance its full effort brakes it: v^2 / (2 x 350 N / 50 kg) ~ 0.3 mm.
  EXPECT_NEAR(m.word(rcu::kGetPosition), target, 400);
  EXPECT_LT(std::abs(rcu.true_velocity()[2]), 1e-3);
  EXPECT_GT(std::abs(static_cast<int>(e) - static_cast<int>(target)), 5000);
}

TEST(RcuCommands, InitializeSeeksTheStopAndAssignsTheValue) {
  hw::Rcu rcu(microbo(), uncalibrated());
  hw::RcuBus bus(rcu);
  for (std::size_t j = 0; j < 6; ++j) {
    Master m{bus, j};
    EXPECT_EQ(m.byte(rcu::kGetStatus) & hw::kStatusInitialized, 0);
    ASSERT_TRUE(m.put_word(rcu::kInitialize, static_cast<std::uint16_t>(1000 * j + 9000)));
  }
  bus.sync(1.0);
  const kin::JointVector q1 = rcu.true_position();
  for (std::size_t j = 0; j < 6; ++j) {
    EXPECT_LT(q1[j], microbo().joints[j].ready) << j;  // going down to the lower stop
    EXPECT_FALSE(rcu.standby(j));
  }
  // Joint 1 has the longest way: 161 deg at 23 x 16 x 0.00995 counts/ms (11.5 deg/s) = 14 s.
  bus.sync(25.0);
  for (std::size_t j = 0; j < 6; ++j) {
    Master m{bus, j};
    SCOPED_TRACE(j);
    EXPECT_EQ(m.byte(rcu::kGetStatus), hw::kStatusInitialized | hw::kStatusInPosition);
    EXPECT_EQ(m.word(rcu::kGetPosition), 1000 * j + 9000);
    EXPECT_EQ(m.word(rcu::kGetTarget), 1000 * j + 9000);
    EXPECT_EQ(rcu.work_area(j), 0);
    EXPECT_NEAR(rcu.true_position()[j], rcu.config().joints[j].lower_stop, 1e-9);
  }
  // A STOP during the seek abandons it: stand-by, not initialized.
  hw::Rcu again(microbo(), uncalibrated());
  hw::RcuBus bus2(again);
  Master m{bus2, 2};
  ASSERT_TRUE(m.put_word(rcu::kInitialize, 10000));
  bus2.sync(0.5);
  ASSERT_TRUE(m.cmd(rcu::kStop));
  bus2.sync(30.0);
  EXPECT_TRUE(again.standby(2));
  EXPECT_EQ(m.byte(rcu::kGetStatus) & hw::kStatusInitialized, 0);
  EXPECT_GT(again.true_position()[2], again.config().joints[2].lower_stop + 0.1);
}

TEST(RcuCommands, InitializeIsTheCalibrationTheConstructorAssumes) {
  // Calibrating by INITIALIZE with the file's value gives the counts a calibrated start has.
  hw::Rcu cal(microbo());
  hw::Rcu raw(microbo(), uncalibrated());
  hw::RcuBus bus(raw);
  for (std::size_t j = 0; j < 6; ++j) {
    Master m{bus, j};
    ASSERT_TRUE(m.put_word(rcu::kInitialize, raw.config().joints[j].initialize_counts));
  }
  bus.sync(25.0);
  for (std::size_t j = 0; j < 6; ++j) {
    const auto& c = cal.config().joints[j];
    const double res = microbo().joints[j].resolution_per_count;
    EXPECT_NEAR(static_cast<double>(raw.absolute_counts(j)), c.initialize_counts, 0.5) << j;
    EXPECT_NEAR(static_cast<double>(cal.absolute_counts(j)),
                c.initialize_counts + (microbo().joints[j].ready - c.calibration_position) / res,
                1.0)
        << j;
  }
  // The calibrated start puts each register between the thresholds.
  EXPECT_EQ(cal.work_area(0), 1);  // 0 deg = 61935 counts: area 1, E = 11935
  EXPECT_EQ(cal.work_area(2), 2);  // 325 mm = 146154 counts: area 2, E = 46154
  for (std::size_t j = 0; j < 6; ++j) {
    const std::int64_t e = p_counts(cal, j);
    EXPECT_GT(e, cal.config().joints[j].lower_threshold) << j;
    EXPECT_LT(e, cal.config().joints[j].upper_threshold) << j;
  }
}

TEST(RcuCommands, ChangeWorkAreaIsAcceptedOnlyNearTheRegisterEnds) {
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  const std::size_t j = 2;
  Master m{bus, j};
  const std::int64_t a0 = rcu.absolute_counts(j);
  ASSERT_EQ(rcu.work_area(j), 2);
  ASSERT_EQ(m.word(rcu::kGetPosition), 46154);
  ASSERT_TRUE(m.cmd(rcu::kChangeWorkArea));  // 15535 <= E <= 50000: ignored
  bus.sync(0.1);
  EXPECT_EQ(rcu.work_area(j), 2);
  EXPECT_EQ(m.word(rcu::kGetPosition), 46154);
  // Up to E = 52000: accepted, E -= 50000, area + 1, and the joint stays where it is.
  move_to(rcu, bus, j, 52000, 5000, 1.5);
  const std::uint16_t e1 = m.word(rcu::kGetPosition);
  ASSERT_NEAR(e1, 52000, 20);
  const std::int64_t a1 = rcu.absolute_counts(j);
  ASSERT_TRUE(m.cmd(rcu::kChangeWorkArea));
  bus.sync(now_s(rcu) + 0.5);
  EXPECT_EQ(rcu.work_area(j), 3);
  EXPECT_NEAR(m.word(rcu::kGetPosition), e1 - 50000, 20);
  EXPECT_EQ(m.word(rcu::kGetTarget), 2000);
  EXPECT_NEAR(static_cast<double>(rcu.absolute_counts(j)), static_cast<double>(a1), 20);
  // Below 15535: accepted the other way.
  ASSERT_TRUE(m.cmd(rcu::kChangeWorkArea));
  bus.sync(now_s(rcu) + 0.1);
  EXPECT_EQ(rcu.work_area(j), 2);
  EXPECT_NEAR(m.word(rcu::kGetPosition), e1, 20);
  // Down at 10000: accepted down (area 1).
  move_to(rcu, bus, j, 10000, 5000, 2.5);
  ASSERT_TRUE(m.cmd(rcu::kChangeWorkArea));
  bus.sync(now_s(rcu) + 0.1);
  EXPECT_EQ(rcu.work_area(j), 1);
  EXPECT_NEAR(m.word(rcu::kGetPosition), 60000, 20);
  EXPECT_NEAR(static_cast<double>(rcu.absolute_counts(j) - a0), -36154.0, 20);
}

TEST(RcuCommands, TheRegisterWrapsWhenTheJointIsDrivenThroughTheZone) {
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  const std::size_t j = 2;
  Master m{bus, j};
  move_to(rcu, bus, j, 64000, 5000, 1.5);
  ASSERT_NEAR(m.word(rcu::kGetPosition), 64000, 20);
  // Soft settings (speed and acceleration 1: 1/32 of the effort, 11 N) and a 100 N push: the
  // joint is moved by hand past 65535 without the master changing its area.
  ASSERT_TRUE(m.put_word(rcu::kSetSpeed, 1));
  ASSERT_TRUE(m.put_word(rcu::kSetAcceleration, 1));
  rcu.set_external_effort(j, 100.0);
  bus.sync(now_s(rcu) + 0.3);
  rcu.set_external_effort(j, 0.0);
  const std::int64_t p = p_counts(rcu, j);
  EXPECT_GT(p, 65535);  // where the joint really is, in this area
  EXPECT_EQ(rcu.work_area(j), 2);
  const std::uint16_t e = m.word(rcu::kGetPosition);
  EXPECT_EQ(e, low16(p));  // the register wrapped: it reads a small number
  EXPECT_LT(e, 15535);
}

// ---------------------------------------------------------------------------------------------
// Faults and relays

TEST(RcuFaults, AJointThatDoesNotAnswerStaysBusyAndLosesEveryByte) {
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  Master m{bus, 4};
  const std::uint16_t e = m.word(rcu::kGetPosition);
  rcu.inject(hw::RcuFault::joint_not_answering, 4);
  EXPECT_EQ(bus.in(hw::rcu_command_register(4)), hw::kIbe);
  bus.out(hw::rcu_command_register(4), rcu::kGetPosition);
  bus.out(hw::rcu_data_register(4), 0);
  EXPECT_EQ(rcu.lost_bytes(4), 2U);
  std::uint16_t w = 0;
  EXPECT_FALSE(m.get_word(rcu::kGetPosition, w));  // put_cmd times out
  bus.sync(now_s(rcu) + 1.0);
  EXPECT_EQ(bus.in(hw::rcu_command_register(4)), hw::kIbe);
  EXPECT_EQ(bus.in(hw::rcu_data_register(4)), e >> 8);  // the stale byte
  Master other{bus, 3};
  EXPECT_TRUE(other.get_word(rcu::kGetPosition, w));  // the others answer
  rcu.clear_faults();
  EXPECT_TRUE(m.get_word(rcu::kGetPosition, w));
  EXPECT_EQ(w, e);
  EXPECT_EQ(hw::to_string(hw::RcuFault::joint_not_answering), "joint_not_answering");
}

TEST(RcuFaults, EncoderAndPhaseErrorsShowInTheStatus) {
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  Master m{bus, 0};
  const std::int64_t a = rcu.absolute_counts(0);
  rcu.inject(hw::RcuFault::encoder_error, 0);
  EXPECT_EQ(rcu.absolute_counts(0) - a, 4096);  // the counts jump
  EXPECT_EQ(m.byte(rcu::kGetStatus) & hw::kStatusEncoderError, hw::kStatusEncoderError);
  Master m5{bus, 5};
  rcu.inject(hw::RcuFault::phase_error, 5);
  EXPECT_EQ(m5.byte(rcu::kGetStatus) & (hw::kStatusPhaseError | hw::kStatusEncoderError),
            hw::kStatusPhaseError);
  rcu.clear_faults();
  EXPECT_EQ(m.byte(rcu::kGetStatus) & hw::kStatusEncoderError, 0);
  EXPECT_EQ(m5.byte(rcu::kGetStatus) & hw::kStatusPhaseError, 0);
  EXPECT_EQ(hw::to_string(hw::RcuFault::encoder_error), "encoder_error");
  EXPECT_EQ(hw::to_string(hw::RcuFault::phase_error), "phase_error");
}

TEST(RcuFaults, PowerLossFaultsEveryJointUntilCleared) {
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  for (std::size_t j = 0; j < 6; ++j) {
    Master m{bus, j};
    ASSERT_TRUE(m.put_word(rcu::kSetTarget, m.word(rcu::kGetPosition)) && m.taken());
    EXPECT_FALSE(rcu.standby(j));
  }
  rcu.inject(hw::RcuFault::power_loss, 0);
  EXPECT_FALSE(rcu.power());
  EXPECT_FALSE(rcu.set_power(true));
  const kin::JointVector q = rcu.true_position();
  bus.sync(now_s(rcu) + 1.0);
  for (std::size_t j = 0; j < 6; ++j) {
    Master m{bus, j};
    EXPECT_TRUE(rcu.standby(j));
    EXPECT_EQ(m.byte(rcu::kGetStatus) & hw::kStatusFault, hw::kStatusFault);
    EXPECT_NEAR(rcu.true_position()[j], q[j], 1e-4);  // the brakes hold (d2 too)
    ASSERT_TRUE(m.put_word(rcu::kSetTarget, m.word(rcu::kGetPosition)) && m.taken());
    EXPECT_TRUE(rcu.standby(j));  // no amplifier, no servo
  }
  rcu.clear_faults();
  EXPECT_TRUE(rcu.set_power(true));
  for (std::size_t j = 0; j < 6; ++j) {
    Master m{bus, j};
    EXPECT_EQ(m.byte(rcu::kGetStatus) & hw::kStatusFault, 0);
    ASSERT_TRUE(m.put_word(rcu::kSetTarget, m.word(rcu::kGetPosition)) && m.taken());
    EXPECT_FALSE(rcu.standby(j));
  }
  EXPECT_EQ(hw::to_string(hw::RcuFault::power_loss), "power_loss");
}

TEST(RcuFaults, RelaysArePlainStateAndPowerOffIsStandby) {
  hw::Rcu rcu(microbo());
  hw::Relays& relays = rcu;
  EXPECT_TRUE(relays.power());
  EXPECT_FALSE(relays.hand_closed());
  relays.set_hand_closed(true);
  relays.set_outputs(0xA5A5);
  EXPECT_TRUE(relays.hand_closed());
  EXPECT_EQ(relays.outputs(), 0xA5A5);
  hw::RcuBus bus(rcu);
  Master m{bus, 1};
  ASSERT_TRUE(m.put_word(rcu::kSetTarget, m.word(rcu::kGetPosition)) && m.taken());
  EXPECT_FALSE(rcu.standby(1));
  EXPECT_TRUE(relays.set_power(false));
  EXPECT_TRUE(rcu.standby(1));
  ASSERT_TRUE(m.put_word(rcu::kInitialize, 140) && m.taken());  // refused without power
  bus.sync(1.0);
  EXPECT_TRUE(rcu.standby(1));
  EXPECT_EQ(m.byte(rcu::kGetStatus) & hw::kStatusInitialized, hw::kStatusInitialized);
  EXPECT_TRUE(relays.set_power(true));
  hw::SimulatedArmOptions off;
  off.powered = false;
  EXPECT_FALSE(hw::Rcu(microbo(), off).power());
}

// ---------------------------------------------------------------------------------------------
// The joint law (thesis 2.5.2, 4.4.3)

/// Holds joint j where it is with `speed` and `acceleration`, for `seconds`; returns how far it
/// went (counts) and the status byte.
std::pair<std::int64_t, std::uint8_t> hold(std::size_t j, std::uint16_t speed,
                                           std::uint16_t acceleration, double seconds) {
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  Master m{bus, j};
  const std::int64_t a0 = rcu.absolute_counts(j);
  EXPECT_TRUE(m.put_word(rcu::kSetSpeed, speed));
  EXPECT_TRUE(m.put_word(rcu::kSetAcceleration, acceleration));
  EXPECT_TRUE(m.put_word(rcu::kSetTarget, m.word(rcu::kGetPosition)));
  bus.sync(seconds);
  return {rcu.absolute_counts(j) - a0, m.byte(rcu::kGetStatus)};
}

TEST(RcuLaw, SmallSpeedAndAccelerationSettingsLoseStiffness) {
  // d2 carries 117.7 N. Full effort (300 N) holds it; at speed 1 and acceleration 1 the joint
  // has 1/32 of it (9.4 N), which with 15 N of dry friction cannot hold: it sags until its
  // following error (39 x 64 counts = 5 mm) faults it and the brake catches it.
  const auto [still, s1] = hold(1, 32, 1, 1.0);  // the defaults
  EXPECT_LE(std::abs(still), 10);                // 20 um
  EXPECT_EQ(s1 & hw::kStatusFault, 0);
  const auto [sag, s2] = hold(1, 1, 1, 1.0);
  EXPECT_LT(sag, -2000);  // 4 mm down
  EXPECT_EQ(s2 & hw::kStatusFault, hw::kStatusFault);
  const auto [sag8, s3] = hold(1, 4, 1, 1.0);  // 1/8: 37.5 N, still too little
  EXPECT_LT(sag8, -2000);
  // A large acceleration setting keeps it stiff at the smallest speed.
  const auto [stiff, s4] = hold(1, 1, 64, 1.0);
  EXPECT_LE(std::abs(stiff), 10);
  EXPECT_EQ(s4 & hw::kStatusFault, 0);
  // A horizontal joint has no load to lose: d3 holds at the smallest settings.
  EXPECT_LE(std::abs(hold(2, 1, 1, 1.0).first), 10);
}

TEST(RcuLaw, ASmallSustainedForceInTheStaticZoneIsUnderdamped) {
  // Joint 3 at rest in the static zone: proportional gain Kp/16, integral Kp x 10/8 per s.
  // A push of 10 % of its effort (35 N) is taken up by the integral, which overshoots: the
  // joint swings back past its target, then past it again, each swing smaller.
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  const std::size_t j = 2;
  Master m{bus, j};
  const std::int64_t target = p_counts(rcu, j);
  ASSERT_TRUE(m.put_word(rcu::kSetAcceleration, rcu.config().joints[j].follow_acceleration));
  ASSERT_TRUE(m.put_word(rcu::kSetTarget, static_cast<std::uint16_t>(target)));
  bus.sync(0.5);
  ASSERT_TRUE(rcu.static_zone(j));
  rcu.set_external_effort(j, 0.1 * rcu.config().joints[j].max_effort);
  std::vector<double> x;
  for (int i = 0; i < 4000; ++i) {
    rcu.advance_us(1000);
    x.push_back(static_cast<double>(p_counts(rcu, j) - target));
    ASSERT_TRUE(rcu.static_zone(j)) << i;  // the reference stays at the target
  }
  // Extremes between sign changes.
  std::vector<double> swings;
  double extreme = 0.0;
  for (double v : x) {
    if (v != 0.0 && extreme != 0.0 && (v > 0) != (extreme > 0)) {
      swings.push_back(extreme);
      extreme = 0.0;
    }
    if (std::abs(v) > std::abs(extreme)) extreme = v;
  }
  if (extreme != 0.0) swings.push_back(extreme);
  ASSERT_GE(swings.size(), 3U);             // pushed, back past the target, and past it again
  EXPECT_GT(swings[0], 50.0);               // the push moves it first (with the force)
  EXPECT_LT(swings[1], -0.25 * swings[0]);  // overshoot of more than 25 %: underdamped
  EXPECT_GT(swings[2], 0.0);
  EXPECT_LT(std::abs(swings[2]), std::abs(swings[1]));  // decaying
  EXPECT_LE(std::abs(x.back()), 0.5 * swings[0]);       // the integral takes the load
  EXPECT_EQ(m.byte(rcu::kGetStatus) & hw::kStatusFault, 0);
}

struct Tracking {
  double ripple = 0.0;      ///< RMS of (true velocity - rate) / rate, at 1 ms
  double mean_error = 0.0;  ///< sampled Xm - p(t), counts
  double std_error = 0.0;
  double dip_fraction = 0.0;  ///< periods whose slowest ms is under half the rate
  int area_changes = 0;
};

/// Joint 3 tracks a ramp at `rate_mm_s` from the ready pose, sampled every 28 ms over RcuBus:
/// GET POSITION (and CHANGE WORK AREA past a threshold), then SET TARGET and SET SPEED by the
/// follow scheme (X = Xd + (Xd - Xm), V = (Xd - Xm) / T) or raw (X = Xd at a fixed speed).
Tracking track(bool follow, double rate_mm_s, double raw_speed_factor) {
  hw::Rcu rcu(microbo());
  hw::RcuBus bus(rcu);
  const std::size_t j = 2;
  Master m{bus, j};
  const hw::RcuJointConfig& c = rcu.config().joints[j];
  const double res = microbo().joints[j].resolution_per_count;
  int area = rcu.work_area(j);
  EXPECT_TRUE(m.put_word(rcu::kSetAcceleration, c.follow_acceleration));
  EXPECT_TRUE(m.put_word(rcu::kSetTarget, m.word(rcu::kGetPosition)));
  constexpr double kT = 0.028;
  constexpr int kStart = 10, kEnd = kStart + 60, kSettle = 18;  // samples
  const double rate = rate_mm_s * 1e-3 / res;                   // counts/s
  const double raw_speed = raw_speed_factor * rate / 1e3 / c.counts_per_ms_per_speed_unit;
  double start = 0.0;
  std::vector<double> errors;
  double ripple2 = 0.0;
  int ripple_n = 0, dips = 0, periods = 0;
  Tracking out;
  for (int k = 0; k < kEnd + 5; ++k) {
    const double t = k * kT;
    bus.sync(t);
    const std::uint16_t e = m.word(rcu::kGetPosition);
    const double xm = e + 50000.0 * area;
    if (k == kStart) start = xm;
    if (e > c.upper_threshold && m.cmd(rcu::kChangeWorkArea)) ++area, ++out.area_changes;
    if (e < c.lower_threshold && m.cmd(rcu::kChangeWorkArea)) --area, ++out.area_changes;
    const auto p = [&](double tt) {
      return start + rate * std::clamp(tt - kStart * kT, 0.0, (kEnd - kStart) * kT);
    };
    const bool measured = k >= kStart + kSettle && k < kEnd;
    if (measured) errors.push_back(xm - p(t));
    double x = xm, speed = c.default_speed;
    if (k >= kStart) {
      const double xd = p(t + kT);
      x = follow ? 2.0 * xd - xm : xd;
      speed = follow ? std::abs(xd - xm) / kT / 1e3 / c.counts_per_ms_per_speed_unit : raw_speed;
    }
    EXPECT_TRUE(m.put_word(rcu::kSetTarget, static_cast<std::uint16_t>(std::clamp(
                                                std::lround(x - 50000.0 * area), 0L, 65535L))));
    EXPECT_TRUE(m.put_word(rcu::kSetSpeed,
                           static_cast<std::uint16_t>(std::clamp(std::lround(speed), 1L, 65535L))));
    double slowest = 1e300;
    while (now_s(rcu) < t + kT - 1e-9) {
      rcu.advance_us(std::min<std::int64_t>(1000, std::llround((t + kT - now_s(rcu)) * 1e6)));
      const double v = rcu.true_velocity()[j] / res;
      if (measured) {
        ripple2 += (v - rate) * (v - rate);
        ++ripple_n;
        slowest = std::min(slowest, v);
      }
    }
    if (measured) {
      ++periods;
      if (slowest < 0.5 * rate) ++dips;
    }
  }
  out.ripple = std::sqrt(ripple2 / ripple_n) / rate;
  double sum = 0.0, sum2 = 0.0;
  for (double err : errors) sum += err;
  out.mean_error = sum / static_cast<double>(errors.size());
  for (double err : errors) sum2 += (err - out.mean_error) * (err - out.mean_error);
  out.std_error = std::sqrt(sum2 / static_cast<double>(errors.size()));
  out.dip_fraction = static_cast<double>(dips) / periods;
  EXPECT_EQ(m.byte(rcu::kGetStatus) & hw::kStatusFault, 0);
  return out;
}

TEST(RcuLaw, TheFollowSchemeTracksARampSmoothly) {
  // 20 mm/s for 1.68 s on joint 3 (25850 counts: across the upper threshold, so the master
  // changes work area on the way). Measured: ripple 0.1 %, error within +-1 count. Margins:
  // ripple under 5 % and a steady error under 10 counts (13 um), a tenth of the static zone.
  const Tracking f = track(true, 20.0, 0.0);
  EXPECT_LT(f.ripple, 0.05);
  EXPECT_LT(std::abs(f.mean_error), 10.0);
  EXPECT_LT(f.std_error, 10.0);
  EXPECT_EQ(f.dip_fraction, 0.0);
  EXPECT_GE(f.area_changes, 1);
}

TEST(RcuLaw, RawTargetsDecelerateAtEverySampleAndOscillate) {
  // The same ramp with the next setpoint itself as the target at a fixed speed of twice the
  // ramp's: the reference brakes toward every target, stops, and starts again when the next
  // one comes: the velocity swings at the sample frequency (measured ripple 45 %, under half
  // the rate in every period). Margins: ripple over 25 %, a dip in 90 % of the periods, and
  // ten times the follow scheme's ripple.
  const Tracking raw = track(false, 20.0, 2.0);
  const Tracking f = track(true, 20.0, 0.0);
  EXPECT_GT(raw.ripple, 0.25);
  EXPECT_GE(raw.dip_fraction, 0.9);
  EXPECT_GT(raw.ripple, 10.0 * f.ripple);
  // Sampled once a period the oscillation is invisible (aliased to a steady lag).
  EXPECT_LT(raw.std_error, 10.0);
  EXPECT_LT(raw.mean_error, -50.0);
  // Raw targets at exactly the ramp's speed do not oscillate: the reference can never catch
  // up, so it lags by its braking distance instead (measured 190 counts at 20 mm/s).
  const Tracking slow = track(false, 20.0, 1.0);
  EXPECT_LT(slow.ripple, 0.05);
  EXPECT_LT(slow.mean_error, -100.0);
}

TEST(RcuLaw, JointsInStandbyStayPutAndTimeIsExact) {
  hw::Rcu rcu(microbo());
  for (int i = 0; i < 1000; ++i) rcu.advance_us(3599);
  rcu.advance_us(1000);
  EXPECT_EQ(rcu.time_us(), 3'600'000);
  for (std::size_t j = 0; j < 6; ++j)
    EXPECT_NEAR(rcu.true_position()[j], microbo().joints[j].ready, 1e-9);
}

}  // namespace
