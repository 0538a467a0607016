#include "rccx/io/console.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "rccx/io/file.hpp"

namespace rccx::io {

void error_text(std::string_view text) noexcept {
  (void)write_all(STDERR_FILENO, text.data(), text.size());
}

bool flush_stdout(std::string& why) noexcept {
  errno = 0;
  const bool ok = std::fflush(stdout) == 0 && std::ferror(stdout) == 0;
  if (!ok) {
    try {
      why = errno != 0 ? std::strerror(errno) : "a write failed";
    } catch (...) {
    }
  }
  return ok;
}

}  // namespace rccx::io
