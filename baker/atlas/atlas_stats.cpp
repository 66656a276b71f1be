#include "atlas/atlas_stats.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <numeric>
#include <string>

#include <tbb/parallel_for.h>

#include "atlas/pack.h"

namespace irbake::atlas {
namespace {

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

uint32_t findRoot(std::vector<uint32_t>& parent, uint32_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// The islands of one primitive: faces joined through shared vertex indices (the atlas never shares a vertex
// across charts), or through vertices split only for other attributes (normals, TEXCOORD_0), which share
// position and uv1. Numbered in the order their first triangle appears; returns the island of each vertex.
std::vector<int32_t> islandsOf(const Primitive& prim, size_t& islands) {
  std::vector<uint32_t> parent(prim.positions.size());
  std::iota(parent.begin(), parent.end(), 0u);
  for (size_t t = 0; t < prim.triangleCount(); ++t) {
    const uint32_t a = findRoot(parent, prim.indices[3 * t]);
    for (int k = 1; k < 3; ++k) parent[findRoot(parent, prim.indices[3 * t + k])] = a;
  }
  // Same position and uv1, compared as bytes: sort the vertices by them and join the runs.
  struct Key {
    glm::vec3 p;
    glm::vec2 uv;
  };
  auto bytesLess = [&](uint32_t a, uint32_t b) {
    const Key ka{prim.positions[a], prim.uv1[a]}, kb{prim.positions[b], prim.uv1[b]};
    const int c = std::memcmp(&ka, &kb, sizeof(Key));
    return c < 0 || (c == 0 && a < b);
  };
  std::vector<uint32_t> sorted(prim.positions.size());
  std::iota(sorted.begin(), sorted.end(), 0u);
  std::sort(sorted.begin(), sorted.end(), bytesLess);
  for (size_t i = 1; i < sorted.size(); ++i) {
    const Key a{prim.positions[sorted[i - 1]], prim.uv1[sorted[i - 1]]}, b{prim.positions[sorted[i]], prim.uv1[sorted[i]]};
    if (std::memcmp(&a, &b, sizeof(Key)) == 0) parent[findRoot(parent, sorted[i])] = findRoot(parent, sorted[i - 1]);
  }
  std::vector<int32_t> islandOfRoot(prim.positions.size(), -1), islandOfVertex(prim.positions.size(), -1);
  islands = 0;
  for (size_t t = 0; t < prim.triangleCount(); ++t) {
    const uint32_t root = findRoot(parent, prim.indices[3 * t]);
    if (islandOfRoot[root] < 0) islandOfRoot[root] = int32_t(islands++);
    for (int k = 0; k < 3; ++k) islandOfVertex[prim.indices[3 * t + k]] = islandOfRoot[root];
  }
  return islandOfVertex;
}

// What one run of triangles adds to the figures; runs are joined in a fixed order.
struct Partial {
  std::vector<std::pair<double, double>> ratios;  // (uv area / 3D area, 3D area)
  double uvSum = 0.0, areaSum = 0.0, l2Sum = 0.0;
  size_t flipped = 0, uncovered = 0, overlapping = 0;
};

// The texel grids of the pages, written by many threads at once.
struct PageGrids {
  std::vector<std::vector<uint8_t>> centre;   // 1 where a texel centre lies inside a triangle
  std::vector<std::vector<int32_t>> owner;    // island touching the texel; -1 none, -2 two or more
};

// Marks texel i of `owner` as touched by `island`; true the first time a second island touches it.
// The count of such texels does not depend on the order the triangles arrive in.
bool touch(int32_t& slot, int32_t island) {
  std::atomic_ref<int32_t> owner(slot);
  int32_t seen = owner.load(std::memory_order_relaxed);
  for (;;) {
    if (seen == -2 || seen == island) return false;
    const int32_t next = seen == -1 ? island : -2;
    if (owner.compare_exchange_weak(seen, next, std::memory_order_relaxed)) return next == -2;
  }
}

void measureTriangles(const Primitive& prim, const std::vector<int32_t>& islandOfVertex, int32_t firstIsland,
                      const AtlasPage& pg, size_t page, double diagonal, size_t begin, size_t end, PageGrids& grids,
                      Partial& out) {
  const int w = pg.width, h = pg.height;
  for (size_t t = begin; t < end; ++t) {
    const int32_t island = firstIsland + islandOfVertex[prim.indices[3 * t]];
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
      if (areaUv <= 0.0) ++out.flipped;
      out.ratios.push_back({areaUv / area3d, area3d});
      out.uvSum += areaUv;
      out.areaSum += area3d;
      if (areaUv > 0.0) {  // Sander et al.'s L2 stretch of the map UV -> 3D, from ∂p/∂s and ∂p/∂t
        const glm::dvec3 dPds = (q[0] * (uv[1].y - uv[2].y) + q[1] * (uv[2].y - uv[0].y) + q[2] * (uv[0].y - uv[1].y)) / (2.0 * areaUv);
        const glm::dvec3 dPdt = (q[0] * (uv[2].x - uv[1].x) + q[1] * (uv[0].x - uv[2].x) + q[2] * (uv[1].x - uv[0].x)) / (2.0 * areaUv);
        out.l2Sum += area3d * 0.5 * (glm::dot(dPds, dPds) + glm::dot(dPdt, dPdt));
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
          std::atomic_ref<uint8_t>(grids.centre[page][i]).store(1, std::memory_order_relaxed);
          coversCentre = true;
        }
        if (triangleOverlapsTexel(uv[0], uv[1], uv[2], x, y) && touch(grids.owner[page][i], island)) ++out.overlapping;
      }
    if (!degenerate && !coversCentre) ++out.uncovered;
  }
}

constexpr size_t kTrianglesPerRun = 2048;  // fixed, so the sums' order does not follow the thread count

}  // namespace

void measureAtlas(const Scene& scene, const std::vector<AtlasPage>& pages, AtlasStats& stats) {
  PageGrids grids;
  grids.centre.resize(pages.size());
  grids.owner.resize(pages.size());
  for (size_t p = 0; p < pages.size(); ++p) {
    grids.centre[p].assign(size_t(pages[p].width) * pages[p].height, 0);
    grids.owner[p].assign(size_t(pages[p].width) * pages[p].height, -1);
  }
  const size_t count = scene.primitives.size();
  auto measured = [&](const Primitive& prim) {
    const int page = prim.lightmap.page;
    return page >= 0 && size_t(page) < pages.size() && prim.uv1.size() == prim.positions.size();
  };
  std::vector<std::vector<int32_t>> islandOf(count);
  std::vector<size_t> islandCount(count, 0);
  std::vector<double> diagonal(count, 0.0);
  tbb::parallel_for(size_t(0), count, [&](size_t p) {
    const Primitive& prim = scene.primitives[p];
    if (!measured(prim)) return;
    islandOf[p] = islandsOf(prim, islandCount[p]);
    Bounds3 bounds;
    for (const glm::vec3& q : prim.positions) bounds.extend(q);
    diagonal[p] = bounds.diagonal();
  });
  // Runs of triangles: (primitive, first triangle), numbered islands continuing from one primitive to the next.
  std::vector<std::pair<size_t, size_t>> runs;
  std::vector<int32_t> firstIsland(count, 0);
  size_t islands = 0;
  for (size_t p = 0; p < count; ++p) {
    if (!measured(scene.primitives[p])) continue;
    firstIsland[p] = int32_t(islands);
    islands += islandCount[p];
    for (size_t t = 0; t < scene.primitives[p].triangleCount(); t += kTrianglesPerRun) runs.push_back({p, t});
  }
  std::vector<Partial> partial(runs.size());
  tbb::parallel_for(size_t(0), runs.size(), [&](size_t r) {
    const auto [p, begin] = runs[r];
    const Primitive& prim = scene.primitives[p];
    const size_t end = std::min(prim.triangleCount(), begin + kTrianglesPerRun);
    measureTriangles(prim, islandOf[p], firstIsland[p], pages[size_t(prim.lightmap.page)], size_t(prim.lightmap.page),
                     diagonal[p], begin, end, grids, partial[r]);
  });
  std::vector<std::pair<double, double>> ratios;  // (uv area / 3D area, 3D area)
  double uvSum = 0.0, areaSum = 0.0, l2Sum = 0.0;
  size_t flipped = 0, uncovered = 0, overlapping = 0;
  for (const Partial& part : partial) {
    ratios.insert(ratios.end(), part.ratios.begin(), part.ratios.end());
    uvSum += part.uvSum;
    areaSum += part.areaSum;
    l2Sum += part.l2Sum;
    flipped += part.flipped;
    uncovered += part.uncovered;
    overlapping += part.overlapping;
  }
  double pageArea = 0.0, covered = 0.0;
  for (size_t p = 0; p < pages.size(); ++p) {
    pageArea += double(pages[p].width) * pages[p].height;
    covered += double(std::count(grids.centre[p].begin(), grids.centre[p].end(), uint8_t(1)));
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
