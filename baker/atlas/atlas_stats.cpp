#include "atlas/atlas_stats.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <string>
#include <unordered_map>

#include "atlas/pack.h"

namespace irbake::atlas {
namespace {

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

uint32_t findRoot(std::vector<uint32_t>& parent, uint32_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

void measureAtlas(const Scene& scene, const std::vector<AtlasPage>& pages, AtlasStats& stats) {
  std::vector<std::vector<uint8_t>> centre(pages.size());
  std::vector<std::vector<int32_t>> owner(pages.size());
  for (size_t p = 0; p < pages.size(); ++p) {
    centre[p].assign(size_t(pages[p].width) * pages[p].height, 0);
    owner[p].assign(size_t(pages[p].width) * pages[p].height, -1);
  }
  std::vector<std::pair<double, double>> ratios;  // (uv area / 3D area, 3D area)
  double uvSum = 0.0, areaSum = 0.0, l2Sum = 0.0;
  size_t islands = 0, flipped = 0, uncovered = 0, overlapping = 0;
  for (const Primitive& prim : scene.primitives) {
    const int page = prim.lightmap.page;
    if (page < 0 || size_t(page) >= pages.size() || prim.uv1.size() != prim.positions.size()) continue;
    const int w = pages[size_t(page)].width, h = pages[size_t(page)].height;
    // Islands: faces joined through shared vertex indices (the atlas never shares a vertex across charts).
    std::vector<uint32_t> parent(prim.positions.size());
    std::iota(parent.begin(), parent.end(), 0u);
    for (size_t t = 0; t < prim.triangleCount(); ++t) {
      const uint32_t a = findRoot(parent, prim.indices[3 * t]);
      for (int k = 1; k < 3; ++k) parent[findRoot(parent, prim.indices[3 * t + k])] = a;
    }
    // Vertices split only for other attributes (normals, TEXCOORD_0) share position and uv1: same chart.
    std::unordered_map<std::string, uint32_t> samePoint;
    for (uint32_t v = 0; v < prim.positions.size(); ++v) {
      std::string key(sizeof(glm::vec3) + sizeof(glm::vec2), '\0');
      std::memcpy(key.data(), &prim.positions[v], sizeof(glm::vec3));
      std::memcpy(key.data() + sizeof(glm::vec3), &prim.uv1[v], sizeof(glm::vec2));
      auto [it, added] = samePoint.try_emplace(key, v);
      if (!added) parent[findRoot(parent, v)] = findRoot(parent, it->second);
    }
    std::vector<int32_t> islandOf(prim.positions.size(), -1);
    Bounds3 bounds;
    for (const glm::vec3& q : prim.positions) bounds.extend(q);
    const double diagonal = bounds.diagonal();
    double meanEdge = 0.0;
    for (size_t t = 0; t < prim.triangleCount(); ++t)
      for (int k = 0; k < 3; ++k)
        meanEdge += glm::length(prim.positions[prim.indices[3 * t + (k + 1) % 3]] - prim.positions[prim.indices[3 * t + k]]);
    meanEdge /= std::max<double>(1.0, 3.0 * prim.triangleCount());
    for (size_t t = 0; t < prim.triangleCount(); ++t) {
      const uint32_t root = findRoot(parent, prim.indices[3 * t]);
      if (islandOf[root] < 0) islandOf[root] = int32_t(islands++);
      const int32_t island = islandOf[root];
      glm::dvec2 uv[3];
      glm::dvec3 q[3];
      for (int k = 0; k < 3; ++k) {
        uv[k] = glm::dvec2(prim.uv1[prim.indices[3 * t + k]]) * glm::dvec2(w, h);
        q[k] = glm::dvec3(prim.positions[prim.indices[3 * t + k]]);
      }
      const double area3d = 0.5 * glm::length(glm::cross(q[1] - q[0], q[2] - q[0]));
      const double areaUv = 0.5 * cross2(uv[1] - uv[0], uv[2] - uv[0]);
      const double longest = std::max({glm::length(q[1] - q[0]), glm::length(q[2] - q[1]), glm::length(q[0] - q[2])});
      const bool degenerate = !(area3d > 1e-6 * diagonal * longest);  // as the atlas mesh decides
      if (!degenerate) {
        if (areaUv <= 0.0) ++flipped;
        ratios.push_back({areaUv / area3d, area3d});
        uvSum += areaUv;
        areaSum += area3d;
        if (areaUv > 0.0) {  // Sander et al.'s L2 stretch of the map UV -> 3D, from ∂p/∂s and ∂p/∂t
          const glm::dvec3 dPds = (q[0] * (uv[1].y - uv[2].y) + q[1] * (uv[2].y - uv[0].y) + q[2] * (uv[0].y - uv[1].y)) / (2.0 * areaUv);
          const glm::dvec3 dPdt = (q[0] * (uv[2].x - uv[1].x) + q[1] * (uv[0].x - uv[2].x) + q[2] * (uv[1].x - uv[0].x)) / (2.0 * areaUv);
          l2Sum += area3d * 0.5 * (glm::dot(dPds, dPds) + glm::dot(dPdt, dPdt));
        }
      }
      const glm::dvec2 lo = glm::min(uv[0], glm::min(uv[1], uv[2])), hi = glm::max(uv[0], glm::max(uv[1], uv[2]));
      const int x0 = std::max(0, int(std::floor(lo.x))), x1 = std::min(w - 1, int(std::ceil(hi.x)) - 1);
      const int y0 = std::max(0, int(std::floor(lo.y))), y1 = std::min(h - 1, int(std::ceil(hi.y)) - 1);
      bool coversCentre = false;
      const double sign = areaUv < 0.0 ? -1.0 : 1.0;
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const size_t i = size_t(y) * w + x;
          const glm::dvec2 c(x + 0.5, y + 0.5);
          if (areaUv != 0.0 && sign * cross2(uv[1] - uv[0], c - uv[0]) >= 0 && sign * cross2(uv[2] - uv[1], c - uv[1]) >= 0 &&
              sign * cross2(uv[0] - uv[2], c - uv[2]) >= 0) {
            centre[size_t(page)][i] = 1;
            coversCentre = true;
          }
          if (triangleOverlapsTexel(uv[0], uv[1], uv[2], x, y)) {
            int32_t& o = owner[size_t(page)][i];
            const int32_t id = island;
            if (o < 0) {
              o = id;
            } else if (o != id && o >= 0) {
              ++overlapping;
              o = -2;  // count each shared texel once
            }
          }
        }
      if (!degenerate && !coversCentre) ++uncovered;
    }
  }
  double pageArea = 0.0, covered = 0.0;
  for (size_t p = 0; p < pages.size(); ++p) {
    pageArea += double(pages[p].width) * pages[p].height;
    covered += double(std::count(centre[p].begin(), centre[p].end(), uint8_t(1)));
  }
  stats.charts = islands;
  stats.overlappingTexels = overlapping;
  stats.flippedTriangles = flipped;
  stats.uncoveredTriangles = uncovered;
  stats.centreUtilisation = pageArea > 0.0 ? covered / pageArea : 0.0;
  if (!ratios.empty() && uvSum > 0.0) {
    const double global = uvSum / areaSum;
    for (auto& r : ratios) r.first /= global;
    std::sort(ratios.begin(), ratios.end());
    auto percentile = [&](double q) {
      double acc = 0.0;
      for (const auto& [ratio, area] : ratios) {
        acc += area;
        if (acc >= q * areaSum) return ratio;
      }
      return ratios.back().first;
    };
    stats.areaStretchP5 = percentile(0.05);
    stats.areaStretchP50 = percentile(0.50);
    stats.areaStretchP95 = percentile(0.95);
    stats.l2Stretch = std::sqrt(l2Sum / areaSum * global);
  }
}

}  // namespace irbake::atlas
