// Lines from a file descriptor (a terminal, a pipe) that give up when a stop signal arrives:
// std::getline on std::cin would sit in read(2) through Ctrl-C when the signal lands on another
// of the process's threads (a session's), and end the input with an error when it lands here.
// StopAwareInput is a std::streambuf, so a console keeps reading with std::istream.
//
//   io::StopAwareInput buffer(STDIN_FILENO);
//   std::istream in(&buffer);
//   std::string line, problem;
//   while (io::read_line(in, line, problem)) ...   // ends at end of input or on SIGINT / SIGTERM
//   if (buffer.stopped()) ...                      // and says which
#pragma once

#include <array>
#include <cstdint>
#include <istream>
#include <streambuf>
#include <string>

namespace rccx::io {

class StopAwareInput : public std::streambuf {
 public:
  /// Reads `fd`; stops at the first stop signal after construction.
  explicit StopAwareInput(int fd) noexcept;
  /// Reads `fd`; stops once more than `stops_before` stop signals have arrived. A program that
  /// installed the handlers at its start gives 0: a signal during its start-up counts.
  StopAwareInput(int fd, std::uint32_t stops_before) noexcept;
  /// True when reading ended because of SIGINT / SIGTERM.
  [[nodiscard]] bool stopped() const noexcept { return stopped_; }
  /// True when reading ended because of a read error (not end of input).
  [[nodiscard]] int error() const noexcept { return error_; }

 protected:
  int_type underflow() override;

 private:
  int fd_;
  std::uint32_t stops_at_start_;
  bool stopped_ = false;
  int error_ = 0;
  std::array<char, 4096> buffer_{};
};

/// The longest console line: a command is a few words.
inline constexpr std::size_t kMaxLineBytes = 4096;

/// std::getline with a bound, for consoles: false at the end of input. A line longer than
/// `max_bytes` is refused whole (`problem` says so, `line` is empty) and the rest of it
/// skipped; input that runs on for a MiB without a line end (/dev/zero, a binary file) is not
/// commands: `problem` says so and the next call returns false. Memory stays bounded either way.
bool read_line(std::istream& in, std::string& line, std::string& problem,
               std::size_t max_bytes = kMaxLineBytes);

}  // namespace rccx::io
