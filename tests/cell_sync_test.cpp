// Synchronisation between the robots of a cell (Multi-RCCL), in simulated time on
// cells/cvarl.json (PUMA every 7 ms tick, Microbo every fourth): motions started by other
// robots' events, sample-exact whatever the robots' order; joint starts and joint ends in the
// same sample; a motion waiting on a robot whose motion failed or whose control ended is
// cancelled with the reason; the program waiting on any robot's events.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "cell_helpers.hpp"
#include "rccx/cell/cell.hpp"
#include "rccx/hw/simulated_arm.hpp"

using namespace rccx;
using namespace rccx::cell_test;
using namespace std::chrono_literals;

namespace {

const math::Vec3 kPumaAt = kAbove + math::Vec3{-0.05, 0.0, 0.0};
const math::Vec3 kMicroboAt = kAbove + math::Vec3{0.10, 0.0, 0.0};
const math::Vec3 kDy{0.0, 0.03, 0.0};

/// The Microbo is sampled at ticks 1, 5, 9, ... (every fourth of the 7 ms clock).
bool microbo_due(std::uint64_t tick) {
  return (tick - 1) % 4 == 0;
}
std::uint64_t next_microbo_tick_after(std::uint64_t tick) {
  std::uint64_t k = tick + 1;
  while (!microbo_due(k)) ++k;
  return k;
}

/// The events a robot has sent so far, kept across calls (take_events empties the queue).
struct Events {
  std::vector<rccl::MotionEvent> all;
  void take(rccl::Manipulator& m) {
    for (const rccl::MotionEvent& e : m.take_events()) all.push_back(e);
  }
  /// The sample (tick) of motion id's event of that kind; 0 when it has not happened.
  [[nodiscard]] std::uint64_t sample(rccl::EventKind kind, std::uint64_t id) const {
    for (const rccl::MotionEvent& e : all) {
      if (e.kind == kind && e.id == id) return e.sample;
    }
    return 0;
  }
  [[nodiscard]] std::string message(std::uint64_t id) const {
    for (const rccl::MotionEvent& e : all) {
      if (e.id == id &&
          (e.kind == rccl::EventKind::failed || e.kind == rccl::EventKind::cancelled)) {
        return std::string(e.message());
      }
    }
    return {};
  }
};

/// A cell with both arms moved to their places above the board, at rest.
std::unique_ptr<cell::Cell> cell_at_rest(cell::CellOptions o = {},
                                         cell::CellModel model = cell::load_cell_file(kCvarl)) {
  auto c = std::make_unique<cell::Cell>(std::move(model), o);
  c->start();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  for (rccl::Manipulator* m : {&puma, &microbo}) m->set_velocity(0.05, 0.5);
  puma.move(world_position(*c, "puma", "P0", down_at(kPumaAt)));
  microbo.move(world_position(*c, "microbo", "M0", down_at(kMicroboAt)));
  EXPECT_EQ(puma.waitfor(rccl::Manipulator::completed(), 20s), rccl::WaitResult::reached)
      << failures_of(puma);
  EXPECT_EQ(microbo.waitfor(rccl::Manipulator::completed(), 20s), rccl::WaitResult::reached)
      << failures_of(microbo);
  (void)puma.take_events();
  (void)microbo.take_events();
  for (rccl::Manipulator* m : {&puma, &microbo}) m->set_mode(rccl::Mode::cartesian);
  return c;
}

}  // namespace

