// What the RTC level (rtc_compat.cpp: control, rtc_open, ...) and the RCCL level
// (rccl_session.cpp, rccl_cell.cpp: rccl_open, rccl_cell_open) of rccx's C layer must know of
// each other: one of them may have a session open at a time. Not installed.
#pragma once

namespace rccx::compat {

/// True while an RCCL session (rccl_open) or a cell (rccl_cell_open) is open.
bool rccl_session_open() noexcept;
/// True while an RTC session (rtc_open, control) is open.
bool rtc_session_open() noexcept;

}  // namespace rccx::compat
