#include "rccx/rccl/tool_calibration.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace rccx::rccl {

namespace {

/// The wrist turns of each pose, in units of wrist_turn_rad, for joints dof-3, dof-2, dof-1:
/// the present pose, the middle joint either way, the outer two together either way, and all
/// three: gravity takes six directions in the sensor frame about two or more axes.
constexpr std::array<std::array<double, 3>, 6> kTurns{{
    {0, 0, 0},
    {0, 1, 0},
    {0, -1, 0},
    {1, 0, 1},
    {-1, 0, -1},
    {1, 1, -1},
}};

/// Joint j turned by `turn` from q[j], kept inside its limits (less a margin of a tenth of the
/// turn): the other way when that side has no room, else as far as the limit allows.
double turned(const kin::Joint& joint, double q, double turn) {
  const double margin = 0.1 * std::abs(turn);
  const double lo = joint.lower + margin, hi = joint.upper - margin;
  if (lo > hi) return q;
  const double there = q + turn;
  if (there >= lo && there <= hi) return there;
  const double back = q - turn;
  if (back >= lo && back <= hi) return back;
  return std::clamp(there, lo, hi);
}

std::string robot_name(Manipulator& arm) {
  return arm.kinematics().model().name;
}

/// Control ended (a limit, a fault, the sensor saturated or frozen): says which.
[[noreturn]] void throw_ended(Manipulator& arm, const std::string& name) {
  const rtc::Termination t = arm.session().termination();
  throw ToolCalibrationError(fmt::format(
      "tool calibration on {}: control ended at {}: {} ({}){}{}; see to it and calibrate again",
      robot_name(arm), name, rtc::to_string(t.code), rtc::describe(t.code),
      t.detail_view().empty() ? "" : ": ", t.detail_view()));
}

void move_and_settle(Manipulator& arm, const kin::JointVector& q, const std::string& name,
                     const ToolCalibrationOptions& options) {
  const Motion m = arm.move(Position::joints(name, q));
  const WaitResult r = arm.waitfor(m.end(), options.timeout);
  if (r == WaitResult::session_ended) throw_ended(arm, name);
  if (r != WaitResult::reached) {
    std::string why(to_string(r));
    for (const MotionEvent& e : arm.failures()) {
      if (e.id == m.id) why = std::string(e.message());
    }
    throw ToolCalibrationError(fmt::format(
        "tool calibration on {}: the move to {} did not end ({}); clear the way and calibrate "
        "again, or give a smaller wrist_turn_rad",
        robot_name(arm), name, why));
  }
  rtc::Session& session = arm.session();
  const double rest = options.rest_speed;
  const bool still = session.wait_until(
      [rest](const rtc::How& h) {
        for (std::size_t j = 0; j < h.dof; ++j) {
          if (std::abs(h.joint[j].velocity) >= rest) return false;
        }
        return true;
      },
      options.timeout);
  if (!still && session.termination().ended()) throw_ended(arm, name);
  if (!still) {
    throw ToolCalibrationError(fmt::format(
        "tool calibration on {}: the arm did not come to rest at {} (no sample with every "
        "joint slower than {} rad/s or m/s); check that nothing pushes it, or raise rest_speed",
        robot_name(arm), name, rest));
  }
  const rtc::Termination t = session.wait_for(options.settle);
  if (t.ended()) throw_ended(arm, name);
}

/// Averages `n` distinct sensor readings; the measured joints of the last.
force::LoadSample average_readings(Manipulator& arm, const std::string& name,
                                   const ToolCalibrationOptions& options, kin::JointVector& q) {
  math::Wrench sum;
  int count = 0;
  bool have = false;
  std::uint32_t last = 0;
  const char* fault = nullptr;
  const int n = options.readings_per_pose;
  const bool done = arm.session().wait_until(
      [&](const rtc::How& h) {
        if (!h.force.present || h.force.frozen) {
          fault = "froze (its reading counter stopped)";
          return true;
        }
        if (h.force.saturated) {
          fault = "saturated (a reading reached its measuring range)";
          return true;
        }
        if (have && h.force.sequence == last) return false;
        have = true;
        last = h.force.sequence;
        sum = sum + h.force.wrench;
        q = h.q();
        return ++count >= n;
      },
      options.timeout);
  if (fault != nullptr) {
    throw ToolCalibrationError(fmt::format(
        "tool calibration on {}: the wrist sensor {} at {}; check the sensor and its tool, then "
        "calibrate again",
        robot_name(arm), fault, name));
  }
  if (!done && arm.session().termination().ended()) throw_ended(arm, name);
  if (!done) {
    throw ToolCalibrationError(fmt::format(
        "tool calibration on {}: {} of {} sensor readings at {} before the time ran out",
        robot_name(arm), count, n, name));
  }
  const math::Rot3 base_from_t6 = arm.kinematics().forward(q).R;
  return {options.world_from_base * base_from_t6, sum * (1.0 / count)};
}

}  // namespace

force::ToolLoad calibrate_tool_load(Manipulator& arm, const ToolCalibrationOptions& options,
                                    force::LoadFit* fit, ToolCalibrationReadings* readings) {
  const kin::RobotModel& model = arm.kinematics().model();
  const std::size_t dof = model.dof();
  const rtc::How now = arm.session().how();
  if (!now.force.present) {
    throw ToolCalibrationError(fmt::format(
        "tool calibration on {}: the robot has no wrist force sensor (How::force.present is "
        "false); it needs an arm whose plant reports the wrist load",
        model.name));
  }
  if (dof < 3) {
    throw ToolCalibrationError(fmt::format(
        "tool calibration on {}: needs three wrist joints to turn the sensor; it has {} joints",
        model.name, dof));
  }
  if (!(options.wrist_turn_rad > 0.0) || options.readings_per_pose < 1) {
    throw std::invalid_argument(
        "tool calibration: wrist_turn_rad must be > 0 and readings_per_pose >= 1");
  }

  const kin::JointVector start = now.q();
  std::vector<force::LoadSample> samples;
  std::vector<kin::JointVector> where;
  for (std::size_t i = 0; i < kTurns.size(); ++i) {
    kin::JointVector goal = start;
    for (std::size_t k = 0; k < 3; ++k) {
      const std::size_t j = dof - 3 + k;
      goal[j] = turned(model.joints[j], start[j], kTurns[i][k] * options.wrist_turn_rad);
    }
    const std::string name = fmt::format("tool calibration pose {}", i + 1);
    move_and_settle(arm, goal, name, options);
    kin::JointVector q;
    samples.push_back(average_readings(arm, name, options, q));
    where.push_back(q);
  }
  if (options.return_to_start) move_and_settle(arm, start, "the start", options);

  const force::ToolLoad load = force::estimate_tool_load(samples, fit);
  if (readings != nullptr) {
    readings->joints = std::move(where);
    readings->samples = std::move(samples);
  }
  return load;
}

}  // namespace rccx::rccl
