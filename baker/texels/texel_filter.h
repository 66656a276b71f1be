// A geometry-aware box filter over a page's texels: smooths a per-texel estimate that is noisy but
// spatially smooth on each surface (the clamp residual, interleaved VPL subsets) without mixing light
// across surfaces: a neighbour counts only if it is valid, on a surface facing the same way and close
// in world space (not just in the atlas, where unrelated charts can touch).
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
                                // brighter side there; Sponza's column feet +12%, docs/accuracy.md)
  bool tent = false;            // weights (r+1−|dx|)(r+1−|dy|) instead of a box: with r = n−1 every
                                // texel class (x mod n, y mod n) gets the same total weight
};

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
  std::vector<glm::vec3> position_, normal_;  // per texel
  std::vector<uint8_t> hasSample_;            // per texel: some sample has weight
  float spacing_ = 0.0f;
};

// A SurfaceFilter's neighbour tests for one set of options and one validity mask, made once (a bit per window
// position per texel): a page filtered many times with the same window (the compensation's sweeps: 5 on
// Sponza's 3.2M-texel page) then pays only for the sums, not for a normal, a distance and a square root per
// neighbour. apply() gives the bits of SurfaceFilter::apply with the same arguments. Costs 16 bytes per texel.
class SurfaceFilterPlan {
 public:
  static constexpr int kMaxRadius = 5;  // (2r + 1)² ≤ 128 window positions per texel
  // options.radius ≤ kMaxRadius (std::invalid_argument otherwise). The plan copies what it needs from filter.
  SurfaceFilterPlan(const SurfaceFilter& filter, const std::vector<uint8_t>& valid, const TexelFilterOptions& options);
  std::vector<glm::vec3> apply(const std::vector<glm::vec3>& values) const;

 private:
  int radius_ = 0;
  std::vector<std::array<uint64_t, 2>> accepted_;  // per texel: bit b = window position b (row-major) counts;
                                                   // none for texels not filtered (invalid, no sample)
  std::vector<ptrdiff_t> offset_;                  // per window position: dy·width + dx
  std::vector<float> weight_;                      // per window position: 1, or the tent weight
};

// One-off forms of the above.
float texelSpacing(const TexelSamples& ts);
std::vector<glm::vec3> filterOnSurface(const TexelSamples& ts, const std::vector<glm::vec3>& values,
                                       const std::vector<uint8_t>& valid, const TexelFilterOptions& options = {});

}  // namespace irbake
