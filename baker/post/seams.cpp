// Seam stitching: the same smooth 3D edge drawn in two charts must show the same light on both sides.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "post/post.h"

namespace irbake {
namespace {

// A 3D edge keyed by its quantised endpoints in a fixed order (so both triangles find the same key).
struct EdgeKey {
  std::array<int64_t, 6> q;
  bool operator==(const EdgeKey& o) const { return q == o.q; }
};
struct EdgeKeyHash {
  size_t operator()(const EdgeKey& k) const {
    uint64_t h = 1469598103934665603ull;
    for (int64_t v : k.q) h = (h ^ static_cast<uint64_t>(v)) * 1099511628211ull;
    return static_cast<size_t>(h);
  }
};

// One triangle's view of an edge, endpoints in key order.
struct EdgeSide {
  int page;
  glm::vec2 uv0, uv1;
  glm::vec3 n0, n1;
};

std::array<int64_t, 3> quantise(const glm::vec3& p, double cell) {
  return {static_cast<int64_t>(std::llround(p.x / cell)), static_cast<int64_t>(std::llround(p.y / cell)),
          static_cast<int64_t>(std::llround(p.z / cell))};
}

// Bilinear taps of one lookup (same convention as sampleLightmap): up to 4 (texel index, weight).
struct Tap {
  size_t index;
  double weight;
};
void bilinearTaps(int w, int h, glm::vec2 uv, double sign, std::vector<Tap>& out, size_t pageOffset) {
  double fx = double(uv.x) * w - 0.5, fy = double(uv.y) * h - 0.5;
  int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  double tx = fx - x0, ty = fy - y0;
  auto idx = [&](int x, int y) {
    x = std::clamp(x, 0, w - 1);
    y = std::clamp(y, 0, h - 1);
    return pageOffset + static_cast<size_t>(y) * w + x;
  };
  out.push_back({idx(x0, y0), sign * (1 - tx) * (1 - ty)});
  out.push_back({idx(x0 + 1, y0), sign * tx * (1 - ty)});
  out.push_back({idx(x0, y0 + 1), sign * (1 - tx) * ty});
  out.push_back({idx(x0 + 1, y0 + 1), sign * tx * ty});
}

// Seam samples as sparse rows r_s with r_s·x = bilinear_A − bilinear_B; indices are global texel
// indices (page offset + texel).
struct SeamRows {
  std::vector<size_t> start;  // row s spans taps[start[s], start[s+1])
  std::vector<Tap> taps;
};

SeamRows buildRows(const std::vector<Lightmap>& maps, const std::vector<size_t>& offsets,
                   const std::vector<SeamEdge>& seams, const SeamOptions& options) {
  SeamRows rows;
  rows.start.push_back(0);
  for (const SeamEdge& e : seams) {
    if (e.pageA < 0 || e.pageB < 0 || e.pageA >= int(maps.size()) || e.pageB >= int(maps.size())) continue;
    const Lightmap& a = maps[e.pageA];
    const Lightmap& b = maps[e.pageB];
    if (a.size() == 0 || b.size() == 0) continue;
    double lenA = glm::length((e.uvA1 - e.uvA0) * glm::vec2(a.width, a.height));
    double lenB = glm::length((e.uvB1 - e.uvB0) * glm::vec2(b.width, b.height));
    int n = std::max(2, static_cast<int>(std::ceil(std::max(lenA, lenB) * options.samplesPerTexel)) + 1);
    for (int k = 0; k < n; ++k) {
      float t = (k + 0.5f) / n;
      bilinearTaps(a.width, a.height, glm::mix(e.uvA0, e.uvA1, t), +1.0, rows.taps, offsets[e.pageA]);
      bilinearTaps(b.width, b.height, glm::mix(e.uvB0, e.uvB1, t), -1.0, rows.taps, offsets[e.pageB]);
      rows.start.push_back(rows.taps.size());
    }
  }
  return rows;
}

std::vector<size_t> pageOffsets(const std::vector<Lightmap>& maps) {
  std::vector<size_t> off(maps.size() + 1, 0);
  for (size_t i = 0; i < maps.size(); ++i) off[i + 1] = off[i] + maps[i].size();
  return off;
}

double rowsMismatch(const std::vector<Lightmap>& maps, const std::vector<size_t>& offsets, const SeamRows& rows) {
  size_t count = rows.start.size() - 1;
  if (count == 0) return 0.0;
  auto texel = [&](size_t g) -> const glm::vec3& {
    size_t p = std::upper_bound(offsets.begin(), offsets.end(), g) - offsets.begin() - 1;
    return maps[p].texels[g - offsets[p]];
  };
  double sum = 0.0;
  for (size_t s = 0; s < count; ++s) {
    glm::dvec3 d(0.0);
    for (size_t k = rows.start[s]; k < rows.start[s + 1]; ++k) d += rows.taps[k].weight * glm::dvec3(texel(rows.taps[k].index));
    sum += glm::dot(d, d) / 3.0;
  }
  return std::sqrt(sum / double(count));
}

}  // namespace

std::vector<SeamEdge> findSeams(const Scene& scene, const SeamOptions& options) {
  double cell = std::max(1e-12, double(options.positionTolerance) * std::max(1e-6f, scene.bounds().diagonal()));
  std::unordered_map<EdgeKey, std::vector<EdgeSide>, EdgeKeyHash> edges;
  for (const Primitive& prim : scene.primitives) {
    if (prim.lightmap.page < 0 || prim.uv1.size() != prim.positions.size()) continue;
    bool haveNormals = prim.normals.size() == prim.positions.size();
    for (size_t t = 0; t + 2 < prim.indices.size(); t += 3) {
      for (int e = 0; e < 3; ++e) {
        uint32_t i0 = prim.indices[t + e], i1 = prim.indices[t + (e + 1) % 3];
        auto q0 = quantise(prim.positions[i0], cell), q1 = quantise(prim.positions[i1], cell);
        if (q0 == q1) continue;  // degenerate edge
        if (q1 < q0) {
          std::swap(q0, q1);
          std::swap(i0, i1);
        }
        EdgeKey key{{q0[0], q0[1], q0[2], q1[0], q1[1], q1[2]}};
        glm::vec3 n0 = haveNormals ? prim.normals[i0] : glm::vec3(0.0f);
        glm::vec3 n1 = haveNormals ? prim.normals[i1] : glm::vec3(0.0f);
        edges[key].push_back({prim.lightmap.page, prim.uv1[i0], prim.uv1[i1], n0, n1});
      }
    }
  }
  std::vector<SeamEdge> seams;
  const float uvTol = 1e-6f;
  for (const auto& [key, sides] : edges) {
    // Manifold edges only: an edge shared by three or more triangles has no single "other side".
    if (sides.size() != 2) continue;
    const EdgeSide& a = sides[0];
    const EdgeSide& b = sides[1];
    bool sameUv = a.page == b.page && glm::length(a.uv0 - b.uv0) < uvTol && glm::length(a.uv1 - b.uv1) < uvTol;
    if (sameUv) continue;  // an edge inside one chart
    // A crease (flat-shaded box corner) is not a seam: light there may legitimately differ.
    if (glm::dot(a.n0, b.n0) < options.normalCosTolerance || glm::dot(a.n1, b.n1) < options.normalCosTolerance) continue;
    seams.push_back({a.page, b.page, a.uv0, a.uv1, b.uv0, b.uv1});
  }
  // Deterministic order (the hash map's is not).
  std::sort(seams.begin(), seams.end(), [](const SeamEdge& x, const SeamEdge& y) {
    auto kx = std::make_tuple(x.pageA, x.uvA0.x, x.uvA0.y, x.uvA1.x, x.uvA1.y);
    auto ky = std::make_tuple(y.pageA, y.uvA0.x, y.uvA0.y, y.uvA1.x, y.uvA1.y);
    return kx < ky;
  });
  return seams;
}

double seamMismatch(const std::vector<Lightmap>& maps, const std::vector<SeamEdge>& seams, const SeamOptions& options) {
  auto offsets = pageOffsets(maps);
  return rowsMismatch(maps, offsets, buildRows(maps, offsets, seams, options));
}

double stitchSeams(std::vector<Lightmap>& maps, const std::vector<SeamEdge>& seams, const SeamOptions& options) {
  auto offsets = pageOffsets(maps);
  SeamRows rows = buildRows(maps, offsets, seams, options);
  size_t rowCount = rows.start.size() - 1;
  if (rowCount == 0) return 0.0;

  // Unknowns: only the texels some seam sample touches; every other texel keeps its value.
  std::unordered_map<size_t, size_t> unknownOf;
  std::vector<size_t> globalOf;
  for (Tap& t : rows.taps) {
    auto [it, inserted] = unknownOf.emplace(t.index, globalOf.size());
    if (inserted) globalOf.push_back(t.index);
    t.index = it->second;  // rows now index unknowns
  }
  const size_t n = globalOf.size();
  auto texel = [&](size_t g) -> glm::vec3& {
    size_t p = std::upper_bound(offsets.begin(), offsets.end(), g) - offsets.begin() - 1;
    return maps[p].texels[g - offsets[p]];
  };
  const double ws = options.seamWeight, wd = options.dataWeight;
  // (ws Σ r rᵀ + wd I) x = wd x0: symmetric positive definite, solved matrix-free by conjugate gradients.
  auto apply = [&](const std::vector<double>& x, std::vector<double>& y) {
    for (size_t i = 0; i < n; ++i) y[i] = wd * x[i];
    for (size_t s = 0; s < rowCount; ++s) {
      double d = 0.0;
      for (size_t k = rows.start[s]; k < rows.start[s + 1]; ++k) d += rows.taps[k].weight * x[rows.taps[k].index];
      d *= ws;
      for (size_t k = rows.start[s]; k < rows.start[s + 1]; ++k) y[rows.taps[k].index] += rows.taps[k].weight * d;
    }
  };
  for (int c = 0; c < 3; ++c) {
    std::vector<double> x0(n), x(n), r(n), p(n), ap(n);
    for (size_t i = 0; i < n; ++i) x[i] = x0[i] = texel(globalOf[i])[c];
    apply(x, ap);
    double bnorm = 0.0;
    for (size_t i = 0; i < n; ++i) {
      r[i] = wd * x0[i] - ap[i];
      p[i] = r[i];
      bnorm += (wd * x0[i]) * (wd * x0[i]);
    }
    double rr = 0.0;
    for (double v : r) rr += v * v;
    const double stop = 1e-20 * std::max(bnorm, 1e-30);
    for (int it = 0; it < options.iterations && rr > stop; ++it) {
      apply(p, ap);
      double pap = 0.0;
      for (size_t i = 0; i < n; ++i) pap += p[i] * ap[i];
      if (!(pap > 0.0)) break;
      double alpha = rr / pap;
      double rrNew = 0.0;
      for (size_t i = 0; i < n; ++i) {
        x[i] += alpha * p[i];
        r[i] -= alpha * ap[i];
        rrNew += r[i] * r[i];
      }
      double beta = rrNew / rr;
      rr = rrNew;
      for (size_t i = 0; i < n; ++i) p[i] = r[i] + beta * p[i];
    }
    for (size_t i = 0; i < n; ++i) texel(globalOf[i])[c] = static_cast<float>(std::isfinite(x[i]) ? x[i] : x0[i]);
  }
  // Mismatch with the rows in global indices again.
  return seamMismatch(maps, seams, options);
}

}  // namespace irbake
