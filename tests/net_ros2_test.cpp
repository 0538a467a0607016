// ROS 2's view of a robot (src/rccx/net/ros2_joint_state.hpp): a subscriber built from the same
// IDL (the generated C type) on another participant reads JointState_ samples as ROS 2 would,
// with ROS 2's default and sensor-data QoS; the writer is seen on the wire with ROS 2's topic and
// type names and in plain CDR (XCDR1), the only encoding rmw_cyclonedds_cpp's readers accept.
// No ROS 2 here: what ROS 2 itself does with them is docs/NETWORK.md's to say, not tested.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "counting_new.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/net/ros2_joint_state.hpp"

using namespace rccx;
using namespace std::chrono_literals;

namespace {

/// A domain of this test process's own (200 .. 231: apart from net_dds_test's 100 .. 199).
net::NetOptions loopback() {
  net::NetOptions o;
  o.domain = 200 + static_cast<std::uint32_t>(getpid() % 32);
  o.interface = "lo";
  return o;
}

/// rclcpp's default subscription (rmw_qos_profile_default): reliable, keep last 10, volatile;
/// and, as rmw_cyclonedds_cpp's readers, accepting plain CDR (XCDR1) only.
void ros2_default_qos(dds_qos_t* q) {
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 10);
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(q, 1, &xcdr1);
}

/// rmw_qos_profile_sensor_data: best effort, keep last 5, volatile; XCDR1 only likewise.
void ros2_sensor_data_qos(dds_qos_t* q) {
  dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 5);
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(q, 1, &xcdr1);
}

/// A ROS 2 style subscriber of `topic_name` on `p`, with the QoS `set_qos` sets.
struct Subscriber {
  net::Entity topic;
  net::Entity reader;
  Subscriber(const net::Participant& p, const std::string& topic_name,
             void (*set_qos)(dds_qos_t*)) {
    const net::Qos qos;
    set_qos(qos.get());
    topic = net::Entity(net::check(dds_create_topic(p.get(), &sensor_msgs_msg_dds__JointState__desc,
                                                    topic_name.c_str(), nullptr, nullptr),
                                   "test topic"));
    reader = net::Entity(
        net::check(dds_create_reader(p.get(), topic.get(), qos.get(), nullptr), "test reader"));
  }
};

/// One sample as read, copied out of Cyclone's loan.
struct Read {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  std::string frame_id;
  std::vector<std::string> names;
  std::vector<double> position, velocity, effort;
};

std::vector<Read> take_all(dds_entity_t reader) {
  std::vector<Read> out;
  void* samples[16] = {};
  dds_sample_info_t infos[16];
  const dds_return_t n = dds_take(reader, samples, infos, 16, 16);
  for (dds_return_t i = 0; i < n; ++i) {
    if (!infos[i].valid_data) continue;
    const auto* s = static_cast<const sensor_msgs_msg_dds__JointState_*>(samples[i]);
    Read r;
    r.sec = s->header.stamp.sec;
    r.nanosec = s->header.stamp.nanosec;
    r.frame_id = s->header.frame_id;
    for (std::uint32_t k = 0; k < s->name._length; ++k) r.names.emplace_back(s->name._buffer[k]);
    r.position.assign(s->position._buffer, s->position._buffer + s->position._length);
    r.velocity.assign(s->velocity._buffer, s->velocity._buffer + s->velocity._length);
    r.effort.assign(s->effort._buffer, s->effort._buffer + s->effort._length);
    out.push_back(std::move(r));
  }
  if (n > 0) dds_return_loan(reader, samples, n);
  return out;
}

/// Waits (at most 10 s: discovery on a loaded machine) until `writer` has matched `count`
/// readers; returns whether it did.
bool wait_matched(dds_entity_t writer, std::uint32_t count) {
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < until) {
    dds_publication_matched_status_t st{};
    if (dds_get_publication_matched_status(writer, &st) >= 0 && st.current_count >= count) {
      return true;
    }
    std::this_thread::sleep_for(5ms);
  }
  return false;
}

}  // namespace

TEST(NetRos2, TopicNamesAreRos2sAndRobotNamesBecomeValidRosNames) {
  EXPECT_EQ(net::ros2_joint_states_topic("puma"), "rt/puma/joint_states");
  EXPECT_EQ(net::ros2_joint_states_topic("arm-2.b"), "rt/arm_2_b/joint_states");
  EXPECT_EQ(net::ros2_joint_states_topic("a--b"), "rt/a_b/joint_states");
  EXPECT_EQ(net::ros2_joint_states_topic("2arm"), "rt/robot_2arm/joint_states");
}

