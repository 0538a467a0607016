#include "rccx/net/middleware.hpp"

#include <pthread.h>
#include <sched.h>

#include <random>

namespace rccx::net::detail {

std::uint64_t random_instance() {
  std::random_device rd;
  const std::uint64_t v = (static_cast<std::uint64_t>(rd()) << 32) ^ rd();
  return v == 0 ? 1 : v;
}

void raise_priority() noexcept {
  sched_param p{};
  p.sched_priority = sched_get_priority_min(SCHED_FIFO);
  (void)pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
}

}  // namespace rccx::net::detail
