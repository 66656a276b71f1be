// Atlas pages rasterised into per-texel surface samples, with leak control.
#include "texels/texel_samples.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common/maths.h"
#include "texels/contact_cuts.h"

namespace irbake {
namespace {

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();

float cross2(glm::vec2 a, glm::vec2 b) { return a.x * b.y - a.y * b.x; }

// A triangle of one primitive in texel space of its page, with what its samples need.
struct RasterTriangle {
  uint32_t primitive, triangle;
  glm::vec2 t0, t1, t2;  // uv1 × page size
  float area2;           // signed 2 × texel-space area
};

// Barycentric (u, v) of p with respect to t0 + u (t1 - t0) + v (t2 - t0) (RayHit's convention).
glm::vec2 barycentric(const RasterTriangle& t, glm::vec2 p) {
  float u = cross2(p - t.t0, t.t2 - t.t0) / t.area2;
  float v = cross2(t.t1 - t.t0, p - t.t0) / t.area2;
  return {u, v};
}

glm::vec2 closestOnSegment(glm::vec2 p, glm::vec2 a, glm::vec2 b) {
  glm::vec2 ab = b - a;
  float len2 = glm::dot(ab, ab);
  float s = len2 > 0.0f ? glm::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return a + s * ab;
}

// The point of the (outside) triangle nearest to p, as barycentrics clamped onto the triangle.
glm::vec2 nearestBarycentric(const RasterTriangle& t, glm::vec2 p, float& distance) {
  glm::vec2 c[3] = {closestOnSegment(p, t.t0, t.t1), closestOnSegment(p, t.t1, t.t2), closestOnSegment(p, t.t2, t.t0)};
  int best = 0;
  for (int i = 1; i < 3; ++i)
    if (glm::length(c[i] - p) < glm::length(c[best] - p)) best = i;
  distance = glm::length(c[best] - p);
  glm::vec2 b = glm::max(barycentric(t, c[best]), glm::vec2(0.0f));
  float s = b.x + b.y;
  if (s > 1.0f) b /= s;
  return b;
}

// Separating-axis test of the triangle against the texel square [x, x+1] × [y, y+1], shrunk by a
// hair so that a triangle merely touching the texel's border (the chart next door) does not count.
bool overlapsTexel(const RasterTriangle& t, int x, int y) {
  const float e = 1e-4f;
  glm::vec2 lo(x + e, y + e), hi(x + 1 - e, y + 1 - e);
  glm::vec2 v[3] = {t.t0, t.t1, t.t2};
  glm::vec2 tmin = glm::min(v[0], glm::min(v[1], v[2])), tmax = glm::max(v[0], glm::max(v[1], v[2]));
  if (tmax.x <= lo.x || tmin.x >= hi.x || tmax.y <= lo.y || tmin.y >= hi.y) return false;
  glm::vec2 corners[4] = {lo, {hi.x, lo.y}, hi, {lo.x, hi.y}};
  for (int i = 0; i < 3; ++i) {
    glm::vec2 edge = v[(i + 1) % 3] - v[i];
    glm::vec2 n(-edge.y, edge.x);
    float tMin = 1e30f, tMax = -1e30f, sMin = 1e30f, sMax = -1e30f;
    for (auto& p : v) tMin = std::min(tMin, glm::dot(n, p)), tMax = std::max(tMax, glm::dot(n, p));
    for (auto& p : corners) sMin = std::min(sMin, glm::dot(n, p)), sMax = std::max(sMax, glm::dot(n, p));
    if (tMax <= sMin || sMax <= tMin) return false;
  }
  return true;
}

// World-space edge of one texel on this triangle: sqrt(3D area / texel-space area).
float texelFootprint(const Primitive& prim, uint32_t tri, const glm::ivec2& pageSize) {
  uint32_t i0 = prim.indices[3 * tri], i1 = prim.indices[3 * tri + 1], i2 = prim.indices[3 * tri + 2];
  float area3 = 0.5f * glm::length(glm::cross(prim.positions[i1] - prim.positions[i0], prim.positions[i2] - prim.positions[i0]));
  glm::vec2 s(pageSize);
  float area2 = 0.5f * std::abs(cross2((prim.uv1[i1] - prim.uv1[i0]) * s, (prim.uv1[i2] - prim.uv1[i0]) * s));
  return area2 > 0.0f ? std::sqrt(area3 / area2) : 0.0f;
}

// Rays over the hemisphere of the geometric normal: the normal and a ring of grazing directions.
constexpr int kLeakRays = 9;
void leakDirections(const glm::vec3& n, glm::vec3 out[kLeakRays]) {
  glm::vec3 a = std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  glm::vec3 t = glm::normalize(glm::cross(n, a)), b = glm::cross(n, t);
  out[0] = n;
  const float elevation = 0.25f;  // ~14°: low enough to find walls that cut the texel
  for (int k = 0; k < kLeakRays - 1; ++k) {
    float phi = 2.0f * kPiF * (k + 0.5f) / (kLeakRays - 1);
    out[k + 1] = glm::normalize(std::cos(phi) * t + std::sin(phi) * b + elevation * n);
  }
}

// A sample leaks when it sits behind a nearby back face (a wall cutting the texel) or inside a
// closed solid (every ray, or all but one that slipped through a crack, leaves through a back face).
// Not a majority: a ceiling 1 cm above a one-sided emitter sees the emitter's back in most directions
// but is lit through the gap at grazing angles, and a path tracer finds those texels lit; a majority rule
// filled them by dilation.
// Double-sided surfaces have no inside.
bool leaks(const RayTracer& rt, const Scene& scene, const SurfacePoint& s, float nearDistance, float farDistance) {
  glm::vec3 dirs[kLeakRays];
  leakDirections(s.geometricNormal, dirs);
  const glm::vec3 origin = s.position + s.geometricNormal * rt.epsilon();
  // One packet from one origin (and the ninth ray alone), sides and distances only: every sample of a page.
  RayHit hits[kLeakRays];
  rt.intersectPackets(origin, dirs, kLeakRays, hits, RayTracer::HitDetail::Surface);
  int backHits = 0;
  for (const RayHit& h : hits) {
    if (!h.hit || !h.backFace || h.t > farDistance) continue;
    if (h.primitive < scene.primitives.size()) {
      const Primitive& p = scene.primitives[h.primitive];
      if (p.material >= 0 && p.material < int(scene.materials.size()) && scene.materials[p.material].doubleSided) continue;
    }
    if (h.t <= nearDistance) return true;
    ++backHits;
  }
  return backHits >= kLeakRays - 1;
}

// A nearest point lies on the triangle's border, and on a concave edge (floor meeting wall) the VPL
// geometry term is singular there: the clamp loses up to half the wall's light and compensation
// recovers it with high variance. Pull the point kEdgePull texels (in uv1 space) towards the
// centroid, never past it, so it stays on the triangle but off the edge.
constexpr float kEdgePull = 0.5f;
glm::vec2 pullInside(const RasterTriangle& t, glm::vec2 b) {
  glm::vec2 p = t.t0 * (1.0f - b.x - b.y) + t.t1 * b.x + t.t2 * b.y;
  glm::vec2 c = (t.t0 + t.t1 + t.t2) / 3.0f;
  glm::vec2 toC = c - p;
  float len = glm::length(toC);
  if (!(len > 1e-6f)) return b;
  float step = std::min(kEdgePull, len);
  glm::vec2 q = p + toC * (step / len);
  return barycentric(t, q);
}

TexelSamples rasterisePage(const Scene& scene, int page, int width, int height, int S) {
  TexelSamples ts;
  ts.page = page;
  ts.width = width;
  ts.height = height;
  ts.supersample = S;
  const size_t layer = ts.layerSize(), slots = ts.slotCount();
  ts.positionWeight.assign(slots, glm::vec4(0.0f));
  ts.normal.assign(slots, glm::vec4(0.0f));
  ts.primitive.assign(slots, kNone);
  ts.triangle.assign(slots, 0);
  ts.covered.assign(layer, 0);
  ts.valid.assign(layer, 0);

  // Texels touched by a triangle but with no sub-sample centre inside any: the nearest point of a
  // touching triangle to the texel centre (conservative rasterisation).
  std::vector<float> nearestDistance(layer, std::numeric_limits<float>::infinity());
  std::vector<uint32_t> nearestPrim(layer, kNone), nearestTri(layer, 0);
  std::vector<glm::vec2> nearestBary(layer);

  const glm::vec2 size(width, height);
  // The page in bands of rows, one task each; every band takes the triangles that reach it in scene order, so
  // each texel sees its triangles in the order of a single pass ("first wins" and the nearest point alike).
  std::vector<RasterTriangle> triangles;
  std::vector<glm::ivec4> boxes;  // texel bounds x0, x1, y0, y1 (inclusive)
  for (uint32_t pi = 0; pi < scene.primitives.size(); ++pi) {
    const Primitive& prim = scene.primitives[pi];
    if (prim.lightmap.page != page || prim.uv1.size() != prim.positions.size()) continue;
    for (uint32_t tri = 0; tri < prim.triangleCount(); ++tri) {
      RasterTriangle t{pi, tri, prim.uv1[prim.indices[3 * tri]] * size, prim.uv1[prim.indices[3 * tri + 1]] * size,
                       prim.uv1[prim.indices[3 * tri + 2]] * size, 0.0f};
      t.area2 = cross2(t.t1 - t.t0, t.t2 - t.t0);
      if (!(std::abs(t.area2) > 1e-12f)) continue;  // no texel area: nothing to rasterise
      glm::vec2 lo = glm::min(t.t0, glm::min(t.t1, t.t2)), hi = glm::max(t.t0, glm::max(t.t1, t.t2));
      const glm::ivec4 box(std::max(0, int(std::floor(lo.x))), std::min(width - 1, int(std::floor(hi.x))),
                           std::max(0, int(std::floor(lo.y))), std::min(height - 1, int(std::floor(hi.y))));
      if (box.x > box.y || box.z > box.w) continue;
      triangles.push_back(t);
      boxes.push_back(box);
    }
  }
  constexpr int kBandRows = 32;
  const int bands = (height + kBandRows - 1) / kBandRows;
  std::vector<std::vector<uint32_t>> inBand(static_cast<size_t>(std::max(0, bands)));
  for (uint32_t k = 0; k < triangles.size(); ++k)
    for (int b = boxes[k].z / kBandRows; b <= boxes[k].w / kBandRows; ++b) inBand[static_cast<size_t>(b)].push_back(k);
  tbb::parallel_for(0, bands, [&](int band) {
    const int bandY0 = band * kBandRows, bandY1 = std::min(height - 1, bandY0 + kBandRows - 1);
    for (uint32_t k : inBand[static_cast<size_t>(band)]) {
      const RasterTriangle& t = triangles[k];
      const uint32_t pi = t.primitive, tri = t.triangle;
      const glm::ivec4& box = boxes[k];
      for (int y = std::max(box.z, bandY0); y <= std::min(box.w, bandY1); ++y)
        for (int x = box.x; x <= box.y; ++x) {
          if (!overlapsTexel(t, x, y)) continue;
          size_t texel = size_t(y) * width + x;
          ts.covered[texel] = 1;
          for (int sy = 0; sy < S; ++sy)
            for (int sx = 0; sx < S; ++sx) {
              size_t slot = size_t(sy * S + sx) * layer + texel;
              if (ts.primitive[slot] != kNone) continue;  // first triangle wins on shared edges
              glm::vec2 p(x + (sx + 0.5f) / S, y + (sy + 0.5f) / S);
              glm::vec2 b = barycentric(t, p);
              const float tol = -1e-6f;
              if (b.x < tol || b.y < tol || b.x + b.y > 1.0f - tol) continue;
              ts.primitive[slot] = pi;
              ts.triangle[slot] = tri;
              ts.positionWeight[slot] = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
              ts.normal[slot] = glm::vec4(b, 0.0f, 0.0f);  // barycentrics until the surface pass
            }
          float d;
          glm::vec2 b = nearestBarycentric(t, glm::vec2(x + 0.5f, y + 0.5f), d);
          b = pullInside(t, b);
          if (d < nearestDistance[texel]) {
            nearestDistance[texel] = d;
            nearestPrim[texel] = pi;
            nearestTri[texel] = tri;
            nearestBary[texel] = b;
          }
        }
    }
  });
  for (size_t texel = 0; texel < layer; ++texel) {
    bool any = false;
    for (int l = 0; l < S * S && !any; ++l) any = ts.primitive[l * layer + texel] != kNone;
    if (!any && nearestPrim[texel] != kNone) {
      ts.primitive[texel] = nearestPrim[texel];
      ts.triangle[texel] = nearestTri[texel];
      ts.positionWeight[texel] = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
      ts.normal[texel] = glm::vec4(nearestBary[texel], 0.0f, 0.0f);
    }
  }
  return ts;
}

}  // namespace

SurfacePoint surfacePoint(const Primitive& prim, uint32_t tri, glm::vec2 b) {
  uint32_t i0 = prim.indices[3 * tri], i1 = prim.indices[3 * tri + 1], i2 = prim.indices[3 * tri + 2];
  float w0 = 1.0f - b.x - b.y;
  SurfacePoint s;
  const glm::vec3 &p0 = prim.positions[i0], &p1 = prim.positions[i1], &p2 = prim.positions[i2];
  s.position = w0 * p0 + b.x * p1 + b.y * p2;
  glm::vec3 g = glm::cross(p1 - p0, p2 - p0);
  float gl = glm::length(g);
  s.geometricNormal = gl > 0.0f ? g / gl : glm::vec3(0.0f, 0.0f, 1.0f);
  s.shadingNormal = s.geometricNormal;
  if (prim.normals.size() == prim.positions.size()) {
    glm::vec3 n = w0 * prim.normals[i0] + b.x * prim.normals[i1] + b.y * prim.normals[i2];
    float nl = glm::length(n);
    if (nl > 1e-12f && std::isfinite(nl)) s.shadingNormal = n / nl;
  }
  return s;
}

std::vector<TexelSamples> buildTexelSamples(const Scene& scene, const RayTracer& rt, const TexelSampleOptions& options) {
  const int S = std::max(1, options.supersample);
  int pageCount = 0;
  for (const auto& p : scene.primitives) pageCount = std::max(pageCount, p.lightmap.page + 1);
  std::vector<TexelSamples> pages;
  const float farDistance = std::max(1e-3f, 2.0f * scene.bounds().diagonal());
  for (int page = 0; page < pageCount; ++page) {
    int w = 0, h = 0;
    for (const auto& p : scene.primitives)
      if (p.lightmap.page == page && p.lightmap.width > 0) {
        w = p.lightmap.width;
        h = p.lightmap.height;
        break;
      }
    TexelSamples ts = rasterisePage(scene, page, w, h, S);
    const size_t layer = ts.layerSize();
    std::vector<uint8_t> leaked(ts.slotCount(), 0);
    std::atomic<size_t> done{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, ts.slotCount(), 1024), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t slot = r.begin(); slot < r.end(); ++slot) {
        if (ts.primitive[slot] == kNone) continue;
        const Primitive& prim = scene.primitives[ts.primitive[slot]];
        glm::vec2 b(ts.normal[slot].x, ts.normal[slot].y);
        SurfacePoint s = surfacePoint(prim, ts.triangle[slot], b);
        ts.positionWeight[slot] = glm::vec4(s.position, 1.0f);
        ts.normal[slot] = glm::vec4(s.shadingNormal, 0.0f);
        if (options.leakControl) {
          float nearDistance = options.leakRayScale * texelFootprint(prim, ts.triangle[slot], {w, h});
          leaked[slot] = leaks(rt, scene, s, nearDistance, farDistance) ? 1 : 0;
        }
      }
      size_t n = done.fetch_add(r.size()) + r.size();
      if (options.progress) options.progress("texels", (page + double(n) / ts.slotCount()) / pageCount);
    });
    // Weights: equal over the texel's surviving samples, summing to 1.
    for (size_t texel = 0; texel < layer; ++texel) {
      int kept = 0;
      for (int l = 0; l < S * S; ++l) {
        size_t slot = l * layer + texel;
        if (ts.primitive[slot] == kNone) continue;
        if (leaked[slot]) {
          ts.primitive[slot] = kNone;
          ts.triangle[slot] = 0;
          ts.positionWeight[slot].w = 0.0f;
        } else {
          ++kept;
        }
      }
      ts.valid[texel] = kept > 0 ? 1 : 0;
      for (int l = 0; l < S * S && kept; ++l) {
        size_t slot = l * layer + texel;
        if (ts.primitive[slot] != kNone) ts.positionWeight[slot].w = 1.0f / kept;
      }
    }
    markContactCuts(ts, rt);
    pages.push_back(std::move(ts));
  }
  if (options.progress) options.progress("texels", 1.0);
  return pages;
}

}  // namespace irbake
