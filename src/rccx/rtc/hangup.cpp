#include "rccx/rtc/hangup.hpp"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <thread>
#include <vector>

#include "rccx/io/signals.hpp"
#include "rccx/rtc/session.hpp"

namespace rccx::rtc::detail {

namespace {

// The sessions in control, and the thread that runs their user hang-up handlers. Planning-level
// state only: the mutex is never taken in the sample loop.
class Registry {
 public:
  Registry() = default;
  ~Registry() {
    if (watcher_.joinable()) {
      stopping_ = true;
      io::wake_stop_waiter();
      watcher_.join();
    }
  }
  Registry(const Registry&) = delete;
  Registry& operator=(const Registry&) = delete;

  void add(Session* s) {
    std::lock_guard lock(mutex_);
    if (sessions_.empty()) io::install_stop_handlers();
    sessions_.push_back(s);
    if (!watcher_.joinable()) watcher_ = std::thread([this] { watch(); });
  }

  void remove(Session* s) {
    std::lock_guard lock(mutex_);
    const auto it = std::find(sessions_.begin(), sessions_.end(), s);
    if (it == sessions_.end()) return;
    sessions_.erase(it);
    if (sessions_.empty()) io::restore_stop_handlers();
  }

 private:
  void watch() {
    for (;;) {
      io::wait_stop_signal();
      if (stopping_) return;
      std::lock_guard lock(mutex_);
      for (Session* s : sessions_) s->hangup();
    }
  }

  std::mutex mutex_;
  std::vector<Session*> sessions_;
  std::thread watcher_;
  std::atomic<bool> stopping_{false};
};

Registry& registry() {
  // Never destroyed: a session may still be released by another static's destructor at exit
  // (a C program that calls exit() with its session open), after this one would have gone.
  static Registry* const r = new Registry;
  return *r;
}

}  // namespace

std::uint32_t hangup_count() noexcept {
  return io::stop_count();
}
void register_for_hangup(Session* s) {
  registry().add(s);
}
void unregister_for_hangup(Session* s) {
  registry().remove(s);
}

}  // namespace rccx::rtc::detail
