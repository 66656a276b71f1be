#include "texels/contact_cuts.h"

#include <algorithm>
#include <atomic>

#include <tbb/parallel_for.h>

namespace irbake {

void markContactCuts(TexelSamples& ts, const RayTracer& rt) {
  const int W = ts.width, H = ts.height;
  const size_t layer = ts.layerSize();
  std::vector<glm::vec3> position(layer), normal(layer);
  std::vector<uint8_t> has(layer, 0);
  tbb::parallel_for(size_t(0), layer, [&](size_t t) {
    if (!texelMean(ts, t, [&](size_t s) { return glm::vec3(ts.positionWeight[s]); }, position[t])) return;
    texelMean(ts, t, [&](size_t s) { return glm::vec3(ts.normal[s]); }, normal[t]);
    const float len = glm::length(normal[t]);
    if (!(len > 0.0f)) return;
    normal[t] /= len;
    has[t] = 1;
  });
  std::vector<uint8_t> cut(layer, 0);
  std::atomic<bool> any{false};
  tbb::parallel_for(0, H, [&](int y) {
    for (int x = 0; x < W; ++x) {
      const size_t i = static_cast<size_t>(y) * W + x;
      if (!has[i]) continue;
      uint8_t bits = 0;
      for (const auto& [j, bit] : {std::pair<size_t, uint8_t>{x + 1 < W ? i + 1 : i, kCutRight},
                                   std::pair<size_t, uint8_t>{y + 1 < H ? i + W : i, kCutDown}}) {
        if (j == i || !has[j] || glm::dot(normal[i], normal[j]) <= 0.0f) continue;
        const float d = glm::length(position[j] - position[i]);
        if (!(d > 0.0f)) continue;
        const glm::vec3 a = position[i] + 0.5f * d * normal[i], b = position[j] + 0.5f * d * normal[j];
        const float len = glm::length(b - a);
        if (len > 0.0f && rt.occluded(a, (b - a) / len, 0.0f, len)) bits |= bit;
      }
      if (bits) {
        cut[i] = bits;
        any = true;
      }
    }
  });
  if (any) ts.cut = std::move(cut);
  else ts.cut.clear();
}

}  // namespace irbake
