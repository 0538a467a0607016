// RCCL's interface as its manual documents it (compat/rccl.h), each name against its meaning:
// the algebra against rccx::math, the transform types (const and hold read at move(), varb and
// functional at every sample, a function called once a sample), distance, update, setconf,
// stop, nextmove and teach's database on the simulated robots, measured through t6 and the
// RCCX_LOG file, and the bad inputs that change nothing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"
#include "rccx/rccl/position_db.hpp"
// clang-format off
#include "rccl.h"
#include "rtc.h"
// clang-format on

namespace {

namespace math = rccx::math;
namespace kin = rccx::kin;
constexpr double kDeg = std::numbers::pi / 180.0;

std::string message() {
  return rtc_error_message();
}

math::Transform value_mm(const TRSF& t) {
  math::Transform v;
  v.R.n = {t.n.x, t.n.y, t.n.z};
  v.R.o = {t.o.x, t.o.y, t.o.z};
  v.R.a = {t.a.x, t.a.y, t.a.z};
  v.p = {t.p.x, t.p.y, t.p.z};
  return v;
}

double max_diff(const math::Transform& a, const math::Transform& b) {
  const auto ra = a.rows(), rb = b.rows();
  double d = 0.0;
  for (std::size_t i = 0; i < ra.size(); ++i) d = std::max(d, std::abs(ra[i] - rb[i]));
  return d;
}

/// Waits `n` samples.
void wait_samples(int n) {
  for (int i = 0; i < n; ++i) ASSERT_EQ(rccl_wait_sample(), RTC_OK) << message();
}

/// Distance (mm) between the measured T6 and `goal` (mm), and the largest rotation element
/// difference.
double position_error_mm(const math::Transform& goal) {
  const math::Transform m = value_mm(*t6);
  return (m.p - goal.p).norm();
}

class CompatManual : public ::testing::Test {
 protected:
  void SetUp() override {
    rtc_error = RTC_OK;
    ::unsetenv("RCCX_ROBOT");
    ::unsetenv("RCCX_LOG");
    nextmove = NO;
  }
  void TearDown() override {
    rccl_close(0);
    ::unsetenv("RCCX_LOG");
    ::unsetenv("RCCX_DB");
  }
  /// Opens the Microbo and parks it.
  void open_parked(const char* robot = "microbo") {
    ASSERT_EQ(rccl_open(robot, 0), RTC_OK) << message();
    ASSERT_EQ(rccl_control(), RTC_OK) << message();
    ASSERT_EQ(setmod('j'), RTC_OK);  // settings outlive sessions, as RCCL's did
    ASSERT_EQ(setvel(100, 100), RTC_OK);
    ASSERT_EQ(move(park), RTC_OK) << message();
    waitfor(park->end);
  }
};

TEST_F(CompatManual, AlgebraAgreesWithRccxMath) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-180.0, 180.0), len(-500.0, 500.0);
  for (int i = 0; i < 200; ++i) {
    const double r1 = angle(rng), p1 = angle(rng) / 2.0, y1 = angle(rng);
    const double x = len(rng), y = len(rng), z = len(rng);
    TRSF a{}, b{}, r{};
    Rpy(&a, r1, p1, y1);
    a.p = {x, y, z};
    Eul(&b, y1, std::abs(p1), r1);
    Trsl(&r, z, x, y);
    Trmult(&b, &r, &b);  // b = Trans(z, x, y) Euler
    const math::Transform A{math::Rot3::from_rpy(r1 * kDeg, p1 * kDeg, y1 * kDeg), {x, y, z}};
    const math::Transform B{math::Rot3::from_zyz(y1 * kDeg, std::abs(p1) * kDeg, r1 * kDeg),
                            {z, x, y}};
    ASSERT_LT(max_diff(value_mm(a), A), 1e-9);
    ASSERT_LT(max_diff(value_mm(b), B), 1e-9);
    EXPECT_LT(max_diff(value_mm(*trmult(&r, &a, &b)), A * B), 1e-9);
    EXPECT_LT(max_diff(value_mm(*invert(&r, &a)), A.inverse()), 1e-9);
    EXPECT_LT(max_diff(value_mm(*trmultinv(&r, &a, &b)), A * B.inverse()), 1e-9);
    EXPECT_LT(max_diff(value_mm(*invtrmult(&r, &a, &b)), A.inverse() * B), 1e-9);
    // In place: the result may be an argument.
    Assigntr(&r, &a);
    Trmult(&r, &r, &r);
    EXPECT_LT(max_diff(value_mm(r), A * A), 1e-9);
    // Turning and moving in a transform's own frame.
    Assigntr(&r, &a);
    Rotr(&r, yunit, 30.0);
    Trslr(&r, 1.0, 2.0, 3.0);
    EXPECT_LT(max_diff(value_mm(r), A * math::Transform{math::Rot3::rot_y(30.0 * kDeg), {}} *
                                        math::Transform::translation(1.0, 2.0, 3.0)),
              1e-9);
    double e1 = 0, e2 = 0, e3 = 0;
    Trtorpy(&a, &e1, &e2, &e3);
    TRSF back{};
    Rpy(&back, e1, e2, e3);
    EXPECT_LT(max_diff(value_mm(*takerot(&r, &back)), math::Transform{A.R, value_mm(r).p}), 1e-9);
    Trtoeul(&b, &e1, &e2, &e3);
    Eul(&back, e1, e2, e3);
    Taketrsl(&back, &b);
    EXPECT_LT(max_diff(value_mm(back), B), 1e-9);
    const VECT v{len(rng), len(rng), len(rng)};
    VECT out{};
    Vecmult(&out, &a, &v);
    const math::Vec3 want = A * math::Vec3{v.x, v.y, v.z};
    EXPECT_NEAR(out.x, want.x, 1e-9);
    EXPECT_NEAR(out.y, want.y, 1e-9);
    EXPECT_NEAR(out.z, want.z, 1e-9);
    Rotvec(&out, &a, &v);
    EXPECT_NEAR(out.z, (A.R * math::Vec3{v.x, v.y, v.z}).z, 1e-9);
    Cross(&out, &v, &xunit);
    EXPECT_NEAR(dot(&out, &v), 0.0, 1e-6);
    EXPECT_NEAR(dot(&out, &xunit), 0.0, 1e-9);
    Unit(&out, &v);
    EXPECT_NEAR(norm(&out), 1.0, 1e-12);
    EXPECT_NEAR(norm(&v), std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z), 1e-9);
  }
  // The manual's one line: a transform allocated and set to a rotation about z.
  TRSF_PTR trans = rot(newtrans("TRANS", const), zunit, 90.);
  ASSERT_NE(trans, nullptr) << message();
  EXPECT_EQ(trans->type, RCCL_CONST);
  EXPECT_STREQ(trans->name, "TRANS");
  EXPECT_NEAR(trans->n.y, 1.0, 1e-12);
  EXPECT_NEAR(trans->o.x, -1.0, 1e-12);
  // gentr_pao: a and o (made orthogonal), n = o x a.
  TRSF_PTR pao = gentr_pao("PAO", 1, 2, 3, 0, 0, -1, 0, -1, 0.2);
  ASSERT_NE(pao, nullptr) << message();
  EXPECT_LT(
      max_diff(value_mm(*pao), math::Transform{math::Rot3::rot_x(std::numbers::pi), {1, 2, 3}}),
      1e-12);
  // Printing: the name and three rows.
  char buffer[512] = {};
  FILE* f = fmemopen(buffer, sizeof buffer, "w");
  printr(pao, f);
  std::fclose(f);
  EXPECT_NE(std::string(buffer).find("PAO:"), std::string::npos) << buffer;
}