TEST(CellSync, ChainedEventsRunInTheOrderAskedSampleExact) {
  const auto c = cell_at_rest();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  // A (PUMA) -> B (Microbo) starts when A has ended -> C (PUMA) starts when B has started ->
  // D (Microbo) starts when C has ended. The Microbo is stepped after the PUMA in a tick (B, D)
  // and the PUMA before the Microbo (C): both orders.
  const rccl::Motion a = puma.move(world_position(*c, "puma", "A", down_at(kPumaAt + kDy)));
  const rccl::Motion b = microbo.move(world_position(*c, "microbo", "B", down_at(kMicroboAt + kDy)),
                                      c->after("puma", a.end()));
  const rccl::Motion cc =
      puma.move(world_position(*c, "puma", "C", down_at(kPumaAt)), c->after("microbo", b.start()));
  const rccl::Motion d = microbo.move(world_position(*c, "microbo", "D", down_at(kMicroboAt)),
                                      c->after("puma", cc.end()));

  ASSERT_EQ(c->waitfor({c->event("microbo", d.end())}, 30s), rccl::WaitResult::reached)
      << failures_of(puma) << failures_of(microbo);
  Events ep, em;
  ep.take(puma);
  em.take(microbo);
  const std::uint64_t a_end = ep.sample(rccl::EventKind::ended, a.id);
  const std::uint64_t b_start = em.sample(rccl::EventKind::started, b.id);
  const std::uint64_t c_start = ep.sample(rccl::EventKind::started, cc.id);
  const std::uint64_t c_end = ep.sample(rccl::EventKind::ended, cc.id);
  const std::uint64_t d_start = em.sample(rccl::EventKind::started, d.id);
  ASSERT_GT(a_end, 0U);
  // Each starts at its robot's first sample after the tick of the event it waits for.
  EXPECT_EQ(b_start, next_microbo_tick_after(a_end));
  EXPECT_EQ(c_start, b_start + 1);  // the PUMA is sampled every tick
  EXPECT_EQ(d_start, next_microbo_tick_after(c_end));
  EXPECT_TRUE(puma.failures().empty()) << failures_of(puma);
  EXPECT_TRUE(microbo.failures().empty()) << failures_of(microbo);
  // And each went where it was sent.
  c->wait_for(1s);
  EXPECT_LT((tool_point(*c, "microbo", c->session("microbo").how().q()) - kMicroboAt).norm(), 2e-3);
}

TEST(CellSync, AGatedMotionWhoseGateIsOpenJoinsItsPredecessorWithoutStopping) {
  const auto c = cell_at_rest();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  const rccl::Motion m =
      microbo.move(world_position(*c, "microbo", "M", down_at(kMicroboAt + kDy)));
  ASSERT_EQ(microbo.waitfor(m.end(), 20s), rccl::WaitResult::reached);
  // The PUMA's second motion waits for an event that has happened: it blends in as usual.
  const rccl::Motion a = puma.move(world_position(*c, "puma", "A", down_at(kPumaAt + kDy)));
  const rccl::Motion b =
      puma.move(world_position(*c, "puma", "B", down_at(kPumaAt)), c->after("microbo", m.end()));
  ASSERT_EQ(puma.waitfor(b.end(), 20s), rccl::WaitResult::reached) << failures_of(puma);
  Events ep;
  ep.take(puma);
  // B's transition in began before A came to rest: B started before A ended.
  EXPECT_LT(ep.sample(rccl::EventKind::started, b.id), ep.sample(rccl::EventKind::ended, a.id));
}

TEST(CellSync, MotionsOfAJointStartStartInTheSameSample) {
  const auto c = cell_at_rest();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  // The PUMA is busy first; the Microbo's part waits at rest for it.
  const rccl::Motion first = puma.move(world_position(*c, "puma", "F", down_at(kPumaAt + kDy)));
  const cell::Together go = c->together({"puma", "microbo"});
  const rccl::Motion a =
      puma.move(world_position(*c, "puma", "A", down_at(kPumaAt)), go.when("puma"));
  const rccl::Motion b = microbo.move(
      world_position(*c, "microbo", "B", down_at(kMicroboAt + kDy + kDy)), go.when("microbo"));
  ASSERT_EQ(c->waitfor({c->event("puma", a.end()), c->event("microbo", b.end())}, 30s),
            rccl::WaitResult::reached)
      << failures_of(puma) << failures_of(microbo);
  Events ep, em;
  ep.take(puma);
  em.take(microbo);
  const std::uint64_t sa = ep.sample(rccl::EventKind::started, a.id);
  EXPECT_GT(sa, ep.sample(rccl::EventKind::ended, first.id));
  EXPECT_EQ(sa, em.sample(rccl::EventKind::started, b.id));
  EXPECT_TRUE(microbo_due(sa));
  // Not asked to end together: the shorter one ends first.
  EXPECT_LT(ep.sample(rccl::EventKind::ended, a.id), em.sample(rccl::EventKind::ended, b.id));
}

