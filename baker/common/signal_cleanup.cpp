#include "common/signal_cleanup.h"

#include <atomic>
#include <csignal>
#include <cstring>
#include <mutex>

#include <unistd.h>

namespace irbake {

namespace {

// Fixed storage: a signal handler may only read memory that is never reallocated.
constexpr int kSlots = 256;
constexpr size_t kPathBytes = 4096;
char gPaths[kSlots][kPathBytes];
std::atomic<bool> gUsed[kSlots];
std::mutex gClaim;

void onSignal(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (gUsed[i].load(std::memory_order_acquire)) ::unlink(gPaths[i]);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace

void installSignalCleanup() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int sig : {SIGTERM, SIGINT, SIGHUP, SIGQUIT, SIGABRT}) {
      struct sigaction action {};
      action.sa_handler = onSignal;
      sigemptyset(&action.sa_mask);
      action.sa_flags = SA_RESETHAND;
      sigaction(sig, &action, nullptr);
    }
  });
}

int removeOnSignal(const std::filesystem::path& path) {
  const std::string text = path.string();
  if (text.size() + 1 > kPathBytes) return -1;
  std::lock_guard<std::mutex> lock(gClaim);
  for (int i = 0; i < kSlots; ++i) {
    if (gUsed[i].load(std::memory_order_relaxed)) continue;
    std::memcpy(gPaths[i], text.c_str(), text.size() + 1);
    gUsed[i].store(true, std::memory_order_release);
    return i;
  }
  return -1;
}

void forgetPath(int slot) {
  if (slot < 0 || slot >= kSlots) return;
  std::lock_guard<std::mutex> lock(gClaim);
  gUsed[slot].store(false, std::memory_order_release);
}

}  // namespace irbake