TEST_F(CompatManual, BadTransformsAndEquationsAreRefusedAndChangeNothing) {
  EXPECT_EQ(rccl_newtrans("F", RCCL_FUNCT, nullptr), nullptr);
  EXPECT_EQ(rtc_error, RTC_E_ARGUMENT);
  EXPECT_EQ(rccl_newtrans("T", 99, nullptr), nullptr);
  EXPECT_EQ(gentr_pao("P", 0, 0, 0, 0, 0, 1, 0, 0, 2), nullptr);  // a parallel to o
  EXPECT_NE(message().find("not parallel"), std::string::npos) << message();
  EXPECT_EQ(gentr_rot("R", 0, 0, 0, VECT{0, 0, 0}, 10), nullptr);
  EXPECT_EQ(gentr_trsl("N", NAN, 0, 0), nullptr);
  TRSF local{};  // not made by newtrans: algebra only
  EXPECT_EQ(makeposition("L", t6, EQ, &local, TL, t6), nullptr);
  EXPECT_EQ(rtc_error, RTC_E_EQUATION);
  TRSF_PTR b = gentr_rot("B", 325.0, 150.0, 300.0, xunit, 180.0);
  TRSF_PTR tool = gentr_trsl("TOOL", 0, 0, 50);
  EXPECT_EQ(makeposition("T", t6, EQ, b, TL, tool), nullptr);  // tool not on the left
  EXPECT_NE(message().find("tool"), std::string::npos) << message();
  EXPECT_EQ(distance("dq", 1.0), RTC_E_ARGUMENT);
  EXPECT_NE(message().find("dx dy dz"), std::string::npos) << message();
  EXPECT_EQ(comply("fq", 10.0), RTC_E_ARGUMENT);
  EXPECT_NE(message().find("fx fy fz"), std::string::npos) << message();
  EXPECT_EQ(comply("fz", NAN), RTC_E_ARGUMENT);
  EXPECT_EQ(limit("fz fx", 1.0, 2.0), RTC_E_ARGUMENT);
  EXPECT_NE(message().find("one axis"), std::string::npos) << message();
  EXPECT_EQ(limit("f", -3.0), RTC_E_ARGUMENT);
  EXPECT_EQ(lock("fw"), RTC_E_ARGUMENT);
  EXPECT_EQ(lock("all"), RTC_OK);
  EXPECT_EQ(limit("off"), RTC_OK);

  // A hold set to something that is not a rotation: refused at move(), nothing queued.
  open_parked();
  TRSF_PTR h = newtrans("H", hold);
  POS_PTR p = makeposition("P", t6, EQ, b, h, TL, t6);
  ASSERT_NE(p, nullptr) << message();
  h->n.x = 2.0;
  EXPECT_EQ(move(p), RTC_E_EQUATION);
  EXPECT_NE(message().find("not a rigid transform"), std::string::npos) << message();
  EXPECT_EQ(p->end, 1);
  EXPECT_EQ(completed, 1);
  EXPECT_EQ(update(t6, p), nullptr);
  EXPECT_EQ(rtc_error, RTC_E_ARGUMENT);
}

