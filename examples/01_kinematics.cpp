// Example 01: kinematics of the thesis's robots, with no hardware.
//
// The Microbo Ecureuil's closed-form inverse puts the tool down at the four corners of the
// thesis's washer program (section 4.5.4.6); forward kinematics checks each answer. Then the
// PUMA 560 reaches one pose in each of its eight RCCL configurations.
//
// Run: ./build/release/examples/01_kinematics
#include <fmt/format.h>

#include "rccx/kinematics/kinematics.hpp"
#include "rccx/math/units.hpp"

using namespace rccx;
using namespace rccx::math::literals;

namespace {

void print_joints(const kin::Kinematics& k, const kin::JointVector& q) {
  for (std::size_t i = 0; i < q.size(); ++i) {
    const bool revolute = k.model().joints[i].type == kin::JointType::revolute;
    fmt::print(" {}={:.1f}{}", k.model().joints[i].name,
               revolute ? math::rad_to_deg(q[i]) : q[i] * 1e3, revolute ? "deg" : "mm");
  }
  fmt::print("\n");
}

}  // namespace

int main() {
  // Robots are data: robots/microbo.json, compiled into the library.
  const auto microbo = kin::make_kinematics(kin::builtin_robot("microbo"));
  fmt::print("{} - the washer program's tool-down corners\n", microbo->model().title);

  // Tool pointing down (a = -z) and turned half a turn about x, the same at every corner.
  const math::Rot3 tool_down = math::Rot3::rot_x(180_deg);
  for (double z : {250_mm, 300_mm}) {
    for (double y : {-150_mm, 150_mm}) {
      const math::Vec3 p{325_mm, y, z};
      const math::Transform T{tool_down, p};

      const kin::IkResult r = microbo->inverse(T);  // closest to the ready pose
      if (!r) {
        fmt::print("  ({:.0f}, {:.0f}, {:.0f}) mm: {}\n", p.x * 1e3, p.y * 1e3, p.z * 1e3,
                   kin::describe(r.status));
        continue;
      }
      const double error = math::max_abs_difference(microbo->forward(r.q), T);
      fmt::print("  p=({:.0f}, {:+.0f}, {:.0f}) mm  config {}:", p.x * 1e3, p.y * 1e3, p.z * 1e3,
                 microbo->configuration_name(r.configuration));
      print_joints(*microbo, r.q);
      fmt::print("      FK(IK(T)) - T = {:.1e}\n", error);
    }
  }

  // The PUMA 560: the same pose in all eight configurations. A copy of the model without joint
  // limits tells which joint keeps a configuration out of reach.
  const kin::RobotModel puma_model = kin::builtin_robot("puma560");
  const auto puma = kin::make_kinematics(puma_model);
  kin::RobotModel unlimited = puma_model;
  for (kin::Joint& j : unlimited.joints) {
    j.lower = -4 * math::kPi;
    j.upper = 4 * math::kPi;
  }
  const auto puma_unlimited = kin::make_kinematics(unlimited);
  const kin::JointVector q0{-0.8, 0.7, -2.6, 0.4, 0.9, -0.5};
  const math::Transform T = puma->forward(q0);
  fmt::print("\n{} - one pose, every configuration (from q = ", puma->model().title);
  print_joints(*puma, q0);
  for (std::string_view name : puma->configuration_names()) {
    kin::IkOptions options;
    options.configuration = puma->find_configuration(name);
    const kin::IkResult r = puma->inverse(T, options);
    fmt::print("  {}:", name);
    if (r) {
      print_joints(*puma, r.q);
      continue;
    }
    const kin::IkResult free = puma_unlimited->inverse(T, options);
    const int j = free ? puma_model.first_joint_outside_limits(free.q) : -1;
    if (j < 0) {
      fmt::print(" {}\n", kin::describe(r.status));
      continue;
    }
    const kin::Joint& joint = puma_model.joints[static_cast<std::size_t>(j)];
    fmt::print(" needs {} = {:.1f} deg, outside its limits {:.0f} .. {:.0f} deg\n", joint.name,
               math::rad_to_deg(free.q[static_cast<std::size_t>(j)]), math::rad_to_deg(joint.lower),
               math::rad_to_deg(joint.upper));
  }

  // A pose beyond the arm's reach gives a reason, not NaN.
  const kin::IkResult far = puma->inverse(math::Transform::translation(2.0, 0.0, 0.0));
  fmt::print("\n  2 m away: {}\n", kin::describe(far.status));
  return 0;
}
