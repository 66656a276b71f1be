#include "texels/texel_area.h"

#include <algorithm>
#include <cmath>

namespace irbake {

std::vector<std::vector<float>> texelWorldAreas(const Scene& scene) {
  int pageCount = 0;
  for (const auto& p : scene.primitives) pageCount = std::max(pageCount, p.lightmap.page + 1);
  std::vector<std::vector<float>> areas(pageCount);
  std::vector<glm::ivec2> sizes(pageCount, glm::ivec2(0));
  for (const auto& p : scene.primitives)
    if (p.lightmap.page >= 0 && sizes[p.lightmap.page].x == 0) sizes[p.lightmap.page] = {p.lightmap.width, p.lightmap.height};
  for (int i = 0; i < pageCount; ++i) areas[i].assign(size_t(std::max(0, sizes[i].x)) * std::max(0, sizes[i].y), 0.0f);

  for (const auto& prim : scene.primitives) {
    if (prim.lightmap.page < 0 || prim.uv1.size() != prim.positions.size()) continue;
    const glm::ivec2 sz = sizes[prim.lightmap.page];
    std::vector<float>& page = areas[prim.lightmap.page];
    for (size_t t = 0; t + 2 < prim.indices.size(); t += 3) {
      uint32_t i0 = prim.indices[t], i1 = prim.indices[t + 1], i2 = prim.indices[t + 2];
      glm::vec2 a = prim.uv1[i0] * glm::vec2(sz), b = prim.uv1[i1] * glm::vec2(sz), c = prim.uv1[i2] * glm::vec2(sz);
      float area2 = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
      if (!(std::abs(area2) > 1e-12f)) continue;
      float area3 = 0.5f * glm::length(glm::cross(prim.positions[i1] - prim.positions[i0], prim.positions[i2] - prim.positions[i0]));
      float perTexel = area3 / (0.5f * std::abs(area2));
      glm::vec2 lo = glm::min(a, glm::min(b, c)), hi = glm::max(a, glm::max(b, c));
      int x0 = std::max(0, int(std::floor(lo.x))), x1 = std::min(sz.x - 1, int(std::ceil(hi.x)));
      int y0 = std::max(0, int(std::floor(lo.y))), y1 = std::min(sz.y - 1, int(std::ceil(hi.y)));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          glm::vec2 p(x + 0.5f, y + 0.5f);
          float u = ((p.x - a.x) * (c.y - a.y) - (p.y - a.y) * (c.x - a.x)) / area2;
          float v = ((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)) / area2;
          if (u < -1e-6f || v < -1e-6f || u + v > 1.0f + 1e-6f) continue;
          float& dst = page[size_t(y) * sz.x + x];
          if (dst == 0.0f) dst = perTexel;  // first triangle wins on shared edges
        }
    }
  }
  return areas;
}

}  // namespace irbake
