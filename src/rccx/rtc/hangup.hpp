// Ctrl-C (or SIGTERM) during a control session (thesis 4.5.2, `user_hangup`). The handler of
// rccx::io::signals only counts and posts a semaphore; the communication task sees the count
// change at its next tick and ends the session with `user_interrupt`, unless the session has a
// hang-up handler of the user's, which a watcher thread then runs (never the sample loop).
//
//   session.set_hangup_handler([](rtc::Session& s) { s.terminate(); });  // before control()
//   session.control(f1, f2);            // calls detail::register_for_hangup(this)
#pragma once

#include <cstdint>

namespace rccx::rtc {
class Session;
}

namespace rccx::rtc::detail {

/// How many SIGINT / SIGTERM have arrived while a handler was installed.
std::uint32_t hangup_count() noexcept;
/// A session starting control: installs the handler on first use.
void register_for_hangup(Session* s);
/// A session releasing control: the previous SIGINT disposition is restored after the last.
void unregister_for_hangup(Session* s);

}  // namespace rccx::rtc::detail