TEST(CellSync, MotionsAskedToEndTogetherEndInTheSameSampleTheFasterSlowed) {
  const auto c = cell_at_rest();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  // 10 mm for the PUMA against 60 mm for the Microbo, at the same speed.
  const cell::Together go = c->together({"microbo", "puma"}, true);
  const rccl::Motion a =
      puma.move(world_position(*c, "puma", "A", down_at(kPumaAt + math::Vec3{0.0, 0.01, 0.0})),
                go.when("puma"));
  const rccl::Motion b = microbo.move(
      world_position(*c, "microbo", "B", down_at(kMicroboAt + kDy + kDy)), go.when("microbo"));
  ASSERT_EQ(c->waitfor({c->event("puma", a.end()), c->event("microbo", b.end())}, 30s),
            rccl::WaitResult::reached)
      << failures_of(puma) << failures_of(microbo);
  Events ep, em;
  ep.take(puma);
  em.take(microbo);
  EXPECT_EQ(ep.sample(rccl::EventKind::started, a.id), em.sample(rccl::EventKind::started, b.id));
  EXPECT_EQ(ep.sample(rccl::EventKind::ended, a.id), em.sample(rccl::EventKind::ended, b.id));
  // Their reports say so too: the time of the sample they ended in, not of their setpoints
  // (the Microbo's run two 28 ms periods ahead, the PUMA's two 7 ms ones).
  const std::uint64_t end_tick = ep.sample(rccl::EventKind::ended, a.id);
  const double base_period_s = std::chrono::duration<double>(c->group().period()).count();
  for (rccl::Manipulator* arm : {&puma, &microbo}) {
    const rccl::Motion& m = arm == &puma ? a : b;
    EXPECT_NEAR(arm->report(m).end_s, static_cast<double>(end_tick) * base_period_s, 1e-9);
  }
  EXPECT_DOUBLE_EQ(puma.report(a).start_s, microbo.report(b).start_s);
  // The PUMA's 10 mm took as long as the Microbo's 60 mm (0.05 m/s alone: about 0.2 s + its
  // transitions), still on its line.
  const rccl::SegmentReport ra = puma.report(a);
  EXPECT_GT(ra.duration_s, 1.0) << "not slowed";
  EXPECT_LT(ra.max_commanded_path_error_m, 1e-4);
  c->wait_for(1s);
  EXPECT_LT((tool_point(*c, "puma", c->session("puma").how().q()) -
             (kPumaAt + math::Vec3{0.0, 0.01, 0.0}))
                .norm(),
            2e-3);
  EXPECT_TRUE(puma.failures().empty()) << failures_of(puma);
  EXPECT_TRUE(microbo.failures().empty()) << failures_of(microbo);
}

TEST(CellSync, AMotionWaitingOnAFailedMotionIsCancelledWithTheReason) {
  const auto c = cell_at_rest();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  const rccl::Motion a = puma.move(world_position(*c, "puma", "A", down_at(kPumaAt + kDy)));
  const rccl::Motion b = microbo.move(world_position(*c, "microbo", "B", down_at(kMicroboAt + kDy)),
                                      c->after("puma", a.end()));
  const rccl::Motion b2 = microbo.move(world_position(*c, "microbo", "B2", down_at(kMicroboAt)));
  c->wait_for(100ms);
  puma.halt();  // A fails
  EXPECT_EQ(c->waitfor({c->event("puma", a.end())}, 5s), rccl::WaitResult::failed);
  EXPECT_EQ(microbo.waitfor(b.end(), 5s), rccl::WaitResult::failed);
  EXPECT_EQ(microbo.waitfor(b2.end(), 5s), rccl::WaitResult::failed);  // after it: cancelled
  Events em;
  em.take(microbo);
  const std::string why = em.message(b.id);
  EXPECT_NE(why.find("waited for the end of puma's motion"), std::string::npos) << why;
  EXPECT_NE(why.find("failed or was cancelled"), std::string::npos) << why;
  EXPECT_TRUE(c->session("microbo").controlling());
  EXPECT_EQ(em.sample(rccl::EventKind::started, b.id), 0U) << "it never started";
}

