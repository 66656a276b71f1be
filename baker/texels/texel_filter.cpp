#include "texels/texel_filter.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

namespace irbake {

SurfaceFilter::SurfaceFilter(const TexelSamples& ts) : width_(ts.width), height_(ts.height) {
  const size_t layer = ts.layerSize();
  position_.assign(layer, glm::vec3(0.0f));
  normal_.assign(layer, glm::vec3(0.0f));
  hasSample_.assign(layer, 0);
  for (size_t t = 0; t < layer; ++t) {
    if (!texelMean(ts, t, [&](size_t s) { return glm::vec3(ts.positionWeight[s]); }, position_[t])) continue;
    texelMean(ts, t, [&](size_t s) { return glm::vec3(ts.normal[s]); }, normal_[t]);
    const float len = glm::length(normal_[t]);
    if (len > 0.0f) normal_[t] /= len;
    hasSample_[t] = 1;
  }
  // Spacing: median over every other texel's right and lower neighbours on the same surface.
  std::vector<float> d;
  const int W = width_, H = height_;
  auto ok = [&](size_t i) { return i < ts.valid.size() && ts.valid[i] && hasSample_[i]; };
  for (int y = 0; y < H; y += 2)
    for (int x = 0; x < W; x += 2) {
      const size_t i = static_cast<size_t>(y) * W + x;
      if (!ok(i)) continue;
      for (size_t j : {i + 1, i + static_cast<size_t>(W)}) {
        if ((j == i + 1 && x + 1 >= W) || (j != i + 1 && y + 1 >= H) || !ok(j)) continue;
        if (glm::dot(normal_[i], normal_[j]) < 0.99f) continue;
        d.push_back(glm::length(position_[i] - position_[j]));
      }
    }
  if (d.empty()) return;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  spacing_ = d[d.size() / 2];
}

std::vector<glm::vec3> SurfaceFilter::apply(const std::vector<glm::vec3>& values, const std::vector<uint8_t>& valid,
                                            const TexelFilterOptions& options) const {
  return std::move(apply(std::vector<const std::vector<glm::vec3>*>{&values}, valid, options)[0]);
}

std::vector<std::vector<glm::vec3>> SurfaceFilter::apply(const std::vector<const std::vector<glm::vec3>*>& sets,
                                                         const std::vector<uint8_t>& valid,
                                                         const TexelFilterOptions& options) const {
  std::vector<std::vector<glm::vec3>> out;
  for (const std::vector<glm::vec3>* values : sets) out.push_back(*values);
  const int r = std::max(0, options.radius);
  const float h = spacing_;
  if (r == 0 || !(h > 0.0f)) return out;
  const int W = width_, H = height_;
  const size_t setCount = sets.size();
  tbb::parallel_for(0, H, [&](int y) {
    std::vector<glm::vec3> sum(setCount);
    for (int x = 0; x < W; ++x) {
      const size_t i = static_cast<size_t>(y) * W + x;
      if (!valid[i] || !hasSample_[i]) continue;
      const glm::vec3 p = position_[i], n = normal_[i];
      std::fill(sum.begin(), sum.end(), glm::vec3(0.0f));
      float count = 0.0f;
      for (int dy = -r; dy <= r; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= H) continue;
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= W) continue;
          const size_t j = static_cast<size_t>(yy) * W + xx;
          if (!valid[j] || !hasSample_[j]) continue;
          if (j != i) {
            if (glm::dot(n, normal_[j]) < options.minNormalCos) continue;
            const float reach = options.maxSpacings * h * std::sqrt(static_cast<float>(dx * dx + dy * dy));
            const glm::vec3 d = position_[j] - p;
            if (glm::dot(d, d) > reach * reach) continue;
          }
          const float w = options.tent ? static_cast<float>((r + 1 - std::abs(dx)) * (r + 1 - std::abs(dy))) : 1.0f;
          for (size_t s = 0; s < setCount; ++s) sum[s] += w * (*sets[s])[j];
          count += w;
        }
      }
      for (size_t s = 0; s < setCount; ++s) out[s][i] = sum[s] / count;
    }
  });
  return out;
}

float texelSpacing(const TexelSamples& ts) { return SurfaceFilter(ts).spacing(); }

std::vector<glm::vec3> filterOnSurface(const TexelSamples& ts, const std::vector<glm::vec3>& values,
                                       const std::vector<uint8_t>& valid, const TexelFilterOptions& options) {
  return SurfaceFilter(ts).apply(values, valid, options);
}

}  // namespace irbake
