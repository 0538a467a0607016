// The robot file's "hardware": {"rcu": {...}} block (robots/README.md), read strictly: every key
// says its unit, unknown keys are refused, and each error names the key and the joint.
#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <stdexcept>
#include <string>

#include "rccx/hw/arm_base.hpp"
#include "rccx/hw/rcu.hpp"
#include "rccx/io/json_reader.hpp"

namespace rccx::hw {

namespace {

using nlohmann::json;

/// The RCU section's numbers are counts, gains and rates of their own sizes: no magnitude bound.
class Reader : public io::JsonObjectReader<std::invalid_argument> {
 public:
  Reader(const nlohmann::json& object, std::string where)
      : JsonObjectReader(object, std::move(where), std::numeric_limits<double>::infinity()) {}
};

/// The 16 bytes of command 0EH, in order, named with the unit the emulated law reads them in.
constexpr std::array<const char*, 16> kMotorParameterKeys{
    "proportional_gain_rad_per_s",            // 1
    "initialization_speed_x16_speed_units",   // 2
    "sensor_error_tolerance_x64_counts",      // 3
    "static_zone_x4_counts",                  // 4
    "maximum_speed_x256_speed_units",         // 5
    "dynamic_integration_eighths_per_s",      // 6
    "static_integration_eighths_per_s",       // 7
    "static_speed_x8_speed_units",            // 8
    "motor_resistance_per_thermal_capacity",  // 9 (stored, unused)
    "inverse_thermal_resistance",             // 10 (stored, unused)
    "maximum_temperature",                    // 11 (stored, unused)
    "gravity_compensation_128ths",            // 12
    "inertia_128ths",                         // 13
    "viscous_friction_128ths",                // 14
    "dry_friction_128ths",                    // 15
    "maximum_acceleration_div_4",             // 16 (stored, unused)
};

RcuJointConfig parse_joint(const json& object, const kin::Joint& joint, const std::string& where) {
  Reader r(object, where);
  const bool revolute = joint.type == kin::JointType::revolute;
  // Joint values in the file: deg or mm; efforts: N m or N.
  const double unit = revolute ? std::numbers::pi / 180.0 : 1e-3;
  const char* value_suffix = revolute ? "_deg" : "_mm";
  const auto key = [&](const char* stem) { return std::string(stem) + value_suffix; };
  const auto pick = [&](const char* rev, const char* pri) {
    return std::string(revolute ? rev : pri);
  };

  RcuJointConfig c;
  c.hard_stop_margin = r.has(key("hard_stop_margin"))
                           ? r.positive(key("hard_stop_margin")) * unit
                           : (revolute ? kHardStopMargin_rad : kHardStopMargin_m);
  c.lower_stop = joint.lower - c.hard_stop_margin;
  c.upper_stop = joint.upper + c.hard_stop_margin;
  const std::string at = r.string("calibrate_at");
  if (at == "lower_stop") {
    c.calibration_position = c.lower_stop;
  } else if (at == "upper_stop") {
    c.calibration_position = c.upper_stop;
  } else {
    r.fail("\"calibrate_at\" must be \"lower_stop\" or \"upper_stop\"");
  }
  c.initialize_counts = static_cast<std::uint16_t>(r.integer("initialize_counts", 0, 65535));
  c.work_areas = r.boolean("work_areas");
  c.lower_threshold = static_cast<std::int32_t>(
      r.integer_or("lower_threshold_counts", 1, kWorkAreaAcceptBelow - 1, 7450));
  c.upper_threshold = static_cast<std::int32_t>(
      r.integer_or("upper_threshold_counts", kWorkAreaAcceptAbove + 1, 65534, 57550));
  if (c.upper_threshold <= c.lower_threshold + kWorkAreaShift) {
    r.fail(
        "\"upper_threshold_counts\" must exceed \"lower_threshold_counts\" + 50000 (hysteresis)");
  }

  c.counts_per_motor_turn = r.positive("counts_per_motor_turn");
  const double counts_per_motor_rad = c.counts_per_motor_turn / (2.0 * std::numbers::pi);
  c.counts_per_ms_per_speed_unit = counts_per_motor_rad / 32.0 / 1e3;         // 1/32 rad/s
  c.counts_per_ms2_per_acceleration_unit = counts_per_motor_rad / 4.0 / 1e6;  // 1/4 rad/s^2
  c.default_speed = static_cast<std::uint16_t>(r.integer_or("default_speed", 0, 65535, 32));
  c.default_acceleration =
      static_cast<std::uint16_t>(r.integer_or("default_acceleration", 0, 65535, 1));
  c.follow_acceleration = static_cast<std::uint16_t>(r.integer("follow_acceleration", 1, 65535));

  {
    Reader m(r.get("motor_parameters"), where + ": \"motor_parameters\"");
    for (std::size_t i = 0; i < kMotorParameterKeys.size(); ++i) {
      c.motor_parameters[i] = static_cast<std::uint8_t>(m.integer(kMotorParameterKeys[i], 0, 255));
    }
    m.has("note");
    m.no_unknown_keys();
  }

  c.inertia = r.positive(pick("inertia_kg_m2", "inertia_kg"));
  c.viscous_friction = r.non_negative_or(pick("viscous_N_m_s_per_rad", "viscous_N_s_per_m"), 0.0);
  c.coulomb_friction = r.non_negative_or(pick("coulomb_N_m", "coulomb_N"), 0.0);
  c.max_effort = r.positive(pick("max_effort_N_m", "max_effort_N"));
  const std::string gravity_key = pick("gravity_N_m", "gravity_N");
  c.gravity_effort = r.number_or(gravity_key, 0.0);
  if (!(std::abs(c.gravity_effort) < c.max_effort)) {
    r.fail(fmt::format("\"{}\" must be smaller than the max effort, or the joint cannot hold",
                       gravity_key));
  }
  r.has("note");
  r.no_unknown_keys();

  // The top speed must be a speed setting the joint accepts.
  const double top_counts_per_ms = joint.max_velocity / joint.resolution_per_count / 1e3;
  const double top_setting = top_counts_per_ms / c.counts_per_ms_per_speed_unit;
  if (top_setting > 65535.0) {
    r.fail(
        fmt::format("the top speed needs a speed setting of {:.0f} > 65535: raise "
                    "\"counts_per_motor_turn\"",
                    top_setting));
  }
  if (top_setting > 256.0 * c.motor_parameters[motor::kMaximumSpeed]) {
    r.fail(
        fmt::format("\"motor_parameters\": \"{}\" caps the speed setting below the top "
                    "speed ({:.0f})",
                    kMotorParameterKeys[motor::kMaximumSpeed], top_setting));
  }

  // Where the counts are: A = initialize_counts at the calibration stop, growing with q.
  const double span = (c.upper_stop - c.lower_stop) / joint.resolution_per_count;
  const double a_lo = at == "lower_stop" ? c.initialize_counts : c.initialize_counts - span;
  const double a_hi = a_lo + span;
  if (!c.work_areas && (a_lo < 0.0 || a_hi > 65535.0)) {
    r.fail(
        fmt::format("from stop to stop the counts run {:.0f} .. {:.0f}, beyond the 16-bit "
                    "register: set \"work_areas\" or move \"initialize_counts\"",
                    a_lo, a_hi));
  }
  if (c.work_areas &&
      (c.initialize_counts <= c.lower_threshold || c.initialize_counts >= c.upper_threshold)) {
    r.fail(
        "\"initialize_counts\" must lie between the thresholds, so that a driver does not "
        "change work area at the calibration stop");
  }
  return c;
}

}  // namespace

namespace {

json parse_hardware(const kin::RobotModel& model) {
  try {
    return json::parse(model.hardware_json, nullptr, true, true);
  } catch (const json::exception& e) {
    throw std::invalid_argument(fmt::format("{}: \"hardware\": {}", model.name, e.what()));
  }
}

}  // namespace

bool has_rcu(const kin::RobotModel& model) {
  if (model.hardware_json.empty()) return false;
  const json doc = parse_hardware(model);
  return doc.is_object() && doc.contains("rcu");
}

RcuConfig rcu_config(const kin::RobotModel& model) {
  if (model.hardware_json.empty()) {
    throw std::invalid_argument(
        fmt::format("{}: the robot file has no \"hardware\": {{\"rcu\": ...}} block", model.name));
  }
  const json doc = parse_hardware(model);
  Reader hardware(doc, fmt::format("{}: \"hardware\"", model.name));
  Reader r(hardware.get("rcu"), fmt::format("{}: \"hardware\": \"rcu\"", model.name));
  (void)hardware.has("mujoco");  // the MuJoCo plant's scene (scene_from_file) reads it
  hardware.no_unknown_keys();

  RcuConfig config;
  config.exchange_us = r.number_or("exchange_us", 75.0);
  if (!(config.exchange_us > 0)) r.fail("\"exchange_us\" must be > 0");
  config.follow_gain = r.number_or("follow_gain", 1.0);
  if (!(config.follow_gain > 0)) r.fail("\"follow_gain\" must be > 0");
  const json& joints = r.get("joints");
  if (!joints.is_array() || joints.size() != model.dof()) {
    r.fail(fmt::format("\"joints\" must be an array of {} objects, one per joint", model.dof()));
  }
  if (model.dof() > kRcuMaxJoints)
    r.fail(fmt::format("an RCU serves at most {} joints", kRcuMaxJoints));
  for (std::size_t i = 0; i < joints.size(); ++i) {
    config.joints.push_back(parse_joint(joints[i], model.joints[i],
                                        fmt::format("{}: \"hardware\": \"rcu\": joint {} ({})",
                                                    model.name, i + 1, model.joints[i].name)));
  }
  r.has("note");
  r.no_unknown_keys();
  return config;
}

}  // namespace rccx::hw
