// A scene twice for the light-cull tests: whole (every light as given) and culled (lights without range cut at
// `fraction` of the scene's reference, lights/light_reach.h), with the reach, its grid, one sampled page and
// the direct-light-only inputs of a brute-force and a culled bake.
#pragma once
#include <memory>
#include <vector>

#include "evaluators/bake_inputs.h"
#include "lights/light_reach.h"
#include "raytrace/ray_tracer.h"

namespace irbake::testing {

struct CutLightsCase {
  Scene whole, culled;
  LightReach reach;
  std::unique_ptr<LightGrid> grid;
  std::vector<TexelSamples> pages;
  VplSet vpls;
  std::unique_ptr<RayTracer> wholeRt, culledRt;
  BakeInputs bruteInputs() const;   // the whole scene, no grid
  BakeInputs culledInputs() const;  // the culled scene through its grid
};

// `whole` cut at `fraction`, sampled by `page`.
std::unique_ptr<CutLightsCase> cutLightsCase(Scene whole, float fraction, TexelSamples page);

}  // namespace irbake::testing
