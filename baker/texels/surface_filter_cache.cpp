#include "texels/surface_filter_cache.h"

namespace irbake {

SurfaceFilterCache::SurfaceFilterCache(const std::vector<TexelSamples>& pages) : pages_(pages), cache_(pages.size()) {}
SurfaceFilterCache::~SurfaceFilterCache() = default;

SurfaceFilterCache::Page* SurfaceFilterCache::pageOf(const TexelSamples& ts) {
  for (size_t p = 0; p < pages_.size(); ++p) {
    if (&pages_[p] != &ts) continue;
    Page& page = cache_[p];
    const std::lock_guard<std::mutex> lock(making_);
    if (!page.plan) {
      // The filter's texel means (24 bytes a texel) live only while the plan is made.
      const SurfaceFilter filter(ts);
      page.spacing = filter.spacing();
      TexelFilterOptions o;
      o.radius = SurfaceFilterPlan::kMaxRadius;
      page.plan = std::make_unique<SurfaceFilterPlan>(filter, ts.valid, o);
      ++plansMade_;
    }
    return &page;
  }
  return nullptr;
}

float SurfaceFilterCache::spacing(const TexelSamples& ts) {
  const Page* page = pageOf(ts);
  return page ? page->spacing : SurfaceFilter(ts).spacing();
}

const SurfaceFilterPlan* SurfaceFilterCache::plan(const TexelSamples& ts, const std::vector<uint8_t>& valid,
                                                  const TexelFilterOptions& options) {
  const Page* page = pageOf(ts);
  return page && page->plan->serves(valid, options) ? page->plan.get() : nullptr;
}

std::vector<std::vector<glm::vec3>> SurfaceFilterCache::apply(const TexelSamples& ts,
                                                              const std::vector<const std::vector<glm::vec3>*>& sets,
                                                              const std::vector<uint8_t>& valid,
                                                              const TexelFilterOptions& options) {
  if (const SurfaceFilterPlan* p = plan(ts, valid, options)) return p->apply(sets, options);
  ++fallbacks_;
  return SurfaceFilter(ts).apply(sets, valid, options);
}

std::vector<glm::vec3> SurfaceFilterCache::apply(const TexelSamples& ts, const std::vector<glm::vec3>& values,
                                                 const std::vector<uint8_t>& valid, const TexelFilterOptions& options) {
  return std::move(apply(ts, std::vector<const std::vector<glm::vec3>*>{&values}, valid, options)[0]);
}

std::vector<std::vector<glm::vec3>> filterOnSurface(SurfaceFilterCache* cache, const TexelSamples& ts,
                                                    const std::vector<const std::vector<glm::vec3>*>& sets,
                                                    const std::vector<uint8_t>& valid, const TexelFilterOptions& options) {
  return cache ? cache->apply(ts, sets, valid, options) : SurfaceFilter(ts).apply(sets, valid, options);
}

std::vector<glm::vec3> filterOnSurface(SurfaceFilterCache* cache, const TexelSamples& ts, const std::vector<glm::vec3>& values,
                                       const std::vector<uint8_t>& valid, const TexelFilterOptions& options) {
  return cache ? cache->apply(ts, values, valid, options) : SurfaceFilter(ts).apply(values, valid, options);
}

float texelSpacing(SurfaceFilterCache* cache, const TexelSamples& ts) {
  return cache ? cache->spacing(ts) : SurfaceFilter(ts).spacing();
}

}  // namespace irbake
