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
  // The cube face size when unset (chooseCubeFaceSize on the inputs' pages, VPLs and clamp).
  std::vector<EvaluatorChoice> settle(const BakeInputs& inputs) override;
  // report "renderer", "gl" (the counts) and "timings.gl".
  void describe(nlohmann::json& report) const override;
  // The report's "gl" counts and the texels evaluated (GlBakeStats::addCounts).
  nlohmann::json counts() const override;
  void addCounts(const nlohmann::json& counts) override;

 private:
  GlBackendOptions options_;
  const Evaluator* contacts_;
  mutable GlBakeStats ownStats_;  // the figures when options.stats is null
  GlBakeStats* stats_;
};

}  // namespace irbake
