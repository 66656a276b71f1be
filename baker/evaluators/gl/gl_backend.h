// The OpenGL evaluator: each VPL's shadowed contribution rendered into the light-map pages (EGL,
// headless) and accumulated in float, folded into double. The same transport maths (transport/) as the
// other evaluators; the texels its depth tests cannot resolve go to the evaluator its builder hands it.
#pragma once
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "evaluators/evaluator.h"
#include "lightmap/lightmap.h"

namespace irbake {

class GlContext;

// Measured by GlEvaluator (wall clock with glFinish between stages when GlBackendOptions::stageTimings).
struct GlBakeStats {
  std::string renderer;          // GL_RENDERER | GL_VERSION | EGL platform
  double setupSeconds = 0.0;     // context, programs, geometry and G-buffer upload
  double shadowSeconds = 0.0;    // VPL depth cubes and punctual shadow maps
  double accumulateSeconds = 0.0;// accumulation passes (VPLs and direct lights)
  double foldSeconds = 0.0;      // read-backs into the double accumulators
  double geometrySeconds = 0.0;  // scene geometry sorted, clustered and uploaded (once per context and scene)
  double readSeconds = 0.0;      // the double sums turned into maps
  // GPU elapsed time (GL_TIME_ELAPSED) of the same stages' commands, with GlBackendOptions::gpuTimers.
  double gpuShadowSeconds = 0.0;
  double gpuAccumulateSeconds = 0.0;
  double gpuFoldSeconds = 0.0;
  size_t calls = 0;              // evaluator calls (interleaved sampling makes n² + 1)
  double shadowCpuSeconds = 0.0;     // process CPU time (all llvmpipe threads) in the shadow stage
  double accumulateCpuSeconds = 0.0; // process CPU time in the accumulation stage (load-independent figures)
  int cubeFaceSize = 0;          // VPL depth-cube face size used (the largest over calls after add)
  size_t vpls = 0;               // VPLs evaluated
  size_t passes = 0;             // accumulation passes per page
  size_t facesRendered = 0;      // shadow views drawn (cube faces, spot/directional maps)
  size_t trianglesDrawn = 0;     // triangles submitted to shadow views after CPU culling
  size_t trianglesBeforeCulling = 0;  // triangles that would be submitted without culling
  size_t contactTexels = 0;      // texels handed to the contact evaluator (GlBackendOptions::resolveContacts)
  size_t texelsEvaluated = 0;    // valid texels of the pages
  double contactSeconds = 0.0;   // the contact evaluator's time on them
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
            {"contactSeconds", contactSeconds},       {"geometrySeconds", geometrySeconds},
            {"readSeconds", readSeconds},             {"gpuShadowSeconds", gpuShadowSeconds},
            {"gpuAccumulateSeconds", gpuAccumulateSeconds}, {"gpuFoldSeconds", gpuFoldSeconds},
            {"calls", calls}};
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
  // Adds another call's figures (the bake calls the evaluator once per VPL block).
  void add(const GlBakeStats& o) {
    renderer = o.renderer;
    setupSeconds += o.setupSeconds;
    shadowSeconds += o.shadowSeconds;
    accumulateSeconds += o.accumulateSeconds;
    foldSeconds += o.foldSeconds;
    geometrySeconds += o.geometrySeconds;
    readSeconds += o.readSeconds;
    gpuShadowSeconds += o.gpuShadowSeconds;
    gpuAccumulateSeconds += o.gpuAccumulateSeconds;
    gpuFoldSeconds += o.gpuFoldSeconds;
    calls += o.calls;
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
  int minCubeFaceSize = 128;     // automatic face size: lower bound (occluder detail the light map cannot see; docs/validation.md)
  int maxCubeFaceSize = 256;     // automatic face size: upper bound
  int pointFaceSize = 1024;      // point-light depth-cube face size (texels)
  int lightMapSize = 4096;       // spot / directional shadow map size (texels; 64 MiB): smaller maps miss sub-texel
                                 // slivers of occluders that rays hit (docs/validation.md)
  int shadowFlushTriangles = 32768;  // VPL shadow pass: glFlush after this many triangles drawn into the depth atlas (0: once per batch)
  int foldEveryPasses = 8;       // float passes summed on the GPU before folding into double
  int clusterTriangles = 64;     // triangles per culling cluster (CPU per-face culling: smaller clusters cull more)
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
  // texel's light go to the contact evaluator (same inputs, those texels only), so an unresolved texel is
  // off by at most that fraction from such lookups. Without a contact evaluator this is off.
  bool resolveContacts = true;
  float contactLeakFraction = 0.01f;
  bool stageTimings = false;     // glFinish between stages so GlBakeStats splits shadow/accumulation time
  bool gpuTimers = false;        // GL_TIME_ELAPSED queries per pass kind (GlBakeStats::gpu*Seconds)
  const GlContext* context = nullptr;  // an existing context, made current per call; null: one made per call
  GlBakeStats* stats = nullptr;  // where every call's figures are added (null: the evaluator keeps its own)
};

// L1 pages (EvaluationRequest::directional) come from the same passes, three more float targets per page
// (contact texels: from the contact evaluator's L1 pages). A texel subset is rendered whole and then cut
// (no time saved). stats(): {"renderer", "counts" (the report's "gl"), "timings" (its "timings.gl")}.
class GlEvaluator final : public Evaluator {
 public:
  // contacts: the evaluator of the contact texels (null: resolveContacts is off); it must outlive this one.
  explicit GlEvaluator(const GlBackendOptions& options = {}, const Evaluator* contacts = nullptr);
  GlEvaluator(const GlEvaluator&) = delete;
  GlEvaluator& operator=(const GlEvaluator&) = delete;
  // Throws Error(Gl) when no GL 4.5 context can be created (hint: --backend embree) and
  // Error(NumericError) if a non-finite value appears.
  std::vector<Lightmap> evaluate(const BakeInputs& inputs, const EvaluationRequest& request = {}) const override;
  const char* name() const override { return "gl"; }
  nlohmann::json stats() const override;

 private:
  GlBackendOptions options_;
  const Evaluator* contacts_;
  mutable GlBakeStats ownStats_;  // the figures when options.stats is null
  GlBakeStats* stats_;
};

}  // namespace irbake
