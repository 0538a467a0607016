// Real-time scenarios across processes, run again when a serve overran: shared by the serve
// tests (loopback) and the hosts tests (network namespaces).
//
// A serve's control cycle that overran its period ends that robot's control (RTC's watchdog),
// and this shared machine does not always hold a period: other tests' SCHED_FIFO tasks at the
// serves' own priorities (80 / 79) run beside them, and the virtual machine itself has woken a
// SCHED_FIFO task 25 ms late (`rccx cell-load --realtime`, release build, beside a build). An
// overrun is printed and the scenario run again, on fresh serves; when the last attempt overran too
// the test is skipped, saying so (the machine could not give the serves their real time: nothing of
// the link was judged). Any other failure fails the test.
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace rccx::test {

constexpr int kAttempts = 3;

/// True (and says so) when `output` shows a serve's control ended by an overrun: RTC's two
/// details of TerminateCode::overrun (the clock's watchdog, and the robot's f1 late).
inline bool overran(const std::string& output, int attempt) {
  if (output.find("was still running at the next tick") == std::string::npos &&
      output.find("did not hand Chg over within its period") == std::string::npos) {
    return false;
  }
  std::printf(
      "[ overrun  ] attempt %d of %d: a serve's control cycle overran its period (this "
      "machine did not hold it; the serve's clock figures say whether it woke late):\n%s\n",
      attempt, kAttempts, output.c_str());
  return true;
}

/// A scenario (it sets `again` to be run again on fresh serves) up to kAttempts times.
inline void run_with_attempts(void (*once)(int attempt, bool& again)) {
  for (int attempt = 1; attempt <= kAttempts; ++attempt) {
    bool again = false;
    once(attempt, again);
    if (!again) break;
  }
}

}  // namespace rccx::test

/// In a scenario (a void function with `attempt` and `again`): after an overrun in `text`, run
/// again, or skip the test after the last attempt.
#define RETRY_OR_SKIP_ON_OVERRUN(text)                                                            \
  do {                                                                                            \
    if (::rccx::test::overran((text), attempt)) {                                                 \
      if (attempt < ::rccx::test::kAttempts) {                                                    \
        again = true;                                                                             \
        return;                                                                                   \
      }                                                                                           \
      GTEST_SKIP() << "each of the " << ::rccx::test::kAttempts                                   \
                   << " attempts was ended by a serve's overrun (above): this machine is too "    \
                      "loaded to give the serves their real time; nothing of the link is judged"; \
    }                                                                                             \
  } while (false)
