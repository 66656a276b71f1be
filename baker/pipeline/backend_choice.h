// --backend auto: which VPL backend a scene gets, and why (the log and report's backendChoice).
//
// Why 10k triangles (docs/validation.md, "GPU runs" and "GL backend costs"): on llvmpipe the GL shadow
// pass rasterises every triangle once per VPL cube face on the CPU, so above it Embree is faster. On a
// hardware GPU the shadow pass is nearly free, but the GL backend still traces its contact texels with
// rays and reads each interleave class back: above it GL was no faster than Embree and took more memory,
// while on small scenes it was faster. So one threshold serves both renderers; only the reason differs.
#pragma once
#include <cstddef>
#include <functional>
#include <string>

namespace irbake {

enum class BackendKind { Auto, Gl, Embree, Reference };

struct AutoBackendChoice {
  BackendKind backend = BackendKind::Embree;
  std::string reason;
};

// At or below this many triangles the GL backend was as fast as Embree or faster on both renderers.
constexpr size_t kGlTriangleHint = 10000;

// What a GL context says of itself: why none could be made (empty: one was made), and whether it renders on
// the CPU (llvmpipe and the like).
struct GlProbe {
  std::string error;
  bool softwareRenderer = true;
};

// The rule: seeThrough names the scene's first see-through material (empty: none), which sends most texels
// to rays. probeGl makes a context (bake.cpp keeps it for the bake) and is called only when the choice
// depends on it: a small scene without see-through materials.
AutoBackendChoice chooseAutoBackend(size_t triangles, const std::string& seeThrough,
                                    const std::function<GlProbe()>& probeGl);

// "auto" | "gl" | "embree" | "reference" (throws Error(Usage) otherwise), and back.
BackendKind parseBackend(const std::string& name);
const char* toString(BackendKind kind);

}  // namespace irbake
