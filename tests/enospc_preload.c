/* A full disk for the tests where no small tmpfs can be mounted (tests/full_disk_test.sh):
 * preloaded, it fails every write(2) to a file under $RCCX_ENOSPC_DIR with ENOSPC once
 * $RCCX_ENOSPC_AFTER bytes (default 0) have gone to such files, as a full file system does. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static long long written;

static int under_full_dir(int fd) {
  const char* dir = getenv("RCCX_ENOSPC_DIR");
  if (dir == NULL || *dir == '\0') return 0;
  char link[64], path[PATH_MAX];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t n = readlink(link, path, sizeof path - 1);
  if (n <= 0) return 0;
  path[n] = '\0';
  return strncmp(path, dir, strlen(dir)) == 0;
}

static ssize_t limited(int fd, size_t count) {
  const char* after = getenv("RCCX_ENOSPC_AFTER");
  const long long limit = after ? atoll(after) : 0;
  if (written + (long long)count > limit) {
    errno = ENOSPC;
    return -1;
  }
  written += (long long)count;
  (void)fd;
  return 0;
}

ssize_t write(int fd, const void* buf, size_t count) {
  static ssize_t (*real)(int, const void*, size_t);
  /* POSIX's way to take a function from dlsym (a plain cast is not ISO C). */
  if (real == NULL) *(void**)&real = dlsym(RTLD_NEXT, "write");
  if (under_full_dir(fd) && limited(fd, count) < 0) return -1;
  return real(fd, buf, count);
}

ssize_t pwrite64(int fd, const void* buf, size_t count, off_t offset) {
  static ssize_t (*real)(int, const void*, size_t, off_t);
  if (real == NULL) *(void**)&real = dlsym(RTLD_NEXT, "pwrite64");
  if (under_full_dir(fd) && limited(fd, count) < 0) return -1;
  return real(fd, buf, count, offset);
}
