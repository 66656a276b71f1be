// What every evaluator (evaluators/evaluator.h: gl, embree, reference) receives; each returns one Lightmap per page.
#pragma once
#include <cstdint>
#include <vector>

#include "lightmap/lightmap.h"
#include "common/progress.h"
#include "lights/light_reach.h"
#include "raytrace/ray_tracer.h"
#include "scene/footprint_albedo.h"
#include "scene/scene.h"
#include "texels/surface_filter_cache.h"
#include "texels/texel_samples.h"
#include "vpl/vpl.h"

namespace irbake {

struct VplEvalOptions {
  float clampBound = 0.0f;         // upper bound on the VPL geometry term cosθx cosθy / r² (1/m²); 0 = no clamp
  bool biasCompensation = false;   // recover the clamped energy: the pipeline's compensation stage
                                   // (stages/compensation) after the backends; no backend reads it
  bool includeDirect = true;       // punctual lights evaluated exactly (shadow ray / shadow map)
  bool includeVpls = true;         // area emitters and bounces through the VPLs
  std::vector<uint8_t> directLights;  // per scene light, 1: the direct term includes it (empty: every light;
                                      // mixed lighting splits the lights written from those left out)
  bool directIncludes(size_t light) const { return directLights.empty() || (light < directLights.size() && directLights[light]); }
};

struct BakeInputs {
  const Scene& scene;
  const RayTracer& rayTracer;
  const std::vector<TexelSamples>& texels;  // one per page
  const VplSet& vpls;
  VplEvalOptions eval;
  ProgressCallback progress;
  // The base colour at the hits of the stages that multiply it by the map read there (the clamp compensation,
  // the final gather), at one map texel's footprint; the pipeline builds one for both. Null: read at the point.
  const FootprintAlbedo* footprintAlbedo = nullptr;
  glm::vec3 albedoAtHit(const RayHit& hit) const {
    return footprintAlbedo ? footprintAlbedo->at(hit.primitive, hit.triangle, hit.barycentric) : rayTracer.albedoAt(hit);
  }
  // The pages' surface filters, each page's neighbour tests made once for every stage that filters it (the
  // interleave's mix, the sky, the compensation, the final gather); the pipeline makes one per bake. Null: each
  // filter makes its own (the same bits).
  SurfaceFilterCache* surfaceFilters = nullptr;
  // The lights' reach spheres (lights/light_reach.h), built once per bake: every stage's per-light loop visits
  // lightsNear(x) only. Null: every light everywhere.
  const LightGrid* lightGrid = nullptr;
  LightSpan lightsNear(const glm::vec3& x) const {
    return lightGrid ? lightGrid->near(x) : LightSpan{nullptr, static_cast<uint32_t>(scene.lights.size())};
  }
};

// A page's map with every texel 0 and invalid, sized like its texel samples.
inline Lightmap blankLightmap(const TexelSamples& ts) {
  Lightmap map;
  map.page = ts.page;
  map.width = ts.width;
  map.height = ts.height;
  map.texels.assign(ts.layerSize(), glm::vec3(0.0f));
  map.valid.assign(ts.layerSize(), 0);
  return map;
}

}  // namespace irbake
