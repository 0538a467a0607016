#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "rccx/hw/gravity.hpp"
#include "rccx/hw/ideal_arm.hpp"
#include "rccx/hw/simulated_arm.hpp"
#include "rccx/hw/simulated_puma.hpp"
#include "rccx/kinematics/dh_kinematics.hpp"
#include "rccx/math/units.hpp"

namespace {

using namespace rccx;
using hw::ServoCommand;

void run_for(hw::SimulatedArm& arm, double seconds) {
  arm.advance_to(arm.time_s() + seconds);
}

ServoCommand move(double target, double rate) {
  return {ServoCommand::Kind::move, target, rate};
}

double counts_to_value(const hw::SimulatedArm& arm, std::size_t j, std::int64_t counts) {
  return static_cast<double>(counts) * arm.model().joints[j].resolution_per_count;
}

bool is_puma(const hw::SimulatedArm& arm) {
  return dynamic_cast<const hw::SimulatedPuma*>(&arm) != nullptr;
}

// Within 5 counts: the integrator of the PUMA servo keeps pulling a joint in until Coulomb
// friction can hold it, so what is left is a few counts (see HwPuma.SettlesAfterASteps); the
// ideal servo is exact.
double position_tolerance(const hw::SimulatedArm& arm, std::size_t j) {
  return is_puma(arm) ? 5.0 * arm.model().joints[j].resolution_per_count : 1e-12;
}

TEST(HwFactory, PicksThePumaSimulatorWhenEveryJointHasDynamics) {
  EXPECT_TRUE(is_puma(*hw::make_simulated_arm(kin::builtin_robot("puma560"))));
  EXPECT_TRUE(is_puma(*hw::make_simulated_arm(kin::builtin_robot("puma260"))));
  for (const char* name : {"microbo", "stanford"}) {
    const auto arm = hw::make_simulated_arm(kin::builtin_robot(name));
    EXPECT_NE(dynamic_cast<const hw::IdealArm*>(arm.get()), nullptr) << name;
  }
  kin::RobotModel partial = kin::builtin_robot("puma560");
  partial.joints[4].dynamics = {};
  EXPECT_FALSE(is_puma(*hw::make_simulated_arm(partial)));
  EXPECT_THROW(hw::SimulatedPuma{partial}, std::invalid_argument);
  hw::SimulatedArmOptions two_values;
  two_values.initial = {0.0, 0.0};
  EXPECT_THROW((void)hw::make_simulated_arm(kin::builtin_robot("puma560"), two_values),
               std::invalid_argument);
  EXPECT_EQ(hw::to_string(hw::Fault::joint_not_answering), "joint_not_answering");
  EXPECT_EQ(hw::to_string(hw::Fault::encoder_error), "encoder_error");
  EXPECT_EQ(hw::to_string(hw::Fault::power_loss), "power_loss");
}

// The behaviour every simulated arm shares, on every shipped robot.
class HwArm : public ::testing::TestWithParam<std::string> {
 protected:
  kin::RobotModel model_ = kin::builtin_robot(GetParam());
};

INSTANTIATE_TEST_SUITE_P(Robots, HwArm,
                         ::testing::Values("puma560", "puma260", "microbo", "stanford"));

TEST_P(HwArm, StartsCalibratedAtTheReadyPoseAndHolds) {
  const auto arm = hw::make_simulated_arm(model_);
  EXPECT_TRUE(arm->power());
  EXPECT_EQ(arm->time_s(), 0.0);
  run_for(*arm, 1.0);
  EXPECT_NEAR(arm->time_s(), 1.0, 1e-9);
  const kin::JointVector q = arm->true_position();
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    EXPECT_NEAR(q[j], model_.joints[j].ready, position_tolerance(*arm, j)) << j;
    const hw::JointReading r = arm->read(j);
    EXPECT_TRUE(r.answered && r.calibrated && !r.calibrating && !r.encoder_error);
  }
  // Earlier times do nothing.
  arm->advance_to(0.5);
  EXPECT_NEAR(arm->time_s(), 1.0, 1e-9);
}

