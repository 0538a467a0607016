#include "rccx/io/input.hpp"

#include <poll.h>
#include <unistd.h>

#include <cerrno>

#include "rccx/io/signals.hpp"

namespace rccx::io {

StopAwareInput::StopAwareInput(int fd) noexcept : fd_(fd), stops_at_start_(stop_count()) {}

StopAwareInput::int_type StopAwareInput::underflow() {
  if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
  for (;;) {
    if (stop_count() != stops_at_start_) {
      stopped_ = true;
      return traits_type::eof();
    }
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, 50);  // looks at the stop count 20 times a second
    if (ready < 0 && errno != EINTR) {
      error_ = errno;
      return traits_type::eof();
    }
    if (ready <= 0) continue;
    const ssize_t n = ::read(fd_, buffer_.data(), buffer_.size());
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      error_ = errno;
      return traits_type::eof();
    }
    if (n == 0) return traits_type::eof();
    setg(buffer_.data(), buffer_.data(), buffer_.data() + n);
    return traits_type::to_int_type(*gptr());
  }
}

}  // namespace rccx::io
