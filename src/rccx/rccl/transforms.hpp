// The transforms of RCCL's motion equations (thesis 2.4.1), each named, of three kinds:
//
//   constant    its value never changes; adjacent constants of an equation are multiplied once
//               when the equation is made.
//   functional  a user function gives its value; the trajectory generator evaluates it at most
//               once per sample (a conveyor moving at a set speed, a sensor reading).
//   hold        set by the planning level at any time; a motion that uses it latches the value
//               it has when the trajectory generator takes that motion from the queue: when
//               the motion before it begins (up to one segment ahead of its own start), or at
//               once from rest. A set() after that reaches the next motion that uses it.
//
// And T6 itself, the pose of the last link in the robot's base frame: `t6()`.
//
// Transforms are shared (`TransformPtr`): equations keep the ones they use alive. Values are
// in m and rad.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "rccx/math/transform.hpp"
#include "rccx/rtc/latest.hpp"

namespace rccx::rtc {
struct How;
}

namespace rccx::rccl {

enum class TransformKind : std::uint8_t { constant, functional, hold, t6 };
std::string_view to_string(TransformKind kind) noexcept;

/// What a functional transform's function is given each sample.
struct SampleContext {
  double t_s = 0.0;               ///< the time the setpoint is for, s since the session opened
  std::uint64_t sample = 0;       ///< the sample it is computed in
  const rtc::How* how = nullptr;  ///< the arm as read this sample (nullptr outside a session)
  /// True when the trajectory generator asks for the value at another time than the sample's
  /// (t_s ahead of or behind it, to plan a transition with a moving goal's velocity): the
  /// function is called afresh (not cached for the sample), with `how` still this sample's.
  bool predicted = false;
  /// The time of the sample itself (How::time_s), s: what motion events and reports say, so
  /// that robots sampled at different periods (pipelines of different lengths) ending in the
  /// same tick report the same time. Outside a session: t_s.
  [[nodiscard]] double sample_time_s() const noexcept;
};

/// A functional transform's function: its value at that sample (m, rad). Runs in the sample
/// loop: it must not block, and should not allocate.
using TransformFunction = std::function<math::Transform(const SampleContext&)>;

class Transform;
using TransformPtr = std::shared_ptr<Transform>;

class Transform {
 public:
  /// Use the factory functions below.
  Transform(std::string name, TransformKind kind, const math::Transform& value,
            TransformFunction function);
  Transform(const Transform&) = delete;
  Transform& operator=(const Transform&) = delete;

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] TransformKind kind() const noexcept { return kind_; }
  /// How a process that cannot call this functional transform's function names it, so that a
  /// position using it can be sent across processes (docs/NETWORK.md): "frame:<robot>" (that
  /// robot's commanded T6 TOOL in the world), "function:<name>" (registered in the serve
  /// process), "stream:<name>" (samples the program writes). Empty: not sendable.
  [[nodiscard]] const std::string& reference() const noexcept { return reference_; }
  /// Set before the transform is used in a motion (planning level).
  void set_reference(std::string reference) { reference_ = std::move(reference); }

  /// A constant's value, or the value a hold transform was last set to (planning level).
  [[nodiscard]] const math::Transform& value() const noexcept { return planning_value_; }

  /// Hold transforms: the value the next motion that uses it will latch. Planning level only
  /// (one thread). Throws std::logic_error for other kinds, std::invalid_argument for a value
  /// that is not a rigid transform.
  void set(const math::Transform& value);

  // --- Sample loop (the trajectory generator's thread) ---------------------------------------

  /// Planning level: the value now - a constant's or hold's value(), a functional's function
  /// called afresh with `ctx` (not the loop's cached value). T6 has none: std::logic_error.
  [[nodiscard]] math::Transform value_now(const SampleContext& ctx) const;

  /// A functional transform's value at this sample, computed once per sample number.
  [[nodiscard]] const math::Transform& evaluate(const SampleContext& ctx) const;
  /// A hold transform's value as the loop sees it now (the newest set() taken).
  [[nodiscard]] const math::Transform& latch() const noexcept;

 private:
  std::string name_;
  std::string reference_;
  TransformKind kind_;
  math::Transform planning_value_;
  TransformFunction function_;
  // Loop side: a functional's value cached per sample; a hold's newest value.
  mutable math::Transform loop_value_;
  mutable std::uint64_t loop_sample_ = ~std::uint64_t{0};
  mutable rtc::detail::Latest<math::Transform> published_;
};

/// True when R is orthonormal and right-handed within `tolerance` and every element is finite.
bool is_rigid(const math::Transform& t, double tolerance = 1e-6) noexcept;

/// A constant transform. Throws std::invalid_argument when `value` is not rigid.
TransformPtr constant(std::string name, const math::Transform& value);
/// A functional transform, re-evaluated every sample by `function`.
TransformPtr functional(std::string name, TransformFunction function);
/// A hold transform starting at `value`.
TransformPtr hold(std::string name, const math::Transform& value = math::Transform::identity());
/// T6, the pose of the robot's last link in its base frame: the unknown of every equation.
TransformPtr t6();

}  // namespace rccx::rccl
