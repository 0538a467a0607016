// The kinematics interface: one object per robot model, answering forward, inverse and
// Jacobian questions. All calls are noexcept and allocation-free so that the trajectory
// generator may call them every sample; failures come back as an IkStatus, never as an
// exception (the planning level turns them into messages).
//
//   const auto k = kin::make_kinematics(kin::builtin_robot("puma560"));   // the closed form
//   const math::Transform T = k->forward(q);                // q rad / m -> T6 in the base, m
//   const kin::IkResult r = k->inverse(T, {.configuration = k->find_configuration("lun")});
//   if (!r) fmt::print("{}\n", kin::describe(r.status));     // "out of reach: ..."
//   const kin::IkSolutions all = k->inverse_all(T);          // one per configuration
//   const kin::Jacobian J = k->jacobian(q);                  // 6 x dof: m/s, rad/s per joint
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string_view>

#include "rccx/kinematics/dh_step.hpp"
#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::kin {

/// Why an inverse solution was not given.
enum class IkStatus : std::uint8_t {
  ok,
  out_of_reach,       ///< no joint values put the wrist at that pose
  joint_limits,       ///< solutions exist, but none (of the asked configuration) within limits
  singular,           ///< the numeric solver met a singularity it could not leave
  no_convergence,     ///< the numeric solver ran out of iterations
  bad_configuration,  ///< the configuration asked for does not exist for this robot
  bad_input,          ///< the pose has non-finite elements, or `near` has the wrong size
};

/// A one-line reason for people ("out of reach: ...").
std::string_view describe(IkStatus status) noexcept;
std::string_view to_string(IkStatus status) noexcept;

/// Where a closed-form solution had to take a joint value from the `near` vector because the
/// pose leaves it undetermined (thesis 3.6: "use the previous value of theta4").
enum class Singularity : std::uint8_t { none, shoulder, elbow, wrist };
std::string_view to_string(Singularity s) noexcept;

/// A named arm configuration of a closed-form robot (an index into configuration_names()).
struct Configuration {
  std::uint8_t index = 0;
  constexpr bool operator==(const Configuration&) const noexcept = default;
};

struct IkResult {
  IkStatus status = IkStatus::bad_input;
  JointVector q;  ///< rad / m; valid only when status is ok
  Configuration configuration;
  Singularity singularity = Singularity::none;
  explicit operator bool() const noexcept { return status == IkStatus::ok; }
};

inline constexpr std::size_t kMaxIkSolutions = 8;

/// Every configuration's solution within limits, at most kMaxIkSolutions.
struct IkSolutions {
  std::array<IkResult, kMaxIkSolutions> items{};
  std::size_t count = 0;
  IkStatus status = IkStatus::ok;  ///< why there are none, when count is 0
  [[nodiscard]] std::span<const IkResult> solutions() const noexcept {
    return {items.data(), count};
  }
};

struct IkOptions {
  /// Solve for this configuration only. Without it, the solution closest to `near` is chosen.
  std::optional<Configuration> configuration;
  /// Joint values (rad / m) to stay close to: they pick among configurations and among the
  /// 2 pi turns of revolute joints with more than a turn of range, fill joints left free by a
  /// singularity, and seed the numeric solver. Defaults to the robot's ready pose.
  std::optional<JointVector> near;
  /// The redundant joint's value (rad or m) for a solver that takes one: SevenAxisKinematics
  /// holds joint 7 there. Without it such a solver keeps the value `near` has where it can.
  /// Solvers of non-redundant arms ignore it.
  std::optional<double> redundant;
};

/// The geometric Jacobian: rows vx vy vz (m/s) and wx wy wz (rad/s) of frame T6, both expressed
/// in the base frame, per unit joint velocity (rad/s or m/s). Fixed capacity: never allocates.
using Jacobian = Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::ColMajor, 6, kMaxJoints>;

/// Joint limits are checked with this much slack (rad or m), and values within it are clamped:
/// a pose computed from a joint vector on its limit must solve back to that vector.
inline constexpr double kLimitTolerance = 1e-9;

class Kinematics {
 public:
  explicit Kinematics(RobotModel model);
  virtual ~Kinematics() = default;
  Kinematics(const Kinematics&) = delete;
  Kinematics& operator=(const Kinematics&) = delete;

  [[nodiscard]] const RobotModel& model() const noexcept { return model_; }
  [[nodiscard]] std::size_t dof() const noexcept { return model_.dof(); }

  /// T6, the pose of the last link frame in the base frame, for joint values q (rad / m).
  /// q must have dof() values.
  [[nodiscard]] virtual math::Transform forward(const JointVector& q) const noexcept = 0;

  /// Joint values that put T6 at `pose`, within the joint limits.
  [[nodiscard]] virtual IkResult inverse(const math::Transform& pose,
                                         const IkOptions& options = {}) const noexcept = 0;

