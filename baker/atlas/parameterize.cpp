#include "atlas/parameterize.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "common/maths.h"

namespace irbake::atlas {

double uvArea(const ChartUv& chart, size_t face) {
  const auto& c = chart.corner[face];
  const glm::dvec2 a = chart.uv[c[1]] - chart.uv[c[0]], b = chart.uv[c[2]] - chart.uv[c[0]];
  return 0.5 * (a.x * b.y - a.y * b.x);
}

namespace {

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }
double orient(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) { return cross2(b - a, c - a); }

// Boundary edges as local vertex pairs (edges with no neighbour inside the chart).
std::vector<std::array<uint32_t, 2>> boundaryEdges(const AtlasMesh& mesh, const ChartUv& chart,
                                                   const std::unordered_map<uint32_t, uint32_t>& faceLocal) {
  std::vector<std::array<uint32_t, 2>> edges;
  for (size_t i = 0; i < chart.faces.size(); ++i) {
    const uint32_t f = chart.faces[i];
    for (int k = 0; k < 3; ++k) {
      const uint32_t g = mesh.faceNeighbour[f][k];
      if (g != kNone && faceLocal.count(g)) continue;
      edges.push_back({chart.corner[i][k], chart.corner[i][(k + 1) % 3]});
    }
  }
  return edges;
}

bool boundarySelfIntersects(const ChartUv& chart, const std::vector<std::array<uint32_t, 2>>& edges) {
  if (edges.size() < 4) return false;
  glm::dvec2 lo(1e300), hi(-1e300);
  double lengthSum = 0.0;
  for (const auto& e : edges) {
    lo = glm::min(lo, glm::min(chart.uv[e[0]], chart.uv[e[1]]));
    hi = glm::max(hi, glm::max(chart.uv[e[0]], chart.uv[e[1]]));
    lengthSum += glm::length(chart.uv[e[1]] - chart.uv[e[0]]);
  }
  // Uniform grid broad phase: cells about two mean edge lengths wide, at most ~4 cells per edge.
  const double cell = std::max(2.0 * lengthSum / double(edges.size()), 1e-12 * glm::length(hi - lo) + 1e-300);
  const int gx = std::clamp(int((hi.x - lo.x) / cell) + 1, 1, 2048), gy = std::clamp(int((hi.y - lo.y) / cell) + 1, 1, 2048);
  const double sx = gx / std::max(hi.x - lo.x, 1e-300), sy = gy / std::max(hi.y - lo.y, 1e-300);
  std::vector<std::vector<uint32_t>> grid(size_t(gx) * size_t(gy));
  for (uint32_t i = 0; i < edges.size(); ++i) {
    const glm::dvec2 a = chart.uv[edges[i][0]], b = chart.uv[edges[i][1]];
    const int x0 = std::clamp(int((std::min(a.x, b.x) - lo.x) * sx), 0, gx - 1), x1 = std::clamp(int((std::max(a.x, b.x) - lo.x) * sx), 0, gx - 1);
    const int y0 = std::clamp(int((std::min(a.y, b.y) - lo.y) * sy), 0, gy - 1), y1 = std::clamp(int((std::max(a.y, b.y) - lo.y) * sy), 0, gy - 1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) grid[size_t(y) * gx + x].push_back(i);
  }
  for (const auto& bucket : grid)
    for (size_t p = 0; p < bucket.size(); ++p)
      for (size_t q = p + 1; q < bucket.size(); ++q) {
        const auto &e = edges[bucket[p]], &g = edges[bucket[q]];
        if (e[0] == g[0] || e[0] == g[1] || e[1] == g[0] || e[1] == g[1]) continue;
        const glm::dvec2 a = chart.uv[e[0]], b = chart.uv[e[1]], c = chart.uv[g[0]], d = chart.uv[g[1]];
        const double d1 = orient(c, d, a), d2 = orient(c, d, b), d3 = orient(a, b, c), d4 = orient(a, b, d);
        if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
        // Touching (a vertex on the other edge) also makes the boundary non-simple.
        if ((d1 == 0 || d2 == 0 || d3 == 0 || d4 == 0) && std::max(std::min(a.x, b.x), std::min(c.x, d.x)) <= std::min(std::max(a.x, b.x), std::max(c.x, d.x)) &&
            std::max(std::min(a.y, b.y), std::min(c.y, d.y)) <= std::min(std::max(a.y, b.y), std::max(c.y, d.y)) &&
            ((d1 == 0 && d2 == 0) || (d1 * d2 <= 0 && d3 * d4 <= 0)))
          return true;
      }
  return false;
}

bool solveLscm(const AtlasMesh& mesh, ChartUv& chart, const std::vector<std::array<uint32_t, 2>>& boundary) {
  const size_t n = chart.vertex.size();
  // Pins: two boundary vertices far apart (farthest from any, then farthest from that).
  auto farthestFrom = [&](uint32_t from) {
    uint32_t best = from;
    double bestD = -1.0;
    for (const auto& e : boundary) {
      const double d = glm::length(mesh.vertexPos[chart.vertex[e[0]]] - mesh.vertexPos[chart.vertex[from]]);
      if (d > bestD) { bestD = d; best = e[0]; }
    }
    return best;
  };
  const uint32_t p0 = farthestFrom(boundary[0][0]);
  const uint32_t p1 = farthestFrom(p0);
  if (p0 == p1) return false;
  const double pinDistance = glm::length(mesh.vertexPos[chart.vertex[p1]] - mesh.vertexPos[chart.vertex[p0]]);
  std::vector<int> freeIndex(n, -1);
  int nFree = 0;
  for (size_t i = 0; i < n; ++i)
    if (i != p0 && i != p1) freeIndex[i] = nFree++;
  const glm::dvec2 pinUv[2] = {{0.0, 0.0}, {pinDistance, 0.0}};
  auto pinOf = [&](uint32_t i) { return i == p0 ? 0 : 1; };

  // Conformality residual per face: ∇v - rot90(∇u) = 0 in the face's own orthonormal frame,
  // weighted by sqrt(area) so the energy is the area integral (Lévy et al. 2002).
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(chart.faces.size() * 12);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(Eigen::Index(2 * chart.faces.size()));
  for (size_t i = 0; i < chart.faces.size(); ++i) {
    const uint32_t f = chart.faces[i];
    const glm::dvec3 p[3] = {mesh.vertexPos[mesh.faceVertex[f][0]], mesh.vertexPos[mesh.faceVertex[f][1]],
                             mesh.vertexPos[mesh.faceVertex[f][2]]};
    const glm::dvec3 e1 = glm::normalize(p[1] - p[0]);
    const glm::dvec3 e2 = glm::cross(mesh.faceNormal[f], e1);
    const glm::dvec2 q[3] = {{0.0, 0.0}, {glm::dot(p[1] - p[0], e1), 0.0}, {glm::dot(p[2] - p[0], e1), glm::dot(p[2] - p[0], e2)}};
    const double area = 0.5 * cross2(q[1] - q[0], q[2] - q[0]);
    if (!(area > 0.0)) continue;
    const double w = std::sqrt(area);
    for (int k = 0; k < 3; ++k) {
      const glm::dvec2 edge = q[(k + 2) % 3] - q[(k + 1) % 3];
      const glm::dvec2 grad = glm::dvec2(-edge.y, edge.x) / (2.0 * area);
      const uint32_t lv = chart.corner[i][k];
      // row 2i:   grad.x * v + grad.y * u ; row 2i+1: grad.y * v - grad.x * u
      const double cu[2] = {w * grad.y, -w * grad.x}, cv[2] = {w * grad.x, w * grad.y};
      for (int r = 0; r < 2; ++r) {
        const Eigen::Index row = Eigen::Index(2 * i + r);
        if (freeIndex[lv] >= 0) {
          triplets.emplace_back(row, freeIndex[lv], cu[r]);
          triplets.emplace_back(row, nFree + freeIndex[lv], cv[r]);
        } else {
          const glm::dvec2 pin = pinUv[pinOf(lv)];
          rhs[row] -= cu[r] * pin.x + cv[r] * pin.y;
        }
      }
    }
  }
  Eigen::SparseMatrix<double> a(Eigen::Index(2 * chart.faces.size()), 2 * nFree);
  a.setFromTriplets(triplets.begin(), triplets.end());
  const Eigen::SparseMatrix<double> at = a.transpose();
  const Eigen::SparseMatrix<double> normal = at * a;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
  if (solver.info() != Eigen::Success) return false;
  const Eigen::VectorXd x = solver.solve(at * rhs);
  if (solver.info() != Eigen::Success) return false;
  for (size_t i = 0; i < n; ++i) {
    if (freeIndex[i] < 0) {
      chart.uv[i] = pinUv[pinOf(uint32_t(i))];
    } else {
      chart.uv[i] = {x[freeIndex[i]], x[nFree + freeIndex[i]]};
      if (!std::isfinite(chart.uv[i].x) || !std::isfinite(chart.uv[i].y)) return false;
    }
  }
  return true;
}

// As-rigid-as-possible refinement (Liu et al. 2008, local/global): starting from the conformal map,
// alternate the best rotation per face (2×2 SVD) with one cotangent-Laplacian solve. Conformal maps
// of curved charts shrink their middle; ARAP trades a little angle error for much less area error.
bool refineArap(const AtlasMesh& mesh, ChartUv& chart, int iterations) {
  const size_t n = chart.vertex.size(), m = chart.faces.size();
  if (n < 4 || iterations <= 0) return true;
  std::vector<std::array<glm::dvec2, 3>> local(m);
  std::vector<std::array<double, 3>> cot(m);  // weight of edge (k+1, k+2), opposite corner k
  for (size_t i = 0; i < m; ++i) {
    const uint32_t f = chart.faces[i];
    const glm::dvec3 p[3] = {mesh.vertexPos[mesh.faceVertex[f][0]], mesh.vertexPos[mesh.faceVertex[f][1]],
                             mesh.vertexPos[mesh.faceVertex[f][2]]};
    const glm::dvec3 e1 = glm::normalize(p[1] - p[0]);
    const glm::dvec3 e2 = glm::cross(mesh.faceNormal[f], e1);
    local[i] = {glm::dvec2(0.0), glm::dvec2(glm::dot(p[1] - p[0], e1), 0.0), glm::dvec2(glm::dot(p[2] - p[0], e1), glm::dot(p[2] - p[0], e2))};
    const double twiceArea = cross2(local[i][1] - local[i][0], local[i][2] - local[i][0]);
    for (int k = 0; k < 3; ++k) {
      const glm::dvec2 a = local[i][(k + 1) % 3] - local[i][k], b = local[i][(k + 2) % 3] - local[i][k];
      cot[i][k] = twiceArea > 0.0 ? 0.5 * glm::dot(a, b) / twiceArea : 0.0;
    }
  }
  // Vertex 0 is held where it is: the Laplacian's null space is a translation.
  std::vector<Eigen::Triplet<double>> triplets;
  for (size_t i = 0; i < m; ++i)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = chart.corner[i][(k + 1) % 3], b = chart.corner[i][(k + 2) % 3];
      const double w = cot[i][k];
      if (a != 0) triplets.emplace_back(a - 1, a - 1, w);
      if (b != 0) triplets.emplace_back(b - 1, b - 1, w);
      if (a != 0 && b != 0) {
        triplets.emplace_back(a - 1, b - 1, -w);
        triplets.emplace_back(b - 1, a - 1, -w);
      }
    }
  Eigen::SparseMatrix<double> lap(Eigen::Index(n - 1), Eigen::Index(n - 1));
  lap.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(lap);
  if (solver.info() != Eigen::Success) return false;
  const glm::dvec2 anchor = chart.uv[0];
  Eigen::VectorXd bu(Eigen::Index(n - 1)), bv(Eigen::Index(n - 1));
  for (int it = 0; it < iterations; ++it) {
    bu.setZero();
    bv.setZero();
    for (size_t i = 0; i < m; ++i) {
      // Best rotation: polar part of S = Σ w (uv edge)(local edge)^T.
      double s00 = 0, s01 = 0, s10 = 0, s11 = 0;
      for (int k = 0; k < 3; ++k) {
        const int a = (k + 1) % 3, b = (k + 2) % 3;
        const glm::dvec2 du = chart.uv[chart.corner[i][a]] - chart.uv[chart.corner[i][b]];
        const glm::dvec2 dq = local[i][a] - local[i][b];
        s00 += cot[i][k] * du.x * dq.x; s01 += cot[i][k] * du.x * dq.y;
        s10 += cot[i][k] * du.y * dq.x; s11 += cot[i][k] * du.y * dq.y;
      }
      // For 2×2, the closest rotation to S has angle atan2(s10 - s01, s00 + s11).
      const double angle = std::atan2(s10 - s01, s00 + s11);
      const double c = std::cos(angle), sn = std::sin(angle);
      for (int k = 0; k < 3; ++k) {
        const int a = (k + 1) % 3, b = (k + 2) % 3;
        const glm::dvec2 dq = local[i][a] - local[i][b];
        const glm::dvec2 r(c * dq.x - sn * dq.y, sn * dq.x + c * dq.y);
        const uint32_t va = chart.corner[i][a], vb = chart.corner[i][b];
        const double w = cot[i][k];
        // Σ w (u_a - u_b - R dq)²: gradient terms for a and b; the anchor moves to the right-hand side.
        if (va != 0) { bu[va - 1] += w * r.x; bv[va - 1] += w * r.y; }
        if (vb != 0) { bu[vb - 1] -= w * r.x; bv[vb - 1] -= w * r.y; }
        if (va != 0 && vb == 0) { bu[va - 1] += w * anchor.x; bv[va - 1] += w * anchor.y; }
        if (vb != 0 && va == 0) { bu[vb - 1] += w * anchor.x; bv[vb - 1] += w * anchor.y; }
      }
    }
    const Eigen::VectorXd u = solver.solve(bu), v = solver.solve(bv);
    if (solver.info() != Eigen::Success) return false;
    for (size_t i = 1; i < n; ++i) {
      chart.uv[i] = {u[Eigen::Index(i - 1)], v[Eigen::Index(i - 1)]};
      if (!std::isfinite(chart.uv[i].x) || !std::isfinite(chart.uv[i].y)) return false;
    }
  }
  return true;
}

