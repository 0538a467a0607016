// The rccx_state topic's samples (ServeStates, rccx_net.idl): a serve process's robots' states,
// one sample a pass for all of them, not one each. StateBatch fills and writes them (the serve);
// StateInbox takes them and hands over each robot's state (programs, other serves, tools).
// Only middleware threads use these (docs/NETWORK.md).
#pragma once

#include <dds/dds.h>

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "rccx_net.h"

namespace rccx::net {

/// The most robot states one ServeStates sample carries (its sequence's bound in rccx_net.idl).
inline constexpr std::size_t kStatesPerSample = 256;

/// A serve's robots' states for one pass, written as one ServeStates sample (one per 256 robots,
/// parts 0, 1, ...). Made once for up to `capacity` robots: add() and write() allocate nothing.
class StateBatch {
 public:
  StateBatch(std::string_view participant, std::uint64_t instance, std::size_t capacity);
  StateBatch(const StateBatch&) = delete;
  StateBatch& operator=(const StateBatch&) = delete;

  /// The next robot's state to fill in, zeroed; at most capacity() a pass.
  rccx_net_RobotState& add() noexcept;
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  /// The i-th state added this pass (i < size()).
  [[nodiscard]] const rccx_net_RobotState& operator[](std::size_t i) const noexcept {
    return states_[i];
  }
  [[nodiscard]] std::size_t capacity() const noexcept { return states_.size(); }
  /// Writes the states added since the last write (nothing when none), then starts a new pass.
  /// Returns the first failed dds_write's code, else 0.
  dds_return_t write(dds_entity_t writer) noexcept;

 private:
  std::vector<rccx_net_RobotState> states_;
  std::vector<rccx_net_ServeStates> parts_;
  std::size_t size_ = 0;
};

/// Takes ServeStates samples off a reader into room made once (a take allocates nothing unless a
/// peer sends more than kStatesPerSample states in one sample) and hands over each robot's state.
class StateInbox {
 public:
  /// Room for `samples` ServeStates a take (each with room for kStatesPerSample states).
  explicit StateInbox(std::size_t samples = 2);
  ~StateInbox();
  StateInbox(const StateInbox&) = delete;
  StateInbox& operator=(const StateInbox&) = delete;

  /// Takes every sample `reader` holds and calls on_state(const rccx_net_RobotState&) for each
  /// robot state in them, in the order they were written. Returns how many robot states.
  template <class OnState>
  std::size_t drain(dds_entity_t reader, OnState&& on_state) {
    std::size_t count = 0;
    for (;;) {
      const int n = take(reader);
      for (int i = 0; i < n; ++i) {
        if (!info_[static_cast<std::size_t>(i)].valid_data) continue;
        const dds_sequence_rccx_net_RobotState& robots =
            samples_[static_cast<std::size_t>(i)].robots;
        for (std::uint32_t k = 0; k < robots._length; ++k) on_state(robots._buffer[k]);
        count += robots._length;
      }
      if (n < static_cast<int>(samples_.size())) return count;
    }
  }

 private:
  /// Takes up to samples_.size() samples: how many (0 on an error).
  int take(dds_entity_t reader) noexcept;

  std::vector<rccx_net_ServeStates> samples_;
  std::vector<void*> ptrs_;
  std::vector<dds_sample_info_t> info_;
};

}  // namespace rccx::net
