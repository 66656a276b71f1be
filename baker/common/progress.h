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

// This process's CPU seconds so far, every thread (a software GL renderer's too): unlike the wall clock, what
// a stage costs whatever else the machine runs.
double processCpuSeconds();

// Wall-clock stopwatch for per-stage timings in reports, with the process's CPU seconds over the same span.
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()), cpuStart_(processCpuSeconds()) {}
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  double cpuSeconds() const { return processCpuSeconds() - cpuStart_; }
  void reset() {
    start_ = std::chrono::steady_clock::now();
    cpuStart_ = processCpuSeconds();
  }

 private:
  std::chrono::steady_clock::time_point start_;
  double cpuStart_ = 0.0;
};

}  // namespace irbake