// Orientation (un-mirror), scale to the 3D area, then the validity checks.
ChartCheck checkChart(const AtlasMesh& mesh, const std::vector<std::array<uint32_t, 2>>& boundary,
                      const ParamOptions& options, ChartUv& out) {
  const auto& faces = out.faces;
  double uvSum = 0.0;
  for (size_t i = 0; i < faces.size(); ++i) uvSum += uvArea(out, i);
  if (uvSum < 0.0) {  // a mirrored solution: flip v so the winding matches 3D
    for (glm::dvec2& uv : out.uv) uv.y = -uv.y;
    uvSum = -uvSum;
  }
  if (!(uvSum > 0.0) || !std::isfinite(uvSum)) return ChartCheck::SolveFailed;
  const double scale = std::sqrt(out.area3d / uvSum);
  for (glm::dvec2& uv : out.uv) uv *= scale;

  // Per-face relative area: flips, zero areas, and the area-weighted 5th/95th percentiles.
  std::vector<std::pair<double, double>> ratios;  // (ratio, 3D area)
  ratios.reserve(faces.size());
  for (size_t i = 0; i < faces.size(); ++i) {
    const double a = uvArea(out, i);
    const double ratio = a / mesh.faceArea[faces[i]];
    if (ratio <= 0.0) return ChartCheck::Flipped;
    if (ratio < options.minAreaRatio) return ChartCheck::ZeroArea;
    ratios.push_back({ratio, mesh.faceArea[faces[i]]});
  }
  if (!out.planar) {
    std::sort(ratios.begin(), ratios.end());
    double acc = 0.0, p5 = ratios.front().first, p95 = ratios.back().first;
    bool have5 = false;
    for (const auto& [ratio, area] : ratios) {
      acc += area;
      if (!have5 && acc >= 0.05 * out.area3d) { p5 = ratio; have5 = true; }
      if (acc >= 0.95 * out.area3d) { p95 = ratio; break; }
    }
    out.stretchP5 = p5;
    out.stretchP95 = p95;
    if (p5 < options.stretchLow || p95 > options.stretchHigh) return ChartCheck::Stretched;
  }
  if (boundarySelfIntersects(out, boundary)) return ChartCheck::SelfIntersecting;
  return ChartCheck::Valid;
}

}  // namespace

