// The ray pilot: what a ray costs in this scene relative to the scene the cost model's per-ray coefficients
// are counted in. A few thousand cosine rays from surface points of the scene, traced as the final gather
// traces them (one origin per packet, the fast BVH), against the same rays in a fixed reference scene (a
// block of houses on a ground, like the calibration towns), each timed on this thread's CPU clock so that the
// machine's load cancels. Interiors (Sponza, the Cornell box) hit a wall with every ray; towns send half their
// rays to the sky.
#pragma once
#include <cstdint>

#include "raytrace/ray_tracer.h"
#include "scene/scene.h"

namespace irbake {

struct RayPilotOptions {
  int points = 512;       // surface points, area-weighted over the mapped triangles
  int pointsPerTriangle = 8;  // of them on each triangle drawn, traced in turn (neighbours, as the bake's texels)
  int raysPerPoint = 16;  // cosine rays from each point (the final gather's count per sample)
  int rounds = 15;        // each scene's rays are traced this many times, alternately; the median ratio counts
  uint64_t seed = 1;      // the points' and the rays' random numbers
};

struct RayPilot {
  double rayCost = 1.0;       // this scene's CPU seconds per ray over the reference scene's, the median over the
                              // rounds (1: no mapped surface)
  double hitFraction = 0.0;   // the share of this scene's pilot rays that hit a surface
  double secondsPerRay = 0.0;           // this scene's fastest round, CPU seconds per ray
  double referenceSecondsPerRay = 0.0;  // the reference scene's, in the same rounds
  long rays = 0;                        // rays traced in one round of this scene
};

// The pilot over `scene` (its mapped primitives are the origins; every primitive occludes), traced by `rt`, the
// scene's own tracer (the bake's, so that no BVH is built twice).
RayPilot measureRayPilot(const Scene& scene, const RayTracer& rt, const RayPilotOptions& options = {});

// The scale of this scene's rays: its seconds per ray over the reference's (1 where either is not positive).
double rayCostScale(double secondsPerRay, double referenceSecondsPerRay);

// The reference scene: 8 x 8 boxed houses, 3 m wide and 4 to 16 m tall on a 5 m grid, on a 40 m ground, their
// faces split into 4 x 4 quads (12,290 triangles).
Scene rayPilotReferenceScene();

}  // namespace irbake
