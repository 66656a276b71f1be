// A geometry-aware box filter over a page's texels: smooths a per-texel estimate that is noisy but
// spatially smooth on each surface (the clamp residual, interleaved VPL subsets) without mixing light
// across surfaces: a neighbour counts only if it is valid, on a surface facing the same way, close
// in world space (not just in the atlas, where unrelated charts can touch) and not behind a contact line
// (an occluder standing on the surface between them: texels/contact_cuts.h).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "texels/texel_samples.h"

namespace irbake {

struct TexelFilterOptions {
  int radius = 1;               // window (2r+1)² texels
  float minNormalCos = 0.95f;   // neighbour's normal within ≈ 18° of the centre's
  float maxSpacings = 1.5f;     // neighbour at most (offset in texels) × this × texel spacing away in space
  bool symmetric = true;        // a neighbour counts only with its mirror image (−dx, −dy): the window's
                                // centroid stays on the texel, so a gradient is not biased where the
                                // window is cut (contact lines, chart borders: a one-sided window read the
                                // brighter side there: docs/units.md)
  bool tent = false;            // weights (r+1−|dx|)(r+1−|dy|) instead of a box: with r = n−1 every
                                // texel class (x mod n, y mod n) gets the same total weight
};

// The interleave's class mix (n×n texel classes, stages/interleave): a tent of half-width n (radius n − 1), not
// symmetric, so that every class keeps its share of the window where a chart border cuts it. The clamp
// compensation's residual, the complement of the clamped VPL sum, gets the same window (the sum they make is
// smooth where each alone is steep: near concave edges and contacts). n ≤ 1: radius 0 (no mix).
inline TexelFilterOptions classMixFilter(int n) {
  TexelFilterOptions o;
  o.radius = n > 1 ? n - 1 : 0;
  o.tent = true;
  o.symmetric = false;
  return o;
}

// The filter over one page: each texel's mean position and normal (over its S×S samples) and the page's
// texel spacing, computed once, so one page can be filtered many times (the compensation's sweeps).
class SurfaceFilter {
 public:
  explicit SurfaceFilter(const TexelSamples& ts);
  // World-space distance between horizontally or vertically adjacent valid texels (median over pairs on
  // the same surface); 0 when the page has no such pair.
  float spacing() const { return spacing_; }
  // values and valid: one per texel of the page. Invalid texels are returned unchanged.
  std::vector<glm::vec3> apply(const std::vector<glm::vec3>& values, const std::vector<uint8_t>& valid,
                               const TexelFilterOptions& options = {}) const;
  // The same filter on several value sets of the page at once (the map and its directional L1 pages): the
  // neighbour tests, most of the cost, are made once for all of them. Each result has the bits the
  // one-set apply gives that set.
  std::vector<std::vector<glm::vec3>> apply(const std::vector<const std::vector<glm::vec3>*>& sets,
                                            const std::vector<uint8_t>& valid,
                                            const TexelFilterOptions& options = {}) const;

 private:
  friend class SurfaceFilterPlan;
  // Whether texel j = i + (dx, dy) counts in i's window (i valid with a sample; j inside the page).
  bool accepts(size_t i, size_t j, int dx, int dy, const std::vector<uint8_t>& valid,
               const TexelFilterOptions& options) const;
  // Calls visit(j, dx, dy) for every accepted texel j of texel (x, y)'s window of radius r, row by row.
  template <class Visit>
  void forEachAccepted(int x, int y, int r, const std::vector<uint8_t>& valid, const TexelFilterOptions& options,
                       Visit&& visit) const;

  int width_ = 0, height_ = 0;
  // Whether texel (x, y) reaches (x + dx, y + dy) along one of the two L-shaped texel paths (row first or
  // column first) without crossing a contact cut (TexelSamples::cut): symmetric, as accepts() must be.
  bool uncut(int x, int y, int dx, int dy) const;

  std::vector<glm::vec3> position_, normal_;  // per texel
  std::vector<uint8_t> hasSample_;            // per texel: some sample has weight
  // Contact cuts as prefix counts (empty without cuts): rowCuts_[y·W + x] counts the cut steps (x′, y) → (x′ + 1, y)
  // with x′ < x; colCuts_[y·W + x] the cut steps (x, y′) → (x, y′ + 1) with y′ < y.
  std::vector<uint32_t> rowCuts_, colCuts_;
  float spacing_ = 0.0f;
};

// A SurfaceFilter's neighbour tests over one validity mask, made once for every window up to a radius: a page
// filtered several times (the interleave's mix, the sky, the compensation's sweeps, the final gather) then pays
// only for the sums. The test is symmetric
// (normals and distance compare the same both ways, and both texels must be valid), so each pair of texels is
// tested once: 60 tests per texel at radius 5. apply() gives the bits of SurfaceFilter::apply with the same
// arguments for any radius up to the plan's, symmetric or not, box or tent. Costs 16 bytes per texel.
class SurfaceFilterPlan {
 public:
  static constexpr int kMaxRadius = 5;  // (2r + 1)² − 1 = 120 neighbours: 60 forward, a 64-bit word each way
  // Tests every window position up to options.radius ≤ kMaxRadius (std::invalid_argument otherwise) with
  // options' thresholds; options.symmetric and options.tent are only apply()'s default. Copies what it needs.
  SurfaceFilterPlan(const SurfaceFilter& filter, const std::vector<uint8_t>& valid, const TexelFilterOptions& options);
  int radius() const { return radius_; }
  // Whether apply(…, options) gives SurfaceFilter::apply(…, valid, options): the same thresholds, a radius
  // within the plan's, and the same texels filtered (valid with a sample: masks may differ where none is).
  bool serves(const std::vector<uint8_t>& valid, const TexelFilterOptions& options) const;
  // With the options the plan was made with, or with options as served (serves()).
  std::vector<glm::vec3> apply(const std::vector<glm::vec3>& values) const;
  std::vector<glm::vec3> apply(const std::vector<glm::vec3>& values, const TexelFilterOptions& options) const;
  // options as served (serves()); several value sets share the window walk, each gets its one-set bits.
  std::vector<std::vector<glm::vec3>> apply(const std::vector<const std::vector<glm::vec3>*>& sets,
                                            const TexelFilterOptions& options) const;

 private:
  static constexpr uint64_t kFiltered = uint64_t(1) << 63;  // in forward_: the texel is filtered (valid, sampled)
  int radius_ = 0;
  bool unchanged_ = false;  // the page has no spacing: every filter returns it as it is
  TexelFilterOptions options_;
  std::vector<uint8_t> hasSample_;  // the filter's, per texel (serves())
  // Per texel, bit k: the pair with forward neighbour k (window positions after the centre, row-major) counts;
  // backward_ bit k: the pair with its mirror image (−dx, −dy) counts. Symmetric windows take forward & backward.
  std::vector<uint64_t> forward_, backward_;
  std::vector<ptrdiff_t> offset_;  // per forward neighbour: dy·width + dx
  std::vector<int> dx_, dy_;       // per forward neighbour
};

// One-off forms of the above.
float texelSpacing(const TexelSamples& ts);
std::vector<glm::vec3> filterOnSurface(const TexelSamples& ts, const std::vector<glm::vec3>& values,
                                       const std::vector<uint8_t>& valid, const TexelFilterOptions& options = {});

}  // namespace irbake
