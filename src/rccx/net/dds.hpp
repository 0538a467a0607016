// A thin C++ face on Cyclone DDS's C API: entities deleted by their owner, errors as NetError
// with Cyclone's own text, each topic's QoS from one function (topics.hpp lists them). Only
// middleware threads call into here; the sample loop never does (docs/NETWORK.md).
#pragma once

#include <dds/dds.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

#include "rccx/net/topics.hpp"
#include "rccx_net.h"

namespace rccx::net {

/// Throws NetError "<what>: <Cyclone's reason>" when `rc` < 0; returns it otherwise.
dds_return_t check(dds_return_t rc, std::string_view what);

/// One DDS entity, deleted (with its children) when this goes.
class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t e) noexcept : e_(e) {}
  ~Entity() { reset(); }
  Entity(Entity&& o) noexcept : e_(o.e_) { o.e_ = 0; }
  Entity& operator=(Entity&& o) noexcept {
    if (this != &o) {
      reset();
      e_ = o.e_;
      o.e_ = 0;
    }
    return *this;
  }
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;
  void reset() noexcept;
  [[nodiscard]] dds_entity_t get() const noexcept { return e_; }
  explicit operator bool() const noexcept { return e_ > 0; }

 private:
  dds_entity_t e_ = 0;
};

/// A QoS, freed when this goes.
class Qos {
 public:
  Qos() : q_(dds_create_qos()) {}
  ~Qos() { dds_delete_qos(q_); }
  Qos(const Qos&) = delete;
  Qos& operator=(const Qos&) = delete;
  [[nodiscard]] dds_qos_t* get() const noexcept { return q_; }

 private:
  dds_qos_t* q_;
};

/// Which topic a reader or writer is for: its QoS follows (topics.hpp's table).
enum class Topic : std::uint8_t { heartbeat, claim, state, request, ack, event, frame };
[[nodiscard]] const char* topic_name(Topic t) noexcept;
[[nodiscard]] const dds_topic_descriptor_t* topic_descriptor(Topic t) noexcept;
enum class Side : std::uint8_t { reader, writer };
/// The QoS of a reader or writer of `t` (the matched QoS the same on both sides, so they always
/// match; acks' and events' writers keep last N, their readers all: topics.hpp).
/// `state_deadline`: RobotState's deadline; `detection`: the liveliness lease of heartbeats.
void set_topic_qos(Qos& qos, Topic t, Side side, std::chrono::nanoseconds detection,
                   std::chrono::nanoseconds state_deadline);

/// One DDS domain participant with rccx's topics made on it, on the domain and interface of
/// `options`, secured when options.secure_dir is set. Throws NetError.
class Participant {
 public:
  explicit Participant(const NetOptions& options);
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  [[nodiscard]] dds_entity_t get() const noexcept { return participant_.get(); }
  [[nodiscard]] dds_entity_t topic(Topic t) const noexcept {
    return topics_[static_cast<std::size_t>(t)].get();
  }
  [[nodiscard]] const NetOptions& options() const noexcept { return options_; }
  [[nodiscard]] std::uint32_t domain() const noexcept { return domain_; }
  /// A reader / writer of `t` with its QoS. `state_deadline` (RobotState only): the deadline.
  [[nodiscard]] Entity reader(Topic t, std::chrono::nanoseconds state_deadline = {}) const;
  [[nodiscard]] Entity writer(Topic t, std::chrono::nanoseconds state_deadline = {}) const;

 private:
  NetOptions options_;
  std::uint32_t domain_ = 0;
  Entity domain_entity_;  ///< dds_create_domain's, when a configuration was given
  Entity participant_;
  Entity topics_[7];
};

/// CLOCK_REALTIME in ns (what stamps and claims compare across processes of one host).
[[nodiscard]] std::int64_t wall_ns() noexcept;
/// "<host>/<pid>".
[[nodiscard]] std::string host_and_pid();

/// Copy `s` into a bounded IDL string (char[N]), cut to N - 1 characters.
template <std::size_t N>
void copy_to(char (&to)[N], std::string_view s) noexcept {
  const std::size_t n = s.size() < N - 1 ? s.size() : N - 1;
  for (std::size_t i = 0; i < n; ++i) to[i] = s[i];
  to[n] = '\0';
}

}  // namespace rccx::net
