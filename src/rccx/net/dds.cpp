#include "rccx/net/dds.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdlib>
#include <ctime>

#include "rccx/io/parse.hpp"
#include "rccx/net/security.hpp"

namespace rccx::net {

dds_return_t check(dds_return_t rc, std::string_view what) {
  if (rc < 0) throw NetError(fmt::format("{}: {}", what, dds_strretcode(rc)));
  return rc;
}

void Entity::reset() noexcept {
  if (e_ > 0) dds_delete(e_);
  e_ = 0;
}

std::uint32_t domain_of(const NetOptions& options) {
  if (options.domain) {
    if (*options.domain > 232) {
      throw NetError(fmt::format("DDS domain {} is out of range: give 0 .. 232", *options.domain));
    }
    return *options.domain;
  }
  const char* env = std::getenv("RCCX_DOMAIN");
  if (env == nullptr || *env == '\0') return 0;
  try {
    return static_cast<std::uint32_t>(io::parse_integer(env, "RCCX_DOMAIN", 0, 232));
  } catch (const std::exception& e) {
    throw NetError(fmt::format("{} (a DDS domain, 0 .. 232; unset it for domain 0)", e.what()));
  }
}

namespace {

constexpr std::array kTopics{
    std::pair{kHeartbeatTopic, &rccx_net_Heartbeat_desc},
    std::pair{kClaimTopic, &rccx_net_Claim_desc},
    std::pair{kStateTopic, &rccx_net_ServeStates_desc},
    std::pair{kRequestTopic, &rccx_net_MotionRequest_desc},
    std::pair{kAckTopic, &rccx_net_MotionAck_desc},
    std::pair{kEventTopic, &rccx_net_MotionEvent_desc},
    std::pair{kFrameTopic, &rccx_net_FrameSample_desc},
};

dds_duration_t to_dds(std::chrono::nanoseconds d) {
  return static_cast<dds_duration_t>(d.count());
}

/// Cyclone's configuration for `interface` ("lo": unicast discovery to 127.0.0.1, since
/// loopback has no multicast), or "" for Cyclone's defaults ($CYCLONEDDS_URI still applies).
std::string domain_config(const std::string& interface) {
  if (interface.empty()) return {};
  std::string peers;
  // No multicast asked for on loopback: Cyclone would find it has none and say so on stderr in
  // every process.
  std::string multicast;
  if (interface == "lo" || interface == "127.0.0.1") {
    multicast = "<AllowMulticast>false</AllowMulticast>";
    peers =
        "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
        "<MaxAutoParticipantIndex>40</MaxAutoParticipantIndex>"
        "<Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery>";
  }
  return fmt::format(
      "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"{}\" "
      "multicast=\"default\"/></Interfaces>{}</General>{}</Domain></CycloneDDS>",
      interface, multicast, peers);
}

}  // namespace

const char* topic_name(Topic t) noexcept {
  return kTopics[static_cast<std::size_t>(t)].first;
}
const dds_topic_descriptor_t* topic_descriptor(Topic t) noexcept {
  return kTopics[static_cast<std::size_t>(t)].second;
}

void set_topic_qos(Qos& qos, Topic t, Side side, std::chrono::nanoseconds detection,
                   std::chrono::nanoseconds state_deadline) {
  dds_qos_t* q = qos.get();
  switch (t) {
    case Topic::heartbeat:
      dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
      dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
      dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, to_dds(detection));
      break;
    case Topic::claim:
      dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
      dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
      dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
      break;
    case Topic::state:
      dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
      dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
      if (state_deadline.count() > 0) dds_qset_deadline(q, to_dds(state_deadline));
      break;
    case Topic::request:
      dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
      dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
      dds_qset_destination_order(q, DDS_DESTINATIONORDER_BY_RECEPTION_TIMESTAMP);
      break;
    case Topic::ack:
    case Topic::event:
      // A serve writes these for every program on the topic. Keep all would let one program
      // that acknowledges nothing (stopped in a debugger: matched until its lease ends) fill the
      // writer's history and block every answer, to everyone: keep last N per instance bounds
      // what it can hold back, and a write never waits (max_blocking_time 0; the serve keeps
      // what it could not write yet, in order: RobotServer::Backlog). Readers keep all they
      // get (history is not a matched QoS): a program takes them on its next pass.
      dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, 0);
      if (side == Side::writer) {
        dds_qset_history(q, DDS_HISTORY_KEEP_LAST, t == Topic::ack ? kAckDepth : kEventDepth);
      } else {
        dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
      }
      dds_qset_destination_order(q, DDS_DESTINATIONORDER_BY_RECEPTION_TIMESTAMP);
      break;
    case Topic::frame:
      dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
      dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
      break;
  }
}

Participant::Participant(const NetOptions& options)
    : options_(options), domain_(domain_of(options)) {
  std::string interface = options.interface;
  if (interface.empty()) {
    if (const char* env = std::getenv("RCCX_DDS_INTERFACE")) interface = env;
  }
  const std::string config = domain_config(interface);
  if (!config.empty()) {
    const dds_entity_t d = dds_create_domain(domain_, config.c_str());
    // Another participant of this process made the domain already: it is shared.
    if (d < 0 && d != DDS_RETCODE_PRECONDITION_NOT_MET) {
      check(d, fmt::format("DDS domain {} on interface '{}'", domain_, interface));
    }
    if (d > 0) domain_entity_ = Entity(d);
  }
  Qos qos;
  if (!options.secure_dir.empty()) add_security_properties(qos.get(), options);
  const dds_entity_t p = dds_create_participant(domain_, qos.get(), nullptr);
  check(p, fmt::format(
               "a DDS participant on domain {}{}", domain_,
               options.secure_dir.empty() ? "" : " (secure: check the files of rccx certs init)"));
  participant_ = Entity(p);
  for (std::size_t i = 0; i < kTopics.size(); ++i) {
    const dds_entity_t topic =
        dds_create_topic(p, kTopics[i].second, kTopics[i].first, nullptr, nullptr);
    check(topic, fmt::format("DDS topic {}", kTopics[i].first));
    topics_[i] = Entity(topic);
  }
}

Entity Participant::reader(Topic t, std::chrono::nanoseconds state_deadline) const {
  Qos qos;
  set_topic_qos(qos, t, Side::reader, options_.detection, state_deadline);
  const dds_entity_t r = dds_create_reader(get(), topic(t), qos.get(), nullptr);
  check(r, fmt::format("a reader of {}", topic_name(t)));
  return Entity(r);
}

Entity Participant::writer(Topic t, std::chrono::nanoseconds state_deadline) const {
  Qos qos;
  set_topic_qos(qos, t, Side::writer, options_.detection, state_deadline);
  const dds_entity_t w = dds_create_writer(get(), topic(t), qos.get(), nullptr);
  check(w, fmt::format("a writer of {}", topic_name(t)));
  return Entity(w);
}

std::int64_t wall_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::string host_and_pid() {
  std::array<char, 256> host{};
  if (gethostname(host.data(), host.size() - 1) != 0) host = {'?'};
  return fmt::format("{}/{}", host.data(), static_cast<long>(getpid()));
}

}  // namespace rccx::net
