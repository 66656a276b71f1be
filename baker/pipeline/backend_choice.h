// --backend auto: which VPL backend a scene gets, and why (the log and report's backendChoice).
//
// Measured (docs/performance.md): on llvmpipe the GL shadow pass rasterises every triangle once per VPL cube
// face on the CPU, so above ~10k triangles Embree is faster (a 58k-triangle room 4–17×). On a hardware GPU
// (an H100 beside 16 EPYC cores, session 15) the shadow pass is nearly free, but the GL backend still
// traces its contact texels with rays and reads each interleave class back: above 10k triangles it was no
// faster than Embree (Sponza 66k: 7.2–7.5 s against 5.5–6.6 s at 16 threads, within 2% at 2 and 4;
// Stanford bunny 69k, Sibenik 74k: Embree faster) and took 0.4–0.5 GiB more memory (Sponza 1.03–1.09 GiB),
// while on the Cornell boxes (36 triangles, 9k VPLs) it was 2.7× faster at 2 threads. So one threshold
// serves both renderers; only the reason differs.
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

}  // namespace irbake
