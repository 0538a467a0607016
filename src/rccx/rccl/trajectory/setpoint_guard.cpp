#include "rccx/rccl/trajectory/setpoint_guard.hpp"

#include "rccx/rccl/trajectory/text.hpp"

namespace rccx::rccl::trajectory {

Failure describe(const GuardTrip& trip, const GeneratorModel& m, const GoalTrack& goals,
                 const Segment& present, double t) noexcept {
  const std::size_t j = trip.joint;
  const int joint = static_cast<int>(j) + 1;
  if (goals.jumped(present.position)) {
    return Failure{kin::IkStatus::ok, joint,
                   text("the goal of {} jumped {:.1f} mm in a sample at t = {:.3f} s, joint {} "
                        "would follow too fast (a varb changed at once? Use hold, read at move(), "
                        "or change it in small steps)",
                        present.position->name(), goals.jump_m * 1e3, t, joint)};
  }
  if (trip.out) {
    return Failure{kin::IkStatus::joint_limits, joint,
                   text("joint {} would leave its limits at t = {:.3f} s", joint, t)};
  }
  if (trip.fast) {
    return Failure{kin::IkStatus::singular, joint,
                   text("joint {} would move at {:.3f}/s, above its top speed {:.3f}/s at t = "
                        "{:.3f} s (the path passes near a singularity?)",
                        joint, trip.speed, m.options.max_velocity[j], t)};
  }
  return Failure{kin::IkStatus::singular, joint,
                 text("joint {} would accelerate at {:.1f}/s^2, {:.1f} times its bound, at t = "
                      "{:.3f} s (the path passes near a singularity, or its goal jumped)",
                      joint, trip.accel, trip.accel / m.options.max_acceleration[j], t)};
}

}  // namespace rccx::rccl::trajectory