TEST_F(CompatManual, ConstAndHoldAreReadAtMoveVarbAtEverySample) {
  TRSF_PTR b = gentr_rot("B", 325.0, 150.0, 300.0, xunit, 180.0);
  TRSF_PTR h = newtrans("H", hold);
  TRSF_PTR c = newtrans("C", const);
  POS_PTR p = makeposition("P", t6, EQ, b, c, h, TL, t6);
  ASSERT_NE(p, nullptr) << message();
  open_parked();
  const math::Transform B = value_mm(*b);

  // A const set after makeposition counts (read at move()), like a hold.
  Trsl(c, 10.0, 0.0, 0.0);
  h->p.z = 20.0;  // B's z points down: 20 mm lower
  ASSERT_EQ(move(p), RTC_OK) << message();
  h->p.z = 40.0;  // after move(): for the next motion only
  waitfor(p->end);
  wait_samples(10);
  EXPECT_LT(position_error_mm(B * math::Transform::translation(10, 0, 20)), 2.0);
  ASSERT_EQ(move(p), RTC_OK) << message();
  waitfor(p->end);
  wait_samples(10);
  EXPECT_LT(position_error_mm(B * math::Transform::translation(10, 0, 40)), 2.0);

  // varb: the arm follows while it holds the position (Cartesian mode tracks a moving goal).
  TRSF_PTR v = newtrans("V", varb);
  POS_PTR q = makeposition("Q", t6, EQ, b, v, TL, t6);
  ASSERT_EQ(setmod('c'), RTC_OK);
  ASSERT_EQ(move(q), RTC_OK) << message();
  waitfor(q->end);
  wait_samples(10);
  EXPECT_LT(position_error_mm(B), 2.0);
  for (int i = 0; i < 50; ++i) {  // 1 mm a sample, 50 mm in all
    v->p.y += 1.0;
    ASSERT_EQ(rccl_wait_sample(), RTC_OK) << message();
  }
  wait_samples(20);
  EXPECT_LT(position_error_mm(B * math::Transform::translation(0, 50, 0)), 2.0);
  EXPECT_EQ(rccl_close(0), RTC_OK) << message();
}

int calls = 0;
long last_sample = -1;
int calls_in_other_samples = 0;
/// A conveyor: 20 mm/s along y from rtime 0, called once a sample.
int conveyor(TRSF_PTR t) {
  ++calls;
  if (rccl_sample == last_sample) ++calls_in_other_samples;  // twice in one sample
  last_sample = rccl_sample;
  Trsl(t, 0.0, 0.020 * static_cast<double>(rtime), 0.0);
  return 0;
}

