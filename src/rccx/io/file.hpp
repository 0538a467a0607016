// Files that are replaced whole or not at all, and writes that never lose an error.
//
//   io::write_file_atomically("positions.json", text);   // the old file or the new, whole
//   io::AtomicFile out("run.svg");                        // content written in pieces:
//   out.write(head);
//   out.write(body);                                      // throws FileError on ENOSPC, EIO ...
//   out.commit();                                         // without it the target stays as it was
//   const std::string back = io::read_file("positions.json");   // at most 64 MiB
//
// write_file_atomically() and AtomicFile write to a temporary file in the target's directory,
// flush and fsync it, rename it over the target and fsync the directory: a reader, a crash or a
// full disk sees the old file or the new one, never a part. A write that fails (ENOSPC, EIO, a
// read-only directory) throws FileError, removes the temporary file and leaves the target as it
// was.
#pragma once

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace rccx::io {

/// A file that could not be read or written; the message names it and the system's reason.
class FileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Writes all of `data` to `fd`, retrying partial writes and EINTR. Returns 0, or the errno
/// of the failure. Never throws; async-signal-safe.
int write_all(int fd, const char* data, std::size_t size) noexcept;

class AtomicFile {
 public:
  /// Creates the temporary file beside `target` (throws FileError when it cannot). A symbolic
  /// link is followed: the file it names is replaced and the link stays. A target that exists
  /// and is not a regular file (a device such as /dev/null, a named pipe), and a path under /dev
  /// or /proc (/dev/stdout), are written in place: replacing them would put a regular file
  /// where the device was, or beside the file the shell opened.
  explicit AtomicFile(std::filesystem::path target);
  /// Removes the temporary file unless committed: the target is untouched.
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Appends; throws FileError on a failed write.
  void write(std::string_view data);
  /// fsync, rename over the target, fsync the directory; throws FileError.
  void commit();
  [[nodiscard]] const std::filesystem::path& target() const noexcept { return target_; }

 private:
  void fail(const char* doing, int error);

  std::filesystem::path target_;       ///< as given, for messages
  std::filesystem::path destination_;  ///< the target with its symbolic links followed
  std::filesystem::path temporary_;
  int fd_ = -1;
  bool committed_ = false;
  bool in_place_ = false;  ///< a device or a named pipe: written directly
};

/// The whole of `data` as the new content of `target`, atomically (see above).
void write_file_atomically(const std::filesystem::path& target, std::string_view data);

/// The whole content of a regular file; FileError for a directory, a missing or unreadable file,
/// or one larger than `max_bytes`.
std::string read_file(const std::filesystem::path& file, std::size_t max_bytes = 64u << 20);

}  // namespace rccx::io
