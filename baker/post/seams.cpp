// Seam stitching: the same smooth 3D edge drawn in two charts must show the same light on both sides.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <unordered_map>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common/error.h"
#include "common/log.h"
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

// One triangle edge in 8 bytes: the 32-bit hash of its key and its corner's global number (the
// corners of all primitives counted in order). Hashes collide about once per 2^32/edges pairs; the
// keys themselves decide within a run of equal hashes.
struct EdgeRef {
  uint32_t hash;    // EdgeKeyHash of the edge's key, folded to 32 bits
  uint32_t corner;  // global corner: cornerBase[primitive] + t + e (edge e of the triangle at t)
};

// The edge's endpoints (vertex indices) in key order, and its key; false for a degenerate edge.
bool edgeKey(const Primitive& prim, uint32_t corner, double cell, EdgeKey& key, uint32_t* i0 = nullptr,
             uint32_t* i1 = nullptr) {
  const uint32_t first = corner - corner % 3;
  uint32_t a = prim.indices[corner], b = prim.indices[first + (corner - first + 1) % 3];
  auto q0 = quantise(prim.positions[a], cell), q1 = quantise(prim.positions[b], cell);
  if (q0 == q1) return false;
  if (q1 < q0) {
    std::swap(q0, q1);
    std::swap(a, b);
  }
  key = EdgeKey{{q0[0], q0[1], q0[2], q1[0], q1[1], q1[2]}};
  if (i0) *i0 = a;
  if (i1) *i1 = b;
  return true;
}

