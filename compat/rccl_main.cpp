// The main() of an RCCL program written as the user's manual teaches: the program defines
// pumatask() and no main(). In an archive of its own (rccx_compat_main), so that the linker
// takes it only for such programs.
#include "rccl.h"
#include "rtc.h"

extern "C" int pumatask();

namespace rccx::compat {
// rccl_session.cpp: the session main() opened is the task's; is a session still open?
void mark_session_for_task() noexcept;
bool session_open() noexcept;
}  // namespace rccx::compat

int main() {
  using namespace rccx::compat;
  if (rccl_open(nullptr, 0.0) != RTC_OK || rccl_control() != RTC_OK) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  mark_session_for_task();
  pumatask();
  if (!session_open()) return 0;  // the task closed its session itself
  waitfor(completed);
  if (rccl_close(0) != RTC_OK) {
    print_rtc_error(rtc_error, 0);
    return 1;
  }
  return 0;
}
