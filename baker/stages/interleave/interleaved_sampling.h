// Interleaved sampling (Keller & Heidrich 2001) in light-map space, around any VPL backend.
//
// The texels of a page are split into n×n classes by (x mod n, y mod n); the VPLs into n² subsets
// (per bounce, n² contiguous chunks in path order, power × bounce count / chunk count: each subset alone
// is an unbiased estimate of the full sum, and a chunk of consecutive Halton paths stays stratified).
// Class c evaluates only subset c, so every texel·VPL pair is evaluated once instead of n² times —
// the accumulation cost per VPL drops by n² while every VPL still gets its shadow map once. A tent
// filter of half-width n over the page then mixes the classes in equal parts (weights (n − |d|) per
// axis give each class the same total weight), keeping only neighbours on the same surface
// (texels/texel_filter.h): on a smooth VPL sum this recovers most of the full set's smoothness.
// Only the VPL part is interleaved: punctual lights (exact, one shadow map) are evaluated on every
// texel by a separate call and never filtered, so their shadows stay sharp. The bake composes the pieces
// below (pipeline/bake.cpp, StagedBake: one backend call per block of a class's VPLs, added exactly, then mixed).
#pragma once
#include <vector>

#include <nlohmann/json.hpp>

#include "evaluators/bake_inputs.h"
#include "lightmap/lightmap.h"

namespace irbake {

struct InterleaveStats {
  int classes = 1;        // n²
  int backendCalls = 0;   // one per VPL block (blocks split each class's VPLs) + 1 when there are punctual lights
  nlohmann::json toJson() const { return {{"classes", classes}, {"backendCalls", backendCalls}}; }
};

// The texels of class (cx, cy) as their own pages ((W − cx)/n × (H − cy)/n, rounded up), same page ids.
std::vector<TexelSamples> interleaveClass(const std::vector<TexelSamples>& pages, int n, int cx, int cy);

// The automatic n: the class filter (half-width n texels) must stay well inside the scale on which the
// clamped VPL sum varies, the clamp radius r_c = 1/√B: n = clamp(⌊r_c / (10 h)⌋, 1, maxN), h the median
// texel spacing over the pages (a small box: 14 mm texels at 1024 paths → 1; 1.75 mm texels at 6144 paths,
// r_c = 10.6 cm → 6). At most kMaxAutoInterleave: against Cycles, 6×6 classes beat 4×4 in accuracy for less
// time, while 8×8 blurs (docs/validation.md, "Tried and not kept").
// filters: the bake's surface filters (their spacings), or null.
constexpr int kMaxAutoInterleave = 6;
int chooseInterleave(const std::vector<TexelSamples>& pages, float clampBound, SurfaceFilterCache* filters = nullptr,
                     int maxN = kMaxAutoInterleave);

// The VPLs of each of the n² classes (class c = cx + n·cy): per bounce the c-th contiguous chunk in path
// order, power × bounce count / chunk count. n ≤ 1: one class with every VPL, unscaled, in path order.
std::vector<VplSet> classVplSubsets(const VplSet& vpls, int n);

// Mixes the classes' VPL sums of one page (vplPart, full page, each texel from its own class) with the
// tent of half-width n on the same surface and adds them to map where vplValid (n ≤ 1: added unfiltered).
void addMixedClasses(const TexelSamples& page, int n, const std::vector<glm::vec3>& vplPart,
                     const std::vector<uint8_t>& vplValid, Lightmap& map);
// The same for several coefficients of one page (the map and its directional L1 pages): vplParts[c] into
// *maps[c], each mixed on its own, the filter's neighbour tests shared (the bits of one call per coefficient).
// filters: the bake's surface filters (page must be one of their pages to use them), or null.
void addMixedClasses(const TexelSamples& page, int n, const std::vector<const std::vector<glm::vec3>*>& vplParts,
                     const std::vector<uint8_t>& vplValid, const std::vector<Lightmap*>& maps,
                     SurfaceFilterCache* filters = nullptr);

}  // namespace irbake
