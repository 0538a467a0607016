// ROS 2's view of a served robot (issue 29, item 8): a spawned `rccx serve` publishes each of its
// robots' joint states on "rt/<robot>/joint_states" as sensor_msgs/JointState; a subscriber of
// the generated C type with ROS 2's default QoS (as tests/net_ros2_test.cpp makes it) reads the
// robot's joint names and its measured joints, the same as the serve's RobotState of that time,
// changing while the robot moves. `--no-ros2` turns it off.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "net_attempts.hpp"
#include "net_serve_helpers.hpp"
#include "rccx/cell/cell_model.hpp"
#include "rccx/net/remote_cell.hpp"
#include "rccx/net/ros2_joint_state.hpp"

using namespace rccx;
using namespace std::chrono_literals;

namespace {

const std::string kCell = std::string(RCCX_CELLS_DIR) + "/cvarl.json";
constexpr std::chrono::milliseconds kDetection{50};

/// A domain of this test process's own, 10 .. 39 (apart from the other net tests' ranges).
/// Domains 10 .. 41: attempt k (net_attempts.hpp) on a domain of its own, as the other tests.
std::uint32_t domain(int attempt) {
  return 10 + static_cast<std::uint32_t>(getpid() % 30) + static_cast<std::uint32_t>(attempt - 1);
}

/// One JointState as read, copied out of Cyclone's loan.
struct Read {
  std::int64_t stamp_ns = 0;
  std::vector<std::string> names;
  std::vector<double> position, velocity, effort;
};

/// A ROS 2 subscriber of `topic` (rclcpp's default QoS: reliable, keep last 10, volatile; plain
/// CDR as rmw_cyclonedds_cpp reads) that takes every sample on a thread of its own.
class Ros2Subscriber {
 public:
  Ros2Subscriber(const net::Participant& p, const std::string& topic) {
    const net::Qos qos;
    dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, 10);
    dds_qset_durability(qos.get(), DDS_DURABILITY_VOLATILE);
    const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
    dds_qset_data_representation(qos.get(), 1, &xcdr1);
    topic_ =
        net::Entity(net::check(dds_create_topic(p.get(), &sensor_msgs_msg_dds__JointState__desc,
                                                topic.c_str(), nullptr, nullptr),
                               "JointState topic"));
    reader_ = net::Entity(net::check(dds_create_reader(p.get(), topic_.get(), qos.get(), nullptr),
                                     "JointState reader"));
    thread_ = std::thread([this] {
      while (!stop_) {
        take();
        std::this_thread::sleep_for(1ms);
      }
    });
  }
  ~Ros2Subscriber() {
    stop_ = true;
    thread_.join();
  }
  Ros2Subscriber(const Ros2Subscriber&) = delete;
  Ros2Subscriber& operator=(const Ros2Subscriber&) = delete;

  [[nodiscard]] std::vector<Read> reads() {
    std::lock_guard lock(mutex_);
    return reads_;
  }
  [[nodiscard]] bool matched() const {
    dds_subscription_matched_status_t st{};
    return dds_get_subscription_matched_status(reader_.get(), &st) >= 0 && st.current_count > 0;
  }

 private:
  void take() {
    void* samples[16] = {};
    dds_sample_info_t infos[16];
    const dds_return_t n = dds_take(reader_.get(), samples, infos, 16, 16);
    std::lock_guard lock(mutex_);
    for (dds_return_t i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const auto* s = static_cast<const sensor_msgs_msg_dds__JointState_*>(samples[i]);
      Read r;
      r.stamp_ns = std::int64_t{s->header.stamp.sec} * 1'000'000'000 + s->header.stamp.nanosec;
      for (std::uint32_t k = 0; k < s->name._length; ++k) r.names.emplace_back(s->name._buffer[k]);
      r.position.assign(s->position._buffer, s->position._buffer + s->position._length);
      r.velocity.assign(s->velocity._buffer, s->velocity._buffer + s->velocity._length);
      r.effort.assign(s->effort._buffer, s->effort._buffer + s->effort._length);
      reads_.push_back(std::move(r));
    }
    if (n > 0) dds_return_loan(reader_.get(), samples, n);
  }

