#include "common/progress.h"

#include <cstdio>
#include <mutex>
#include <time.h>
#include <unistd.h>

#include "common/log.h"

namespace irbake {
namespace {
std::mutex gProgressMutex;
}

// Bars only on a terminal, and never under --quiet (log level above info).
TerminalProgress::TerminalProgress()
    : enabled_(::isatty(STDERR_FILENO) != 0 && log::level() <= log::Level::Info) {}
TerminalProgress::~TerminalProgress() { finish(); }

ProgressCallback TerminalProgress::callback() {
  return [this](const char* stage, double fraction) { update(stage, fraction); };
}

void TerminalProgress::update(const char* stage, double fraction) {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(gProgressMutex);
  auto now = std::chrono::steady_clock::now();
  if (stage_ != stage) {
    if (!stage_.empty()) log::endStatusLine();
    stage_ = stage;
    stageStart_ = now;
    lastDraw_ = {};
  }
  if (fraction < 1.0 && now - lastDraw_ < std::chrono::milliseconds(100)) return;
  lastDraw_ = now;
  double elapsed = std::chrono::duration<double>(now - stageStart_).count();
  double eta = fraction > 1e-6 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  int filled = static_cast<int>(fraction * 30.0 + 0.5);
  char bar[31];
  for (int i = 0; i < 30; ++i) bar[i] = i < filled ? '#' : '.';
  bar[30] = 0;
  char line[160];
  std::snprintf(line, sizeof(line), "%-10s [%s] %5.1f%%  %6.1fs  ETA %6.1fs", stage, bar, fraction * 100.0, elapsed, eta);
  log::drawStatusLine(line);
}

void TerminalProgress::finish() {
  if (enabled_ && !stage_.empty()) log::endStatusLine();
  stage_.clear();
}

double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

}  // namespace irbake