TEST_P(HwArm, FollowsAStepAndARamp) {
  const auto arm = hw::make_simulated_arm(model_);
  const kin::JointVector ready = model_.ready();
  // A step of a fifth of each joint's range, towards the middle of the range.
  kin::JointVector step_goal(arm->dof());
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    const kin::Joint& joint = model_.joints[j];
    const double span = joint.upper - joint.lower;
    const double middle = 0.5 * (joint.lower + joint.upper);
    step_goal[j] = ready[j] + (ready[j] <= middle ? 0.2 : -0.2) * span;
    ASSERT_TRUE(arm->command(j, move(step_goal[j], 0.0)));
  }
  double fastest = 0.0;
  for (int t = 0; t < 3000; ++t) {
    run_for(*arm, hw::kServoPeriod_s);
    const kin::JointVector v = arm->true_velocity();
    for (std::size_t j = 0; j < arm->dof(); ++j) {
      fastest = std::max(fastest, std::abs(v[j]) / model_.joints[j].max_velocity);
    }
  }
  EXPECT_LE(fastest, hw::kOverspeedFactor + 1e-9);
  kin::JointVector q = arm->true_position();
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    EXPECT_NEAR(q[j], step_goal[j], position_tolerance(*arm, j)) << model_.joints[j].name;
    EXPECT_NEAR(arm->true_velocity()[j], 0.0, 1e-3) << model_.joints[j].name;
  }

  // A ramp back to ready at half the top speed: the joint keeps up with its setpoint.
  const double rate_factor = 0.5;
  double worst = 0.0;  // tracking error / its bound
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    ASSERT_TRUE(arm->command(j, move(ready[j], rate_factor * model_.joints[j].max_velocity)));
  }
  for (int t = 0; t < 6000; ++t) {
    run_for(*arm, hw::kServoPeriod_s);
    q = arm->true_position();
    for (std::size_t j = 0; j < arm->dof(); ++j) {
      const auto* base = dynamic_cast<const hw::ArmBase*>(arm.get());
      // The PUMA lags by about rate / w while it accelerates (the velocity feedforward acts
      // through Kd = 3 I w), plus up to Fc / Kp, the error Coulomb friction needs from the P
      // term before the integrator takes it over, plus rate^2 / (2 a) where the motor's effort
      // limits the acceleration a (what is left of max_effort on the torque-speed line at
      // `rate` after friction). The ideal servo does not lag at all.
      const double rate = rate_factor * model_.joints[j].max_velocity;
      double bound = 1e-12;
      if (const auto* puma = dynamic_cast<const hw::SimulatedPuma*>(arm.get())) {
        const kin::JointDynamics& d = model_.joints[j].dynamics;
        const double left =
            d.max_effort * (1 - rate / (hw::kOverspeedFactor * model_.joints[j].max_velocity)) -
            d.coulomb_friction - d.viscous_friction * rate;
        ASSERT_GT(left, 0.0);
        bound = rate / hw::SimulatedPuma::kServoBandwidth_rad_per_s +
                d.coulomb_friction / puma->gains(j).kp + rate * rate / (2 * left / d.inertia);
      }
      worst = std::max(worst, std::abs(q[j] - base->setpoint(j)) / bound);
    }
  }
  EXPECT_LE(worst, 1.0);
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    EXPECT_NEAR(q[j], ready[j], position_tolerance(*arm, j)) << model_.joints[j].name;
  }
}

TEST_P(HwArm, EncoderCountsAreTheQuantizedPosition) {
  const auto arm = hw::make_simulated_arm(model_);
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    const kin::Joint& joint = model_.joints[j];
    arm->command(j,
                 move(joint.ready + 0.1 * (joint.upper - joint.ready), 0.3 * joint.max_velocity));
  }
  for (int t = 0; t < 500; ++t) {
    run_for(*arm, hw::kServoPeriod_s);
    const kin::JointVector q = arm->true_position();
    for (std::size_t j = 0; j < arm->dof(); ++j) {
      const double res = model_.joints[j].resolution_per_count;
      const double read = counts_to_value(*arm, j, arm->read(j).counts);
      ASSERT_LE(std::abs(read - q[j]), 0.5 * res * (1 + 1e-9)) << j << " at tick " << t;
    }
  }
}

