// RCCL over a running RTC session on simulated robots (simulated time): waitfor returns in the
// sample the motion ends in; the washer's log shows the tool on the window's edges with its
// approach vector kept; a conveyor is tracked by the measured arm with bounded lag; a position
// out of reach is refused at move() and queues nothing; halt stops the arm smoothly.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "rccx/math/units.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/simulated_robot.hpp"

namespace {

using namespace rccx;
using namespace rccx::math::literals;
using namespace std::chrono_literals;

rccl::PositionPtr at(const std::string& name, const math::Transform& t6) {
  const auto t6_ = rccl::t6();
  return rccl::Position::make(name, {t6_}, {rccl::constant(name, t6)}, t6_);
}

const rccl::MotionEvent* find(const std::vector<rccl::MotionEvent>& events, rccl::EventKind kind,
                              std::uint64_t id) {
  for (const auto& e : events) {
    if (e.kind == kind && e.id == id) return &e;
  }
  return nullptr;
}

TEST(RcclSession, WaitforReturnsInTheSampleWhereTheMotionEnds) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  const math::Transform home = arm.kinematics().forward(robot.model.ready());
  std::vector<rccl::Motion> motions;
  for (const double dy : {0.1, -0.1, 0.0}) {
    motions.push_back(arm.move(at("P", {home.R, home.p + math::Vec3{0, dy, 0}})));
    ASSERT_EQ(arm.waitfor(motions.back().end()), rccl::WaitResult::reached);
    const std::uint64_t now = robot.session->how().sample;
    const auto events = arm.take_events();
    const rccl::MotionEvent* ended = find(events, rccl::EventKind::ended, motions.back().id);
    ASSERT_NE(ended, nullptr);
    EXPECT_EQ(ended->sample, now) << "motion " << motions.back().id;
  }
  // A start, too.
  const rccl::Motion m = arm.move(arm.park());
  ASSERT_EQ(arm.waitfor(m.start()), rccl::WaitResult::reached);
  const std::uint64_t now = robot.session->how().sample;
  const auto events = arm.take_events();
  const rccl::MotionEvent* started = find(events, rccl::EventKind::started, m.id);
  ASSERT_NE(started, nullptr);
  EXPECT_EQ(started->sample, now);
  EXPECT_EQ(arm.waitfor(arm.completed()), rccl::WaitResult::reached);
  EXPECT_FALSE(arm.stop_control().ended());
}

struct LogRow {
  double t = 0;
  int seg = 0;
  std::vector<double> q, qm;
  math::Vec3 p, a;
};

std::vector<LogRow> read_log(const std::filesystem::path& file, std::size_t dof) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);                                      // the header line
  if (line.starts_with("# rccx-log")) std::getline(in, line);  // then the columns
  std::vector<LogRow> rows;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string cell;
    std::vector<double> v;
    while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
    if (v.size() != 2 + 2 * dof + 6) continue;
    LogRow r;
    r.t = v[0];
    r.seg = static_cast<int>(v[1]);
    r.q.assign(v.begin() + 2, v.begin() + 2 + static_cast<long>(dof));
    r.qm.assign(v.begin() + 2 + static_cast<long>(dof), v.begin() + 2 + 2 * static_cast<long>(dof));
    const std::size_t k = 2 + 2 * dof;
    r.p = {v[k], v[k + 1], v[k + 2]};
    r.a = {v[k + 3], v[k + 4], v[k + 5]};
    rows.push_back(r);
  }
  return rows;
}

double distance_to_line(const math::Vec3& p, const math::Vec3& a, const math::Vec3& b) {
  const math::Vec3 ab = b - a;
  const double s = std::clamp(dot(p - a, ab) / dot(ab, ab), 0.0, 1.0);
  return (p - (a + ab * s)).norm();
}

