// The scene's emitters with their powers, ready to sample: emissive triangles and punctual lights.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"
#include "sampling/sampling.h"

namespace irbake {

struct EmitterTriangle {
  uint32_t primitive = 0, triangle = 0;
  float area = 0.0f;          // m²
  glm::vec3 normal{0.0f};     // unit geometric normal; emission leaves the front face only
  glm::dvec3 power{0.0};      // π · Le(centroid) · area (W), as Scene::emitterPower
};

struct LightSources {
  std::vector<EmitterTriangle> triangles;  // emissive triangles
  std::vector<glm::dvec3> lightPower;      // per Scene::lights (W); directional: I · π R² through its disc
  glm::dvec3 skyPower{0.0};                // Scene::environment: π R² ∫ L dω through the bounding sphere (W)
  bool hasSky = false;                     // the sky is the last entry of `all`
  std::vector<double> startWeights;  // what `all` samples by: triangles, then lights, then the sky (channel-mean power)
  AliasTable all;       // triangles first, then lights, then the sky, by channel-mean power (the walk's start points)
  AliasTable areaOnly;  // emissive triangles only (next-event estimation in the reference)
  std::vector<int64_t> firstSlot;          // per primitive: slot of its triangle 0 in `triangles`, -1 if not emissive
  glm::vec3 sceneCentre{0.0f};             // centre of the scene bounds
  float sceneRadius = 0.0f;                // radius of the bounding sphere (directional lights' disc)
  glm::dvec3 totalPower{0.0};
  // Probability density (per m²) that areaOnly-sampling picks a point on this triangle, 0 if not an emitter.
  double areaPdf(uint32_t primitive, uint32_t triangle) const;
};

LightSources collectLightSources(const Scene& scene);

// ρ̄: the area-weighted mean over all triangles of the largest channel of the base colour (each
// triangle's albedo averaged at four points, so textures count), clamped to [0, 0.999]. Keller's mean
// reflectivity. The largest channel, not the channel mean: a bounce-j VPL carries Π(a_k/ρ̄) and with the
// mean the strongest channel grows as (a/ρ̄)^j, into splotches of a saturated wall's colour.
double meanReflectivity(const Scene& scene);

}  // namespace irbake