  net::Entity topic_, reader_;
  std::mutex mutex_;
  std::vector<Read> reads_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace

/// One attempt (net_attempts.hpp): a serve's overrun makes it again on fresh serves.
static void ros2_once(int attempt, bool& again) {
  const std::uint32_t d = domain(attempt);
  auto serve = test::spawn_serve(kCell, d, "puma", "ros2_serve_puma", kDetection);
  auto quiet =
      test::spawn_serve(kCell, d, "microbo", "ros2_serve_microbo", kDetection, {"--no-ros2"});
  const net::Participant ros(test::loopback(d, kDetection));
  Ros2Subscriber puma_js(ros, "rt/puma/joint_states");
  Ros2Subscriber microbo_js(ros, "rt/microbo/joint_states");
  test::StateRecorder states(d, kDetection);
  const cell::CellModel model = cell::load_cell_file(kCell);
  net::RemoteCell cell(model, test::loopback(d, kDetection));  // waits for both robots' states
  // The start lines say what each serve publishes for ROS 2.
  ASSERT_TRUE(serve->wait_out("ROS 2 joint states on rt/puma/joint_states", 10s)) << serve->out();
  ASSERT_TRUE(quiet->wait_out("no ROS 2 joint states (--no-ros2)", 10s)) << quiet->out();

  // A joint move of the PUMA: 0.3 rad of its first joint, 0.1 of its third.
  net::RemoteArm& puma = cell.robot("puma");
  kin::JointVector q = puma.state().q_commanded;
  q[0] += 0.3;
  q[2] -= 0.1;
  const std::int64_t moved_from_ns = net::wall_ns();
  const rccl::Motion m = puma.move(rccl::Position::joints("J", q));
  const rccl::WaitResult ended = puma.waitfor(m.end(), 20s);
  if (ended != rccl::WaitResult::reached) RETRY_OR_SKIP_ON_OVERRUN(serve->err() + quiet->err());
  ASSERT_EQ(ended, rccl::WaitResult::reached) << serve->err() << quiet->err();
  std::this_thread::sleep_for(300ms);  // the arm settles; its last states arrive
  const std::int64_t moved_to_ns = net::wall_ns();

  const std::vector<Read> reads = puma_js.reads();
  const auto recorded = states.of("puma");
  ASSERT_GT(reads.size(), 20U) << "few JointState samples from the serve";
  ASSERT_GT(recorded.size(), 20U);
  const std::vector<std::string> names =
      net::ros2_joint_names("puma", model.find_robot("puma")->model);
  ASSERT_EQ(names.size(), 6U);
  EXPECT_EQ(names[0], "puma_theta1");

  // Each JointState against the RobotState of the same stamp (its written_ns), where the
  // recorder has it (best effort may drop one): the measured joints and commanded speeds.
  std::size_t matched = 0;
  double worst_q = 0.0, worst_qd = 0.0;
  double lo = 1e9, hi = -1e9;  // joint 1 while it moved (rad)
  for (const Read& r : reads) {
    ASSERT_EQ(r.names, names);
    ASSERT_EQ(r.position.size(), names.size());
    ASSERT_EQ(r.velocity.size(), names.size());
    EXPECT_TRUE(r.effort.empty()) << "efforts are not known: ROS's empty array";
    if (r.stamp_ns >= moved_from_ns && r.stamp_ns <= moved_to_ns) {
      lo = std::min(lo, r.position[0]);
      hi = std::max(hi, r.position[0]);
    }
    const auto it = std::find_if(recorded.begin(), recorded.end(),
                                 [&](const auto& s) { return s.state.written_ns == r.stamp_ns; });
    if (it == recorded.end()) continue;
    ++matched;
    for (std::size_t j = 0; j < names.size(); ++j) {
      worst_q = std::max(worst_q, std::abs(r.position[j] - it->state.q_measured[j]));
      worst_qd = std::max(worst_qd, std::abs(r.velocity[j] - it->state.qd_commanded[j]));
    }
  }
  std::printf(
      "ROS 2 joint states: %zu read, %zu matched to a RobotState by stamp; worst |position - "
      "q_measured| = %.3g rad, |velocity - qd_commanded| = %.3g rad/s; joint 1 moved %.3f rad\n",
      reads.size(), matched, worst_q, worst_qd, hi - lo);
  EXPECT_GT(matched, reads.size() / 2) << "most JointStates should have their RobotState";
  EXPECT_LE(worst_q, 1e-12);
  EXPECT_LE(worst_qd, 1e-12);
  // The values follow the motion: joint 1 travelled (nearly) its 0.3 rad in the samples read.
  EXPECT_GT(hi - lo, 0.25) << "the JointState positions did not follow the motion";
  EXPECT_NEAR(reads.back().position[0], q[0], 1e-3) << "the last JointState is not at the goal";
  // Speeds were published while it moved, and are 0 at rest.
  const bool some_speed = std::any_of(reads.begin(), reads.end(),
                                      [](const Read& r) { return std::abs(r.velocity[0]) > 0.01; });
  EXPECT_TRUE(some_speed);
  EXPECT_NEAR(reads.back().velocity[0], 0.0, 1e-12);

  // --no-ros2: the Microbo's states cross, but nothing is written on its JointState topic.
  EXPECT_FALSE(states.of("microbo").empty());
  EXPECT_FALSE(microbo_js.matched()) << "a --no-ros2 serve has a JointState writer";
  EXPECT_TRUE(microbo_js.reads().empty());
}

TEST(NetServeRos2, AServedRobotsJointStateIsReadByARos2SubscriberAsItsRobotStateSaysIt) {
  test::run_with_attempts(ros2_once);
}
