// Emitters the probes leave to the clients' exact shading (lightmap/probe_emitters.h; docs/units.md, "Irradiance
// probes"): a small emitter near an object varies over its surface faster than L2 follows (a ceiling light
// close above an object: through the SH its near side reads too dark and its far side too bright). The rule: an emissive primitive
// whose emission is uniform (no emissive texture) and that is planar (every vertex within 0.1% of its extent of
// one plane, every triangle facing the same side) or small (its bounds' diagonal at most half a probe spacing),
// brightest by power first, while the kept triangles total at most `maxTriangles`.
#pragma once
#include <cstdint>
#include <vector>

#include "evaluators/bake_inputs.h"
#include "lightmap/probe_grid.h"

namespace irbake {

struct ExactEmitters {
  std::vector<ProbeEmitter> emitters;    // positions and radiance (Le/π); visibility left empty
  std::vector<uint32_t> primitives;      // the scene primitive of each
  std::vector<uint8_t> exactPrimitive;   // per scene primitive: 1 when kept
  bool contains(uint32_t primitive) const { return primitive < exactPrimitive.size() && exactPrimitive[primitive]; }
};

ExactEmitters chooseExactEmitters(const Scene& scene, float spacing, int maxTriangles);

// Each kept emitter's visibility at every valid probe (grid.position): `samples` shadow rays to points spread by
// area over its triangles on a rotated 2D Fibonacci lattice, each weighted by its solid angle cosθ_y/r²; the
// arriving share, rounded to steps of 1/255 as the export stores it. 1 where the probe sees none of its front
// (nothing to shade there). Fills grid.emitters; returns the rays traced.
size_t bakeEmitterVisibility(const BakeInputs& in, const ExactEmitters& exact, int samples, uint32_t seed,
                             LightProbeGrid& grid);

}  // namespace irbake
