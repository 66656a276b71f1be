// Importance-driven VPL selection (after Georgiev & Slusallek 2010, "Simple and robust iterative importance
// sampling of virtual point lights", for light maps instead of one camera view): the walk places f times
// the VPLs it keeps; each candidate's contribution is measured at about a thousand random texel samples,
// relative to what those texels receive in all (so a VPL that lights a dim region counts as much as one
// that lights a bright one), I = √(Σ_t (c_t/E_t)²), and it is kept with probability p = clamp(I/I*, p_min, 1),
// carrying Φ/p: unbiased for any p > 0 (E[kept Φ/p] = Φ). Dim regions that only a few VPLs reach (a gallery
// lit through several bounces) then keep all of theirs, while the many VPLs that light already bright texels are
// thinned. A probe's total is its direct light (punctual lights by shadow ray, the sky by cosine rays) plus
// every candidate's clamped contribution; the probes and the systematic draws are seeded, so the bytes are
// deterministic. docs/units.md has the maths.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "raytrace/ray_tracer.h"
#include "scene/scene.h"
#include "texels/texel_samples.h"
#include "vpl/vpl.h"

namespace irbake {

struct VplImportanceOptions {
  std::optional<double> candidateFactor = 1.0;  // f: the walk runs f × the paths and about keepShare × the
                                                // plain walk's count is kept; 1 (default): off, the plain
                                                // walk; unset: auto (a pilot, chooseCandidateFactor; the bake
                                                // runs it only under the final gather). Off in the library:
                                                // without the final gather it trades one region's error for
                                                // another's (docs/validation.md, "Tried and not kept")
  int probes = 1024;             // texel samples the candidates are measured at (uniform over valid samples)
  int pilotProbes = 256;         // auto: the plain walk's VPLs measured at this many probes first, and
  double maxEvenness = 0.3;      // the selection runs only where their evenness (below) is at most this
  double pairBudget = 64.0e6;    // auto f: probes × candidates at most this (each pair one shadow ray at most)
  double maxFactor = 16.0;       // auto f at most this
  double keepShare = 0.5;        // VPLs kept = this × the plain walk's count (the kept ones are the useful
                                 // ones: each meets more receivers, so costs the Embree backend more shadow
                                 // rays; 0.5 of the count costs about the plain walk's backend time)
  double maxBoost = 4.0;         // a kept VPL carries at most this × a plain-walk VPL's power: every candidate
                                 // is kept at least with probability keepFraction / maxBoost (its light is
                                 // never lost, and no rare pick lights a region up as one bright VPL)
  double floorFraction = 0.05;   // a probe's total is taken as at least this × the probes' median
  int skyRays = 64;              // cosine rays per probe for the sky's share of its total (with a sky)
};

// What one selection uses besides the options: set by the bake.
struct VplSelection {
  double keepFraction = 1.0;  // expected share of the candidates kept (1/f)
  float clampBound = 0.0f;    // the geometry-term bound of the contributions (0: none), as the kept set's
  uint64_t seed = 0;
};

struct VplImportanceStats {
  double factor = 1.0;    // f: candidates walked per plain-walk path (set by the bake)
  double evenness = 0.0;  // of the plain walk (auto), 0: not measured
  size_t candidates = 0, kept = 0, probes = 0, litProbes = 0;
  double seconds = 0.0;
  nlohmann::json toJson() const {
    return {{"factor", factor}, {"evenness", evenness}, {"candidates", candidates}, {"kept", kept}, {"probes", probes}, {"litProbes", litProbes}};
  }
};

// The importances I_v of VPLs at `probeCount` probes (the measure the selection uses; litProbes: probes
// that receive any light).
std::vector<double> measureVplImportance(const Scene& scene, const RayTracer& rt, const std::vector<TexelSamples>& pages,
                                         const std::vector<Vpl>& vpls, const VplImportanceOptions& options,
                                         int probeCount, float clampBound, uint64_t seed, size_t* litProbes = nullptr);

// How evenly a walk's VPLs matter, (Σ I)² / (n Σ I²) over options.pilotProbes probes: 1 when every VPL adds
// the same (a closed box: nothing to gain from selecting), near 0 when a few carry what the texels receive
// (an open level whose walk leaves most VPLs on the roof and in the street).
double vplImportanceEvenness(const Scene& scene, const RayTracer& rt, const std::vector<TexelSamples>& pages,
                             const std::vector<Vpl>& vpls, const VplImportanceOptions& options, float clampBound,
                             uint64_t seed);

// Auto f for a plain walk of `plainVpls` VPLs with that evenness: 1 (the walk stays plain) above
// maxEvenness, else ⌊pairBudget / (probes · plainVpls)⌋ within [1, maxFactor]. A set factor is returned as
// is (≥ 1).
double chooseCandidateFactor(const VplImportanceOptions& options, size_t plainVpls, double evenness);

// Thins `vpls` in place (order kept, so bounces stay contiguous); counts and powers per bounce updated.
// Writes the selection's fields of *stats (candidates, kept, probes, litProbes, seconds), not the bake's.
void selectVplsByImportance(const Scene& scene, const RayTracer& rt, const std::vector<TexelSamples>& pages,
                            VplSet& vpls, const VplImportanceOptions& options, const VplSelection& selection,
                            VplImportanceStats* stats = nullptr);

}  // namespace irbake
