#include "rccx/io/file.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace rccx::io {

int write_all(int fd, const char* data, std::size_t size) noexcept {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return EIO;
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return 0;
}

namespace {

/// `path` with its symbolic links followed, also one that names a file not yet made.
std::filesystem::path followed(std::filesystem::path path) {
  std::error_code ec;
  for (int hops = 0; hops < 40 && std::filesystem::is_symlink(path, ec); ++hops) {
    const std::filesystem::path link = std::filesystem::read_symlink(path, ec);
    if (ec) break;
    path = link.is_absolute() ? link : path.parent_path() / link;
  }
  return path;
}

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  struct stat st {};
  const bool exists = ::stat(target_.c_str(), &st) == 0;
  if (exists && S_ISDIR(st.st_mode)) {
    throw FileError(
        fmt::format("cannot write {}: it is a directory; name a file", target_.string()));
  }
  // A device or a pipe (/dev/null, a named pipe), and whatever /dev/stdout or /dev/fd/N names
  // (the shell's redirection): written in place.
  const std::string& name = target_.native();
  if ((exists && !S_ISREG(st.st_mode)) || name.starts_with("/dev/") || name.starts_with("/proc/")) {
    // O_NONBLOCK: a named pipe nobody reads is an error now, not a wait for ever.
    // O_APPEND for a regular file behind /dev/stdout: after what the shell's stdout wrote.
    const int append = exists && S_ISREG(st.st_mode) ? O_APPEND : 0;
    fd_ = ::open(target_.c_str(), O_WRONLY | O_CLOEXEC | O_NONBLOCK | append);
    if (fd_ < 0) {
      throw FileError(
          fmt::format("cannot write {}: {}", target_.string(),
                      errno == ENXIO ? "no process reads this named pipe" : std::strerror(errno)));
    }
    ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) & ~O_NONBLOCK);
    in_place_ = true;
    return;
  }
  destination_ = followed(target_);
  const std::filesystem::path dir =
      destination_.has_parent_path() ? destination_.parent_path() : std::filesystem::path(".");
  // Appended piece by piece: GCC 12 at -O2 takes `"." + name + ...` for an overlapping memcpy
  // (a false -Wrestrict).
  std::string hidden = ".";
  hidden += destination_.filename().string();
  hidden += ".tmp-XXXXXX";
  std::string pattern = (dir / hidden).string();
  fd_ = ::mkstemp(pattern.data());
  if (fd_ < 0) {
    throw FileError(fmt::format("cannot write {}: {} (cannot create a file in {})",
                                target_.string(), std::strerror(errno), dir.string()));
  }
  temporary_ = pattern;
  // mkstemp makes the file 0600; a replaced file gets what an ordinary new file would.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::fchmod(fd_, 0666 & ~mask);
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_ && !temporary_.empty()) ::unlink(temporary_.c_str());
}

void AtomicFile::fail(const char* doing, int error) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (!temporary_.empty()) ::unlink(temporary_.c_str());
  temporary_.clear();
  if (in_place_) {
    throw FileError(fmt::format("cannot write {}: {} while {}; what it got is incomplete",
                                target_.string(), std::strerror(error), doing));
  }
  throw FileError(fmt::format("cannot write {}: {} while {}; {} was left as it was",
                              target_.string(), std::strerror(error), doing, target_.string()));
}

void AtomicFile::write(std::string_view data) {
  if (fd_ < 0) throw FileError(fmt::format("cannot write {}: already closed", target_.string()));
  if (const int e = write_all(fd_, data.data(), data.size()); e != 0) fail("writing", e);
}

void AtomicFile::commit() {
  if (fd_ < 0) throw FileError(fmt::format("cannot write {}: already closed", target_.string()));
  if (in_place_) {  // a device or a pipe: nothing to rename, and no fsync to ask of it
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) fail("closing", errno);
    committed_ = true;
    return;
  }
  if (::fsync(fd_) != 0) fail("flushing to disk", errno);
  if (::close(fd_) != 0) {
    fd_ = -1;
    fail("closing", errno);
  }
  fd_ = -1;
  if (::rename(temporary_.c_str(), destination_.c_str()) != 0) fail("renaming into place", errno);
  committed_ = true;
  // The rename itself is durable only once the directory is.
  const std::filesystem::path dir =
      destination_.has_parent_path() ? destination_.parent_path() : std::filesystem::path(".");
  if (const int d = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY); d >= 0) {
    ::fsync(d);
    ::close(d);
  }
}

void write_file_atomically(const std::filesystem::path& target, std::string_view data) {
  AtomicFile f(target);
  f.write(data);
  f.commit();
}

std::string read_file(const std::filesystem::path& file, std::size_t max_bytes) {
  // O_NONBLOCK: opening a named pipe nobody writes would otherwise wait for ever; it is
  // refused below like any other file that is not a regular one.
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    throw FileError(fmt::format("cannot read {}: {}", file.string(), std::strerror(errno)));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    const bool dir = S_ISDIR(st.st_mode);
    ::close(fd);
    throw FileError(
        fmt::format("cannot read {}: {}", file.string(),
                    dir ? "it is a directory; name a file"
                        : "not a regular file (a device or a named pipe); name a regular file"));
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  std::string out;
  char chunk[65536];
  for (;;) {
    const ssize_t n = ::read(fd, chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int e = errno;
      ::close(fd);
      throw FileError(fmt::format("cannot read {}: {}", file.string(), std::strerror(e)));
    }
    if (n == 0) break;
    out.append(chunk, static_cast<std::size_t>(n));
    if (out.size() > max_bytes) {
      ::close(fd);
      throw FileError(
          fmt::format("cannot read {}: larger than {} MiB", file.string(), max_bytes >> 20));
    }
  }
  ::close(fd);
  return out;
}

}  // namespace rccx::io
