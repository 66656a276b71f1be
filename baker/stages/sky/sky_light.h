// The sky's direct light (Scene::environment), traced with rays into the maps after either VPL backend:
//   E(x)/π = (1/π) ∫_H L(ω) cosθ V(x, ω) dω.
// A uniform sky is sampled by cosine (each ray then contributes L·V exactly, so an open plane gets L with
// no noise); an environment map by multiple importance sampling, half the rays by cosine and half by the
// map's luminance, balance heuristic (a sun-like texel is found by the second strategy, a broad sky by
// the first). Rays per sample follow a rotated Fibonacci lattice; the result is smoothed on the surface
// by the texel filter. The sky's bounces are VPLs from the walk (vpl/walk.cpp), not this stage.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "transport/directional.h"

namespace irbake {

struct SkyLightOptions {
  int raysPerSample = 64;    // per texel sample (halved per strategy for a map)
  int maxRays = 8 << 20;     // budget over all samples: fewer rays per sample on big pages (never below minRays)
  int minRays = 8;           // per sample at least (the pipeline asks 4 where the final gather counts a uniform
                             // sky itself and this stage's light is read only at the gather's hits)
  int filterRadius = 3;      // (2r+1)² window of the texel filter on the same surface; 0: none. Where a thin
                             // slice of sky shows, a few rays per sample leave texel-sized blotches otherwise
  bool interleave = true;    // the lattices of a filter window's texels interleaved (texels/sample_lattice.h)
                             // instead of rotated independently
  uint32_t seed = 0;         // rotates the per-sample lattices
};

struct SkyLightStats {
  size_t rays = 0;
  int raysPerSample = 0;
  double seconds = 0.0;
  nlohmann::json toJson() const { return {{"rays", rays}, {"raysPerSample", raysPerSample}}; }  // report "sky"
};

// Adds the sky's direct light to every valid texel of `maps` (one per in.texels page). No sky: no-op.
void addSkyLight(const BakeInputs& in, std::vector<Lightmap>& maps, const SkyLightOptions& options = {},
                 SkyLightStats* stats = nullptr);

// Directional maps (transport/directional.h): adds the sky's tangential irradiance vector to the L1 pages
// (axes: x, y, z, one Lightmap per in.texels page each) at every texel valid there; the same rays and
// seeds as addSkyLight, filtered alike. Traced again: only --directional bakes pay for it. No sky: no-op.
void addSkyLightDirectional(const BakeInputs& in, std::array<std::vector<Lightmap>, 3>& axes,
                            const SkyLightOptions& options = {});

// What skyLightAt's rays give as the tangential irradiance vector t at (x, n).
L1Vectors skyDirectionalAt(const BakeInputs& in, const glm::vec3& x, const glm::vec3& n, int rays, double r1, double r2);

// The value one texel sample at (x, n) receives from the sky with `rays` rays (for tests and tools).
glm::vec3 skyLightAt(const BakeInputs& in, const glm::vec3& x, const glm::vec3& n, int rays, double r1, double r2);

}  // namespace irbake