TEST_P(HwArm, NeverPassesItsHardStops) {
  const auto arm = hw::make_simulated_arm(model_);
  const auto& base = dynamic_cast<const hw::ArmBase&>(*arm);
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    const kin::Joint& joint = model_.joints[j];
    EXPECT_GT(base.upper_stop(j), joint.upper);
    EXPECT_LT(base.lower_stop(j), joint.lower);
    arm->command(j, move(joint.upper + 0.5 * (joint.upper - joint.lower), 0.0));
  }
  double beyond = -1.0;
  for (int t = 0; t < 6000; ++t) {
    run_for(*arm, hw::kServoPeriod_s);
    const kin::JointVector q = arm->true_position();
    for (std::size_t j = 0; j < arm->dof(); ++j) {
      beyond = std::max(beyond, q[j] - base.upper_stop(j));
    }
  }
  EXPECT_LE(beyond, 0.0);
  // Every joint got there: it is pressed against the stop.
  const kin::JointVector q = arm->true_position();
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    EXPECT_NEAR(q[j], base.upper_stop(j), 1e-9) << model_.joints[j].name;
  }
}

TEST_P(HwArm, CalibratesFromAnUncalibratedStart) {
  kin::JointVector start = model_.ready();
  for (std::size_t j = 0; j < start.size(); ++j) {
    const kin::Joint& joint = model_.joints[j];
    start[j] += 0.05 * (joint.upper - joint.lower) * (j % 2 == 0 ? 1 : -1);
    start[j] = std::clamp(start[j], joint.lower, joint.upper);
  }
  hw::SimulatedArmOptions options;
  options.initial = start;
  options.calibrated = false;
  const auto arm = hw::make_simulated_arm(model_, options);
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    const hw::JointReading r = arm->read(j);
    EXPECT_FALSE(r.calibrated);
    EXPECT_EQ(r.counts, 0) << "counts start from the power-up position";
  }
  // Uncalibrated, a target is relative to the power-up position, like the counts.
  const double small = 0.01 * (model_.joints[0].upper - model_.joints[0].lower);
  arm->command(0, move(small, 0.0));
  run_for(*arm, 1.0);
  EXPECT_NEAR(arm->true_position()[0], start[0] + small, position_tolerance(*arm, 0));
  EXPECT_NEAR(counts_to_value(*arm, 0, arm->read(0).counts), small,
              position_tolerance(*arm, 0) + model_.joints[0].resolution_per_count);

  for (std::size_t j = 0; j < arm->dof(); ++j) {
    ASSERT_TRUE(arm->command(j, {ServoCommand::Kind::calibrate, 0.0, 0.0}));
    EXPECT_TRUE(arm->read(j).calibrating);
  }
  // At a tenth of the top speed over 5 % of the range: the longest seek is known.
  double longest = 0.0;
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    longest = std::max(longest, std::abs(arm->true_position()[j] - model_.ready()[j]) /
                                    (hw::kCalibrationSpeedFactor * model_.joints[j].max_velocity));
  }
  double fastest = 0.0;
  double t = 0.0;
  auto all_calibrated = [&] {
    for (std::size_t j = 0; j < arm->dof(); ++j) {
      if (!arm->read(j).calibrated) return false;
    }
    return true;
  };
  while (!all_calibrated() && t < longest + 2.0) {
    run_for(*arm, hw::kServoPeriod_s);
    t += hw::kServoPeriod_s;
    for (std::size_t j = 0; j < arm->dof(); ++j) {
      fastest =
          std::max(fastest, std::abs(arm->true_velocity()[j]) / model_.joints[j].max_velocity);
    }
  }
  ASSERT_TRUE(all_calibrated()) << "after " << t << " s";
  EXPECT_GE(t, 0.9 * longest);
  // Slowly: the PUMA's speed overshoots the slow setpoint by about a quarter as it breaks away
  // from Coulomb friction; the ideal servo keeps to it.
  EXPECT_LE(fastest, 1.3 * hw::kCalibrationSpeedFactor) << "calibration moves slowly";
  run_for(*arm, 0.5);
  const kin::JointVector q = arm->true_position();
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    const hw::JointReading r = arm->read(j);
    EXPECT_FALSE(r.calibrating);
    const double res = model_.joints[j].resolution_per_count;
    EXPECT_LE(std::abs(counts_to_value(*arm, j, r.counts) - q[j]), 0.5 * res * (1 + 1e-9));
    EXPECT_NEAR(q[j], model_.ready()[j], hw::kCalibrationTolerance_counts * res + 1e-12);
  }
}

