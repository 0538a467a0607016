#include "rccx/kinematics/link_frames.hpp"

#include <algorithm>
#include <cmath>

#include "rccx/kinematics/dh_step.hpp"
#include "rccx/math/batch_trig.hpp"

namespace rccx::kin {

DhChain::DhChain(const RobotModel& model) noexcept : dof(std::min(model.dof(), kMaxJoints)) {
  for (std::size_t i = 0; i < dof; ++i) {
    const Joint& j = model.joints[i];
    Link& l = links[i];
    l = {j.dh.a_m, std::cos(j.dh.alpha_rad), std::sin(j.dh.alpha_rad),
         j.dh.d_m, j.dh.theta_rad,           j.type == JointType::prismatic};
    // cos(pi/2) is 6e-17, not 0; snapped as Kinematics does, so both chains agree exactly.
    if (std::abs(l.cos_alpha) < 1e-15) l.cos_alpha = 0.0;
    if (std::abs(l.sin_alpha) < 1e-15) l.sin_alpha = 0.0;
  }
  general = model.geometry == Geometry::chain;
  for (std::size_t i = 0; general && i < dof; ++i) {
    steps[i] = PreparedStep(model.joints[i].chain, model.joints[i].type == JointType::prismatic);
  }
}

void link_frames(const DhChain& chain, const JointVector& q, std::span<math::Transform> out,
                 const math::Transform& base) noexcept {
  const std::size_t n = std::min(chain.dof, out.size());
  double theta[kMaxJoints] = {}, st[kMaxJoints], ct[kMaxJoints];
  for (std::size_t i = 0; i < n; ++i) {
    theta[i] = chain.general ? (chain.steps[i].prismatic ? 0.0 : q[i])
                             : chain.links[i].theta_rad + (chain.links[i].prismatic ? 0.0 : q[i]);
  }
  if (n > 4) {
    math::sincos8(theta, st, ct);
  } else {
    math::sincos4(theta, st, ct);
  }
  math::Transform T = base;
  if (chain.general) {  // as Kinematics::chain_forward, from the base
    for (std::size_t i = 0; i < n; ++i) {
      apply_chain_step(T, chain.steps[i], q[i], ct[i], st[i]);
      out[i] = T;
    }
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const DhChain::Link& l = chain.links[i];
    const double d = l.d_m + (l.prismatic ? q[i] : 0.0);
    apply_dh_link(T, ct[i], st[i], l.cos_alpha, l.sin_alpha, l.a_m, d);
    out[i] = T;
  }
}

void link_frames(const RobotModel& model, const JointVector& q,
                 std::span<math::Transform> out) noexcept {
  link_frames(DhChain(model), q, out);
}

}  // namespace rccx::kin
