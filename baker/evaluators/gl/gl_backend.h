// The OpenGL backend: each VPL's shadowed contribution rendered into the light-map pages (EGL,
// headless) and accumulated in float, folded into double. Same transport as the Embree backend.
#pragma once
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "lightmap/lightmap.h"

namespace irbake {

class GlContext;

// Measured by bakeGl (wall clock with glFinish between stages when GlBackendOptions::stageTimings).
struct GlBakeStats {
  std::string renderer;          // GL_RENDERER | GL_VERSION | EGL platform
  double setupSeconds = 0.0;     // context, programs, geometry and G-buffer upload
  double shadowSeconds = 0.0;    // VPL depth cubes and punctual shadow maps
  double accumulateSeconds = 0.0;// accumulation passes (VPLs and direct lights)
  double foldSeconds = 0.0;      // read-backs into the double accumulators
  double shadowCpuSeconds = 0.0;     // process CPU time (all llvmpipe threads) in the shadow stage
  double accumulateCpuSeconds = 0.0; // process CPU time in the accumulation stage (load-independent figures)
  int cubeFaceSize = 0;          // VPL depth-cube face size used (the largest over calls after add)
  size_t vpls = 0;               // VPLs evaluated
  size_t passes = 0;             // accumulation passes per page
  size_t facesRendered = 0;      // shadow views drawn (cube faces, spot/directional maps)
  size_t trianglesDrawn = 0;     // triangles submitted to shadow views after CPU culling
  size_t trianglesBeforeCulling = 0;  // triangles that would be submitted without culling
  size_t contactTexels = 0;      // texels resolved with rays (GlBackendOptions::resolveContacts)
  size_t texelsEvaluated = 0;    // valid texels of the pages
  double contactSeconds = 0.0;   // the rays of the contact texels
  // The report's "gl" object (counts, the same every run) and its "timings.gl" object (wall clock).
  nlohmann::json toJson() const {
    return {{"passes", passes},
            {"facesRendered", facesRendered},
            {"trianglesDrawn", trianglesDrawn},
            {"cubeFaceSize", cubeFaceSize},
            {"contactTexels", contactTexels},
            {"contactFraction", texelsEvaluated ? double(contactTexels) / texelsEvaluated : 0.0}};
  }
  nlohmann::json timingsJson() const {
    return {{"setupSeconds", setupSeconds},           {"shadowSeconds", shadowSeconds},
            {"accumulateSeconds", accumulateSeconds}, {"foldSeconds", foldSeconds},
            {"contactSeconds", contactSeconds}};
  }
  // The counts toJson() reports back from a partial (a merge adds its shards' counts).
  void addCounts(const nlohmann::json& j) {
    passes += j.value("passes", size_t{0});
    facesRendered += j.value("facesRendered", size_t{0});
    trianglesDrawn += j.value("trianglesDrawn", size_t{0});
    cubeFaceSize = std::max(cubeFaceSize, j.value("cubeFaceSize", 0));
    contactTexels += j.value("contactTexels", size_t{0});
    texelsEvaluated += j.value("texelsEvaluated", size_t{0});
  }
  // Adds another call's figures (the bake calls the backend once per VPL block).
  void add(const GlBakeStats& o) {
    renderer = o.renderer;
    setupSeconds += o.setupSeconds;
    shadowSeconds += o.shadowSeconds;
    accumulateSeconds += o.accumulateSeconds;
    foldSeconds += o.foldSeconds;
    shadowCpuSeconds += o.shadowCpuSeconds;
    accumulateCpuSeconds += o.accumulateCpuSeconds;
    cubeFaceSize = std::max(cubeFaceSize, o.cubeFaceSize);
    vpls += o.vpls;
    passes += o.passes;
    facesRendered += o.facesRendered;
    trianglesDrawn += o.trianglesDrawn;
    trianglesBeforeCulling += o.trianglesBeforeCulling;
    contactTexels += o.contactTexels;
    texelsEvaluated += o.texelsEvaluated;
    contactSeconds += o.contactSeconds;
  }
};

struct GlBackendOptions {
  int vplsPerPass = 16;          // K: VPLs (depth cubes, 5 tiles each of one depth atlas) evaluated per accumulation pass
  std::optional<int> cubeFaceSize;  // VPL depth-cube face size (texels, > 0); unset: from the light map (chooseCubeFaceSize)
  float cubeFootprintPerTexel = 1.0f;  // automatic face size: face texel footprint at the median VPL distance, in texel spacings
  int minCubeFaceSize = 128;     // automatic face size: lower bound (occluder detail the light map cannot see: furnished room, 64: GL vs Embree 1.2%, 128: 0.3%)
  int maxCubeFaceSize = 256;     // automatic face size: upper bound
  int pointFaceSize = 1024;      // point-light depth-cube face size (texels)
  int lightMapSize = 4096;      // spot / directional shadow map size (texels; 64 MiB): Sponza's sun at 2048², sub-texel slivers
                                // the rays hit were missing: GL vs Embree 1.5% → 0.28% at 4096² (0.22% at 8192²)
  int shadowFlushTriangles = 32768;  // VPL shadow pass: glFlush after this many triangles drawn into the depth atlas (0: once per batch)
  int foldEveryPasses = 8;       // float passes summed on the GPU before folding into double
  int clusterTriangles = 64;     // triangles per culling cluster (CPU per-face culling; 64: −20% drawn vs 256)
  float maxSpotPerspectiveAngle = 1.05f;  // spots with a wider outer cone (rad) get a cube instead of one map
  float nearPlaneScale = 1e-5f;  // shadow near plane = scale × scene diagonal (reversed-Z float depth)
  float constantBiasScale = 2e-5f;  // constant depth bias = scale × scene diagonal
  float slopeBias = 1.0f;        // depth bias in shadow texel footprints × (tanθ + 1.5): the 2×2 filter reads one texel around the lookup
  float normalOffset = 0.0f;     // lookup point pushed along the receiver normal, in texel footprints
  bool shadowPcf = true;         // VPL cubes: 2×2 percentage-closer filtering (fractional shadow edges)
  bool shadowCompare = true;     // PCF by the sampler's depth comparison (GL_LINEAR, one lookup) instead of 4 fetches
  bool skipInvalidTexels = true; // early depth test against a per-page validity mask: invalid texels are not shaded
  // Contact texels: a shadow lookup that the depth bias counts as lit although the stored surface lies in
  // front of the receiver's plane cannot tell a contact (a box on a floor, a lamp 0.1 mm under a ceiling)
  // from the receiver itself. Texels where such lookups carry more than contactLeakFraction of the
  // texel's light are evaluated again with rays (the Embree backend, same VPLs and lights). At 0.01 an
  // unresolved texel is off by at most 1% from such lookups (Cornell box at 128² faces: 8.5% of texels
  // traced, GL vs Embree 0.11%; at 0.001: 21%, 0.09%).
  bool resolveContacts = true;
  float contactLeakFraction = 0.01f;
  bool stageTimings = false;     // glFinish between stages so GlBakeStats splits shadow/accumulation time
  const GlContext* context = nullptr;  // an existing current context; null: bakeGl creates one
  GlBakeStats* stats = nullptr;  // out: timings and counts (may be null)
  // Out, optional: the directional maps' L1 pages (transport/directional.h), accumulated by the same
  // passes into three more float targets per page (contact texels: from the same rays as the map). Null:
  // the plain shaders and targets, nothing more is done.
  L1Pages* directional = nullptr;
};

// One Lightmap per TexelSamples page (irradiance/π). Throws Error(Gl) when no GL 4.5 context can be
// created (hint: --backend embree) and Error(NumericError) if a non-finite value appears.
std::vector<Lightmap> bakeGl(const BakeInputs& inputs, const GlBackendOptions& options = {});

}  // namespace irbake
