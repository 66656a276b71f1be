// Progress reporting: stages call a callback; the command shows a bar with ETA on a terminal.
#pragma once
#include <chrono>
#include <functional>
#include <string>

namespace irbake {

// stage: short name ("atlas", "walk", "gl"); fraction in [0,1]. Must be cheap and thread-safe.
using ProgressCallback = std::function<void(const char* stage, double fraction)>;

// A stderr progress bar with ETA, drawn only when stderr is a terminal (never in CI logs).
class TerminalProgress {
 public:
  TerminalProgress();
  ~TerminalProgress();
  ProgressCallback callback();
  void finish();

 private:
  void update(const char* stage, double fraction);
  bool enabled_;
  std::string stage_;
  std::chrono::steady_clock::time_point stageStart_;
  std::chrono::steady_clock::time_point lastDraw_;
};

// Wall-clock stopwatch for per-stage timings in reports.
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  void reset() { start_ = std::chrono::steady_clock::now(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace irbake
