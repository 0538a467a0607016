// Drives a TrajectoryGenerator sample by sample with no session: an ideal arm (measured = the
// last setpoint), simulated time t = k P. What the generator tests observe.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/trajectory.hpp"

namespace rccx::test {

struct GeneratorRun {
  explicit GeneratorRun(const std::string& robot, double period_s = 0.01)
      : GeneratorRun(kin::builtin_robot(robot), period_s) {}
  explicit GeneratorRun(kin::RobotModel robot, double period_s = 0.01)
      : model(std::move(robot)),
        kinematics(kin::make_kinematics(model)),
        period(period_s),
        generator(*kinematics, rccl::GeneratorOptions{period_s, {}, {}}) {
    generator.reset(model.ready(), 0.0);
    q = model.ready();
  }

  /// Queues a move to `p` with `s`; returns its id.
  std::uint64_t move(const rccl::PositionPtr& p, const rccl::MotionSettings& s) {
    keep.push_back(p);
    rccl::MotionRequest r;
    r.id = next_id++;
    r.position = p.get();
    r.settings = s;
    p->pending_ends.fetch_add(1);
    if (!generator.submit(r)) throw std::runtime_error("queue full");
    return r.id;
  }

  /// Queues a dwell (RCCL's stop) of `s` seconds; returns its id.
  std::uint64_t dwell(double s) {
    rccl::MotionRequest r;
    r.kind = rccl::RequestKind::dwell;
    r.id = next_id++;
    r.dwell_s = s;
    if (!generator.submit(r)) throw std::runtime_error("queue full");
    return r.id;
  }

  /// One sample; records the setpoint, its segment and the events.
  void step() {
    const rccl::SampleContext ctx{static_cast<double>(k) * period, k, nullptr};
    kin::JointVector measured = q;
    segment.push_back(generator.step(ctx, &measured, q));
    t.push_back(ctx.t_s);
    qs.push_back(q);
    while (auto e = generator.next_event()) events.push_back(*e);
    ++k;
  }

  /// Runs until motion `id` has ended (or failed), at most `max_s` more seconds; true if it did.
  bool run_until_ended(std::uint64_t id, double max_s = 120.0) {
    const std::uint64_t limit = k + static_cast<std::uint64_t>(max_s / period);
    while (generator.ended_upto() < id && k < limit) step();
    return generator.ended_upto() >= id;
  }
  /// Runs until the generator is at rest with nothing queued.
  bool run_until_rest(double max_s = 120.0) {
    const std::uint64_t limit = k + static_cast<std::uint64_t>(max_s / period);
    step();
    while (!(generator.at_rest() && generator.ended_upto() + 1 >= next_id) && k < limit) step();
    return generator.at_rest();
  }
  void run_for(double s) {
    const auto n = static_cast<std::uint64_t>(s / period);
    for (std::uint64_t i = 0; i < n; ++i) step();
  }

  /// The time of the first event of `kind` for motion `id`, or -1.
  [[nodiscard]] double event_time(rccl::EventKind kind, std::uint64_t id) const {
    for (const auto& e : events) {
      if (e.kind == kind && e.id == id) return e.t_s;
    }
    return -1.0;
  }
  [[nodiscard]] const rccl::MotionEvent* find_event(rccl::EventKind kind) const {
    for (const auto& e : events) {
      if (e.kind == kind) return &e;
    }
    return nullptr;
  }

  kin::RobotModel model;
  std::unique_ptr<kin::Kinematics> kinematics;
  double period;
  rccl::TrajectoryGenerator generator;
  std::vector<rccl::PositionPtr> keep;
  std::uint64_t next_id = 1;
  std::uint64_t k = 0;
  kin::JointVector q;
  std::vector<double> t;
  std::vector<kin::JointVector> qs;
  std::vector<std::uint64_t> segment;
  std::vector<rccl::MotionEvent> events;
};

}  // namespace rccx::test
