#include "stages/shadow_edges/texel_square.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "texels/texel_samples.h"

namespace irbake {

namespace {

float cross2(const glm::vec2& a, const glm::vec2& b) { return a.x * b.y - a.y * b.x; }

}  // namespace

// Texels whose visible share jumps against a valid 8-neighbour's (both marked: the edge lies in one of the
// two squares).
std::vector<uint8_t> edgeTexels(const std::vector<float>& share, int w, int h, float jump) {
  std::vector<uint8_t> edge(share.size(), 0);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t t = static_cast<size_t>(y) * w + x;
      const float a = share[t];
      if (a < 0.0f) continue;
      for (int dy = -1; dy <= 1 && !edge[t]; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const float b = share[static_cast<size_t>(ny) * w + nx];
          if (b >= 0.0f && std::abs(a - b) > jump) {
            edge[t] = 1;  // the neighbour marks itself on its own pass
            break;
          }
        }
    }
  });
  return edge;
}

SquareTriangles squareTriangles(const Scene& scene, const TexelSamples& ts, const std::vector<uint8_t>& marked) {
  SquareTriangles out;
  const size_t layer = ts.layerSize();
  out.first.assign(layer + 1, 0);
  const glm::vec2 size(ts.width, ts.height);
  // Two passes over the page's triangles: count per marked texel, then fill (scene order kept).
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<uint32_t> next;
    if (pass == 1) {
      for (size_t t = 0; t < layer; ++t) out.first[t + 1] += out.first[t];
      out.tris.resize(out.first[layer]);
      next.assign(out.first.begin(), out.first.end() - 1);
    }
    for (uint32_t pi = 0; pi < scene.primitives.size(); ++pi) {
      const Primitive& prim = scene.primitives[pi];
      if (prim.lightmap.page != ts.page || prim.uv1.size() != prim.positions.size()) continue;
      for (uint32_t tri = 0; tri < prim.triangleCount(); ++tri) {
        const glm::vec2 a = prim.uv1[prim.indices[3 * tri]] * size, b = prim.uv1[prim.indices[3 * tri + 1]] * size,
                        c = prim.uv1[prim.indices[3 * tri + 2]] * size;
        const glm::vec2 lo = glm::min(a, glm::min(b, c)), hi = glm::max(a, glm::max(b, c));
        const int x0 = std::max(0, int(std::floor(lo.x))), x1 = std::min(ts.width - 1, int(std::floor(hi.x)));
        const int y0 = std::max(0, int(std::floor(lo.y))), y1 = std::min(ts.height - 1, int(std::floor(hi.y)));
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x) {
            const size_t t = static_cast<size_t>(y) * ts.width + x;
            if (!marked[t]) continue;
            if (pass == 0) ++out.first[t + 1];
            else out.tris[next[t]++] = glm::uvec2(pi, tri);
          }
      }
    }
  }
  return out;
}

bool averageOverTexelSquare(const BakeInputs& in, const TexelSamples& ts, size_t t, int S,
                            const SquareTriangles* squares, const SubPointVisit& visit, SquareMean& out) {
  if (ts.positionWeight[t].w <= 0.0f || ts.primitive[t] >= in.scene.primitives.size()) return false;
  const RayTracer& rt = in.rayTracer;
  const float eps = rt.epsilon();
  const glm::vec2 size(ts.width, ts.height);
  const glm::uvec2 own(ts.primitive[t], ts.triangle[t]);
  const glm::uvec2* tris = &own;
  size_t count = 1;
  if (squares && squares->first.size() > t + 1 && squares->first[t + 1] > squares->first[t]) {
    tris = squares->tris.data() + squares->first[t];
    count = squares->first[t + 1] - squares->first[t];
  }
  const glm::vec3 n(ts.normal[t]);
  // The centre's normal may face away from its triangle's winding (a surface seen from its back): the other
  // triangles' normals turn the same way.
  const glm::vec3 ownNormal = surfacePoint(in.scene.primitives[own.x], own.y, glm::vec2(0.0f)).geometricNormal;
  const float side = glm::dot(n, ownNormal) < 0.0f ? -1.0f : 1.0f;
  const glm::vec3 centreOnSurface = rt.insetPoint(own.x, own.y, glm::vec3(ts.positionWeight[t]));
  const glm::vec3 centre = centreOnSurface + n * eps;
  const int x = static_cast<int>(t % ts.width), y = static_cast<int>(t / ts.width);
  bool any = false;
  for (int sy = 0; sy < S; ++sy)
    for (int sx = 0; sx < S; ++sx) {
      const glm::vec2 q(x + (sx + 0.5f) / S, y + (sy + 0.5f) / S);
      // The first triangle that holds q (none: the square's part off the chart, not sampled).
      glm::vec3 xs, nx;
      bool found = false, ownPlane = true;
      for (size_t k = 0; k < count && !found; ++k) {
        const Primitive& prim = in.scene.primitives[tris[k].x];
        const uint32_t tri = tris[k].y;
        const uint32_t i0 = prim.indices[3 * tri], i1 = prim.indices[3 * tri + 1], i2 = prim.indices[3 * tri + 2];
        const glm::vec2 t0 = prim.uv1[i0] * size, t1 = prim.uv1[i1] * size, t2 = prim.uv1[i2] * size;
        const float area2 = cross2(t1 - t0, t2 - t0);
        if (!(std::abs(area2) > 1e-12f)) continue;
        any = true;
        const float b1 = cross2(q - t0, t2 - t0) / area2, b2 = cross2(t1 - t0, q - t0) / area2;
        const float tol = -1e-4f;
        if (b1 < tol || b2 < tol || b1 + b2 > 1.0f - tol) continue;
        found = true;
        const SurfacePoint sp = surfacePoint(prim, tri, glm::vec2(b1, b2));
        xs = rt.insetPoint(tris[k].x, tri, sp.position);
        if (tris[k] == own) {
          nx = n;
        } else {
          ownPlane = std::abs(glm::dot(sp.geometricNormal, ownNormal)) > 0.9999f &&
                     std::abs(glm::dot(xs - centreOnSurface, ownNormal)) <= eps;
          nx = side * sp.shadingNormal;
        }
      }
      if (!found) continue;
      const glm::vec3 origin = xs + nx * eps;
      ++out.points;
      glm::vec3 values[SquareMean::kValues] = {glm::vec3(0.0f), glm::vec3(0.0f)};
      // Dark: shadowed, or cut off from the centre by a surface standing on the chart (the floor under a box
      // resting on it), which is covered, not shadowed, and no part of what a viewer sees. A lit sub-point
      // cannot be under a closed box, so only the dark ones need the ray along the surface, and only in the
      // centre's plane: across a convex crease or a curved chart that ray would pass under the surface itself.
      if (!visit(xs, nx, origin, values) && ownPlane) {
        const glm::vec3 step = origin - centre;
        const float reach = glm::length(step);
        if (reach > eps && rt.occluded(centre, step / reach, 0.0f, reach)) {
          ++out.dropped;
          continue;
        }
      }
      for (int k = 0; k < SquareMean::kValues; ++k) out.sum[k] += glm::dvec3(values[k]);
      ++out.kept;
    }
  return any;
}

}  // namespace irbake