TEST_F(CompatManual, AFunctionRunsOncePerSampleAndIsTracked) {
  TRSF_PTR b = gentr_rot("B", 325.0, 100.0, 300.0, xunit, 180.0);
  TRSF_PTR conv = newtrans("CONV", conveyor);
  ASSERT_NE(conv, nullptr) << message();
  EXPECT_EQ(conv->type, RCCL_FUNCT);
  EXPECT_EQ(conv->age, -1);
  TRSF_PTR start = gentr_trsl("START", 0.0, -100.0, 0.0);
  POS_PTR on_belt = makeposition("BELT", t6, EQ, start, conv, b, TL, t6);
  ASSERT_NE(on_belt, nullptr) << message();
  open_parked();
  calls = 0;
  ASSERT_EQ(setmod('c'), RTC_OK);
  ASSERT_EQ(setvel(200, 100), RTC_OK);
  ASSERT_EQ(move(on_belt), RTC_OK) << message();
  waitfor(on_belt->end);
  const long first = rccl_sample;
  const int calls_before = calls;
  wait_samples(40);
  EXPECT_EQ(calls - calls_before, 40);  // once a sample
  EXPECT_EQ(calls_in_other_samples, 0);
  EXPECT_EQ(conv->age, rccl_sample);
  EXPECT_EQ(rccl_sample - first, 40);
  // The measured tool is on the belt: at most the pipeline's lag behind (2 samples of 28 ms
  // at 20 mm/s, 1.1 mm) plus the servo's.
  const math::Transform goal =
      value_mm(*start) * math::Transform::translation(0, 0.020 * static_cast<double>(rtime), 0) *
      value_mm(*b);
  EXPECT_LT(position_error_mm(goal), 3.0);
  EXPECT_EQ(rccl_close(0), RTC_OK) << message();
}

TEST_F(CompatManual, DistanceDisplacesTheNextGoalInToolCoordinates) {
  TRSF_PTR b = gentr_rot("B", 325.0, 150.0, 250.0, xunit, 180.0);
  TRSF_PTR tool = gentr_trsl("TOOL", 0.0, 0.0, 40.0);
  POS_PTR p = makeposition("P", t6, tool, EQ, b, TL, tool);
  ASSERT_NE(p, nullptr) << message();
  open_parked();
  const math::Transform B = value_mm(*b), T = value_mm(*tool);
  ASSERT_EQ(distance("dz", 30.0), RTC_OK);
  ASSERT_EQ(distance("dx", 10.0), RTC_OK);  // adds up
  ASSERT_EQ(move(p), RTC_OK) << message();
  waitfor(p->end);
  wait_samples(10);
  // T6 TOOL = B D: T6 = B D TOOL^-1.
  EXPECT_LT(position_error_mm(B * math::Transform::translation(10, 0, 30) * T.inverse()), 2.0);
  ASSERT_EQ(move(p), RTC_OK) << message();  // the displacement was for one motion
  waitfor(p->end);
  wait_samples(10);
  EXPECT_LT(position_error_mm(B * T.inverse()), 2.0);

  // update(): the hold that makes the equation hold where the arm is now.
  TRSF_PTR x = newtrans("X", hold);
  POS_PTR q = makeposition("Q", t6, tool, EQ, b, x, TL, tool);
  ASSERT_EQ(update(x, q), x) << message();
  const math::Transform X = value_mm(*x);
  EXPECT_LT(X.p.norm(), 2.0);  // the arm is at B within the servo's error
  EXPECT_LT(max_diff(math::Transform{X.R, {}}, math::Transform::identity()), 0.01);
  EXPECT_EQ(rccl_close(0), RTC_OK) << message();
}

/// Ends the motion that uses it after 600 ms of it: a guarded move's monitor.
long monitor_from = -1;
int monitor(TRSF_PTR t) {
  (void)t;
  if (monitor_from < 0) monitor_from = rtime;
  if (rtime - monitor_from > 600) nextmove = YES;
  return 0;
}

