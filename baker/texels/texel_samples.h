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
  size_t layerSize() const { return static_cast<size_t>(width) * height; }
  size_t slotCount() const { return layerSize() * supersample * supersample; }
};

// Builds samples for every page referenced by the scene's primitives (pages sized as in LightmapRef).
std::vector<TexelSamples> buildTexelSamples(const Scene& scene, const RayTracer& rt, const TexelSampleOptions& options);

}  // namespace irbake
