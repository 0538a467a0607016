// Real-time tests on a shared, loaded machine. A control cycle that overruns its period is a
// verdict on rccx only when the process may run its tasks under SCHED_FIFO (as rtc::Session asks
// for them): without it, the kernel's scheduler gives the processors to the other work and the
// overrun is its doing. Such a test is then skipped, saying why, never passed in silence.
//
//   if (code == TerminateCode::overrun) RCCX_SKIP_UNLESS_FIFO("control overran its period");
#pragma once

#include <pthread.h>
#include <sched.h>

#include <thread>

namespace rccx::test {

/// Whether a thread of this process may take SCHED_FIFO (root, CAP_SYS_NICE or an rtprio
/// limit). Asked on a throwaway thread: the caller's scheduling is left alone.
inline bool may_use_fifo() {
  bool permitted = false;
  std::thread probe([&permitted] {
    sched_param p{};
    p.sched_priority = sched_get_priority_min(SCHED_FIFO);
    permitted = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
  });
  probe.join();
  return permitted;
}

}  // namespace rccx::test

/// In a test body: skips the test, saying `what` happened and why it proves nothing, when this
/// process may not use SCHED_FIFO; does nothing (the test goes on to judge) when it may.
#define RCCX_SKIP_UNLESS_FIFO(what)                                                            \
  if (rccx::test::may_use_fifo()) {                                                            \
  } else                                                                                       \
    GTEST_SKIP() << what                                                                       \
                 << ", and this process may not use SCHED_FIFO (not root, no CAP_SYS_NICE or " \
                    "rtprio limit): on a loaded machine that is the scheduler's doing, not "   \
                    "rccx's. Run the tests as root for a real-time verdict."