double absoluteCurvature(const AtlasMesh& mesh, const std::vector<uint32_t>& faces) {
  std::unordered_map<uint32_t, double> angleSum;
  std::unordered_map<uint32_t, uint8_t> onBoundary;
  std::unordered_map<uint32_t, uint8_t> inChart;
  for (uint32_t f : faces) inChart[f] = 1;
  for (uint32_t f : faces) {
    const auto& v = mesh.faceVertex[f];
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 a = mesh.vertexPos[v[k]], b = mesh.vertexPos[v[(k + 1) % 3]], c = mesh.vertexPos[v[(k + 2) % 3]];
      angleSum[v[k]] += std::acos(std::clamp(glm::dot(glm::normalize(b - a), glm::normalize(c - a)), -1.0, 1.0));
      const uint32_t g = mesh.faceNeighbour[f][k];
      if (g == kNone || !inChart.count(g)) onBoundary[v[k]] = onBoundary[v[(k + 1) % 3]] = 1;
    }
  }
  double total = 0.0;
  for (const auto& [v, sum] : angleSum)
    if (!onBoundary.count(v)) total += std::abs(2.0 * kPi - sum);
  return total;
}

const char* toString(ChartCheck check) {
  switch (check) {
    case ChartCheck::Valid: return "valid";
    case ChartCheck::NoBoundary: return "closed surface";
    case ChartCheck::Flipped: return "flipped triangle";
    case ChartCheck::ZeroArea: return "zero-area triangle";
    case ChartCheck::SelfIntersecting: return "self-intersecting boundary";
    case ChartCheck::Stretched: return "stretch out of bounds";
    case ChartCheck::SolveFailed: return "solver failed";
  }
  return "?";
}

