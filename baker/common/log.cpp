#include "common/log.h"

#include <atomic>
#include <cstdio>
#include <mutex>

namespace irbake::log {
namespace {
std::atomic<Level> gLevel{Level::Info};
std::atomic<int> gWarnings{0};
std::mutex gMutex;
void emit(Level l, const char* tag, const std::string& msg) {
  if (l < gLevel.load()) return;
  std::lock_guard<std::mutex> lock(gMutex);
  std::fprintf(stderr, "irbake: %s%s\n", tag, msg.c_str());
}
}  // namespace

void setLevel(Level l) { gLevel = l; }
Level level() { return gLevel; }
void debug(const std::string& m) { emit(Level::Debug, "debug: ", m); }
void info(const std::string& m) { emit(Level::Info, "", m); }
void warn(const std::string& m) { ++gWarnings; emit(Level::Warn, "warning: ", m); }
void error(const std::string& m) { emit(Level::Error, "error: ", m); }
int warningCount() { return gWarnings; }

}  // namespace irbake::log
