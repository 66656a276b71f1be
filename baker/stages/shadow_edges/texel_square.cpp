#include "stages/shadow_edges/texel_square.h"

#include <cmath>

#include <tbb/parallel_for.h>

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

bool averageOverTexelSquare(const BakeInputs& in, const TexelSamples& ts, size_t t, int S, const SubPointVisit& visit,
                            SquareMean& out) {
  if (ts.positionWeight[t].w <= 0.0f || ts.primitive[t] >= in.scene.primitives.size()) return false;
  const RayTracer& rt = in.rayTracer;
  const float eps = rt.epsilon();
  const glm::vec2 size(ts.width, ts.height);
  const uint32_t pi = ts.primitive[t], tri = ts.triangle[t];
  const Primitive& prim = in.scene.primitives[pi];
  const uint32_t i0 = prim.indices[3 * tri], i1 = prim.indices[3 * tri + 1], i2 = prim.indices[3 * tri + 2];
  const glm::vec2 t0 = prim.uv1[i0] * size, t1 = prim.uv1[i1] * size, t2 = prim.uv1[i2] * size;
  const float area2 = cross2(t1 - t0, t2 - t0);
  if (!(std::abs(area2) > 1e-12f)) return false;
  const glm::vec3 &p0 = prim.positions[i0], &p1 = prim.positions[i1], &p2 = prim.positions[i2];
  const glm::vec3 n(ts.normal[t]);
  const glm::vec3 centre = rt.insetPoint(pi, tri, glm::vec3(ts.positionWeight[t])) + n * eps;
  const int x = static_cast<int>(t % ts.width), y = static_cast<int>(t / ts.width);
  for (int sy = 0; sy < S; ++sy)
    for (int sx = 0; sx < S; ++sx) {
      const glm::vec2 q(x + (sx + 0.5f) / S, y + (sy + 0.5f) / S);
      const float b1 = cross2(q - t0, t2 - t0) / area2, b2 = cross2(t1 - t0, q - t0) / area2;
      const float tol = -1e-4f;
      if (b1 < tol || b2 < tol || b1 + b2 > 1.0f - tol) continue;  // another triangle's part of the square
      const glm::vec3 xs = rt.insetPoint(pi, tri, (1.0f - b1 - b2) * p0 + b1 * p1 + b2 * p2);
      const glm::vec3 origin = xs + n * eps;
      ++out.points;
      glm::vec3 values[SquareMean::kValues] = {glm::vec3(0.0f), glm::vec3(0.0f)};
      // Dark: shadowed, or cut off from the centre by a surface standing on the triangle (the floor under a box
      // resting on it), which is covered, not shadowed, and no part of what a viewer sees. A lit sub-point
      // cannot be under a closed box, so only the dark ones need the ray along the surface.
      if (!visit(xs, origin, values)) {
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
  return true;
}

}  // namespace irbake
