#include <tbb/parallel_for.h>

#include "stages/interleave/interleaved_sampling.h"

#include <algorithm>
#include <cmath>

#include "texels/surface_filter_cache.h"

namespace irbake {

std::vector<TexelSamples> interleaveClass(const std::vector<TexelSamples>& pages, int n, int cx, int cy) {
  std::vector<TexelSamples> out;
  for (const TexelSamples& ts : pages) {
    TexelSamples c;
    c.page = ts.page;
    c.supersample = ts.supersample;
    c.width = std::max(0, (ts.width - cx + n - 1) / n);
    c.height = std::max(0, (ts.height - cy + n - 1) / n);
    const size_t layer = ts.layerSize(), classLayer = c.layerSize();
    const int layers = ts.supersample * ts.supersample;
    c.positionWeight.assign(classLayer * layers, glm::vec4(0.0f));
    c.normal.assign(classLayer * layers, glm::vec4(0.0f));
    c.primitive.assign(classLayer * layers, UINT32_MAX);
    c.triangle.assign(classLayer * layers, 0);
    c.covered.assign(classLayer, 0);
    c.valid.assign(classLayer, 0);
    for (int y = 0; y < c.height; ++y)
      for (int x = 0; x < c.width; ++x) {
        const size_t t = static_cast<size_t>(n * y + cy) * ts.width + (n * x + cx);
        const size_t ct = static_cast<size_t>(y) * c.width + x;
        if (t < ts.covered.size()) c.covered[ct] = ts.covered[t];
        if (t < ts.valid.size()) c.valid[ct] = ts.valid[t];
        for (int l = 0; l < layers; ++l) {
          const size_t s = static_cast<size_t>(l) * layer + t, cs = static_cast<size_t>(l) * classLayer + ct;
          c.positionWeight[cs] = ts.positionWeight[s];
          c.normal[cs] = ts.normal[s];
          if (s < ts.primitive.size()) c.primitive[cs] = ts.primitive[s];
          if (s < ts.triangle.size()) c.triangle[cs] = ts.triangle[s];
        }
      }
    out.push_back(std::move(c));
  }
  return out;
}

int chooseInterleave(const std::vector<TexelSamples>& pages, float clampBound, SurfaceFilterCache* filters, int maxN) {
  std::vector<float> spacings;
  for (const TexelSamples& ts : pages)
    if (float h = texelSpacing(filters, ts); h > 0.0f) spacings.push_back(h);
  if (spacings.empty()) return 1;
  std::nth_element(spacings.begin(), spacings.begin() + spacings.size() / 2, spacings.end());
  const float h = spacings[spacings.size() / 2];
  if (!(clampBound > 0.0f)) return std::max(1, maxN);
  const float clampRadius = 1.0f / std::sqrt(clampBound);
  return static_cast<int>(std::clamp(std::floor(clampRadius / (10.0f * h)), 1.0f, static_cast<float>(std::max(1, maxN))));
}

std::vector<VplSet> classVplSubsets(const VplSet& vpls, int n) {
  if (n <= 1) return {vpls};
  const int m = n * n;
  // VPL indices per bounce, in path order.
  std::vector<std::vector<size_t>> byBounce;
  for (size_t k = 0; k < vpls.vpls.size(); ++k) {
    const size_t b = static_cast<size_t>(std::max(0, vpls.vpls[k].bounce));
    if (b >= byBounce.size()) byBounce.resize(b + 1);
    byBounce[b].push_back(k);
  }
  std::vector<VplSet> subsets(m);
  for (int c = 0; c < m; ++c) {
    VplSet& subset = subsets[c];
    subset.meanReflectivity = vpls.meanReflectivity;
    subset.bounces = vpls.bounces;
    subset.emittedPower = vpls.emittedPower;
    for (const auto& list : byBounce) {
      // Class c takes the c-th contiguous chunk of this bounce's VPLs (in path order): consecutive
      // Halton points stay well stratified, every k-th ones do not (base 2: every 4th point of Φ2
      // lies in one quarter of [0,1)). Scale = the bounce's count over the chunk's, so that each class
      // alone estimates the bounce's whole sum. A bounce with fewer VPLs than classes leaves some chunks
      // empty: there every VPL is in a class of its own and counts m times (the mix averages the m
      // classes, so each VPL is counted exactly once); count/1 would drop (m − count)/m of its light
      // (a level's deep bounces hold fewer VPLs than there are classes).
      const size_t count = list.size(), b0 = count * c / m, b1 = count * (c + 1) / m;
      if (b1 <= b0) continue;
      const float scale = count >= static_cast<size_t>(m) ? static_cast<float>(count) / static_cast<float>(b1 - b0)
                                                          : static_cast<float>(m);
      for (size_t k = b0; k < b1; ++k) {
        Vpl v = vpls.vpls[list[k]];
        v.power *= scale;
        subset.vpls.push_back(v);
      }
    }
  }
  return subsets;
}

void addMixedClasses(const TexelSamples& page, int n, const std::vector<glm::vec3>& vplPart,
                     const std::vector<uint8_t>& vplValid, Lightmap& map) {
  addMixedClasses(page, n, std::vector<const std::vector<glm::vec3>*>{&vplPart}, vplValid, std::vector<Lightmap*>{&map});
}

void addMixedClasses(const TexelSamples& page, int n, const std::vector<const std::vector<glm::vec3>*>& vplParts,
                     const std::vector<uint8_t>& vplValid, const std::vector<Lightmap*>& maps,
                     SurfaceFilterCache* filters) {
  std::vector<std::vector<glm::vec3>> mixed;
  if (n > 1) {
    // Every class must keep its share of the window, which mirror pairs do not (they bias the page border); the
    // one-sided window this leaves at a border reads the clamped sum's inner side, which the compensation's
    // residual, mixed alike, makes up (ClampCompensationOptions::classMix).
    mixed = filterOnSurface(filters, page, vplParts, vplValid, classMixFilter(n));
  }
  for (size_t c = 0; c < maps.size() && c < vplParts.size(); ++c) {
    const std::vector<glm::vec3>& added = n > 1 ? mixed[c] : *vplParts[c];
    Lightmap& map = *maps[c];
    if (map.valid.size() != map.size()) map.valid = page.valid;
    tbb::parallel_for(size_t(0), std::min(map.size(), added.size()), [&](size_t t) {
      if (!vplValid[t]) return;
      map.texels[t] += added[t];
      map.valid[t] = 1;
    });
  }
}

}  // namespace irbake
