// A headless OpenGL 4.5 core context on EGL (no window, no X): Mesa's surfaceless platform first,
// then the EGL device platform (a GPU without a display). Entry points come from libepoxy.
// Shared by the GL backend and the viewer's headless mode.
#pragma once
#include <memory>
#include <string>
#include <vector>

namespace irbake {

class GlProgramCache;

enum class EglPlatform { Surfaceless, Device };

struct GlContextOptions {
  std::vector<EglPlatform> platforms{EglPlatform::Surfaceless, EglPlatform::Device};  // tried in order
  int glMajor = 4, glMinor = 5;  // core profile version required
  bool debugContext = false;     // ask for a debug context (more KHR_debug messages, slower on some drivers)
  bool routeDebugMessages = true;  // KHR_debug messages → irbake log (high: warn, others: debug)
};

// Creates the context and makes it current on the calling thread. Throws Error(Gl) with the hint
// "--backend embree" when no EGL display or no GL 4.5 core context can be had.
class GlContext {
 public:
  explicit GlContext(const GlContextOptions& options = {});
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  void makeCurrent() const;
  const std::string& renderer() const;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  const std::string& version() const;   // GL_VERSION
  const std::string& vendor() const;    // GL_VENDOR
  EglPlatform platform() const;         // the platform that worked
  std::string description() const;      // "renderer | GL version | platform" for reports
  bool softwareRenderer() const;        // llvmpipe / softpipe / swrast
  // Programs built on this context, reused across calls (use with this context current).
  GlProgramCache& programs() const;
  // A caller's objects kept for the context's life under `key` (e.g. the GL backend's scene geometry across
  // its calls in one bake), released before the programs, with this context current.
  std::shared_ptr<void>& resource(const std::string& key) const;
  // KHR_debug messages received so far (all severities), for tests and reports.
  int debugMessageCount() const;
  int debugErrorCount() const;  // messages of type GL_DEBUG_TYPE_ERROR

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

const char* toString(EglPlatform platform);

// Throws Error(Gl, file, "<what>: GL error 0x...") when glGetError reports one (drains the queue).
void checkGlError(const char* what);

}  // namespace irbake
