// Final gather: every texel's bounced light read from the baked map one bounce away, instead of from the
// VPLs that reach it.
//
// The VPL sum at x estimates the indirect irradiance with the walk's few VPLs near x; where few reach (an
// open level's upper gallery, lit only through several bounces) each bake's map there is blotchy, and the
// blotches are 0.5–2 m across, so no texel filter removes them (docs/units.md, "Final gather"). The final
// gather writes instead
//   M'(x) = D(x) + (1/π) ∫_H [Le(y) + ρ(y) M(y)] cosθ dω,
// with D the exactly computed direct light (punctual lights, sun, sky) and M the full baked map (VPLs, clamp
// residual, direct), estimated with cosine rays (pdf cosθ/π: the mean of Le + ρ M over the rays; a uniform
// sky can be left out of D and counted by the rays that miss, L_sky each). M'
// equals M where M is right; where M is blotchy, x sees the blotches averaged over its hemisphere, and the
// first bounce of the direct light, most of an indirectly lit region's light, is read from D, which is
// exact. What remains is the rays' noise, independent texel to texel, which the texel filter averages.
// Small bright emitters make the rays noisy (they are found by chance), so the pipeline uses it only in
// scenes without emissive surfaces. A small surface lit very brightly (a lamp's post top just under the lamp)
// does the same through M: the rare texel whose ray met it would be spread by the filter into a bright
// square. The final pass holds such a texel to outlierRatio × its window's mean and spreads the excess over a
// window about four times as wide, with a soft edge: the light is moved (by up to ~15 texels), not removed,
// so the map's mean keeps it; the moved share is the stats' outlierFraction (the error estimate lists it).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "lightmap/lightmap.h"
#include "transport/directional.h"

namespace irbake {

struct FinalGatherOptions {
  int rays = 16;               // cosine rays per texel sample (fewer on big pages, within rayBudget; the choice
                               // against Cycles: docs/validation.md, "Tried and not kept")
  int minRays = 4;             // never fewer than this per sample
  size_t rayBudget = 48 << 20; // rays over all samples (0: no cap): a level's few million samples still get 16
  int filterRadius = 3;        // the gathered light averaged over (2r+1)² texels on the same surface (0: none)
  glm::vec3 missRadiance{0.0f};  // what a ray that leaves the scene brings: a uniform sky's L when D leaves the sky
                                 // to the gather (the pipeline does: 16 cosine rays per sample instead of the
                                 // sky stage's 8), else 0 (D holds the sky)
  bool interleave = true;      // neighbouring texels' lattices interleaved, one class per texel of a filter window
                               // (the window averages one stratified lattice instead of independent ones)
  uint32_t seed = 0;           // rotates the per-sample ray lattices
  int preRays = 2;             // a first, cheaper gather (these rays per sample, preFilterRadius) whose map the
                               // final pass reads instead of M: the walk's blotches averaged once more before the
                               // final rays see them, which lowers the error against Cycles for few rays
                               // more. 0: off
  int preFilterRadius = 5;     // the first pass's filter (the widest SurfaceFilterCache plan serves it)
  float outlierRatio = 4.0f;   // final pass: a texel's gathered light less its emitted part (Le at the hits)
                               // above this × its window's mean (the filter's window, at least 3×3, the texel
                               // in it) is held there before the filter, and the excess spread over a ~31-texel
                               // soft window (filterGathered): one ray on a tiny, very bright surface no longer
                               // makes a bright square. 0: off
};

struct FinalGatherStats {
  size_t rays = 0;
  int raysPerSample = 0;        // after the budget
  int preRaysPerSample = 0;     // the first pass's (0: none)
  int filterRadius = 0;
  double gatheredFraction = 0;  // Σ gathered / Σ M' over valid texels (channel mean): the indirect share
  double changeFraction = 0;    // Σ |M' − M| / Σ M over valid texels: how much the gather moved the map
  double outlierFraction = 0;   // Σ excess spread / Σ M' (channel mean): the light moved by the outlier spread
  size_t outlierTexels = 0;     // texels held to outlierRatio × their window's mean
  double seconds = 0;
  nlohmann::json toJson() const {  // report "finalGather"
    return {{"rays", rays}, {"raysPerSample", raysPerSample}, {"preRaysPerSample", preRaysPerSample}, {"filterRadius", filterRadius},
            {"gatheredFraction", gatheredFraction}, {"changeFraction", changeFraction},
            {"outlierFraction", outlierFraction}, {"outlierTexels", outlierTexels}};
  }
};

// maps: the full bake M on entry (one per page of in.texels), D + the gather on return, at valid texels. With
// preRays, the final pass reads M1 = D + gather(M) (preRays rays, preFilterRadius) instead of M; both unbiased
// where M is, M1 smoother. stats->rays counts both passes.
// direct: D, the same pages' direct light (valid texels read). Invalid texels are left as they are.
// Directional maps (transport/directional.h): with l1 and directL1 (D's L1 pages), the same rays' tangential
// irradiance vector, t = mean of (Le + ρ M) (ω − (ω·n)n) / cosθ over the rays that hit (1/cosθ held to ≤ 10, as
// the compensation's), filtered like the map, replaces l1 at valid texels by directL1 + t. The rays that leave
// add nothing to t: a sky's L1 comes from its own stage. The map's bytes are the same with and without l1.
void finalGather(const BakeInputs& in, const std::vector<Lightmap>& direct, std::vector<Lightmap>& maps,
                 const FinalGatherOptions& options = {}, FinalGatherStats* stats = nullptr,
                 const L1Pages* directL1 = nullptr, L1Pages* l1 = nullptr);

// The gathered term at one point (x on a surface with normal n), `rays` cosine rays with lattice rotation
// (r1, r2), reading maps; a ray that misses brings missRadiance (for tests and tools).
// With tangential, also the rays' tangential irradiance vector (finalGather's t). A hit reads ρ M bilinearly from
// the maps packed with each texel's base colour (in.albedoAtHit's mean over the texel's samples), as the stage
// does; each call packs every map again, so it suits tests and tools, not loops.
glm::vec3 gatherAt(const BakeInputs& in, const std::vector<Lightmap>& maps, const std::vector<int32_t>& mapOfPage,
                   const glm::vec3& x, const glm::vec3& n, int rays, double r1, double r2,
                   const glm::vec3& missRadiance = glm::vec3(0.0f), L1Vectors* tangential = nullptr);

}  // namespace irbake