TEST(NetRos2, JointNamesAreTheModelsPrefixedByTheRobot) {
  kin::RobotModel model = kin::builtin_robot("puma560");
  std::vector<std::string> names = net::ros2_joint_names("puma", model);
  ASSERT_EQ(names.size(), model.dof());
  for (std::size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(names[i], "puma_" + model.joints[i].name);
  }
  model.joints[1].name.clear();
  names = net::ros2_joint_names("puma", model);
  EXPECT_EQ(names[1], "puma_joint2");
}

TEST(NetRos2, ARos2SubscriberReadsNamesPositionsAndStampsWithDefaultAndSensorDataQos) {
  const net::Participant serve(loopback());
  const net::Participant ros(loopback());
  const kin::RobotModel model = kin::builtin_robot("puma560");
  net::JointStatePublisher pub(serve, "puma", model);
  ASSERT_EQ(pub.topic_name(), "rt/puma/joint_states");

  const Subscriber by_default(ros, pub.topic_name(), ros2_default_qos);
  const Subscriber by_sensor(ros, pub.topic_name(), ros2_sensor_data_qos);
  ASSERT_TRUE(wait_matched(pub.writer(), 2))
      << "the writer did not match ROS 2's default and sensor-data readers in 10 s";

  // The reader's topic has ROS 2's type name exactly (ros2 topic echo resolves it from this).
  char type_name[128] = {};
  ASSERT_GE(dds_get_type_name(by_default.topic.get(), type_name, sizeof type_name), 0);
  EXPECT_STREQ(type_name, "sensor_msgs::msg::dds_::JointState_");
  char topic_name[128] = {};
  ASSERT_GE(dds_get_name(by_default.topic.get(), topic_name, sizeof topic_name), 0);
  EXPECT_STREQ(topic_name, "rt/puma/joint_states");

  const std::size_t n = pub.dof();
  std::vector<double> q(n), qd(n), effort(n);
  const std::int64_t stamp0_ns = 1'700'000'000'123'456'789;
  std::vector<Read> got_default, got_sensor;
  // Best effort may drop a sample: write a few, 20 ms apart, until both have some (<= 10 s).
  const auto until = std::chrono::steady_clock::now() + 10s;
  int written = 0;
  while ((got_default.empty() || got_sensor.empty()) && std::chrono::steady_clock::now() < until) {
    for (std::size_t j = 0; j < n; ++j) {
      q[j] = 0.1 * static_cast<double>(j + 1) + 0.001 * written;
      qd[j] = -0.5 * static_cast<double>(j);
      effort[j] = 2.0 * static_cast<double>(j);
    }
    pub.publish(stamp0_ns + written * 1'000'000, q, qd, effort);
    ++written;
    std::this_thread::sleep_for(20ms);
    for (Read& r : take_all(by_default.reader.get())) got_default.push_back(std::move(r));
    for (Read& r : take_all(by_sensor.reader.get())) got_sensor.push_back(std::move(r));
  }
  ASSERT_FALSE(got_default.empty()) << "the default-QoS reader got nothing in 10 s";
  ASSERT_FALSE(got_sensor.empty()) << "the sensor-data reader got nothing in 10 s";

  for (const Read& r : {got_default.back(), got_sensor.back()}) {
    // Which sample it is follows from its stamp: 1 ms per write after stamp0.
    const std::int64_t stamp_ns = std::int64_t{r.sec} * 1'000'000'000 + r.nanosec;
    const std::int64_t k = (stamp_ns - stamp0_ns) / 1'000'000;
    ASSERT_GE(k, 0);
    ASSERT_LT(k, written);
    EXPECT_EQ(stamp_ns, stamp0_ns + k * 1'000'000);
    EXPECT_EQ(r.frame_id, "");
    EXPECT_EQ(r.names, pub.joint_names());
    ASSERT_EQ(r.position.size(), n);
    ASSERT_EQ(r.velocity.size(), n);
    ASSERT_EQ(r.effort.size(), n);
    for (std::size_t j = 0; j < n; ++j) {
      EXPECT_DOUBLE_EQ(r.position[j],
                       0.1 * static_cast<double>(j + 1) + 0.001 * static_cast<double>(k));
      EXPECT_DOUBLE_EQ(r.velocity[j], -0.5 * static_cast<double>(j));
      EXPECT_DOUBLE_EQ(r.effort[j], 2.0 * static_cast<double>(j));
    }
  }
  // Reliable and in order: the default reader's stamps only grow.
  for (std::size_t i = 1; i < got_default.size(); ++i) {
    EXPECT_GT(std::int64_t{got_default[i].sec} * 1'000'000'000 + got_default[i].nanosec,
              std::int64_t{got_default[i - 1].sec} * 1'000'000'000 + got_default[i - 1].nanosec);
  }
}

TEST(NetRos2, TheWriterIsDiscoveredWithRos2sNamesReliableVolatileAndPlainCdr) {
  const net::Participant serve(loopback());
  const net::Participant ros(loopback());
  net::JointStatePublisher pub(serve, "microbo", std::vector<std::string>{"a", "b", "c"});
  // What a ROS 2 graph sees: the DCPSPublication of the writer, discovered by another participant.
  const net::Entity builtin(
      net::check(dds_create_reader(ros.get(), DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr),
                 "DCPSPublication reader"));
  bool found = false;
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (!found && std::chrono::steady_clock::now() < until) {
    void* samples[8] = {};
    dds_sample_info_t infos[8];
    const dds_return_t got = dds_take(builtin.get(), samples, infos, 8, 8);
    for (dds_return_t i = 0; i < got; ++i) {
      const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
      if (!infos[i].valid_data || std::strcmp(ep->topic_name, "rt/microbo/joint_states") != 0) {
        continue;
      }
      found = true;
      EXPECT_STREQ(ep->type_name, "sensor_msgs::msg::dds_::JointState_");
      dds_reliability_kind_t rel{};
      dds_duration_t blocking = 0;
      ASSERT_TRUE(dds_qget_reliability(ep->qos, &rel, &blocking));
      EXPECT_EQ(rel, DDS_RELIABILITY_RELIABLE);
      dds_durability_kind_t dur{};
      ASSERT_TRUE(dds_qget_durability(ep->qos, &dur));
      EXPECT_EQ(dur, DDS_DURABILITY_VOLATILE);
      uint32_t nrep = 0;
      dds_data_representation_id_t* reps = nullptr;
      ASSERT_TRUE(dds_qget_data_representation(ep->qos, &nrep, &reps));
      ASSERT_GE(nrep, 1U);
      EXPECT_EQ(reps[0], DDS_DATA_REPRESENTATION_XCDR1) << "ROS 2 (rmw_cyclonedds) reads XCDR1";
      dds_free(reps);
    }
    if (got > 0) dds_return_loan(builtin.get(), samples, got);
    if (!found) std::this_thread::sleep_for(10ms);
  }
  EXPECT_TRUE(found) << "no writer of rt/microbo/joint_states discovered in 10 s";
}

TEST(NetRos2, PublishAllocatesNothingInRccxAndBadSizesWriteNothing) {
  const net::Participant serve(loopback());
  const net::Participant ros(loopback());
  net::JointStatePublisher pub(serve, "arm", std::vector<std::string>{"arm_j1", "arm_j2"});
  const Subscriber sub(ros, pub.topic_name(), ros2_default_qos);
  ASSERT_TRUE(wait_matched(pub.writer(), 1)) << "no match in 10 s";

  const std::vector<double> q{0.25, -0.5};
  const long before = test_support::thread_allocations();
  for (int i = 0; i < 100; ++i) pub.publish(net::wall_ns(), q);
  EXPECT_EQ(test_support::thread_allocations(), before)
      << "publish allocated with operator new (the sample's buffers are made once)";

  std::this_thread::sleep_for(200ms);
  std::vector<Read> got = take_all(sub.reader.get());
  ASSERT_FALSE(got.empty()) << "reliable reader got none of 100 samples";
  EXPECT_EQ(got.back().position, q);
  EXPECT_TRUE(got.back().velocity.empty()) << "no velocities given: ROS's empty array";

  std::this_thread::sleep_for(100ms);
  (void)take_all(sub.reader.get());  // nothing of the 100 left to arrive after this
  const std::vector<double> three{1.0, 2.0, 3.0};
  EXPECT_THROW(pub.publish(net::wall_ns(), three), net::NetError);
  EXPECT_THROW(pub.publish(net::wall_ns(), q, three), net::NetError);
  try {
    pub.publish(net::wall_ns(), q, {}, three);
    FAIL() << "3 efforts for 2 joints accepted";
  } catch (const net::NetError& e) {
    EXPECT_NE(std::string(e.what()).find("give 2 each"), std::string::npos) << e.what();
  }
  std::this_thread::sleep_for(200ms);
  EXPECT_TRUE(take_all(sub.reader.get()).empty()) << "a refused publish wrote a sample";
}

TEST(NetRos2, BadJointNamesAreRefusedSayingWhatToGive) {
  const net::Participant p(loopback());
  try {
    net::JointStatePublisher pub(p, "arm", std::vector<std::string>{});
    FAIL() << "no joints accepted";
  } catch (const net::NetError& e) {
    EXPECT_NE(std::string(e.what()).find("give 1 .. 64"), std::string::npos) << e.what();
  }
  EXPECT_THROW(net::JointStatePublisher(p, "arm", std::vector<std::string>{"a", ""}),
               net::NetError);
}
