// One bake's surface filters: each page's neighbour tests made once (a SurfaceFilterPlan at kMaxRadius over
// the page's validity) and shared by every stage that filters on the surface: the interleave's mix of its
// texel classes, the sky, the compensation's sweeps and the final gather. Four filters that each tested every
// neighbour (r = 5, 2, 4 and 3: 250 tests per texel) become one plan that tests each pair once (60 per texel). A request the plan cannot serve (a wider window, other thresholds,
// another validity mask) is filtered by a SurfaceFilter made for it, with the same bits.
// Thread-safe (the compensation's rays may be traced while the GL backend's classes are mixed).
#pragma once
#include <atomic>
#include <cstddef>
#include <memory>
#include <mutex>
#include <vector>

#include <glm/glm.hpp>

#include "texels/texel_filter.h"
#include "texels/texel_samples.h"

namespace irbake {

class SurfaceFilterCache {
 public:
  // pages must outlive the cache; a page's plan is made on its first use.
  explicit SurfaceFilterCache(const std::vector<TexelSamples>& pages);
  ~SurfaceFilterCache();
  // SurfaceFilter(ts).spacing(); ts one of the pages or not.
  float spacing(const TexelSamples& ts);
  // SurfaceFilter(ts).apply(sets, valid, options), bit for bit.
  std::vector<std::vector<glm::vec3>> apply(const TexelSamples& ts, const std::vector<const std::vector<glm::vec3>*>& sets,
                                            const std::vector<uint8_t>& valid, const TexelFilterOptions& options);
  std::vector<glm::vec3> apply(const TexelSamples& ts, const std::vector<glm::vec3>& values,
                               const std::vector<uint8_t>& valid, const TexelFilterOptions& options);
  size_t plansMade() const { return plansMade_; }
  size_t fallbacks() const { return fallbacks_; }  // requests filtered without a plan (each makes a SurfaceFilter)

 private:
  struct Page {
    float spacing = 0.0f;
    std::unique_ptr<SurfaceFilterPlan> plan;  // null until the page's first use
  };
  Page* pageOf(const TexelSamples& ts);  // made on first use; null for a page not in the list
  // The page's plan when it serves (valid, options) (SurfaceFilterPlan::serves), else null.
  const SurfaceFilterPlan* plan(const TexelSamples& ts, const std::vector<uint8_t>& valid,
                                const TexelFilterOptions& options);
  const std::vector<TexelSamples>& pages_;
  std::vector<Page> cache_;
  std::mutex making_;  // a page's plan is made once, by the first caller
  std::atomic<size_t> plansMade_{0}, fallbacks_{0};
};

// With a cache its plans, without one a SurfaceFilter made for the call: the same bits either way.
std::vector<std::vector<glm::vec3>> filterOnSurface(SurfaceFilterCache* cache, const TexelSamples& ts,
                                                    const std::vector<const std::vector<glm::vec3>*>& sets,
                                                    const std::vector<uint8_t>& valid, const TexelFilterOptions& options);
std::vector<glm::vec3> filterOnSurface(SurfaceFilterCache* cache, const TexelSamples& ts, const std::vector<glm::vec3>& values,
                                       const std::vector<uint8_t>& valid, const TexelFilterOptions& options);
float texelSpacing(SurfaceFilterCache* cache, const TexelSamples& ts);

}  // namespace irbake
