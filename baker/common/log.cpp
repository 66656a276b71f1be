#include "common/log.h"

#include <atomic>
#include <cstdio>
#include <mutex>

namespace irbake::log {
namespace {
std::atomic<Level> gLevel{Level::Info};
std::atomic<int> gWarnings{0};
std::atomic<const char*> gProgram{"irbake"};
std::mutex gMutex;
bool gStatusShown = false;  // a bar is on stderr's current line (guarded by gMutex)
void emit(Level l, const char* tag, const std::string& msg) {
  if (l < gLevel.load()) return;
  std::lock_guard<std::mutex> lock(gMutex);
  if (gStatusShown) {
    std::fputs("\r\033[K", stderr);  // back to column 0 and clear the bar
    gStatusShown = false;
  }
  std::fprintf(stderr, "%s: %s%s\n", gProgram.load(), tag, msg.c_str());
}
}  // namespace

void setProgram(const char* name) { gProgram = name; }

void drawStatusLine(const std::string& text) {
  std::lock_guard<std::mutex> lock(gMutex);
  std::fprintf(stderr, "\r%s", text.c_str());
  std::fflush(stderr);
  gStatusShown = true;
}

void endStatusLine() {
  std::lock_guard<std::mutex> lock(gMutex);
  if (gStatusShown) std::fputs("\n", stderr);
  gStatusShown = false;
}

void setLevel(Level l) { gLevel = l; }
Level level() { return gLevel; }
void debug(const std::string& m) { emit(Level::Debug, "debug: ", m); }
void info(const std::string& m) { emit(Level::Info, "", m); }
void warn(const std::string& m) { ++gWarnings; emit(Level::Warn, "warning: ", m); }
void error(const std::string& m) { emit(Level::Error, "error: ", m); }
int warningCount() { return gWarnings; }

}  // namespace irbake::log