TEST_P(HwArm, PowerOffBrakesAndPowerOnHoldsWhereTheJointsAre) {
  const auto arm = hw::make_simulated_arm(model_);
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    const kin::Joint& joint = model_.joints[j];
    arm->command(j,
                 move(joint.ready + 0.4 * (joint.upper - joint.ready), 0.6 * joint.max_velocity));
  }
  run_for(*arm, 0.2);
  ASSERT_TRUE(arm->set_power(false));
  EXPECT_FALSE(arm->power());
  // Moving at up to kOverspeedFactor x the top speed, a joint stops within that x the brake time.
  run_for(*arm, hw::kOverspeedFactor * hw::kBrakeStopTime_s + 2 * hw::kServoPeriod_s);
  const kin::JointVector stopped = arm->true_position();
  for (std::size_t j = 0; j < arm->dof(); ++j) EXPECT_EQ(arm->true_velocity()[j], 0.0) << j;
  // Commands are answered but do nothing; the joints stay (gravity too is held by the brakes).
  EXPECT_TRUE(arm->command(0, move(model_.joints[0].lower, 0.0)));
  run_for(*arm, 1.0);
  EXPECT_EQ(arm->true_position(), stopped);

  ASSERT_TRUE(arm->set_power(true));
  run_for(*arm, 1.0);
  kin::JointVector q = arm->true_position();
  for (std::size_t j = 0; j < arm->dof(); ++j) {
    EXPECT_NEAR(q[j], stopped[j], position_tolerance(*arm, j)) << "no jump to the old goal";
  }
  // Servoing again.
  const double target = stopped[0] - 0.05 * (model_.joints[0].upper - model_.joints[0].lower);
  ASSERT_TRUE(arm->command(0, move(target, 0.0)));
  run_for(*arm, 2.0);
  EXPECT_NEAR(arm->true_position()[0], target, position_tolerance(*arm, 0));
}

TEST_P(HwArm, FaultsHaveTheirEffects) {
  const auto arm = hw::make_simulated_arm(model_);
  const std::size_t last = arm->dof() - 1;
  const kin::Joint& joint = model_.joints[last];
  const double goal = joint.ready + 0.1 * (joint.upper - joint.ready);

  // A joint that stops answering keeps its last goal and refuses new commands.
  ASSERT_TRUE(arm->command(last, move(goal, 0.5 * joint.max_velocity)));
  arm->inject(hw::Fault::joint_not_answering, last);
  EXPECT_FALSE(arm->read(last).answered);
  EXPECT_TRUE(arm->read(0).answered);
  EXPECT_FALSE(arm->command(last, move(joint.ready, 0.0)));
  run_for(*arm, 2.0);
  EXPECT_NEAR(arm->true_position()[last], goal, position_tolerance(*arm, last));
  arm->clear_faults();
  EXPECT_TRUE(arm->read(last).answered);
  EXPECT_TRUE(arm->command(last, {ServoCommand::Kind::hold, 0.0, 0.0}));

  // An encoder error: flagged, and the counts jump by thousands.
  const std::int64_t before = arm->read(1).counts;
  arm->inject(hw::Fault::encoder_error, 1);
  const hw::JointReading bad = arm->read(1);
  EXPECT_TRUE(bad.encoder_error);
  EXPECT_GE(std::abs(bad.counts - before), 1000);
  EXPECT_FALSE(arm->read(0).encoder_error);
  arm->clear_faults();
  EXPECT_FALSE(arm->read(1).encoder_error);
  EXPECT_LE(std::abs(arm->read(1).counts - before), 1);

  // Power loss: brakes, and power cannot come back until the fault is cleared.
  arm->inject(hw::Fault::power_loss, 0);
  EXPECT_FALSE(arm->power());
  EXPECT_FALSE(arm->set_power(true));
  EXPECT_FALSE(arm->power());
  arm->clear_faults();
  EXPECT_TRUE(arm->set_power(true));
  EXPECT_TRUE(arm->power());

  // Commands to joints that do not exist, and non-finite ones, are refused.
  EXPECT_FALSE(arm->command(arm->dof(), move(0.0, 0.0)));
  EXPECT_FALSE(arm->command(0, move(std::nan(""), 0.0)));
  EXPECT_FALSE(arm->read(arm->dof()).answered);
}

