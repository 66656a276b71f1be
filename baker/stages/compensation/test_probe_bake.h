// Test helper: the clamp compensation measured on probe grids (gridSamples over a region of interest, such
// as the texels near a corner) rather than on whole atlas pages. ClampGather reads the radiance of what its
// rays hit from the baked maps, so the scene gets an atlas and its pages are baked beside the probes.
#pragma once
#include <memory>
#include <utility>
#include <vector>

#include "atlas/atlas.h"
#include "stages/compensation/clamp_compensation.h"
#include "evaluators/embree/embree_backend.h"
#include "raytrace/ray_tracer.h"
#include "raytrace/test_scenes.h"
#include "texels/texel_samples.h"

namespace irbake::testing {

// The probes baked by the Embree backend with eval's clamp, then with the residual ClampGather adds back.
struct ProbeBake {
  std::vector<Lightmap> clamped, compensated;  // one map per probe grid, in order
};

inline ProbeBake bakeProbesCompensated(const AtlasedScene& atlased, const std::vector<TexelSamples>& probes,
                                       const VplSet& vpls, const VplEvalOptions& eval,
                                       const ClampCompensationOptions& options = {}) {
  std::vector<TexelSamples> texels = atlased.pages;
  for (TexelSamples probe : probes) {
    probe.page = -1;  // no light-map page of its own: no ray reads a probe, and it shadows no atlas page
    texels.push_back(std::move(probe));
  }
  const BakeInputs in{atlased.scene, *atlased.rayTracer, texels, vpls, eval, {}};
  std::vector<Lightmap> maps = bakeEmbree(in);
  ProbeBake out;
  out.clamped.assign(maps.begin() + atlased.pages.size(), maps.end());
  compensateClamp(in, maps, options);
  out.compensated.assign(maps.begin() + atlased.pages.size(), maps.end());
  return out;
}

}  // namespace irbake::testing
