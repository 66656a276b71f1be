#include "testing/probe_bake.h"

#include <utility>

#include "evaluators/embree/embree_backend.h"

namespace irbake::testing {

ProbeBake bakeProbesCompensated(const AtlasedScene& atlased, const std::vector<TexelSamples>& probes,
                                const VplSet& vpls, const VplEvalOptions& eval, const ClampCompensationOptions& options) {
  std::vector<TexelSamples> texels = atlased.pages;
  for (TexelSamples probe : probes) {
    probe.page = -1;  // no light-map page of its own: no ray reads a probe, and it shadows no atlas page
    texels.push_back(std::move(probe));
  }
  const BakeInputs in{atlased.scene, *atlased.rayTracer, texels, vpls, eval, {}};
  std::vector<Lightmap> maps = bakeEmbree(in);
  ProbeBake out;
  out.clamped.assign(maps.begin() + atlased.pages.size(), maps.end());
  ClampGather(in, options).apply(maps);
  out.compensated.assign(maps.begin() + atlased.pages.size(), maps.end());
  return out;
}

}  // namespace irbake::testing
