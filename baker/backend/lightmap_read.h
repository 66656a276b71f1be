// Reading a baked map at a ray hit: which page the hit surface's light map is on, where on it, and the value
// there. Shared by the stages that gather from the map (backend/compensation, backend/gather).
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "backend/lightmap.h"
#include "raytrace/ray_tracer.h"
#include "scene/scene.h"
#include "texels/texel_samples.h"

namespace irbake {

// Light-map page number → index of its texel page (= its map, in the same order); −1 where none.
inline std::vector<int32_t> mapIndexOfPages(const std::vector<TexelSamples>& texels) {
  std::vector<int32_t> mapOfPage;
  for (size_t i = 0; i < texels.size(); ++i) {
    int page = texels[i].page;
    if (page < 0) continue;
    if (static_cast<size_t>(page) >= mapOfPage.size()) mapOfPage.resize(page + 1, -1);
    mapOfPage[page] = static_cast<int32_t>(i);
  }
  return mapOfPage;
}

// Where a hit lands on the maps: map index (−1: the surface has no light map) and continuous texel
// coordinates (u·W − ½, v·H − ½).
struct MapPoint {
  int map = -1;
  glm::vec2 texel{0.0f};
};

inline MapPoint mapPointOf(const Scene& scene, const std::vector<int32_t>& mapOfPage,
                           const std::vector<TexelSamples>& texels, const RayHit& hit) {
  MapPoint point;
  const Primitive& prim = scene.primitives[hit.primitive];
  const int page = prim.lightmap.page;
  if (page < 0 || static_cast<size_t>(page) >= mapOfPage.size() || mapOfPage[page] < 0 ||
      prim.uv1.size() != prim.positions.size())
    return point;
  const uint32_t* idx = &prim.indices[3 * static_cast<size_t>(hit.triangle)];
  const float b1 = hit.barycentric.x, b2 = hit.barycentric.y;
  const glm::vec2 uv = (1.0f - b1 - b2) * prim.uv1[idx[0]] + b1 * prim.uv1[idx[1]] + b2 * prim.uv1[idx[2]];
  const TexelSamples& m = texels[mapOfPage[page]];
  point.map = mapOfPage[page];
  point.texel = glm::vec2(uv.x * m.width - 0.5f, uv.y * m.height - 0.5f);
  return point;
}

// Bilinear read of irradiance/π over the valid texels of a map (values: one per texel of m, e.g. m.texels);
// the nearest valid texel of the 3×3 neighbourhood when none of the four is valid (chart borders); 0 when
// none at all.
inline glm::vec3 readLightmap(const Lightmap& m, const std::vector<glm::vec3>& value, glm::vec2 t) {
  const int x0 = static_cast<int>(std::floor(t.x)), y0 = static_cast<int>(std::floor(t.y));
  const float fx = t.x - x0, fy = t.y - y0;
  glm::vec3 sum(0.0f);
  float weight = 0.0f;
  for (int dy = 0; dy < 2; ++dy)
    for (int dx = 0; dx < 2; ++dx) {
      const int x = x0 + dx, y = y0 + dy;
      if (x < 0 || y < 0 || x >= m.width || y >= m.height) continue;
      const size_t i = static_cast<size_t>(y) * m.width + x;
      if (!m.valid[i]) continue;
      const float w = (dx ? fx : 1.0f - fx) * (dy ? fy : 1.0f - fy) + 1e-6f;
      sum += w * value[i];
      weight += w;
    }
  if (weight > 0.0f) return sum / weight;
  const int cx = static_cast<int>(std::lround(t.x)), cy = static_cast<int>(std::lround(t.y));
  float best = 1e30f;
  glm::vec3 nearest(0.0f);
  for (int y = cy - 1; y <= cy + 1; ++y)
    for (int x = cx - 1; x <= cx + 1; ++x) {
      if (x < 0 || y < 0 || x >= m.width || y >= m.height) continue;
      const size_t i = static_cast<size_t>(y) * m.width + x;
      if (!m.valid[i]) continue;
      const float d = (x - t.x) * (x - t.x) + (y - t.y) * (y - t.y);
      if (d < best) best = d, nearest = value[i];
    }
  return nearest;
}

}  // namespace irbake
