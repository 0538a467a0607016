#include "rccx/io/input.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>

#include "rccx/io/signals.hpp"

namespace rccx::io {

StopAwareInput::StopAwareInput(int fd) noexcept : fd_(fd), stops_at_start_(stop_count()) {}

StopAwareInput::StopAwareInput(int fd, std::uint32_t stops_before) noexcept
    : fd_(fd), stops_at_start_(stops_before) {}

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

bool read_line(std::istream& in, std::string& line, std::string& problem, std::size_t max_bytes) {
  constexpr std::size_t kGiveUpBytes = std::size_t{1} << 20;
  line.clear();
  problem.clear();
  if (!in.good()) return false;
  std::streambuf* const buffer = in.rdbuf();
  std::size_t length = 0;
  for (;;) {
    const auto c = buffer->sbumpc();
    if (std::streambuf::traits_type::eq_int_type(c, std::streambuf::traits_type::eof())) {
      in.setstate(length == 0 ? std::ios::eofbit | std::ios::failbit : std::ios::eofbit);
      if (length == 0) return false;
      break;
    }
    if (c == '\n') break;
    if (++length <= max_bytes) {
      line.push_back(static_cast<char>(c));
    } else if (length > kGiveUpBytes) {
      line.clear();
      problem = fmt::format(
          "standard input: more than {} MiB without a line end; it is not lines of commands "
          "(reading stopped)",
          kGiveUpBytes >> 20);
      in.setstate(std::ios::eofbit);
      return true;
    }
  }
  if (length > max_bytes) {
    line.clear();
    problem = fmt::format("a line of {} bytes was refused whole; a command line is at most {}",
                          length, max_bytes);
  }
  return true;
}

}  // namespace rccx::io