TEST_F(CompatManual, NextmoveEndsTheMotionAndTheQueueGoesOn) {
  TRSF_PTR b = gentr_rot("B", 325.0, 150.0, 300.0, xunit, 180.0);
  TRSF_PTR deep = gentr_trsl("DEEP", 0.0, 0.0, 50.0);  // 50 mm down from B
  TRSF_PTR mon = newtrans("MON", monitor);
  POS_PTR above = makeposition("ABOVE", t6, EQ, b, TL, t6);
  POS_PTR down = makeposition("DOWN", t6, EQ, b, deep, mon, TL, t6);
  ASSERT_NE(down, nullptr) << message();
  open_parked();
  ASSERT_EQ(move(above), RTC_OK) << message();
  waitfor(above->end);
  const math::Transform B = value_mm(*b);
  ASSERT_EQ(setmod('c'), RTC_OK);
  ASSERT_EQ(setvel(20, 50), RTC_OK);  // 50 mm at 20 mm/s: 2.5 s, far longer than 600 ms
  monitor_from = -1;
  const long t0 = rtime;
  ASSERT_EQ(move(down), RTC_OK) << message();
  ASSERT_EQ(move(above), RTC_OK) << message();
  waitfor(down->end);
  EXPECT_EQ(down->code, RCCL_NEXTMOVE);
  EXPECT_LT(rtime - t0, 2000);
  EXPECT_EQ(nextmove, NO);  // taken
  const math::Transform stopped = value_mm(*t6);
  const double depth = (stopped.p - B.p).norm();
  EXPECT_GT(depth, 3.0);
  EXPECT_LT(depth, 30.0);
  waitfor(completed);
  wait_samples(10);
  EXPECT_EQ(above->code, 0);
  EXPECT_LT(position_error_mm(B), 2.0);

  // From the program: nextmove = YES ends a long dwell (stop) at once.
  ASSERT_EQ(stop(5000.0), RTC_OK) << message();
  const long t1 = rtime;
  wait_samples(5);
  nextmove = YES;
  waitfor(completed);
  EXPECT_LT(rtime - t1, 1000);
  EXPECT_EQ(rccl_close(0), RTC_OK) << message();  // no failure, no limit passed
}

TEST_F(CompatManual, StopHoldsTheArmForItsTime) {
  TRSF_PTR b = gentr_rot("B", 325.0, 150.0, 300.0, xunit, 180.0);
  TRSF_PTR c = gentr_rot("C", 325.0, -150.0, 300.0, xunit, 180.0);
  POS_PTR p1 = makeposition("P1", t6, EQ, b, TL, t6);
  POS_PTR p2 = makeposition("P2", t6, EQ, c, TL, t6);
  open_parked();
  ASSERT_EQ(move(p1), RTC_OK) << message();
  ASSERT_EQ(stop(1000.0), RTC_OK) << message();
  ASSERT_EQ(move(p2), RTC_OK) << message();
  waitfor(p1->end);
  wait_samples(5);
  const long t1 = rtime;
  // The arm stays at P1 for the whole dwell, from the sample it came to rest on (p1's end):
  // a stop is not blended with the motions either side (docs/RCCL.md, "stop(ms)").
  while (rtime - t1 < 1000 - 5 * 28 - 28) {
    EXPECT_LT(position_error_mm(value_mm(*b)), 2.0) << "at " << rtime - t1 << " ms";
    ASSERT_EQ(rccl_wait_sample(), RTC_OK);
  }
  waitfor(p2->end);
  EXPECT_GT(rtime - t1, 1000);
  // stop(0): come to rest and go on; a negative or not-a-number time is refused.
  EXPECT_EQ(stop(0.0), RTC_OK) << message();
  EXPECT_EQ(stop(-1.0), RTC_E_ARGUMENT);
  EXPECT_EQ(stop(std::nan("")), RTC_E_ARGUMENT);
  waitfor(completed);
  EXPECT_EQ(rccl_close(0), RTC_E_ARGUMENT);  // the program's refused calls are its error status
}

/// The measured joints of the last row of an RCCX_LOG file (rad).
std::vector<double> last_measured_joints(const std::string& file, std::size_t dof) {
  std::ifstream in(file);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  std::vector<double> cells;
  std::stringstream ss(last);
  std::string cell;
  while (std::getline(ss, cell, ',')) cells.push_back(std::stod(cell));
  // t, seg, dof commanded, dof measured, ...
  return std::vector<double>(cells.begin() + 2 + static_cast<long>(dof),
                             cells.begin() + 2 + 2 * static_cast<long>(dof));
}