  /// All distinct solutions within limits (one per configuration for closed forms; the numeric
  /// solver gives the one it finds).
  [[nodiscard]] virtual IkSolutions inverse_all(const math::Transform& pose,
                                                const IkOptions& options = {}) const noexcept;

  /// The geometric Jacobian at q, from the chain (DH or general).
  [[nodiscard]] virtual Jacobian jacobian(const JointVector& q) const noexcept;

  /// Names of the arm configurations ("lun", "rdf" ... for the PUMA); empty when the solver
  /// has none.
  [[nodiscard]] virtual std::span<const std::string_view> configuration_names() const noexcept {
    return {};
  }
  /// The configuration a joint vector is in.
  [[nodiscard]] virtual Configuration configuration_of(const JointVector& q) const noexcept {
    (void)q;
    return {};
  }
  /// The configuration with that name, if any.
  [[nodiscard]] std::optional<Configuration> find_configuration(
      std::string_view name) const noexcept;
  [[nodiscard]] std::string_view configuration_name(Configuration c) const noexcept;

 protected:
  /// Moves each revolute joint of q by whole turns to the value within limits closest to
  /// `toward`, and checks prismatic ones. False when some joint cannot be brought within limits.
  bool fit_to_limits(JointVector& q, const JointVector& toward) const noexcept;
  /// The pose to stay near: `near` when given, else the ready pose. nullptr when the request
  /// is bad input: a pose with a non-finite element, or `near` of the wrong size or non-finite.
  /// Points into `options` or *this: nothing is copied.
  const JointVector* checked_reference(const math::Transform& pose,
                                       const IkOptions& options) const noexcept;
  /// The model's ready pose, built once.
  const JointVector& ready_pose() const noexcept { return ready_; }

  /// T6 by multiplying the DH chain's A matrices (thesis eq. 3.11), or a general chain's
  /// steps; frames[i], when given, receives the frame of link i+1 (A1 ... A(i+1)).
  math::Transform chain_forward(const JointVector& q,
                                math::Transform* frames = nullptr) const noexcept;

  /// The geometric Jacobian from the link frames chain_forward filled (frames[dof() - 1] = T6).
  Jacobian jacobian_from_frames(const math::Transform* frames) const noexcept;

  /// Cached per-link constants of the DH chain.
  struct Link {
    double a, ca, sa, d, theta;
    bool prismatic;
  };
  std::array<Link, kMaxJoints> links_{};

  /// Cached per-joint constants of a general chain (Geometry::chain): see ChainStep.
  std::array<PreparedStep, kMaxJoints> steps_{};
  /// The model is a general chain: chain_forward and jacobian_from_frames use steps_.
  bool general_ = false;

 private:
  /// Per-joint limit constants for fit_to_limits, which runs on every inverse call.
  struct Limit {
    double lower, upper;  ///< the limits
    double lo, hi;        ///< the limits widened by kLimitTolerance
    bool revolute;
    bool multi_turn;  ///< revolute with a turn or more of (widened) range
  };

  RobotModel model_;
  std::array<Limit, kMaxJoints> limits_{};
  JointVector ready_;  ///< model_.ready(), which builds a new vector each call
};

/// Closed-form solvers enumerate one raw solution per configuration; this base turns them into
/// the inverse/inverse_all contract (limits, 2 pi turns, closest to near).
class AnalyticKinematics : public Kinematics {
 public:
  using Kinematics::Kinematics;
  [[nodiscard]] IkResult inverse(const math::Transform& pose,
                                 const IkOptions& options = {}) const noexcept final;
  [[nodiscard]] IkSolutions inverse_all(const math::Transform& pose,
                                        const IkOptions& options = {}) const noexcept final;

 protected:
  /// Writes the raw solution (angles in (-pi, pi]) of configuration `which` into `out`; returns
  /// ok or out_of_reach. `reference` fills joints a singularity leaves free.
  virtual IkStatus solve(const math::Transform& pose, Configuration which,
                         const JointVector& reference, IkResult& out) const noexcept = 0;
};

namespace detail {
/// Throws RobotFileError unless `model` is a DH table of 6 revolute joints with these alphas
/// (deg), no theta offsets and a != 0 only where `a_allowed`: the form a closed form (named
/// `solver` in the message) is written for.
void require_dh_form(const RobotModel& model, std::string_view solver,
                     const std::array<double, 6>& alpha_deg, const std::array<bool, 6>& a_allowed);
/// The RobotFileError a closed form (named `solver`) throws for a model not of its form.
RobotFileError not_of_form(const RobotModel& model, std::string_view solver, std::string_view what);
}  // namespace detail

/// The solver the model asks for. Throws RobotFileError when the model's DH table does not have
/// the structure its closed form needs.
std::unique_ptr<Kinematics> make_kinematics(const RobotModel& model);

}  // namespace rccx::kin
