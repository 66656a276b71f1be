// What every stage runner reads of the bake's record.
#include "pipeline/bake_state.h"

#include "stages/interleave/interleaved_sampling.h"

namespace irbake {

ProgressCallback withProgress(const BakeState& s, ProgressCallback cb) { return cb ? cb : s.options.progress; }

BakeInputs inputs(const BakeState& s, const std::vector<TexelSamples>& pages, const VplSet& set,
                  const VplEvalOptions& e, ProgressCallback progress) {
  BakeInputs in{s.scene, *s.rayTracer, pages, set, e, std::move(progress)};
  in.lightGrid = s.lightGrid.get();
  return in;
}

StageContext stageContext(BakeState& s, nlohmann::json& report) {
  return StageContext{s.scene, *s.wholeInputs, s.plan, s.options.compensation, s.options.progress, s.seconds, s.cpuSeconds,
                      report};
}

bool estimating(const BakeState& s) {
  return s.options.errorEstimate.enabled && s.plan.backend != BackendKind::Reference && s.options.eval.includeVpls;
}

bool targeting(const BakeState& s) {
  return estimating(s) && !s.halfB.pages.empty() && s.options.errorEstimate.targetError > 0.0;
}

int coefficients(const BakeState& s) { return s.plan.directional ? 1 + 3 : 1; }

ExactVplSums zeroSums(const BakeState& s) {
  std::vector<std::vector<uint8_t>> receivers;
  for (const TexelSamples& ts : s.texels)
    receivers.push_back(ts.valid.size() == ts.layerSize() ? ts.valid : std::vector<uint8_t>(ts.layerSize(), 1));
  return ExactVplSums::zeros(receivers, coefficients(s));
}

const std::vector<TexelSamples>& pagesOf(BakeState& s, int vplClass) {
  if (s.plan.interleave <= 1) return s.texels;
  if (s.pagesClass != vplClass) {
    s.classPages = interleaveClass(s.texels, s.plan.interleave, vplClass % s.plan.interleave, vplClass / s.plan.interleave);
    s.pagesClass = vplClass;
  }
  return s.classPages;
}

}  // namespace irbake
