// The RTC level's session, for tests that compare the C side (how, terminate) with what the
// session measured. Not installed; not for programs.
#pragma once

namespace rccx::rtc {
class Session;
}

namespace rccx::compat {

/// The session rtc_open() or control() opened, or null.
rtc::Session* rtc_session() noexcept;

}  // namespace rccx::compat
