// The sun's visibility on a finer lattice where its shadow crosses the probe grid (lightmap/probe_grid.h,
// ProbeSunLevel). A directional light's shadow edge is sharp, and a blend of probes a spacing apart smears it
// over the whole cell even after the visibility fit (light_visibility_fit.h), so a sunlit floor beside a
// shadow reads darker than the sun it gets. Here the light's visibility is traced at every point of a lattice S times finer than the grid
// (one shadow ray each, shared by neighbouring cells), and a cell is refined where that lattice differs from
// the blend of the probes' fitted visibilities by more than a tolerance at some point; the clients then replace
// the blend's sun by the lattice's there. Point visibility is binary (see-through surfaces: lit when at least
// half the light passes), so the lattice is stored as bits.
#pragma once
#include <cstddef>
#include <vector>

#include "evaluators/bake_inputs.h"
#include "lightmap/probe_grid.h"

namespace irbake {

struct SunLevelOptions {
  int subdivisions = 4;     // S per axis: (S+1)³ lattice points per cell; 0: no sun level
  float tolerance = 0.1f;   // refine a cell where |lattice − blend| exceeds this at one of its points
};

struct SunLevelStats {
  size_t cells = 0;  // refined
  size_t rays = 0;   // shadow rays traced
};

// The strongest directional light of the scene (channel mean of its map value), or -1 when there is none.
int strongestDirectionalLight(const std::vector<Light>& lights);

// The sun level of `grid` (positions and validity set) for `light` (a directional light of in.scene), its probes
// carrying `visibility` (one per probe: the fitted value their coefficients hold).
ProbeSunLevel bakeSunLevel(const BakeInputs& in, const LightProbeGrid& grid, size_t light,
                           const std::vector<float>& visibility, const SunLevelOptions& options,
                           SunLevelStats* stats = nullptr);

}  // namespace irbake
