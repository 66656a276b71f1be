// GPU elapsed time of ranges of GL commands (GL_TIME_ELAPSED queries, one range open at a time), read when
// the call ends so that no query stalls the pipeline. The GL backend's "what the GPU does" per stage.
#pragma once
#include <epoxy/gl.h>

#include <utility>
#include <vector>

namespace irbake {

class GpuTimer {
 public:
  explicit GpuTimer(bool enabled) : enabled_(enabled) {}
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;
  ~GpuTimer() {
    for (const auto& [query, target] : pending_) glDeleteQueries(1, &query);
  }
  // Opens a range whose GPU time is added to *seconds by resolve(); closes the open one first.
  void begin(double* seconds) {
    end();
    if (!enabled_) return;
    GLuint query = 0;
    glGenQueries(1, &query);
    glBeginQuery(GL_TIME_ELAPSED, query);
    pending_.emplace_back(query, seconds);
    open_ = true;
  }
  void end() {
    if (!open_) return;
    glEndQuery(GL_TIME_ELAPSED);
    open_ = false;
  }
  // Waits for every range (after the call's read-backs it waits for nothing) and adds their times.
  void resolve() {
    end();
    for (const auto& [query, target] : pending_) {
      GLuint64 ns = 0;
      glGetQueryObjectui64v(query, GL_QUERY_RESULT, &ns);
      *target += 1e-9 * static_cast<double>(ns);
      glDeleteQueries(1, &query);
    }
    pending_.clear();
  }

 private:
  std::vector<std::pair<GLuint, double*>> pending_;
  bool enabled_ = false;  // off: every call is a no-op
  bool open_ = false;
};

}  // namespace irbake
