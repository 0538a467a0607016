#include "rccx/io/signals.hpp"

#include <semaphore.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <mutex>

namespace rccx::io {
namespace {

std::atomic<std::uint32_t> g_count{0};
std::atomic<int> g_signal{0};

sem_t& semaphore() {
  static sem_t s;
  static const bool made = [] { return sem_init(&s, 0, 0) == 0; }();
  (void)made;
  return s;
}

extern "C" void on_stop_signal(int signo) {
  const int saved = errno;  // a handler must leave errno as it found it
  g_signal.store(signo, std::memory_order_relaxed);
  g_count.fetch_add(1, std::memory_order_relaxed);
  sem_post(&semaphore());
  errno = saved;
}

std::mutex g_mutex;  // planning level only: install and restore
int g_installed = 0;
struct sigaction g_previous_int {};
struct sigaction g_previous_term {};
struct sigaction g_previous_hup {};
bool g_hup_installed = false;

}  // namespace

void install_stop_handlers() noexcept {
  std::lock_guard lock(g_mutex);
  (void)semaphore();  // made before any handler can post to it
  if (g_installed++ > 0) return;
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sa.sa_flags = 0;  // no SA_RESTART: a write blocked on a full pipe must not outlive Ctrl-C
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &g_previous_int);
  sigaction(SIGTERM, &sa, &g_previous_term);
  // SIGHUP (the terminal went away: a closed ssh session) stops cleanly too, so that a log is
  // put in place rather than left as a temporary file; unless it is ignored (nohup).
  sigaction(SIGHUP, nullptr, &g_previous_hup);
  g_hup_installed = g_previous_hup.sa_handler != SIG_IGN;
  if (g_hup_installed) sigaction(SIGHUP, &sa, nullptr);
}

void restore_stop_handlers() noexcept {
  std::lock_guard lock(g_mutex);
  if (g_installed == 0 || --g_installed > 0) return;
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
  if (g_hup_installed) sigaction(SIGHUP, &g_previous_hup, nullptr);
}

std::uint32_t stop_count() noexcept {
  return g_count.load(std::memory_order_relaxed);
}

int last_stop_signal() noexcept {
  return g_signal.load(std::memory_order_relaxed);
}

int stop_exit_code() noexcept {
  const int s = last_stop_signal();
  return 128 + (s == 0 ? SIGINT : s);
}

void wait_stop_signal() noexcept {
  while (sem_wait(&semaphore()) != 0 && errno == EINTR) {
  }
}

void wake_stop_waiter() noexcept {
  sem_post(&semaphore());
}

}  // namespace rccx::io
