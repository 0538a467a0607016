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

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  std::error_code ec;
  if (std::filesystem::is_directory(target_, ec)) {
    throw FileError(
        fmt::format("cannot write {}: it is a directory; name a file", target_.string()));
  }
  const std::filesystem::path dir =
      target_.has_parent_path() ? target_.parent_path() : std::filesystem::path(".");
  std::string pattern = (dir / ("." + target_.filename().string() + ".tmp-XXXXXX")).string();
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
  ::unlink(temporary_.c_str());
  temporary_.clear();
  throw FileError(fmt::format("cannot write {}: {} while {}; {} was left as it was",
                              target_.string(), std::strerror(error), doing, target_.string()));
}

void AtomicFile::write(std::string_view data) {
  if (fd_ < 0) throw FileError(fmt::format("cannot write {}: already closed", target_.string()));
  if (const int e = write_all(fd_, data.data(), data.size()); e != 0) fail("writing", e);
}

void AtomicFile::commit() {
  if (fd_ < 0) throw FileError(fmt::format("cannot write {}: already closed", target_.string()));
  if (::fsync(fd_) != 0) fail("flushing to disk", errno);
  if (::close(fd_) != 0) {
    fd_ = -1;
    fail("closing", errno);
  }
  fd_ = -1;
  if (::rename(temporary_.c_str(), target_.c_str()) != 0) fail("renaming into place", errno);
  committed_ = true;
  // The rename itself is durable only once the directory is.
  const std::filesystem::path dir =
      target_.has_parent_path() ? target_.parent_path() : std::filesystem::path(".");
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
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    throw FileError(fmt::format("cannot read {}: {}", file.string(), std::strerror(errno)));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    const bool dir = S_ISDIR(st.st_mode);
    ::close(fd);
    throw FileError(fmt::format("cannot read {}: {}", file.string(),
                                dir ? "it is a directory; name a file" : "not a regular file"));
  }
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