// The thesis's washer on the emulated Microbo RCU, judged from its CSV log: every commanded
// tool point of the Cartesian rounds lies within 0.1 mm of its edge outside the corner
// transitions (whose times the generator's events give), the approach vector points at the
// table throughout, and the measured arm keeps close to the edges too.
TEST(RcclSession, WasherLogShowsTheWindowFollowedOnItsEdges) {
  const auto log = std::filesystem::temp_directory_path() / "rccx_washer_test.csv";
  rtc::SimulatedRobotOptions o;
  o.log = log;
  std::vector<rccl::MotionEvent> events;
  std::vector<math::Vec3> corners;
  std::vector<std::uint64_t> cartesian;
  double period_s = 0;
  std::uint64_t park_id = 0;
  kin::JointVector ready;
  {
    rtc::SimulatedRobot robot(kin::builtin_robot("microbo"), o);
    period_s = robot.period_s();
    rccl::Manipulator arm(*robot.session);
    const auto corner = [&](const char* name, double y_mm, double z_mm) {
      corners.push_back({0.325, y_mm * 1e-3, z_mm * 1e-3});
      return at(name, {math::Rot3::rot_x(180_deg), corners.back()});
    };
    const auto p1 = corner("P1", 150, 300), p2 = corner("P2", -150, 300),
               p3 = corner("P3", -150, 250), p4 = corner("P4", 150, 250);
    arm.start();
    arm.set_velocity(0.1, 100_deg);
    arm.move(arm.park());
    ASSERT_EQ(arm.waitfor(arm.ended(arm.park())), rccl::WaitResult::reached);
    ASSERT_EQ(arm.waitfor(arm.move(p1).end()), rccl::WaitResult::reached);
    arm.set_mode(rccl::Mode::cartesian);
    for (int round = 0; round < 3; ++round) {
      for (const auto& p : {p2, p3, p4, p1}) cartesian.push_back(arm.move(p).id);
      arm.set_velocity(0.1 + 0.005 * (round + 1), (100 + 10 * (round + 1)) * 1_deg);
    }
    ASSERT_EQ(arm.waitfor(arm.completed()), rccl::WaitResult::reached);
    arm.set_mode(rccl::Mode::joint);  // back to park in joint mode, as the thesis does
    park_id = arm.move(arm.park()).id;
    ASSERT_EQ(arm.waitfor(arm.completed()), rccl::WaitResult::reached);
    robot.session->wait_for(500ms);  // rows at rest
    ready = robot.model.ready();
    events = arm.take_events();
    ASSERT_TRUE(arm.failures().empty());
    ASSERT_FALSE(arm.stop_control().ended());
  }  // the log is written out when the robot goes
  const std::vector<LogRow> rows = read_log(log, 6);
  std::filesystem::remove(log);
  ASSERT_GT(rows.size(), 500u);

  const auto time_of = [&](rccl::EventKind kind, std::uint64_t id) {
    const rccl::MotionEvent* e = find(events, kind, id);
    return e ? e->t_s : -1.0;
  };
  std::size_t judged = 0;
  double worst_commanded = 0, worst_measured = 0;
  for (std::size_t i = 0; i < cartesian.size(); ++i) {
    const std::uint64_t id = cartesian[i];
    const math::Vec3 from = corners[i % 4], to = corners[(i + 1) % 4];
    // Events carry the time of the sample they were computed in; the log's time is the sample
    // the setpoint went out in, the pipeline's two periods later. Keep two periods clear of the
    // transitions either side.
    const double pipeline_s = 2 * period_s;
    const double begin = time_of(rccl::EventKind::ended, id - 1) + pipeline_s + 2 * period_s;
    const double end = i + 1 < cartesian.size()
                           ? time_of(rccl::EventKind::started, id + 1) + pipeline_s - 2 * period_s
                           : 1e9;
    for (const LogRow& r : rows) {
      const bool next_cartesian = i + 1 < cartesian.size();
      if (r.seg == static_cast<int>(id) || (next_cartesian && r.seg == static_cast<int>(id) + 1)) {
        EXPECT_NEAR(r.a.z, -1.0, 1e-6) << "approach at t = " << r.t;
        EXPECT_NEAR(r.p.x, 0.325, 1e-6) << "the window's plane at t = " << r.t;
      }
      if (r.seg != static_cast<int>(id) || r.t < begin || r.t > end) continue;
      ++judged;
      const double d = distance_to_line(r.p, from, to);
      worst_commanded = std::max(worst_commanded, d);
      kin::JointVector qm(6);
      for (std::size_t j = 0; j < 6; ++j) qm[j] = r.qm[j];
      const auto kin = kin::make_kinematics(kin::builtin_robot("microbo"));
      worst_measured = std::max(worst_measured, distance_to_line(kin->forward(qm).p, from, to));
    }
  }
  std::printf(
      "washer from its log: %zu samples on the edges, commanded within %.4f mm, measured "
      "within %.3f mm\n",
      judged, worst_commanded * 1e3, worst_measured * 1e3);
  EXPECT_GT(judged, 200u);
  EXPECT_LT(worst_commanded, 1e-4);
  EXPECT_LT(worst_measured, 3e-3);  // the emulated RCU's servo lag, joint by joint

  // Joint mode ends exactly on its end point: the commanded joints of the rows after park's
  // end are the ready pose (to the log's 9 significant digits).
  const double park_end = time_of(rccl::EventKind::ended, park_id);
  std::size_t at_rest = 0;
  for (const LogRow& r : rows) {
    if (r.t < park_end + 2 * period_s) continue;
    ++at_rest;
    for (std::size_t j = 0; j < 6; ++j) EXPECT_NEAR(r.q[j], ready[j], 5e-9) << "joint " << j + 1;
  }
  EXPECT_GE(at_rest, 8u);
}

