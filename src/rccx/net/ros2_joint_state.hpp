// Each robot's joint state as ROS 2 sees a topic: "rt/<robot>/joint_states", of DDS type
// "sensor_msgs::msg::dds_::JointState_" (ros2_joint_state.idl), so `ros2 topic echo
// /puma/joint_states` reads a robot served by rccx with no bridge (docs/NETWORK.md, "ROS 2").
//
//   net::Participant participant(options);
//   net::JointStatePublisher ros2(participant, "puma", model);  // puma_theta1 .. puma_theta6
//   ros2.publish(net::wall_ns(), q_rad, qd_rad_per_s);          // from a middleware thread
//
// QoS: reliable, keep last 1, volatile. A reliable writer matches both ROS 2's default
// subscription (reliable, keep last 10, volatile) and its sensor-data one (best effort, keep
// last 5); a best-effort writer would not match the default, which is what `ros2 topic echo`
// and most nodes ask for. Keep last 1: only the newest state matters, and it bounds what the
// writer holds for retransmission to one sample.
//
// Allocation: the sample's buffers (joint names, position, velocity, effort) are made once
// here and reused; publish() copies into them and calls dds_write, so rccx's code allocates
// nothing per publish (Cyclone's own serialization buffer is Cyclone's). Not for the sample
// loop: DDS calls happen on middleware threads only.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/kinematics/robot_model.hpp"
#include "rccx/net/dds.hpp"
#include "ros2_joint_state.h"

namespace rccx::net {

/// "rt/<robot>/joint_states": ROS 2's DDS topic for ROS's "/<robot>/joint_states". Characters a
/// ROS name does not allow (rccx names also have '-' and '.') become '_', repeated '_' one, and
/// a name starting with a digit gets "robot_" before it ("arm-2" -> "rt/arm_2/joint_states").
[[nodiscard]] std::string ros2_joint_states_topic(std::string_view robot);

/// The joint names a robot publishes: "<robot>_<joint's name in the model>" (a robot file names
/// every joint: "puma_theta1"), "<robot>_joint<i>" (from 1) for a joint without a name. The
/// robot's name in front keeps them unique across a cell, as multi-arm URDFs do.
[[nodiscard]] std::vector<std::string> ros2_joint_names(std::string_view robot,
                                                        const kin::RobotModel& model);

/// One robot's sensor_msgs/JointState writer on a participant. Not copyable; one per robot.
class JointStatePublisher {
 public:
  /// A writer of "rt/<robot>/joint_states" with `joint_names` (1 .. 64 of them, each non-empty).
  /// Throws NetError when a name is bad or the topic or writer cannot be made.
  JointStatePublisher(const Participant& participant, std::string_view robot,
                      std::vector<std::string> joint_names);
  /// The same, with ros2_joint_names(robot, model).
  JointStatePublisher(const Participant& participant, std::string_view robot,
                      const kin::RobotModel& model);
  JointStatePublisher(const JointStatePublisher&) = delete;
  JointStatePublisher& operator=(const JointStatePublisher&) = delete;

  /// Writes one JointState: header.stamp = stamp_ns (ns since the epoch, CLOCK_REALTIME as
  /// ROS 2's system time; net::wall_ns()), position = q (rad / m, one per joint), velocity = qd
  /// (rad/s, m/s), effort (N m, N); qd and effort may be empty (ROS: not known). Throws NetError,
  /// writing nothing, when a non-empty span's size is not dof() or DDS refuses the write.
  void publish(std::int64_t stamp_ns, std::span<const double> q, std::span<const double> qd = {},
               std::span<const double> effort = {});

  [[nodiscard]] const std::string& topic_name() const noexcept { return topic_name_; }
  [[nodiscard]] const std::vector<std::string>& joint_names() const noexcept { return names_; }
  [[nodiscard]] std::size_t dof() const noexcept { return names_.size(); }
  [[nodiscard]] dds_entity_t writer() const noexcept { return writer_.get(); }

  /// The most joints a JointState of rccx carries (RobotState carries 8; room for more).
  static constexpr std::size_t kMaxJoints = 64;

 private:
  std::string topic_name_;
  std::vector<std::string> names_;
  std::vector<char*> name_ptrs_;  ///< into names_: the sample's name._buffer
  std::vector<double> position_, velocity_, effort_;
  char frame_id_[1] = {'\0'};  ///< header.frame_id: "" (joint states have no frame)
  sensor_msgs_msg_dds__JointState_ sample_{};
  Entity topic_;
  Entity writer_;
};

}  // namespace rccx::net
