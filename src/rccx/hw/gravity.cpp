#include "rccx/hw/gravity.hpp"

#include <algorithm>
#include <cmath>

#include "rccx/math/transform.hpp"

namespace rccx::hw {

GravityModel::GravityModel(const kin::RobotModel& model) noexcept
    : general_(model.geometry == kin::Geometry::chain), n_(std::min(model.dof(), kin::kMaxJoints)) {
  for (std::size_t i = 0; i < n_; ++i) {
    const kin::Joint& j = model.joints[i];
    links_[i] = {j.dh.a_m,
                 std::cos(j.dh.alpha_rad),
                 std::sin(j.dh.alpha_rad),
                 j.dh.d_m,
                 j.dh.theta_rad,
                 j.type == kin::JointType::prismatic,
                 j.dynamics.link_mass_kg,
                 j.dynamics.link_com_m};
    if (general_) steps_[i] = kin::PreparedStep(j.chain, j.type == kin::JointType::prismatic);
  }
}

kin::JointVector GravityModel::load(const kin::JointVector& q) const noexcept {
  using math::Vec3;
  // Frame i-1's origin and z axis for each joint i, and each link's centre of mass, in the base.
  std::array<Vec3, kin::kMaxJoints> origin{}, axis{}, com{};
  math::Transform T = math::Transform::identity();
  for (std::size_t i = 0; i < n_ && general_; ++i) {
    const kin::PreparedStep& step = steps_[i];
    const math::Transform at = T * step.origin;  // the joint's frame before its motion
    origin[i] = at.p;
    axis[i] = at.R * step.axis;
    const double c = step.prismatic ? 1.0 : std::cos(q[i]);
    const double s = step.prismatic ? 0.0 : std::sin(q[i]);
    kin::apply_chain_step(T, step, q[i], c, s);
    const Link& l = links_[i];
    com[i] = T * Vec3{l.com[0], l.com[1], l.com[2]};
  }
  for (std::size_t i = 0; i < n_ && !general_; ++i) {
    const Link& l = links_[i];
    origin[i] = T.p;
    axis[i] = T.R.a;
    const double theta = l.prismatic ? l.theta : l.theta + q[i];
    const double d = l.prismatic ? l.d + q[i] : l.d;
    const double ct = std::cos(theta), st = std::sin(theta);
    // A_i = Rot(z, theta) Trans(z, d) Trans(x, a) Rot(x, alpha) (thesis eq. 3.3).
    const math::Transform A{
        {{ct, st, 0.0}, {-st * l.ca, ct * l.ca, l.sa}, {st * l.sa, -ct * l.sa, l.ca}},
        {l.a * ct, l.a * st, d}};
    T = T * A;
    com[i] = T * Vec3{l.com[0], l.com[1], l.com[2]};
  }
  // From the tip down: the mass beyond joint j and its first moment about the base origin.
  kin::JointVector tau(n_);
  double mass = 0.0;
  Vec3 moment{};
  for (std::size_t k = n_; k-- > 0;) {
    mass += links_[k].mass;
    moment += com[k] * links_[k].mass;
    if (links_[k].prismatic) {
      tau[k] = kGravity_m_per_s2 * mass * axis[k].z;
    } else {
      tau[k] = kGravity_m_per_s2 * math::cross(axis[k], moment - origin[k] * mass).z;
    }
  }
  return tau;
}

}  // namespace rccx::hw