TEST_P(HwArm, HandAndOutputsAreState) {
  const auto arm = hw::make_simulated_arm(model_);
  EXPECT_FALSE(arm->hand_closed());
  arm->set_hand_closed(true);
  EXPECT_TRUE(arm->hand_closed());
  EXPECT_EQ(arm->outputs(), 0);
  arm->set_outputs(0xA5C3);
  EXPECT_EQ(arm->outputs(), 0xA5C3);
}

TEST_P(HwArm, ZeroGravityFollowsAPushAndStaysWhenReleased) {
  const auto arm = hw::make_simulated_arm(model_);
  arm->set_zero_gravity(true);
  const kin::JointVector start = arm->true_position();
  const std::size_t j = 0;
  const kin::Joint& joint = model_.joints[j];
  // Enough to beat the joint's Coulomb friction (the PUMA), pushing toward the middle.
  const double push = std::copysign(joint.dynamics.coulomb_friction + 20.0,
                                    0.5 * (joint.lower + joint.upper) - start[j] + 1e-9);
  arm->set_external_effort(j, push);
  run_for(*arm, 0.5);
  const double moved = arm->true_position()[j] - start[j];
  EXPECT_GT(moved * push, 0.0) << "moves with the push";
  EXPECT_GT(std::abs(moved), 0.01);
  if (!is_puma(*arm)) {
    EXPECT_NEAR(moved, 0.5 * hw::kIdealAdmittance_rad_per_s_per_N_m * push, 1e-9);
  }
  arm->set_external_effort(j, 0.0);
  run_for(*arm, 0.5);
  const kin::JointVector left = arm->true_position();
  run_for(*arm, 2.0);
  EXPECT_EQ(arm->true_position(), left) << "stays where it is left";
  for (std::size_t k = 1; k < arm->dof(); ++k) {
    EXPECT_NEAR(left[k], start[k], position_tolerance(*arm, k)) << "unpushed joints stay";
  }
  // Leaving zero gravity holds that pose.
  arm->set_zero_gravity(false);
  run_for(*arm, 1.0);
  for (std::size_t k = 0; k < arm->dof(); ++k) {
    EXPECT_NEAR(arm->true_position()[k], left[k], position_tolerance(*arm, k));
  }
}

// The PUMA's plant and servo.

double potential_energy(const kin::RobotModel& model, const kin::JointVector& q) {
  double v = 0.0;
  for (std::size_t i = 1; i <= model.dof(); ++i) {
    kin::RobotModel chain = model;
    chain.joints.resize(i);
    chain.solver = kin::SolverKind::dh;
    const kin::DhKinematics k(chain);
    kin::JointVector qi(i);
    for (std::size_t m = 0; m < i; ++m) qi[m] = q[m];
    const math::Transform T = k.forward(qi);
    const auto& c = model.joints[i - 1].dynamics.link_com_m;
    v += model.joints[i - 1].dynamics.link_mass_kg * hw::kGravity_m_per_s2 *
         (T * math::Vec3{c[0], c[1], c[2]}).z;
  }
  return v;
}

