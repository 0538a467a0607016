// SIGINT, SIGTERM and SIGHUP (unless ignored, as under nohup) as requests to stop, for the
// whole process. The handler only counts, keeps the signal's number and posts a semaphore (all
// async-signal-safe). It is installed without SA_RESTART, so that a call blocked on a full pipe
// or a terminal returns (EINTR) instead of holding the program: rccx's own waits retry EINTR or
// end cleanly. Whoever waits (a session's wait functions, a console reading its input, a long
// import) looks at stop_count() and ends cleanly within its own period.
//
//   io::install_stop_handlers();                     // at the start of main()
//   while (io::stop_count() == 0 && more) more = step();
//   io::restore_stop_handlers();
//   if (io::stop_count() > 0) return io::stop_exit_code();   // 130 for SIGINT, 143 SIGTERM
//
// Programs (the rccx commands) install the handlers for their whole run; a library user's
// program gets them from rtc::Session only while it is in control (thesis 4.5.2, user_hangup).
#pragma once

#include <cstdint>

namespace rccx::io {

/// Installs the counting handler for SIGINT, SIGTERM and SIGHUP; the dispositions it replaced are
/// returned by restore_stop_handlers(). Safe to call again (nesting is counted).
void install_stop_handlers() noexcept;
/// Undoes one install_stop_handlers(); the last one restores the earlier dispositions.
void restore_stop_handlers() noexcept;

/// The stop handlers installed for a scope (a console's whole run: Ctrl-C while no control
/// runs must end it cleanly too, not kill it).
struct ScopedStopHandlers {
  ScopedStopHandlers() noexcept { install_stop_handlers(); }
  ~ScopedStopHandlers() { restore_stop_handlers(); }
  ScopedStopHandlers(const ScopedStopHandlers&) = delete;
  ScopedStopHandlers& operator=(const ScopedStopHandlers&) = delete;
};

/// How many SIGINT / SIGTERM have arrived while the handler was installed.
std::uint32_t stop_count() noexcept;
/// The number of the last such signal (SIGINT or SIGTERM), 0 before the first.
int last_stop_signal() noexcept;
/// The exit status a shell gives a program ended by that signal: 128 + its number (130, 143,
/// 129 for SIGHUP).
int stop_exit_code() noexcept;

/// Blocks until a stop signal arrives or wake_stop_waiter() is called (for one watcher thread).
void wait_stop_signal() noexcept;
void wake_stop_waiter() noexcept;

}  // namespace rccx::io