TEST(CellSync, AFaultCancelsTheMotionsWaitingOnTheFailedRobot) {
  cell::CellOptions o;
  o.stop_others_on_fault = false;  // only the gate's cancellation, not the cell's stop
  const auto c = cell_at_rest(o);
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  const rccl::Motion a = puma.move(world_position(*c, "puma", "A", down_at(kPumaAt + kDy)));
  const rccl::Motion b = microbo.move(world_position(*c, "microbo", "B", down_at(kMicroboAt + kDy)),
                                      c->after("puma", a.end()));
  // A joint start with the PUMA that it will never reach.
  const cell::Together go = c->together({"puma", "microbo"});
  c->wait_for(100ms);
  c->hardware("puma").arm->inject(hw::Fault::joint_not_answering, 1);
  EXPECT_EQ(microbo.waitfor(b.end(), 5s), rccl::WaitResult::failed);
  Events em;
  em.take(microbo);
  const std::string why = em.message(b.id);
  EXPECT_NE(why.find("puma's control ended"), std::string::npos) << why;
  EXPECT_EQ(c->waitfor({c->event("puma", a.end())}, 1s), rccl::WaitResult::failed);
  // A part of a joint start whose other robot's control has ended is cancelled too.
  const rccl::Motion j =
      microbo.move(world_position(*c, "microbo", "J", down_at(kMicroboAt)), go.when("microbo"));
  EXPECT_EQ(microbo.waitfor(j.end(), 5s), rccl::WaitResult::failed);
  em.take(microbo);
  EXPECT_NE(em.message(j.id).find("joint start cannot happen: puma's control ended"),
            std::string::npos)
      << em.message(j.id);
  EXPECT_TRUE(c->session("microbo").controlling());
}

TEST(CellSync, AJointStartWhoseOtherPartIsCancelledIsCancelled) {
  const auto c = cell_at_rest();
  rccl::Manipulator& puma = c->robot("puma");
  rccl::Manipulator& microbo = c->robot("microbo");
  const cell::Together go = c->together({"puma", "microbo"});
  // The PUMA's part is queued behind a motion that will be halted: both are cancelled.
  const rccl::Motion first = puma.move(world_position(*c, "puma", "F", down_at(kPumaAt + kDy)));
  const rccl::Motion a =
      puma.move(world_position(*c, "puma", "A", down_at(kPumaAt)), go.when("puma"));
  const rccl::Motion b = microbo.move(world_position(*c, "microbo", "B", down_at(kMicroboAt + kDy)),
                                      go.when("microbo"));
  c->wait_for(100ms);
  puma.halt();
  EXPECT_EQ(puma.waitfor(first.end(), 5s), rccl::WaitResult::failed);
  EXPECT_EQ(puma.waitfor(a.end(), 5s), rccl::WaitResult::failed);
  EXPECT_EQ(microbo.waitfor(b.end(), 5s), rccl::WaitResult::failed);
  Events em;
  em.take(microbo);
  const std::string why = em.message(b.id);
  EXPECT_NE(why.find("joint start cannot happen: puma's motion"), std::string::npos) << why;
  EXPECT_NE(why.find("halted by the program"), std::string::npos) << why;
  // A used or broken rendezvous is refused at the call.
  EXPECT_THROW((void)microbo.move(microbo.park(), go.when("microbo")), rccl::MotionError);
  EXPECT_THROW((void)go.when("scara"), std::invalid_argument);
}

