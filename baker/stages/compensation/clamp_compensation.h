// Recovers the energy the VPL clamp removed, for any backend, by a short final gather into the baked map.
//
// The clamped VPL sum estimates ∫ L(y→x) min(G, B) V dA; what is missing is
//   C(x)/π-units = ∫ L(y→x) · max(0, 1 − B/G(x, y)) · G V dA,
// non-zero only where a surface is closer than the clamp radius (corners, contacts). With cosine-sampled
// rays (pdf cosθ/π) from x its estimator is the mean of w · L(y→x), w = max(0, 1 − B/G) at the hit y.
// Kollig & Keller (2004) estimate L(y→x) by recursing into the VPL sum at y; here it is read from the map
// that was just baked: L(y→x) = Le(y) + ρ(y) · M(y), M = irradiance/π at y (bilinear over valid texels).
// M(y) itself lacks y's residual, so the residual is iterated (Jacobi sweeps over the stored hits, one more
// bounce inside the clamp radius each: an open corner converges in 2–3, the 20 cm gap between a cupboard and
// a wall needs ~6; the sweeps stop when one changes the map by less than sweepTolerance). Rays whose hit is farther
// than the clamp radius (w = 0) cost one intersection and are forgotten; only the few hits with w > 0
// are kept, so later sweeps cost lookups only. Samples whose first rays found clamped transport get more
// rays (corners are where the residual is large and its variance lives).
// With --directional the same hits, kept with their directions, give the residual's L1 share
// (applyDirectional). Limits: back faces and surfaces without a light map return only what they emit.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "lightmap/lightmap.h"

namespace irbake {

// k of deriveClampBound when the residual is compensated: a tighter clamp (clamp radius ≈ 9 VPL spacings
// instead of 2.3) removes the VPL splotches and the gather gives the near-field back; a larger k lets the
// gather's own noise (its rays finding a small bright emitter) dominate (docs/validation.md).
constexpr double kCompensatedClampVplsPerMean = 256.0;
// The same without small emitters (punctual lights, sun, sky, or emissive surfaces covering at least half the
// surface, which the gather's rays meet anyway): the gather then meets no small bright emitter, so a tighter
// clamp hands more of the transport to the gather instead of to the few VPLs that reach a dim region or, under
// emitters everywhere, that lie near a corner (their count was the corner's noise); past this a sharp sunlit map
// makes the gather noisy in close-ups.
constexpr double kCompensatedClampVplsPerMeanNoEmitters = 1024.0;

struct ClampCompensationOptions {
  int rays = 16;               // cosine rays per texel sample in the first round (fewer if over the budget)
  int minRays = 4;             // never fewer than this per sample
  size_t rayBudget = 1 << 21;  // first-round rays over all samples (0: no cap); large pages get fewer rays
                               // per sample and a wider filter instead
  int refineRays = 112;        // extra rays (scaled like rays, within the budget again) at samples next to one
  float refineFraction = 0.0f; // (own texel or the 8 around, itself left out) where at least this fraction of
                               // the first rays hit clamped transport (0: any hit)
  std::optional<int> filterRadius;  // residual smoothed over (2r+1)² texels on the same surface (0: none); unset:
                                    // auto (below 32 rays: r ≤ 4 with r texels ≤ r_c / 20, r_c = 1/√B)
  int sweeps = 8;              // at most this many Jacobi sweeps; each reads the map with the previous sweep's
                               // residual added
  double sweepTolerance = 5e-4;  // stop when a sweep changes the summed map by less than this fraction (< 0: never),
                                 // or when the extrapolated tail is known to within it
  bool extrapolateTail = true;   // once the sweeps' ratio settles, add the remaining sweeps as a geometric tail
  bool filterEachSweep = true;   // false: the summed residual filtered once, after the last sweep (the pipeline's
                                 // choice with the final gather, whose rays and windows average this map again)
  int classMix = 1;            // the interleave's n: each sweep's residual mixed like the n×n classes' VPL sum
                               // (texel_filter.h, classMixFilter), so a border texel's one-sided window averages the
                               // smooth sum of both, not the clamped part's steep rise off a concave edge; 1: none
  uint32_t seed = 0;           // rotates the per-sample ray lattices (deterministic per seed)
  bool directional = false;    // keep each kept hit's direction for applyDirectional (12 bytes a hit)
};

struct ClampCompensationStats {
  size_t raysTraced = 0;      // intersections
  size_t samplesRefined = 0;  // texel samples that got the extra rays
  size_t hitsKept = 0;        // hits with w > 0 (stored for the sweeps)
  int raysPerSample = 0;      // first round, after the budget
  int filterRadius = 0;       // as applied (largest over pages)
  int sweeps = 0;             // Jacobi sweeps run
  bool tailExtrapolated = false;  // the sweeps after the last were added as a geometric tail
  double addedFraction = 0;   // residual / map before, summed over valid texels (channel mean)
  double seconds = 0;
  nlohmann::json toJson() const {  // report "compensation" (seconds go to timings)
    return {{"rays", raysTraced},       {"samplesRefined", samplesRefined}, {"hitsKept", hitsKept},
            {"addedFraction", addedFraction}, {"raysPerSample", raysPerSample}, {"filterRadius", filterRadius},
            {"sweeps", sweeps}, {"tailExtrapolated", tailExtrapolated}};
  }
};

// The compensation in two halves. Construction traces the rays and keeps the hits inside the clamp
// radius: it reads the geometry and the texel samples only, not the maps, so it can run while a backend
// bakes them (the pipeline does so for the GL backend, whose rasteriser leaves CPU time idle; on a GPU
// the whole trace hides behind it). apply() then runs the sweeps on the baked maps. `in` must outlive it.
// in.eval.clampBound is B: with B ≤ 0, or the VPLs not evaluated, apply() changes nothing.
class ClampGather {
 public:
  explicit ClampGather(const BakeInputs& in, const ClampCompensationOptions& options = {});
  ~ClampGather();
  ClampGather(const ClampGather&) = delete;
  ClampGather& operator=(const ClampGather&) = delete;
  // Adds the residual to maps (one per page of the inputs' texels, same order and size); only valid texels change.
  void apply(std::vector<Lightmap>& maps, ClampCompensationStats* stats = nullptr) const;
  // Directional maps (transport/directional.h): adds the residual's tangential irradiance vector to the L1
  // pages (axes x, y, z; one Lightmap per page each). Call after apply, with the maps it returned: at the
  // sweeps' fixed point the residual is one more gather from the final map, R = Σ w (Le + ρ M(y)) / n, and
  // this is that gather with each hit's term along its direction ω: t += term · (ω − (ω·n)n) / cosθ (the
  // cosine rays' estimator of the irradiance vector; 1/cosθ held to ≤ 10, which only rays within 6° of the
  // horizon reach). Filtered like the residual. Needs options.directional; otherwise a no-op.
  void applyDirectional(const std::vector<Lightmap>& maps, L1Pages& axes) const;
  double traceSeconds() const;  // the construction's wall time

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace irbake
