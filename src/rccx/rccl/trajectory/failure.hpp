// Why a motion fails: the kinematics' status, the joint concerned and the message for people, in
// a fixed buffer (the sample loop makes them without allocating; text.hpp formats them). What the
// segment builder and the setpoint guard hand the generator, which fails the motion with it.
//
//   if (std::optional<Failure> f = builder.build(request, ctx, t_via, segment)) {
//     fail(request.id, ctx, f->status, f->joint, f->text);
//   }
#pragma once

#include <array>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/trajectory/requests.hpp"

namespace rccx::rccl::trajectory {

using Text = std::array<char, kEventText>;

struct Failure {
  kin::IkStatus status = kin::IkStatus::ok;
  int joint = 0;  ///< 1-based, or 0: none in particular
  Text text{};
};

}  // namespace rccx::rccl::trajectory
