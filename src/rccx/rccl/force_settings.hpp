// What a motion asks of the wrist force sensor (RCCL's force control, which the Microbo port
// had to leave out, thesis 4.4.2): a guard that ends the motion on contact (RCCL's monitor
// and nextmove, sensor-driven), and compliance along chosen axes of the tool frame (RCCL's
// comply / lock). Plain values: each motion request carries a copy, as it does the speeds.
//
//   arm.set_guard({.kind = rccl::ForceGuard::Kind::along, .axis = 2, .threshold = 5.0});
//   arm.waitfor(arm.move(below).end());              // stops once fz reaches 5 N
//   arm.set_guard({});
//   arm.set_compliance({.axes = 1U << 2, .force = {0, 0, 10.0}});   // press 10 N along z
//   arm.waitfor(arm.move(along).end());              // slides, holding the force
//   arm.set_compliance({});
//
// Axes are those of the motion's tool frame F = T6 TOOL: 0..2 forces along x y z (N), 3..5
// torques about them (N m). Forces are the ones the tool exerts on what it touches: pressing
// the tool's z axis onto a table is a positive fz.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace rccx::rccl {

inline constexpr std::array<std::string_view, 6> kForceAxisNames = {"fx", "fy", "fz",
                                                                    "tx", "ty", "tz"};

/// Ends a motion smoothly, as nextmove does, when the contact force passes a threshold.
struct ForceGuard {
  enum class Kind : std::uint8_t {
    none,
    along,      ///< the component on `axis` reaches `threshold` (its sign says which way)
    magnitude,  ///< the force's magnitude (N, the three force axes) reaches `threshold`
  };
  Kind kind = Kind::none;
  std::uint8_t axis = 2;   ///< along: 0..5 (fx .. tz of the tool frame)
  double threshold = 5.0;  ///< N or N m; along: negative trips on a pull
  [[nodiscard]] bool on() const noexcept { return kind != Kind::none; }
};

/// Default damping of a compliant force axis, N s/m: an unbalanced 10 N moves the tool about
/// 3 mm/s. The admittance stays stable while D is well above period x k, k the stiffness the
/// tool meets through the arm's servos; tuned on the PUMA 560 at 10 ms against MuJoCo's
/// contact with a 20 ms time constant (hw::Scene), where it holds a set force within 10 %
/// while sliding (docs/FORCE.md). Raise it for stiffer contact.
inline constexpr double kDefaultDamping_N_s_per_m = 3000.0;
/// ... of a compliant torque axis, N m s/rad.
inline constexpr double kDefaultDamping_N_m_s_per_rad = 30.0;

/// Admittance along the compliant axes of the tool frame: each yields from the planned path by
/// an offset x that moves as  D dx/dt = (f_set - f) - K x  (f: the force the tool exerts, so
/// a push on the tool towards -x is an f > 0 and the tool gives way towards -x), so a
/// stiffness K alone makes a spring back to the path, a set force f_set alone (K = 0) pushes
/// until the tool exerts f_set, and both together a spring with a preload. Locked
/// axes follow the path; an offset left from a compliant stretch returns to the path along a
/// locked axis within the speed limit.
struct Compliance {
  std::uint8_t axes = 0;                ///< bit i set: axis i (fx .. tz) is compliant
  std::array<double, 6> force{};        ///< f_set, N or N m
  std::array<double, 6> stiffness{};    ///< K, N/m or N m/rad; 0: none
  std::array<double, 6> damping{};      ///< D, N s/m or N m s/rad; 0: the default above
  double max_speed_m_per_s = 0.02;      ///< fastest an offset moves along a force axis
  double max_rotation_rad_per_s = 0.2;  ///< ... about a torque axis
  double max_offset_m = 0.05;           ///< farthest an offset goes from the path
  double max_offset_rad = 0.35;
  /// The motion stops (failed, the arm held) when the tool exerts more than this.
  double max_force_N = 100.0;
  double max_torque_N_m = 10.0;
  [[nodiscard]] bool any() const noexcept { return axes != 0; }
  [[nodiscard]] bool compliant(std::size_t axis) const noexcept {
    return (axes & (1U << axis)) != 0;
  }
};

}  // namespace rccx::rccl