EdgeSide edgeSide(const Primitive& prim, uint32_t corner, double cell) {
  EdgeKey key;
  uint32_t i0 = 0, i1 = 0;
  edgeKey(prim, corner, cell, key, &i0, &i1);
  const bool haveNormals = prim.normals.size() == prim.positions.size();
  return {prim.lightmap.page, prim.uv1[i0], prim.uv1[i1], haveNormals ? prim.normals[i0] : glm::vec3(0.0f),
          haveNormals ? prim.normals[i1] : glm::vec3(0.0f)};
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
  const double cell = std::max(1e-12, double(options.positionTolerance) * std::max(1e-6f, scene.bounds().diagonal()));
  // Every triangle edge as 8 bytes (its key's hash and where it is), sorted so that the triangles
  // sharing a 3D edge sit side by side. A hash map from key to a vector of sides held ~290 bytes per
  // triangle (the bake's peak on large meshes: docs/validation.md, "Memory").
  std::vector<uint64_t> cornerBase(scene.primitives.size() + 1, 0);  // first global corner of each primitive
  for (size_t p = 0; p < scene.primitives.size(); ++p) {
    const Primitive& prim = scene.primitives[p];
    const bool mapped = prim.lightmap.page >= 0 && prim.uv1.size() == prim.positions.size();
    cornerBase[p + 1] = cornerBase[p] + (mapped ? prim.indices.size() / 3 * 3 : 0);
  }
  if (cornerBase.back() > UINT32_MAX)
    throw Error(ErrorCode::InvalidData, scene.sourcePath, "more than 2^32 triangle corners: too large to stitch seams");
  auto locate = [&](uint32_t global, uint32_t& corner) -> const Primitive& {
    const size_t p = std::upper_bound(cornerBase.begin(), cornerBase.end(), uint64_t(global)) - cornerBase.begin() - 1;
    corner = static_cast<uint32_t>(global - cornerBase[p]);
    return scene.primitives[p];
  };
  std::vector<EdgeRef> refs;
  refs.reserve(cornerBase.back());
  for (size_t p = 0; p < scene.primitives.size(); ++p) {
    const Primitive& prim = scene.primitives[p];
    if (cornerBase[p + 1] == cornerBase[p]) continue;
    for (uint32_t corner = 0; corner + cornerBase[p] < cornerBase[p + 1]; ++corner) {
      EdgeKey key;
      if (!edgeKey(prim, corner, cell, key)) continue;  // degenerate edge
      const uint64_t h = EdgeKeyHash()(key);
      refs.push_back({static_cast<uint32_t>(h ^ (h >> 32)), static_cast<uint32_t>(cornerBase[p] + corner)});
    }
  }
  // (hash, corner): within one key the sides keep the order the triangles come in.
  std::sort(refs.begin(), refs.end(), [](const EdgeRef& x, const EdgeRef& y) {
    return x.hash != y.hash ? x.hash < y.hash : x.corner < y.corner;
  });

  std::vector<SeamEdge> seams;
  const float uvTol = 1e-6f;
  auto keyOf = [&](const EdgeRef& r) {
    uint32_t corner = 0;
    const Primitive& prim = locate(r.corner, corner);
    EdgeKey key;
    edgeKey(prim, corner, cell, key);
    return key;
  };
  auto sideOf = [&](const EdgeRef& r) {
    uint32_t corner = 0;
    const Primitive& prim = locate(r.corner, corner);
    return edgeSide(prim, corner, cell);
  };
  // One 3D edge's sides [first, last): a seam when exactly two charts meet there.
  auto consider = [&](const EdgeRef* first, const EdgeRef* last) {
    // Manifold edges only: an edge shared by three or more triangles has no single "other side".
    if (last - first != 2) return;
    const EdgeSide a = sideOf(first[0]);
    const EdgeSide b = sideOf(first[1]);
    bool sameUv = a.page == b.page && glm::length(a.uv0 - b.uv0) < uvTol && glm::length(a.uv1 - b.uv1) < uvTol;
    if (sameUv) return;  // an edge inside one chart
    // A crease (flat-shaded box corner) is not a seam: light there may legitimately differ.
    if (glm::dot(a.n0, b.n0) < options.normalCosTolerance || glm::dot(a.n1, b.n1) < options.normalCosTolerance) return;
    seams.push_back({a.page, b.page, a.uv0, a.uv1, b.uv0, b.uv1});
  };
  for (size_t begin = 0; begin < refs.size();) {
    size_t end = begin + 1;
    while (end < refs.size() && refs[end].hash == refs[begin].hash) ++end;
    if (end - begin == 1) {
      // an edge of one triangle only: a border, never a seam
    } else if (end - begin == 2 && keyOf(refs[begin]) == keyOf(refs[begin + 1])) {
      consider(&refs[begin], &refs[end]);  // the common case: one edge, two triangles
    } else {
      // Several keys under one hash, or one key with many sides: group by the key itself.
      std::vector<std::pair<EdgeKey, EdgeRef>> run;
      for (size_t i = begin; i < end; ++i) run.emplace_back(keyOf(refs[i]), refs[i]);
      std::stable_sort(run.begin(), run.end(), [](const auto& x, const auto& y) { return x.first.q < y.first.q; });
      std::vector<EdgeRef> group;
      for (size_t i = 0; i < run.size();) {
        group.clear();
        size_t j = i;
        for (; j < run.size() && run[j].first == run[i].first; ++j) group.push_back(run[j].second);
        consider(group.data(), group.data() + group.size());
        i = j;
      }
    }
    begin = end;
  }
  // Deterministic order, a total one: a seam's sides and pages decide its place, not the hash.
  std::sort(seams.begin(), seams.end(), [](const SeamEdge& x, const SeamEdge& y) {
    auto kx = std::make_tuple(x.pageA, x.uvA0.x, x.uvA0.y, x.uvA1.x, x.uvA1.y, x.pageB, x.uvB0.x, x.uvB0.y, x.uvB1.x, x.uvB1.y);
    auto ky = std::make_tuple(y.pageA, y.uvA0.x, y.uvA0.y, y.uvA1.x, y.uvA1.y, y.pageB, y.uvB0.x, y.uvB0.y, y.uvB1.x, y.uvB1.y);
    return kx < ky;
  });
  return seams;
}