void expect_gravity_is_the_energy_gradient(const kin::RobotModel& model) {
  const hw::GravityModel gravity(model);
  std::mt19937 rng(7);
  for (int sample = 0; sample < 20; ++sample) {
    kin::JointVector q(model.dof());
    for (std::size_t j = 0; j < q.size(); ++j) {
      q[j] =
          std::uniform_real_distribution<double>(model.joints[j].lower, model.joints[j].upper)(rng);
    }
    const kin::JointVector load = gravity.load(q);
    for (std::size_t j = 0; j < q.size(); ++j) {
      const double h = 1e-6;
      kin::JointVector up = q, down = q;
      up[j] += h;
      down[j] -= h;
      const double gradient =
          (potential_energy(model, up) - potential_energy(model, down)) / (2 * h);
      EXPECT_NEAR(load[j], gradient, 1e-6) << model.name << " joint " << j + 1;
    }
  }
}

TEST(HwGravity, LoadIsTheGradientOfThePotentialEnergy) {
  expect_gravity_is_the_energy_gradient(kin::builtin_robot("puma560"));
  expect_gravity_is_the_energy_gradient(kin::builtin_robot("puma260"));
  // A chain with a prismatic joint (the Stanford arm, with masses made up for the test).
  kin::RobotModel stanford = kin::builtin_robot("stanford");
  for (std::size_t j = 0; j < stanford.dof(); ++j) {
    stanford.joints[j].dynamics.link_mass_kg = 1.0 + static_cast<double>(j);
    stanford.joints[j].dynamics.link_com_m = {0.01 * static_cast<double>(j), -0.02, 0.05};
  }
  expect_gravity_is_the_energy_gradient(stanford);
}

TEST(HwGravity, Puma560ArmOutstretchedLoadsTheShoulder) {
  // q2 = 0: upper arm horizontal, forearm up (Corke's qz). The load is not trivially zero, and
  // joint 1 (vertical axis) never carries gravity.
  const kin::RobotModel m = kin::builtin_robot("puma560");
  const hw::GravityModel gravity(m);
  const kin::JointVector load = gravity.load({0, 0, 0, 0, 0, 0});
  EXPECT_EQ(load[0], 0.0);
  EXPECT_GT(std::abs(load[1]), 20.0);
  EXPECT_LT(std::abs(load[1]), m.joints[1].dynamics.max_effort);
}

TEST(HwPuma, HoldsItsPoseUnderGravityWithTheServoOn) {
  for (const kin::JointVector& pose :
       {kin::JointVector{0, 0, 0, 0, 0, 0}, kin::JointVector{0.3, 0.2, -0.5, 0.5, -0.7, 0.2}}) {
    hw::SimulatedArmOptions options;
    options.initial = pose;
    hw::SimulatedPuma arm(kin::builtin_robot("puma560"), options);
    const kin::JointVector load = arm.gravity_load(pose);
    ASSERT_GT(std::abs(load[1]), 10.0);
    double worst = 0.0;
    for (int t = 0; t < 2000; ++t) {
      run_for(arm, hw::kServoPeriod_s);
      const kin::JointVector q = arm.true_position();
      for (std::size_t j = 0; j < 6; ++j) {
        worst =
            std::max(worst, std::abs(q[j] - pose[j]) / arm.model().joints[j].resolution_per_count);
      }
    }
    EXPECT_LE(worst, 1.0) << "counts of sag";
    // The motors carry the gravity load.
    const kin::JointVector tau = arm.motor_effort();
    for (std::size_t j = 0; j < 6; ++j)
      EXPECT_NEAR(tau[j], load[j], 1e-6 + 0.01 * std::abs(load[j]));
  }
}

