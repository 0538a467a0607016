// rccx's position equations for Python (docs/PYTHON.md, "Position equations"): NumPy (4, 4)
// arrays to and from math::Transform, the transforms' factories and a stream-fed functional
// transform. Plain C++ over arrays.hpp; arm_module.cpp names them for Python.
#pragma once

#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "rccx/cell/seqlock.hpp"
#include "rccx/rccl/position.hpp"
#include "rccx/rccl/transforms.hpp"
#include "transform.hpp"

namespace rccx::python {

rccl::TransformPtr make_constant(const std::string& name, const InArray& T);
rccl::TransformPtr make_hold(const std::string& name, const std::optional<InArray>& T);
/// A hold transform's set(); TypeError for the other kinds.
void set_hold(rccl::Transform& t, const InArray& T);
/// A constant's or hold's value; a functional's value now; ValueError for T6.
OutArray transform_value(const rccl::Transform& t);
std::string transform_repr(const rccl::Transform& t);

/// A functional transform fed by the program: put() (any thread, never waiting for the loop)
/// publishes a pose, the sample loop reads the newest one through a sequence lock (no lock, no
/// allocation, no Python). Before the first put() its value is the initial pose.
/// A pose put with the session time it is for (`at_s`) and its velocity is extrapolated to
/// each setpoint's time, at most `max_extrapolation_s` either way: a feeding thread that comes
/// late leaves a goal still moving smoothly, not one that stands and then jumps.
class StreamTransform : public rccl::Transform {
 public:
  struct Sample {
    math::Transform pose;
    std::int64_t stamp_ns = 0;                               ///< steady clock when put
    double at_s = std::numeric_limits<double>::quiet_NaN();  ///< session time; NaN: not given
    math::Vec3 velocity_m_per_s;                             ///< of pose.p
    math::Vec3 angular_velocity_rad_per_s;                   ///< of pose.R, parent frame
  };
  struct State {
    cell::SeqLock<Sample> latest;
    math::Transform initial;
    double max_extrapolation_s = 0.25;
    std::mutex writers;  ///< the seqlock takes one writer at a time; the loop never takes it
    std::uint64_t count = 0;
  };
  StreamTransform(std::string name, std::shared_ptr<State> state);

  /// T (4, 4), m; at_s: the session time T is for, s; velocity: (6,) linear m/s then angular
  /// rad/s, in the stream's parent frame (needs at_s).
  void put(const InArray& T, std::optional<double> at_s, const std::optional<InArray>& velocity);
  [[nodiscard]] double max_extrapolation_s() const noexcept { return state_->max_extrapolation_s; }
  /// The newest pose put (the initial one before any).
  [[nodiscard]] OutArray newest() const;
  /// Seconds since the newest put(); None before the first.
  [[nodiscard]] std::optional<double> age() const;
  [[nodiscard]] std::uint64_t count() const;

 private:
  std::shared_ptr<State> state_;
};

std::shared_ptr<StreamTransform> make_stream(const std::string& name,
                                             const std::optional<InArray>& T,
                                             double max_extrapolation_s);

/// Position::make with the tool given (null: the left side's last transform).
rccl::PositionPtr make_position(const std::string& name, const std::vector<rccl::TransformPtr>& lhs,
                                const std::vector<rccl::TransformPtr>& rhs,
                                const rccl::TransformPtr& tool);
/// A position in joints (rad / m): finite values, a 1-D array.
rccl::PositionPtr make_joints(const std::string& name, const InArray& q);
/// T6 of a position without functional transforms (holds as last set), m.
OutArray position_t6(const rccl::Position& p);
OutArray position_tool(const rccl::Position& p);
OutArray position_joints(const rccl::Position& p);

}  // namespace rccx::python