TEST(CellSync, BadStartConditionsAreRefusedAtTheCall) {
  const auto c = cell_at_rest();
  rccl::Manipulator& puma = c->robot("puma");
  // Its own live ledger, a motion not queued yet: it would wait for itself.
  rccl::StartWhen own;
  own.after = {puma.gate(rccl::Motion{puma.last_queued() + 1}.end())};
  EXPECT_THROW((void)puma.move(puma.park(), own), rccl::MotionError);
  rccl::StartWhen many;
  many.after.assign(rccl::StartWhen::kMaxGates + 1,
                    c->event("microbo", rccl::Manipulator::completed()));
  EXPECT_THROW((void)puma.move(puma.park(), many), rccl::MotionError);
  const auto p = world_position(*c, "puma", "X", down_at(kPumaAt));
  EXPECT_THROW((void)c->event("puma", rccl::Manipulator::ended(p)), rccl::MotionError);
  EXPECT_THROW((void)c->event("scara", rccl::Manipulator::completed()), std::invalid_argument);
  EXPECT_THROW((void)c->together({"puma", "puma"}), std::invalid_argument);
  // The Microbo's place in a joint start given to the PUMA's motion.
  const cell::Together go = c->together({"puma", "microbo"});
  try {
    (void)puma.move(puma.park(), go.when("microbo"));
    ADD_FAILURE() << "another robot's place in a joint start was taken";
  } catch (const rccl::MotionError& e) {
    EXPECT_NE(std::string(e.what()).find("place 1 is robot microbo's"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(puma.happened(rccl::Manipulator::completed())) << "nothing was queued";
  // Its own place is taken: the arm stays at rest, waiting for the Microbo's part.
  const math::Vec3 at0 = tool_point(*c, "puma", c->session("puma").how().q());
  (void)puma.move(world_position(*c, "puma", "O", down_at(kPumaAt + kDy)), go.when("puma"));
  c->wait_for(300ms);
  // (its servo settles by some 0.05 mm; started, the 30 mm motion would be far on)
  EXPECT_LT((tool_point(*c, "puma", c->session("puma").how().q()) - at0).norm(), 5e-4);
}

TEST(CellSync, AChainedStartIsTheNextSampleWhicheverRobotIsSteppedFirst) {
  // Both robots every tick (ideal servos: the Microbo's RCU does not serve 7 ms), so the
  // sample after an event is the next tick for either, whether the waiting robot is stepped
  // before (PUMA) or after (Microbo) the one it waits for.
  cell::CellModel model = cell::load_cell_file(kCvarl);
  model.robots[1].period_multiple = 1;
  cell::CellOptions o;
  o.ideal_servo = true;
  const auto cp = cell_at_rest(o, model);
  cell::Cell& c = *cp;
  rccl::Manipulator& puma = c.robot("puma");
  rccl::Manipulator& microbo = c.robot("microbo");
  const rccl::Motion a = puma.move(world_position(c, "puma", "A", down_at(kPumaAt + kDy)));
  const rccl::Motion b = microbo.move(world_position(c, "microbo", "B", down_at(kMicroboAt + kDy)),
                                      c.after("puma", a.end()));
  const rccl::Motion a2 =
      puma.move(world_position(c, "puma", "A2", down_at(kPumaAt)), c.after("microbo", b.end()));
  ASSERT_EQ(c.waitfor({c.event("puma", a2.end())}, 60s), rccl::WaitResult::reached)
      << failures_of(puma) << failures_of(microbo);
  Events ep, em;
  ep.take(puma);
  em.take(microbo);
  EXPECT_EQ(em.sample(rccl::EventKind::started, b.id), ep.sample(rccl::EventKind::ended, a.id) + 1);
  EXPECT_EQ(ep.sample(rccl::EventKind::started, a2.id),
            em.sample(rccl::EventKind::ended, b.id) + 1);
}
