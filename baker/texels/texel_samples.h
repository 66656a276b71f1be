// Atlas pages rasterised into per-texel surface samples (position, normal, coverage weight).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "common/progress.h"
#include "raytrace/ray_tracer.h"
#include "scene/scene.h"

namespace irbake {

struct TexelSampleOptions {
  int supersample = 1;        // S: S×S samples per texel, weighted by coverage
  bool leakControl = true;    // invalidate samples inside geometry / behind nearby back faces
  float leakRayScale = 1.0f;  // leak-test ray length in texel footprints
  ProgressCallback progress;
};

// One atlas page. Slot layout: layer l = sy*S + sx; slot = l*width*height + y*width + x (y = 0 is
// the row at v = 0). A slot with weight 0 is empty (outside every chart, or invalidated).
struct TexelSamples {
  int page = 0;
  int width = 0, height = 0;
  int supersample = 1;
  std::vector<glm::vec4> positionWeight;  // xyz: world position; w: weight (coverage, sums to 1 per valid texel)
  std::vector<glm::vec4> normal;          // xyz: unit shading normal; w: unused (0)
  std::vector<uint32_t> primitive;        // per slot: Scene::primitives index (UINT32_MAX if empty)
  std::vector<uint32_t> triangle;         // per slot: triangle index within that primitive
  std::vector<uint8_t> covered;           // per texel: some triangle touches it (before leak control)
  std::vector<uint8_t> valid;             // per texel: at least one valid sample after leak control
  std::vector<uint8_t> cut;               // per texel: an occluder between it and its right / lower neighbour
                                          // (texels/contact_cuts.h bits); empty where no pair is cut
  size_t layerSize() const { return static_cast<size_t>(width) * height; }
  size_t slotCount() const { return layerSize() * supersample * supersample; }
};

// Coverage-weighted mean of value(slot) over texel t's S×S samples, into mean; false (mean untouched)
// when no sample of the texel has weight. How per-sample results become texel values.
template <class T, class ValueOfSlot>
bool texelMean(const TexelSamples& ts, size_t t, ValueOfSlot&& value, T& mean) {
  T sum(0);
  float weight = 0.0f;
  const size_t layer = ts.layerSize();
  const int layers = ts.supersample * ts.supersample;
  for (int l = 0; l < layers; ++l) {
    const size_t s = static_cast<size_t>(l) * layer + t;
    const float w = ts.positionWeight[s].w;
    if (!(w > 0.0f)) continue;
    sum += w * value(s);
    weight += w;
  }
  if (!(weight > 0.0f)) return false;
  mean = sum / weight;
  return true;
}

// A point of triangle tri at barycentrics b (weights of vertices 1 and 2): geometric normal as wound (+z when
// degenerate), shading normal interpolated from the vertex normals where the primitive has them.
struct SurfacePoint {
  glm::vec3 position, shadingNormal, geometricNormal;
};
SurfacePoint surfacePoint(const Primitive& prim, uint32_t tri, glm::vec2 b);

// Builds samples for every page referenced by the scene's primitives (pages sized as in LightmapRef).
std::vector<TexelSamples> buildTexelSamples(const Scene& scene, const RayTracer& rt, const TexelSampleOptions& options);

}  // namespace irbake
