#include "texels/texel_filter.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

namespace irbake {
namespace {

// Per texel: the weighted mean position and normal over its S×S samples (w = 0: no sample).
struct TexelGeometry {
  std::vector<glm::vec4> position;  // xyz, w = weight sum
  std::vector<glm::vec3> normal;
};

TexelGeometry texelGeometry(const TexelSamples& ts) {
  TexelGeometry g;
  const size_t layer = ts.layerSize();
  const int layers = ts.supersample * ts.supersample;
  g.position.assign(layer, glm::vec4(0.0f));
  g.normal.assign(layer, glm::vec3(0.0f));
  for (int l = 0; l < layers; ++l)
    for (size_t t = 0; t < layer; ++t) {
      const size_t s = static_cast<size_t>(l) * layer + t;
      const float w = ts.positionWeight[s].w;
      if (!(w > 0.0f)) continue;
      g.position[t] += glm::vec4(w * glm::vec3(ts.positionWeight[s]), w);
      g.normal[t] += w * glm::vec3(ts.normal[s]);
    }
  for (size_t t = 0; t < layer; ++t) {
    if (!(g.position[t].w > 0.0f)) continue;
    g.position[t] = glm::vec4(glm::vec3(g.position[t]) / g.position[t].w, g.position[t].w);
    const float len = glm::length(g.normal[t]);
    if (len > 0.0f) g.normal[t] /= len;
  }
  return g;
}

float spacing(const TexelSamples& ts, const TexelGeometry& g) {
  std::vector<float> d;
  const int W = ts.width, H = ts.height;
  auto ok = [&](size_t i) { return i < ts.valid.size() && ts.valid[i] && g.position[i].w > 0.0f; };
  for (int y = 0; y < H; y += 2)
    for (int x = 0; x < W; x += 2) {
      size_t i = static_cast<size_t>(y) * W + x;
      if (!ok(i)) continue;
      for (size_t j : {i + 1, i + static_cast<size_t>(W)}) {
        if ((j == i + 1 && x + 1 >= W) || (j != i + 1 && y + 1 >= H) || !ok(j)) continue;
        if (glm::dot(g.normal[i], g.normal[j]) < 0.99f) continue;
        d.push_back(glm::length(glm::vec3(g.position[i]) - glm::vec3(g.position[j])));
      }
    }
  if (d.empty()) return 0.0f;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

}  // namespace

float texelSpacing(const TexelSamples& ts) { return spacing(ts, texelGeometry(ts)); }

std::vector<glm::vec3> filterOnSurface(const TexelSamples& ts, const std::vector<glm::vec3>& values,
                                       const std::vector<uint8_t>& valid, const TexelFilterOptions& options) {
  std::vector<glm::vec3> out = values;
  const int r = std::max(0, options.radius);
  const TexelGeometry g = texelGeometry(ts);
  const float h = spacing(ts, g);
  if (r == 0 || !(h > 0.0f)) return out;
  const int W = ts.width, H = ts.height;
  tbb::parallel_for(0, H, [&](int y) {
    for (int x = 0; x < W; ++x) {
      const size_t i = static_cast<size_t>(y) * W + x;
      if (!valid[i] || !(g.position[i].w > 0.0f)) continue;
      const glm::vec3 p(g.position[i]), n(g.normal[i]);
      glm::vec3 sum(0.0f);
      float count = 0.0f;
      for (int dy = -r; dy <= r; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= H) continue;
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= W) continue;
          const size_t j = static_cast<size_t>(yy) * W + xx;
          if (!valid[j] || !(g.position[j].w > 0.0f)) continue;
          if (j != i) {
            if (glm::dot(n, g.normal[j]) < options.minNormalCos) continue;
            const float reach = options.maxSpacings * h * std::sqrt(static_cast<float>(dx * dx + dy * dy));
            const glm::vec3 d = glm::vec3(g.position[j]) - p;
            if (glm::dot(d, d) > reach * reach) continue;
          }
          const float w = options.tent ? static_cast<float>((r + 1 - std::abs(dx)) * (r + 1 - std::abs(dy))) : 1.0f;
          sum += w * values[j];
          count += w;
        }
      }
      out[i] = sum / count;
    }
  });
  return out;
}

}  // namespace irbake
