// The generator's constant model (Pinocchio's manner: the model apart from the data the loop
// changes): the kinematics, the options with their defaults filled in, the joint limits. Made
// once by the generator's constructor; every part of the generator reads it, none changes it.
//
//   const GeneratorModel model(kinematics, options);  // max_velocity, max_acceleration defaulted
//   double a = model.planning_acceleration(j);        // what transitions are planned at
#pragma once

#include <cstddef>
#include <utility>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/trajectory/requests.hpp"

namespace rccx::rccl::trajectory {

using kin::JointVector;

struct GeneratorModel {
  GeneratorModel(const kin::Kinematics& kinematics, GeneratorOptions opts)
      : kin(kinematics),
        options(std::move(opts)),
        lower(kinematics.model().lower()),
        upper(kinematics.model().upper()) {
    const auto& joints = kin.model().joints;
    const std::size_t n = kin.dof();
    if (options.max_velocity.size() != n) {
      options.max_velocity = JointVector(n);
      for (std::size_t j = 0; j < n; ++j) options.max_velocity[j] = joints[j].max_velocity;
    }
    if (options.max_acceleration.size() != n) {
      options.max_acceleration = JointVector(n);
      for (std::size_t j = 0; j < n; ++j) {
        options.max_acceleration[j] = options.max_velocity[j] / kDefaultAccelerationTime_s;
      }
    }
  }

  /// The acceleration transitions are planned at (rad/s^2 or m/s^2).
  [[nodiscard]] double planning_acceleration(std::size_t j) const noexcept {
    return kPlanningAccelerationFraction * options.max_acceleration[j];
  }

  const kin::Kinematics& kin;
  GeneratorOptions options;  ///< defaults filled in; period_s is the sample period, s
  JointVector lower, upper;  ///< the joints' limits (rad / m)
};

}  // namespace rccx::rccl::trajectory