// A box on a conveyor at 50 mm/s: once the motion onto it has ended the measured tool point
// stays within a bounded distance of the box (the servo's lag), sample after sample.
TEST(RcclSession, ConveyorIsTrackedByTheMeasuredArmWithBoundedLag) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  const math::Transform home = arm.kinematics().forward(robot.model.ready());
  const double speed = 0.05;
  const math::Transform box{home.R, home.p + math::Vec3{0, -0.1, -0.05}};
  const auto conv = rccl::functional("CONV", [speed](const rccl::SampleContext& c) {
    return math::Transform::translation(0, speed * c.t_s, 0);
  });
  const auto t6 = rccl::t6();
  const auto on_belt = rccl::Position::make("BOX", {t6}, {conv, rccl::constant("BOX0", box)}, t6);
  arm.start();
  arm.set_mode(rccl::Mode::cartesian);
  ASSERT_EQ(arm.waitfor(arm.move(on_belt).end()), rccl::WaitResult::reached);
  double worst = 0;
  for (int k = 0; k < 150; ++k) {
    robot.session->wait_for(robot.session->period());
    const rtc::How h = robot.session->how();
    const math::Vec3 goal = box.p + math::Vec3{0, speed * h.time_s, 0};
    worst = std::max(worst, (arm.kinematics().forward(h.q()).p - goal).norm());
  }
  std::printf("conveyor at %.0f mm/s: measured tool point within %.2f mm of the box\n", speed * 1e3,
              worst * 1e3);
  // Three periods of travel (the pipeline: read, compute, send) and the servo's error.
  EXPECT_LT(worst, 3 * 0.01 * speed + 1e-3);
  EXPECT_TRUE(arm.failures().empty());
  arm.halt();
  EXPECT_FALSE(arm.stop_control().ended());
}

TEST(RcclSession, UnreachablePositionIsRefusedAtMoveAndNothingIsQueued) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  const math::Transform home = arm.kinematics().forward(robot.model.ready());
  const std::uint64_t before = arm.last_queued();
  try {
    arm.move(at("FAR", {home.R, home.p + math::Vec3{2.0, 0, 0}}));
    FAIL() << "move() to a point 2 m away was accepted";
  } catch (const rccl::MotionError& e) {
    EXPECT_NE(std::string(e.what()).find("FAR"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("out of reach"), std::string::npos) << e.what();
  }
  kin::JointVector beyond = robot.model.ready();
  beyond[1] = robot.model.joints[1].upper + 0.1;
  EXPECT_THROW(arm.move(rccl::Position::joints("BEYOND", beyond)), rccl::MotionError);
  EXPECT_THROW(arm.set_configuration("nonsense"), rccl::MotionError);
  EXPECT_THROW(arm.set_velocity(-1, 1), rccl::MotionError);
  EXPECT_EQ(arm.last_queued(), before);
  EXPECT_EQ(arm.waitfor(arm.completed(), 100ms), rccl::WaitResult::reached);
  EXPECT_FALSE(arm.stop_control().ended());
}

// halt() mid-motion: the motion and the queue end as failed, the arm decelerates at its bound
// and comes to rest where it is, not at the goal.
TEST(RcclSession, HaltStopsTheArmSmoothlyWhereItIs) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  arm.start();
  kin::JointVector far = robot.model.ready();
  far[0] += 1.0;
  const rccl::Motion m1 = arm.move(rccl::Position::joints("A", far));
  const rccl::Motion m2 = arm.move(arm.park());
  ASSERT_EQ(arm.waitfor(m1.start()), rccl::WaitResult::reached);
  robot.session->wait_for(800ms);
  arm.halt();
  EXPECT_EQ(arm.waitfor(m2.end(), 5s), rccl::WaitResult::failed);
  ASSERT_EQ(arm.failures().size(), 2u);
  EXPECT_NE(arm.failures()[0].message().find("halted"), std::string_view::npos);
  robot.session->wait_for(1s);
  const rtc::How h = robot.session->how();
  EXPECT_LT(std::abs(h.velocity()[0]), 1e-3);  // at rest
  EXPECT_GT(h.q()[0], robot.model.ready()[0] + 0.02);
  EXPECT_LT(h.q()[0], far[0] - 0.05);
  EXPECT_FALSE(arm.stop_control().ended());
}

}  // namespace
