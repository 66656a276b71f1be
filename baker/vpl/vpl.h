// Virtual point lights from Keller's quasi-random walk.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "common/progress.h"
#include "raytrace/ray_tracer.h"
#include "scene/scene.h"

namespace irbake {

// A cosine (Lambertian) emitter at a surface point: radiant intensity I(ω) = Φ max(0, n·ω) / π.
struct Vpl {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f, 0.0f, 1.0f};
  glm::vec3 power{0.0f};  // Φ, watts (RGB)
  int bounce = 0;         // 0: on an area emitter; j ≥ 1: after j diffuse reflections
};

struct WalkOptions {
  int paths = 1024;        // N: paths started from the lights (area emitters and punctual lights)
  int maxBounces = -1;     // -1 = auto: follow the energy left (ρ̄^j N ≥ 1 path), capped by bounceCap
  int bounceCap = 16;      // hard cap for auto
  uint32_t seed = 0;       // Halton scramble / start offset
  ProgressCallback progress;
};

struct VplSet {
  std::vector<Vpl> vpls;
  std::vector<size_t> countPerBounce;       // index = bounce
  std::vector<glm::dvec3> powerPerBounce;   // watts, index = bounce
  glm::dvec3 emittedPower{0.0};             // area emitters + punctual lights (W)
  double meanReflectivity = 0.0;            // ρ̄ used for the path-count reduction
  int bounces = 0;                          // deepest bounce generated
};

VplSet generateVpls(const Scene& scene, const RayTracer& rt, const WalkOptions& options);

}  // namespace irbake