ChartCheck parameterizeChart(const AtlasMesh& mesh, const std::vector<uint32_t>& faces, const ParamOptions& options,
                             ChartUv& out) {
  out = ChartUv{};
  out.faces = faces;
  out.corner.resize(faces.size());
  std::unordered_map<uint32_t, uint32_t> vertexLocal, faceLocal;
  glm::dvec3 normalSum(0.0);
  for (size_t i = 0; i < faces.size(); ++i) {
    const uint32_t f = faces[i];
    faceLocal[f] = uint32_t(i);
    normalSum += mesh.faceNormal[f] * mesh.faceArea[f];
    out.area3d += mesh.faceArea[f];
    for (int k = 0; k < 3; ++k) {
      auto [it, added] = vertexLocal.try_emplace(mesh.faceVertex[f][k], uint32_t(out.vertex.size()));
      if (added) out.vertex.push_back(mesh.faceVertex[f][k]);
      out.corner[i][k] = it->second;
    }
  }
  out.uv.assign(out.vertex.size(), glm::dvec2(0.0));
  const glm::dvec3 normal = glm::normalize(normalSum);
  const double planarCos = std::cos(glm::radians(options.planarDegrees));
  out.planar = std::all_of(faces.begin(), faces.end(), [&](uint32_t f) { return glm::dot(mesh.faceNormal[f], normal) >= planarCos; });
  const auto boundary = boundaryEdges(mesh, out, faceLocal);

  if (out.planar) {
    // Orthographic projection onto the mean plane; (e1, e2, normal) right-handed keeps the winding.
    const glm::dvec3 helper = std::abs(normal.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 e1 = glm::normalize(glm::cross(helper, normal));
    const glm::dvec3 e2 = glm::cross(normal, e1);
    for (size_t i = 0; i < out.vertex.size(); ++i) {
      const glm::dvec3& p = mesh.vertexPos[out.vertex[i]];
      out.uv[i] = {glm::dot(p, e1), glm::dot(p, e2)};
    }
    return checkChart(mesh, boundary, options, out);
  }
  if (boundary.empty()) return ChartCheck::NoBoundary;
  if (!solveLscm(mesh, out, boundary)) return ChartCheck::SolveFailed;
  const ChartCheck conformal = checkChart(mesh, boundary, options, out);
  if (options.arapIterations <= 0 || conformal == ChartCheck::SolveFailed || conformal == ChartCheck::SelfIntersecting) return conformal;
  if (conformal == ChartCheck::Stretched && out.stretchP95 > options.arapHopeless * out.stretchP5) return conformal;
  const std::vector<glm::dvec2> conformalUv = out.uv;
  if (refineArap(mesh, out, options.arapIterations)) {
    const ChartCheck rigid = checkChart(mesh, boundary, options, out);
    if (rigid == ChartCheck::Valid || conformal != ChartCheck::Valid) return rigid;
  }
  out.uv = conformalUv;
  return conformal;
}


}  // namespace irbake::atlas
