#include "rccx/rtc/hangup.hpp"

#include <semaphore.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <mutex>
#include <thread>
#include <vector>

#include "rccx/rtc/session.hpp"

namespace rccx::rtc::detail {

namespace {

std::atomic<std::uint32_t> g_count{0};
sem_t g_posted;

extern "C" void on_sigint(int) {
  g_count.fetch_add(1, std::memory_order_relaxed);
  sem_post(&g_posted);
}

// The sessions in control, and the thread that runs their user hang-up handlers. Planning-level
// state only: the mutex is never taken in the sample loop.
class Registry {
 public:
  Registry() { sem_init(&g_posted, 0, 0); }
  ~Registry() {
    if (watcher_.joinable()) {
      stopping_ = true;
      sem_post(&g_posted);
      watcher_.join();
    }
  }

  void add(Session* s) {
    std::lock_guard lock(mutex_);
    if (sessions_.empty()) {
      struct sigaction sa {};
      sa.sa_handler = on_sigint;
      sigemptyset(&sa.sa_mask);
      sigaction(SIGINT, &sa, &previous_);
    }
    sessions_.push_back(s);
    if (!watcher_.joinable()) watcher_ = std::thread([this] { watch(); });
  }

  void remove(Session* s) {
    std::lock_guard lock(mutex_);
    const auto it = std::find(sessions_.begin(), sessions_.end(), s);
    if (it == sessions_.end()) return;
    sessions_.erase(it);
    if (sessions_.empty()) sigaction(SIGINT, &previous_, nullptr);
  }

 private:
  void watch() {
    for (;;) {
      while (sem_wait(&g_posted) != 0) {
      }
      if (stopping_) return;
      std::lock_guard lock(mutex_);
      for (Session* s : sessions_) s->hangup();
    }
  }

  std::mutex mutex_;
  std::vector<Session*> sessions_;
  struct sigaction previous_ {};
  std::thread watcher_;
  std::atomic<bool> stopping_{false};
};

Registry& registry() {
  static Registry r;
  return r;
}

}  // namespace

std::uint32_t hangup_count() noexcept {
  return g_count.load(std::memory_order_relaxed);
}
void register_for_hangup(Session* s) {
  registry().add(s);
}
void unregister_for_hangup(Session* s) {
  registry().remove(s);
}

}  // namespace rccx::rtc::detail