TEST_F(CompatManual, SetconfMovesThePumaIntoTheAskedConfiguration) {
  const auto k = kin::make_kinematics(kin::builtin_robot("puma560"));
  const std::string log = ::testing::TempDir() + "rccx_setconf.csv";
  // A pose all eight configurations reach within the limits (rccx kin ik --all).
  TRSF_PTR goal = gentr_pao("G", 400.0, -200.0, 300.0, 0, -1, 0, -1, 0, 0);
  POS_PTR p = makeposition("G", t6, EQ, goal, TL, t6);
  for (const char* asked : {"lun", "rdn", "l d f", "righty up noflip"}) {
    SCOPED_TRACE(asked);
    ::setenv("RCCX_LOG", log.c_str(), 1);
    open_parked("puma560");
    ASSERT_EQ(setconf(asked), RTC_OK) << message();
    ASSERT_EQ(move(p), RTC_OK) << message();
    waitfor(p->end);
    wait_samples(20);
    EXPECT_LT(position_error_mm(value_mm(*goal)), 2.0);
    ASSERT_EQ(rccl_close(0), RTC_OK) << message();
    kin::JointVector q(6);
    const std::vector<double> m = last_measured_joints(log, 6);
    for (std::size_t j = 0; j < 6; ++j) q[j] = m[j];
    const std::string got(k->configuration_names()[k->configuration_of(q).index]);
    std::string want = {'l', 'u', 'n'};
    const std::string a = asked;
    if (a == "rdn") want = "rdn";
    if (a == "l d f") want = "ldf";
    if (a == "righty up noflip") want = "run";
    EXPECT_EQ(got, want);
  }
  ASSERT_EQ(rccl_open("puma560", 0), RTC_OK);
  EXPECT_EQ(setconf("x"), RTC_E_ARGUMENT);
  EXPECT_NE(message().find("no configuration letter 'x'"), std::string::npos) << message();
}

// A log that cannot be written (a full disk: /dev/full) makes rccl_close() fail with RTC_E_LOG,
// so that a program that checks only rccl_close(), as the thesis's do, exits with an error.
TEST_F(CompatManual, ALostLogMakesRcclCloseFail) {
  ::setenv("RCCX_LOG", "/dev/full", 1);
  open_parked();
  EXPECT_EQ(rccl_close(0), RTC_E_LOG);
  EXPECT_NE(message().find("rccl_close: the sample log is lost"), std::string::npos) << message();
  ::unsetenv("RCCX_LOG");
  open_parked();
  EXPECT_EQ(rccl_close(0), RTC_OK) << message();
}

TEST_F(CompatManual, TeachTakesAStoredTransformFromTheDatabase) {
  const std::string db = ::testing::TempDir() + "rccx_teach_" + std::to_string(::getpid()) + ".db";
  std::filesystem::remove(db);
  {
    rccx::rccl::PositionDb d(db);
    rccx::rccl::StoredTransform st;
    st.robot = "microbo";
    st.name = "GRASP";
    st.value = math::Transform::translation(0.01, 0.02, 0.03);
    d.put(st);
  }
  ::setenv("RCCX_DB", db.c_str(), 1);
  TRSF_PTR b = gentr_rot("B", 325.0, 150.0, 300.0, xunit, 180.0);
  TRSF_PTR grasp = newtrans("GRASP", hold);
  POS_PTR p = makeposition("P", t6, EQ, b, grasp, TL, t6);
  open_parked();
  EXPECT_EQ(teach(grasp, p), YES) << message();
  EXPECT_NEAR(grasp->p.x, 10.0, 1e-9);
  EXPECT_NEAR(grasp->p.y, 20.0, 1e-9);
  EXPECT_NEAR(grasp->p.z, 30.0, 1e-9);
  ASSERT_EQ(move(p), RTC_OK) << message();
  waitfor(p->end);
  wait_samples(10);
  EXPECT_LT(position_error_mm(value_mm(*b) * math::Transform::translation(10, 20, 30)), 2.0);
  EXPECT_EQ(teach(t6, p), NO);
  EXPECT_EQ(rtc_error, RTC_E_ARGUMENT);
  // A database that cannot be opened: NO, a message naming it, the transform unchanged.
  ::setenv("RCCX_DB", "/nonexistent/dir/rccx.db", 1);
  TRSF_PTR other = newtrans("OTHER", hold);
  POS_PTR q = makeposition("Q", t6, EQ, b, other, TL, t6);
  EXPECT_EQ(teach(other, q), NO);
  EXPECT_EQ(rtc_error, RTC_E_OPEN);
  EXPECT_NE(message().find("/nonexistent/dir/rccx.db"), std::string::npos) << message();
  EXPECT_EQ(other->p.z, 0.0);
  EXPECT_EQ(rccl_close(0), RTC_OK) << message();
  std::filesystem::remove(db);
}

}  // namespace