TEST(HwPuma, SettlesAfterSteps) {
  const kin::RobotModel m = kin::builtin_robot("puma560");
  hw::SimulatedPuma arm(m);
  const kin::JointVector goal = {0.2, 0.6, -2.9, 0.3, 0.5, -0.4};
  for (std::size_t j = 0; j < 6; ++j) ASSERT_TRUE(arm.command(j, move(goal[j], 0.0)));
  std::array<double, 6> overshoot{};
  const kin::JointVector start = arm.true_position();
  for (int t = 0; t < 2000; ++t) {
    run_for(arm, hw::kServoPeriod_s);
    const kin::JointVector q = arm.true_position();
    for (std::size_t j = 0; j < 6; ++j) {
      overshoot[j] = std::max(overshoot[j], (q[j] - goal[j]) * (goal[j] > start[j] ? 1 : -1));
    }
  }
  const kin::JointVector q = arm.true_position();
  for (std::size_t j = 0; j < 6; ++j) {
    // The poles at -40 rad/s with the integrator: settled well within 2 s; a few counts left.
    const double res = m.joints[j].resolution_per_count;
    EXPECT_NEAR(q[j], goal[j], 5 * res) << j;
    EXPECT_NEAR(arm.true_velocity()[j], 0.0, 1e-3) << j;
    // Overshoot under 10 % of the step.
    EXPECT_LE(overshoot[j], 0.1 * std::abs(goal[j] - start[j])) << j;
    const double read = counts_to_value(arm, j, arm.read(j).counts);
    EXPECT_NEAR(read, q[j], 0.5 * res * (1 + 1e-9));
  }
}

TEST(HwPuma, GainsComeFromTheInertia) {
  const kin::RobotModel m = kin::builtin_robot("puma560");
  const hw::SimulatedPuma arm(m);
  const double w = hw::SimulatedPuma::kServoBandwidth_rad_per_s;
  for (std::size_t j = 0; j < 6; ++j) {
    const double inertia = m.joints[j].dynamics.inertia;
    EXPECT_DOUBLE_EQ(arm.gains(j).kp, 3 * inertia * w * w);
    EXPECT_DOUBLE_EQ(arm.gains(j).kd, 3 * inertia * w);
    EXPECT_DOUBLE_EQ(arm.gains(j).ki, inertia * w * w * w);
  }
}

TEST(HwPuma, ZeroGravityNeedsAPushBiggerThanFriction) {
  const kin::RobotModel m = kin::builtin_robot("puma560");
  hw::SimulatedPuma arm(m);
  arm.set_zero_gravity(true);
  const kin::JointVector start = arm.true_position();
  // The shoulder (joint 2) carries gravity: compensated, a push under the friction does nothing.
  arm.set_external_effort(1, 0.9 * m.joints[1].dynamics.coulomb_friction);
  run_for(arm, 1.0);
  EXPECT_EQ(arm.true_position(), start);
  arm.set_external_effort(1, m.joints[1].dynamics.coulomb_friction + 30.0);
  run_for(arm, 0.3);
  EXPECT_GT(arm.true_position()[1], start[1] + 0.01);
  arm.set_external_effort(1, 0.0);
  run_for(arm, 0.5);
  const kin::JointVector left = arm.true_position();
  run_for(arm, 2.0);
  EXPECT_EQ(arm.true_position(), left) << "gravity is compensated at the new pose";
}

TEST(HwPuma, ExternalEffortWithTheServoOnIsResisted) {
  const kin::RobotModel m = kin::builtin_robot("puma560");
  hw::SimulatedPuma arm(m);
  const kin::JointVector start = arm.true_position();
  arm.set_external_effort(2, 40.0);
  run_for(arm, 2.0);
  // The integrator takes the push over: the joint comes back to its setpoint.
  EXPECT_NEAR(arm.true_position()[2], start[2], 5 * m.joints[2].resolution_per_count);
  // At rest, Coulomb friction takes up whatever the motor, gravity and push leave over.
  EXPECT_NEAR(arm.motor_effort()[2], arm.gravity_load(arm.true_position())[2] - 40.0,
              m.joints[2].dynamics.coulomb_friction + 1e-6);
  EXPECT_LT(arm.motor_effort()[2], -20.0) << "the motor resists the push";
}

}  // namespace
