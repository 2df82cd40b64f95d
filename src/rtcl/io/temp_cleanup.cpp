#include "rtcl/io/temp_cleanup.hpp"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <mutex>

namespace rtcl {

namespace {

constexpr int slot_count = 64;
constexpr std::size_t path_bytes = 4096;
constexpr int cleaned_signals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

// Written under registry_mutex, read by the signal handler: a slot's path is
// complete before `used` becomes true, and `used` is false before it changes.
struct Slot {
  std::atomic<bool> used{false};
  char path[path_bytes];
};
Slot slots[slot_count];
std::mutex registry_mutex;
struct sigaction previous[sizeof cleaned_signals / sizeof cleaned_signals[0]];

// Async-signal-safe: unlink(2), sigaction(2) and raise(3) only.
void remove_and_reraise(int signal_number) {
  for (Slot& slot : slots)
    if (slot.used.load()) ::unlink(slot.path);
  for (std::size_t i = 0; i < sizeof cleaned_signals / sizeof cleaned_signals[0]; ++i)
    if (cleaned_signals[i] == signal_number) ::sigaction(signal_number, &previous[i], nullptr);
  ::raise(signal_number);
}

// Once per process: handlers only where the signal would kill the process.
void install_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (std::size_t i = 0; i < sizeof cleaned_signals / sizeof cleaned_signals[0]; ++i) {
      struct sigaction current {};
      ::sigaction(cleaned_signals[i], nullptr, &current);
      if (current.sa_handler != SIG_DFL || (current.sa_flags & SA_SIGINFO)) continue;
      previous[i] = current;
      struct sigaction handler {};
      handler.sa_handler = remove_and_reraise;
      sigemptyset(&handler.sa_mask);
      for (int s : cleaned_signals) sigaddset(&handler.sa_mask, s);
      ::sigaction(cleaned_signals[i], &handler, nullptr);
    }
  });
}

}  // namespace

TempCleanup::TempCleanup(const std::string& path) {
  if (path.size() >= path_bytes) return;
  install_handlers();
  std::lock_guard lock(registry_mutex);
  for (int i = 0; i < slot_count; ++i) {
    if (slots[i].used.load()) continue;
    std::memcpy(slots[i].path, path.c_str(), path.size() + 1);
    slots[i].used.store(true);
    slot_ = i;
    return;
  }
}

TempCleanup::~TempCleanup() {
  if (slot_ < 0) return;
  std::lock_guard lock(registry_mutex);
  slots[slot_].used.store(false);
}

}  // namespace rtcl
