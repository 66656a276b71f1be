#include "stages/shadow_edges/shadow_edges.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/parallel_for.h>

#include "common/progress.h"
#include "transport/geometry_term.h"

namespace irbake {

namespace {

float cross2(const glm::vec2& a, const glm::vec2& b) { return a.x * b.y - a.y * b.x; }

float channelMax(const glm::vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

// Per texel, the share of the punctual lights' unshadowed value that reached it (their visibility, weighted by
// each light's value; -1 where no light faces the texel). Smooth falloff (a point light's 1/r²) keeps it at 1;
// a shadow edge makes it jump.
std::vector<float> visibleShare(const BakeInputs& in, const TexelSamples& ts, const Lightmap& map,
                                const std::vector<uint8_t>& valid) {
  std::vector<float> share(map.size(), -1.0f);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, map.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t) {
      if (!valid[t] || ts.positionWeight[t].w <= 0.0f) continue;
      glm::vec3 x(ts.positionWeight[t]);
      if (ts.primitive[t] < in.scene.primitives.size()) x = in.rayTracer.insetPoint(ts.primitive[t], ts.triangle[t], x);
      const glm::vec3 n(ts.normal[t]);
      glm::vec3 unshadowed(0.0f);
      for (const Light& l : in.scene.lights) unshadowed += punctualDirect(l, x, n).mapValue;
      const float u = channelMax(unshadowed);
      if (u > 0.0f) share[t] = channelMax(map.texels[t]) / u;
    }
  });
  return share;
}

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

}  // namespace

ShadowEdgeStats refineShadowEdges(const BakeInputs& in, std::vector<Lightmap>& directPages,
                                  const ShadowEdgeOptions& options) {
  ShadowEdgeStats stats;
  const int S = options.subSamples;
  if (S <= 1 || in.scene.lights.empty()) return stats;
  Stopwatch watch;
  const RayTracer& rt = in.rayTracer;
  const float eps = rt.epsilon();
  std::atomic<size_t> edges{0}, points{0}, dropped{0};
  for (size_t p = 0; p < directPages.size() && p < in.texels.size(); ++p) {
    const TexelSamples& ts = in.texels[p];
    Lightmap& map = directPages[p];
    if (ts.supersample != 1 || map.size() != ts.layerSize()) continue;
    const std::vector<uint8_t>& valid = map.valid.size() == map.size() ? map.valid : ts.valid;
    const std::vector<uint8_t> edge = edgeTexels(visibleShare(in, ts, map, valid), ts.width, ts.height, options.jump);
    const glm::vec2 size(ts.width, ts.height);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, ts.layerSize(), 256), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t t = r.begin(); t != r.end(); ++t) {
        if (!edge[t] || ts.positionWeight[t].w <= 0.0f || ts.primitive[t] >= in.scene.primitives.size()) continue;
        const uint32_t pi = ts.primitive[t], tri = ts.triangle[t];
        const Primitive& prim = in.scene.primitives[pi];
        const uint32_t i0 = prim.indices[3 * tri], i1 = prim.indices[3 * tri + 1], i2 = prim.indices[3 * tri + 2];
        const glm::vec2 t0 = prim.uv1[i0] * size, t1 = prim.uv1[i1] * size, t2 = prim.uv1[i2] * size;
        const float area2 = cross2(t1 - t0, t2 - t0);
        if (!(std::abs(area2) > 1e-12f)) continue;
        const glm::vec3 &p0 = prim.positions[i0], &p1 = prim.positions[i1], &p2 = prim.positions[i2];
        const glm::vec3 n(ts.normal[t]);
        const glm::vec3 centre = rt.insetPoint(pi, tri, glm::vec3(ts.positionWeight[t])) + n * eps;
        const int x = static_cast<int>(t % ts.width), y = static_cast<int>(t / ts.width);
        glm::dvec3 sum(0.0);
        int kept = 0;
        for (int sy = 0; sy < S; ++sy)
          for (int sx = 0; sx < S; ++sx) {
            const glm::vec2 q(x + (sx + 0.5f) / S, y + (sy + 0.5f) / S);
            const float b1 = cross2(q - t0, t2 - t0) / area2, b2 = cross2(t1 - t0, q - t0) / area2;
            const float tol = -1e-4f;
            if (b1 < tol || b2 < tol || b1 + b2 > 1.0f - tol) continue;  // another triangle's part of the square
            const glm::vec3 xs = rt.insetPoint(pi, tri, (1.0f - b1 - b2) * p0 + b1 * p1 + b2 * p2);
            const glm::vec3 origin = xs + n * eps;
            ++points;
            glm::vec3 value(0.0f);
            bool anyLit = false;
            for (const Light& l : in.scene.lights) {
              const PunctualContribution c = punctualDirect(l, xs, n);
              if (c.mapValue == glm::vec3(0.0f)) continue;
              const float tmax = std::isinf(c.distance) ? 1e30f : c.distance - eps;
              if (tmax > 0.0f && rt.occluded(origin, c.toLight, 0.0f, tmax)) continue;
              anyLit = true;
              value += tmax > 0.0f && rt.hasTransmission() ? c.mapValue * rt.transmittance(origin, c.toLight, 0.0f, tmax)
                                                           : c.mapValue;
            }
            // Dark: shadowed, or cut off from the centre by a surface standing on the triangle (the floor under
            // a box resting on it), which is covered, not shadowed, and no part of what a viewer sees. A lit
            // sub-point cannot be under a closed box, so only the dark ones need the ray along the surface.
            if (!anyLit) {
              const glm::vec3 step = origin - centre;
              const float reach = glm::length(step);
              if (reach > eps && rt.occluded(centre, step / reach, 0.0f, reach)) {
                ++dropped;
                continue;
              }
            }
            sum += glm::dvec3(value);
            ++kept;
          }
        if (kept == 0) continue;  // no sub-point of this triangle in the square: the centre's value stays
        map.texels[t] = glm::vec3(sum / double(kept));
        ++edges;
      }
    });
  }
  stats.edgeTexels = edges;
  stats.subPoints = points;
  stats.droppedInside = dropped;
  stats.seconds = watch.seconds();
  return stats;
}

}  // namespace irbake
