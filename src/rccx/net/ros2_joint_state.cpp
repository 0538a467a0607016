#include "rccx/net/ros2_joint_state.hpp"

#include <fmt/format.h>

#include <utility>

namespace rccx::net {

namespace {

bool ros_name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

/// A sequence over a buffer we own: _release false, so Cyclone never frees it.
template <typename Seq, typename T>
void point(Seq& seq, T* buffer, std::size_t n) {
  seq._buffer = buffer;
  seq._maximum = static_cast<std::uint32_t>(n);
  seq._length = 0;
  seq._release = false;
}

}  // namespace

std::string ros2_joint_states_topic(std::string_view robot) {
  std::string token;
  for (const char c : robot) {
    const char d = ros_name_char(c) ? c : '_';
    // ROS 2 names have no repeated '_' (they would not survive its name mangling).
    if (d == '_' && !token.empty() && token.back() == '_') continue;
    token += d;
  }
  if (token.empty() || (token.front() >= '0' && token.front() <= '9')) token = "robot_" + token;
  return fmt::format("rt/{}/joint_states", token);
}

std::vector<std::string> ros2_joint_names(std::string_view robot, const kin::RobotModel& model) {
  std::vector<std::string> names;
  names.reserve(model.dof());
  for (std::size_t i = 0; i < model.dof(); ++i) {
    const std::string& own = model.joints[i].name;
    names.push_back(own.empty() ? fmt::format("{}_joint{}", robot, i + 1)
                                : fmt::format("{}_{}", robot, own));
  }
  return names;
}

JointStatePublisher::JointStatePublisher(const Participant& participant, std::string_view robot,
                                         const kin::RobotModel& model)
    : JointStatePublisher(participant, robot, ros2_joint_names(robot, model)) {}

JointStatePublisher::JointStatePublisher(const Participant& participant, std::string_view robot,
                                         std::vector<std::string> joint_names)
    : topic_name_(ros2_joint_states_topic(robot)), names_(std::move(joint_names)) {
  if (names_.empty() || names_.size() > kMaxJoints) {
    throw NetError(fmt::format("ROS 2 joint states of '{}': {} joint names; give 1 .. {}", robot,
                               names_.size(), kMaxJoints));
  }
  for (std::size_t i = 0; i < names_.size(); ++i) {
    if (names_[i].empty()) {
      throw NetError(
          fmt::format("ROS 2 joint states of '{}': joint {} has no name; name it", robot, i + 1));
    }
  }
  // Every buffer of the sample is made here, once; publish() only copies into them.
  const std::size_t n = names_.size();
  name_ptrs_.reserve(n);
  for (std::string& s : names_) name_ptrs_.push_back(s.data());
  position_.assign(n, 0.0);
  velocity_.assign(n, 0.0);
  effort_.assign(n, 0.0);
  sample_.header.frame_id = frame_id_;
  point(sample_.name, name_ptrs_.data(), n);
  sample_.name._length = static_cast<std::uint32_t>(n);
  point(sample_.position, position_.data(), n);
  point(sample_.velocity, velocity_.data(), n);
  point(sample_.effort, effort_.data(), n);

  const dds_entity_t topic =
      dds_create_topic(participant.get(), &sensor_msgs_msg_dds__JointState__desc,
                       topic_name_.c_str(), nullptr, nullptr);
  check(topic, fmt::format("DDS topic {} (ROS 2 joint states of '{}')", topic_name_, robot));
  topic_ = Entity(topic);

  const Qos qos;
  dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, 1);
  dds_qset_durability(qos.get(), DDS_DURABILITY_VOLATILE);
  const dds_entity_t w = dds_create_writer(participant.get(), topic, qos.get(), nullptr);
  check(w, fmt::format("a writer of {}", topic_name_));
  writer_ = Entity(w);
}

void JointStatePublisher::publish(std::int64_t stamp_ns, std::span<const double> q,
                                  std::span<const double> qd, std::span<const double> effort) {
  const std::size_t n = dof();
  const auto wrong = [&](std::span<const double> s, bool may_be_empty) {
    return s.size() != n && !(may_be_empty && s.empty());
  };
  if (wrong(q, false) || wrong(qd, true) || wrong(effort, true)) {
    throw NetError(fmt::format(
        "ROS 2 joint state on {}: {} positions, {} velocities, {} efforts for {} joints; give "
        "{} each (velocities and efforts may be empty)",
        topic_name_, q.size(), qd.size(), effort.size(), n, n));
  }
  // ROS 2's Time: whole seconds and the ns within them, ns >= 0 also before the epoch.
  std::int64_t sec = stamp_ns / 1'000'000'000;
  std::int64_t nsec = stamp_ns % 1'000'000'000;
  if (nsec < 0) {
    nsec += 1'000'000'000;
    --sec;
  }
  sample_.header.stamp.sec = static_cast<std::int32_t>(sec);
  sample_.header.stamp.nanosec = static_cast<std::uint32_t>(nsec);
  const auto fill = [](dds_sequence_double& seq, std::span<const double> from) {
    for (std::size_t i = 0; i < from.size(); ++i) seq._buffer[i] = from[i];
    seq._length = static_cast<std::uint32_t>(from.size());
  };
  fill(sample_.position, q);
  fill(sample_.velocity, qd);
  fill(sample_.effort, effort);
  const dds_return_t rc = dds_write(writer_.get(), &sample_);
  if (rc < 0) check(rc, fmt::format("writing {}", topic_name_));  // formats only on failure
}

}  // namespace rccx::net
