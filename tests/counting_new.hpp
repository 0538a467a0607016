// A counting operator new for the tests that prove code allocates nothing (the sample loop's
// rule, ARCHITECTURE.md): link counting_new.cpp into the test executable, read a counter
// before and after the code, and expect no difference. Replaces the global operator new and
// delete of the whole executable (malloc and free underneath).
#pragma once

namespace rccx::test_support {

/// Calls of operator new (any form) in every thread since the program started.
[[nodiscard]] long allocations() noexcept;
/// ... in the calling thread only (other threads' work, a session's, does not count).
[[nodiscard]] long thread_allocations() noexcept;

}  // namespace rccx::test_support