namespace {

// 1 / (wd + ws Σ_s (r_s)_i²) for every unknown i, from the rows' transpose (each unknown's taps in row order).
std::vector<double> jacobiInverseDiagonal(const std::vector<size_t>& columnStart, const std::vector<Tap>& columns,
                                          double ws, double wd) {
  const size_t n = columnStart.size() - 1;
  std::vector<double> inverseDiagonal(n);
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    double diagonal = wd, rowSum = 0.0;
    for (size_t k = columnStart[i]; k < columnStart[i + 1]; ++k) {
      rowSum += columns[k].weight;  // an unknown can sit twice in one row (clamped taps at a page's edge)
      if (k + 1 == columnStart[i + 1] || columns[k + 1].index != columns[k].index) {
        diagonal += ws * rowSum * rowSum;
        rowSum = 0.0;
      }
    }
    inverseDiagonal[i] = 1.0 / diagonal;
  });
  return inverseDiagonal;
}

}  // namespace

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
  // The rows' transpose: each unknown's taps in row order, so that every unknown of Rᵀd is summed by one thread
  // in a fixed order (the same bits for any thread count).
  std::vector<size_t> columnStart(n + 1, 0);
  for (const Tap& t : rows.taps) ++columnStart[t.index + 1];
  for (size_t i = 0; i < n; ++i) columnStart[i + 1] += columnStart[i];
  std::vector<Tap> columns(rows.taps.size());  // index: the row
  {
    std::vector<size_t> fill(columnStart.begin(), columnStart.end() - 1);
    for (size_t s = 0; s < rowCount; ++s)
      for (size_t k = rows.start[s]; k < rows.start[s + 1]; ++k)
        columns[fill[rows.taps[k].index]++] = {s, rows.taps[k].weight};
  }
  auto texel = [&](size_t g) -> glm::vec3& {
    size_t p = std::upper_bound(offsets.begin(), offsets.end(), g) - offsets.begin() - 1;
    return maps[p].texels[g - offsets[p]];
  };
  const double ws = options.seamWeight, wd = options.dataWeight;
  // (ws Σ r rᵀ + wd I) x = wd x0: symmetric positive definite, solved matrix-free by conjugate gradients, one
  // per colour channel; the three run in step so that each product walks the rows once for all of them.
  std::vector<glm::dvec3> d(rowCount);
  auto apply = [&](const std::vector<glm::dvec3>& x, std::vector<glm::dvec3>& y) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rowCount, 1024), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t s = range.begin(); s != range.end(); ++s) {
        glm::dvec3 sum(0.0);
        for (size_t k = rows.start[s]; k < rows.start[s + 1]; ++k) sum += rows.taps[k].weight * x[rows.taps[k].index];
        d[s] = sum * ws;
      }
    });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i != range.end(); ++i) {
        glm::dvec3 v = wd * x[i];
        for (size_t k = columnStart[i]; k < columnStart[i + 1]; ++k) v += columns[k].weight * d[columns[k].index];
        y[i] = v;
      }
    });
  };
  // Jacobi preconditioner: the diagonal wd + ws Σ_s (r_s)_i². Unknowns that only a seam sample's far bilinear
  // corner touches have a diagonal near wd, the rest near ws: without it the system's condition number is
  // ~ws/wd and plain CG runs into its iteration cap on a level's seams.
  const std::vector<double> inverseDiagonal = jacobiInverseDiagonal(columnStart, columns, ws, wd);
  std::vector<glm::dvec3> x0(n), x(n), r(n), z(n), p(n), ap(n);
  for (size_t i = 0; i < n; ++i) x[i] = x0[i] = glm::dvec3(texel(globalOf[i]));
  apply(x, ap);
  std::array<double, 3> rz{}, stop{};
  std::array<bool, 3> active{};
  for (int c = 0; c < 3; ++c) {
    double bnorm = 0.0, rr = 0.0;
    for (size_t i = 0; i < n; ++i) {
      r[i][c] = wd * x0[i][c] - ap[i][c];
      z[i][c] = inverseDiagonal[i] * r[i][c];
      p[i][c] = z[i][c];
      rz[c] += r[i][c] * z[i][c];
      rr += r[i][c] * r[i][c];
      bnorm += (wd * x0[i][c]) * (wd * x0[i][c]);
    }
    stop[c] = options.tolerance * options.tolerance * std::max(bnorm, 1e-30);
    active[c] = rr > stop[c];
  }
  int its = 0;
  for (int it = 0; it < options.iterations; ++it) {
    if (!active[0] && !active[1] && !active[2]) break;
    its = it + 1;
    apply(p, ap);
    glm::dvec3 pap(0.0), rzNew(0.0), rr(0.0), alpha(0.0), beta(0.0);
    for (size_t i = 0; i < n; ++i) pap += p[i] * ap[i];
    for (int c = 0; c < 3; ++c) {
      active[c] = active[c] && pap[c] > 0.0;
      if (active[c]) alpha[c] = rz[c] / pap[c];
    }
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        if (!active[c]) continue;
        x[i][c] += alpha[c] * p[i][c];
        r[i][c] -= alpha[c] * ap[i][c];
        z[i][c] = inverseDiagonal[i] * r[i][c];
        rzNew[c] += r[i][c] * z[i][c];
        rr[c] += r[i][c] * r[i][c];
      }
    for (int c = 0; c < 3; ++c) {
      if (!active[c]) continue;
      beta[c] = rzNew[c] / rz[c];
      rz[c] = rzNew[c];
    }
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        if (active[c]) p[i][c] = z[i][c] + beta[c] * p[i][c];
    for (int c = 0; c < 3; ++c) active[c] = active[c] && rr[c] > stop[c];
  }
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) texel(globalOf[i])[c] = static_cast<float>(std::isfinite(x[i][c]) ? x[i][c] : x0[i][c]);
  log::debug("seams: " + std::to_string(rowCount) + " samples, " + std::to_string(n) + " texels, " + std::to_string(its) +
             " conjugate-gradient iterations");
  // Mismatch with the rows in global indices again.
  return seamMismatch(maps, seams, options);
}

}  // namespace irbake
