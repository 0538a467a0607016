#include "rccx/net/states.hpp"

#include <algorithm>
#include <cassert>

#include "rccx/net/dds.hpp"

namespace rccx::net {

StateBatch::StateBatch(std::string_view participant, std::uint64_t instance, std::size_t capacity)
    : states_(capacity), parts_((capacity + kStatesPerSample - 1) / kStatesPerSample) {
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    rccx_net_ServeStates& p = parts_[k];
    p = rccx_net_ServeStates{};
    copy_to(p.participant, participant);
    p.part = static_cast<std::uint16_t>(k);
    p.instance = instance;
    // The sequence points into states_ (never freed through it: _release false).
    p.robots._buffer = states_.data() + k * kStatesPerSample;
    p.robots._maximum =
        static_cast<std::uint32_t>(std::min(kStatesPerSample, capacity - k * kStatesPerSample));
    p.robots._release = false;
  }
}

rccx_net_RobotState& StateBatch::add() noexcept {
  assert(size_ < states_.size() && "StateBatch::add: more robots than the batch was made for");
  rccx_net_RobotState& s = states_[std::min(size_, states_.size() - 1)];
  size_ = std::min(size_ + 1, states_.size());
  s = rccx_net_RobotState{};
  return s;
}

dds_return_t StateBatch::write(dds_entity_t writer) noexcept {
  dds_return_t first_error = 0;
  for (std::size_t k = 0; k * kStatesPerSample < size_; ++k) {
    rccx_net_ServeStates& p = parts_[k];
    p.robots._length =
        static_cast<std::uint32_t>(std::min(kStatesPerSample, size_ - k * kStatesPerSample));
    ++p.pass;
    const dds_return_t rc = dds_write(writer, &p);
    if (rc < 0 && first_error == 0) first_error = rc;
  }
  size_ = 0;
  return first_error;
}

StateInbox::StateInbox(std::size_t samples)
    : samples_(std::max<std::size_t>(samples, 1)), ptrs_(samples_.size()), info_(samples_.size()) {
  for (std::size_t i = 0; i < samples_.size(); ++i) {
    samples_[i] = rccx_net_ServeStates{};
    // Cyclone's own allocation, released by it (_release): a peer that sends more than the
    // bound is deserialized into a larger buffer Cyclone reallocates, never past this one.
    dds_sequence_rccx_net_RobotState& robots = samples_[i].robots;
    robots._buffer = static_cast<rccx_net_RobotState*>(
        dds_alloc(kStatesPerSample * sizeof(rccx_net_RobotState)));
    robots._maximum = static_cast<std::uint32_t>(kStatesPerSample);
    robots._release = true;
    ptrs_[i] = &samples_[i];
  }
}

StateInbox::~StateInbox() {
  for (rccx_net_ServeStates& s : samples_) dds_free(s.robots._buffer);
}

int StateInbox::take(dds_entity_t reader) noexcept {
  const dds_return_t n = dds_take(reader, ptrs_.data(), info_.data(), samples_.size(),
                                  static_cast<std::uint32_t>(samples_.size()));
  return n < 0 ? 0 : static_cast<int>(n);
}

}  // namespace rccx::net
