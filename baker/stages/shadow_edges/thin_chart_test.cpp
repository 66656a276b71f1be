// Shadow edges on a chart three texels wide made of thin triangles (each spans the strip's width but only
// part of a texel along it, so one texel's square lies on several triangles), under a point light a few
// centimetres above it and a blocker's straight edge crossing it obliquely: each refined texel against the
// mean of E/π over its footprint (its square ∩ the chart's triangles) from the closed form, 64×64 points.
#include "stages/shadow_edges/shadow_edges.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "atlas/atlas.h"
#include "common/maths.h"
#include "evaluators/embree/embree_backend.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

using namespace testing;
constexpr float kLength = 2.0f, kWidth = 0.3f;  // the strip on z = 0, x in [0, kLength], y in [0, kWidth]
constexpr float kStep = 0.061f;                  // triangle spacing along the strip (0.61 texel at 10 per metre)
const glm::vec3 kLight(0.97f, 0.12f, 0.06f);     // 6 cm above the strip
constexpr float kIntensity = 2.0f;               // W/sr
constexpr float kBlockerZ = 0.03f;               // the blocker's plane, half way up to the light
// The blocker covers the points c of its plane with c.x + kSlope·c.y < kEdge (an edge oblique to the strip).
constexpr float kSlope = 2.0f, kEdge = 1.24f;

// A zig-zag of thin triangles: top vertices at x = i·kStep, bottom ones half a step on.
int addThinStrip(Scene& s, int material) {
  Primitive p;
  p.name = "strip";
  p.material = material;
  const int n = static_cast<int>(kLength / kStep);
  for (int i = 0; i <= n; ++i) {
    p.positions.push_back({i * kStep, kWidth, 0.0f});
    p.positions.push_back({std::min(kLength, (i + 0.5f) * kStep), 0.0f, 0.0f});
  }
  for (auto& q : p.positions) {
    p.normals.push_back({0, 0, 1});
    p.uv0.push_back({q.x, q.y});
  }
  for (int i = 0; i < n; ++i) {
    const uint32_t t0 = 2 * i, b0 = 2 * i + 1, t1 = 2 * i + 2, b1 = 2 * i + 3;
    p.indices.insert(p.indices.end(), {t0, b0, b1, t0, b1, t1});  // counter-clockwise seen from +z
  }
  s.primitives.push_back(p);
  return static_cast<int>(s.primitives.size()) - 1;
}

bool litFromLight(glm::dvec3 p) {
  const double f = kBlockerZ / kLight.z;  // where the segment to the light crosses the blocker's plane
  const glm::dvec3 c = p + (glm::dvec3(kLight) - p) * f;
  return c.x + kSlope * c.y >= kEdge;
}

// E/π of the point light at p on the strip (normal +z), 0 in the blocker's shadow.
double mapValueAt(glm::dvec3 p) {
  if (!litFromLight(p)) return 0.0;
  const glm::dvec3 d = glm::dvec3(kLight) - p;
  const double r2 = glm::dot(d, d);
  return kIntensity * (d.z / std::sqrt(r2)) / r2 / kPi;
}

// The mean of E/π and the lit share over texel t's square ∩ the strip's triangles (K×K points).
struct Footprint {
  double mean = 0.0, litShare = 0.0;
  int inside = 0;
};
Footprint footprintMean(const Primitive& strip, const TexelSamples& ts, size_t t) {
  const glm::dvec2 size(ts.width, ts.height);
  const int x = static_cast<int>(t % ts.width), y = static_cast<int>(t / ts.width), K = 64;
  auto cross2 = [](glm::dvec2 u, glm::dvec2 v) { return u.x * v.y - u.y * v.x; };
  Footprint f;
  int lit = 0;
  for (int j = 0; j < K; ++j)
    for (int i = 0; i < K; ++i) {
      const glm::dvec2 q(x + (i + 0.5) / K, y + (j + 0.5) / K);
      for (size_t tri = 0; tri < strip.triangleCount(); ++tri) {
        const uint32_t i0 = strip.indices[3 * tri], i1 = strip.indices[3 * tri + 1], i2 = strip.indices[3 * tri + 2];
        const glm::dvec2 a = glm::dvec2(strip.uv1[i0]) * size, b = glm::dvec2(strip.uv1[i1]) * size,
                         c = glm::dvec2(strip.uv1[i2]) * size;
        const double area = cross2(b - a, c - a);
        const double u = cross2(q - a, c - a) / area, v = cross2(b - a, q - a) / area;
        if (u < 0 || v < 0 || u + v > 1) continue;
        const glm::dvec3 p = (1 - u - v) * glm::dvec3(strip.positions[i0]) + u * glm::dvec3(strip.positions[i1]) +
                             v * glm::dvec3(strip.positions[i2]);
        f.mean += mapValueAt(p);
        lit += litFromLight(p) ? 1 : 0;
        ++f.inside;
        break;
      }
    }
  if (f.inside) {
    f.mean /= f.inside;
    f.litShare = double(lit) / f.inside;
  }
  return f;
}

TEST(ShadowEdges, ThinTrianglesOfANarrowChartUnderAPointLight) {
  Scene s;
  const int white = addMaterial(s, glm::vec3(0.5f));
  const uint32_t strip = static_cast<uint32_t>(addThinStrip(s, white));
  // The blocker: a quad on z = kBlockerZ, facing down, whose one edge is the line x + kSlope·y = kEdge.
  const glm::vec3 e0(kEdge - kSlope * -1.0f, -1.0f, kBlockerZ), e1(kEdge - kSlope * 1.3f, 1.3f, kBlockerZ);
  addQuad(s, white, e0, glm::vec3(-2.0f, 0, 0), e1 - e0);
  s.lights.push_back(pointLight(kLight, kIntensity));
  AtlasOptions atlas;
  atlas.texelsPerUnit = 10.0;  // the strip: 3 texels wide, 20 long
  buildAtlas(s, atlas);
  RayTracer rt(s);
  std::vector<TexelSamples> texels = buildTexelSamples(s, rt, {});
  VplSet none;
  VplEvalOptions e;
  e.includeVpls = false;
  const BakeInputs in{s, rt, texels, none, e, {}};
  const std::vector<Lightmap> centre = bakeEmbree(in);
  std::vector<Lightmap> refined = centre;
  ShadowEdgeOptions o;
  o.subSamples = 8;
  const ShadowEdgeStats st = refineShadowEdges(in, refined, o);
  ASSERT_GT(st.edgeTexels, 4u);
  size_t checked = 0;
  double worst = 0.0, sumErr = 0.0, sumCentreErr = 0.0;
  for (size_t p = 0; p < texels.size(); ++p)
    for (size_t t = 0; t < texels[p].layerSize(); ++t) {
      const TexelSamples& ts = texels[p];
      if (!ts.valid[t] || ts.primitive[t] != strip) continue;
      const Footprint f = footprintMean(s.primitives[strip], ts, t);
      // Texels the shadow's edge crosses (well inside: a sliver of light or shadow is within the sub-points'
      // granularity), at least a quarter of their square on the strip.
      if (f.inside < 64 * 64 / 4 || f.litShare < 0.1 || f.litShare > 0.9) continue;
      ++checked;
      const double r = refined[p].texels[t].x, c = centre[p].texels[t].x;
      // 8×8 sub-points against the exact mean: within 12% of it (a column of sub-points at the edge is 1/8 of
      // the square; E falls by about a third across a texel here).
      EXPECT_NEAR(r, f.mean, 0.12 * f.mean) << "texel " << t % ts.width << "," << t / ts.width << " lit share "
                                            << f.litShare << " centre " << c;
      worst = std::max(worst, std::abs(r - f.mean) / f.mean);
      sumErr += std::abs(r - f.mean) / f.mean;
      sumCentreErr += std::abs(c - f.mean) / f.mean;
    }
  ASSERT_GE(checked, 4u);
  std::printf("[ figure ] thin chart, point light 6 cm up: %zu edge texels, mean |error| %.1f%% (worst %.1f%%), the "
              "centre alone %.1f%%\n",
              checked, 100 * sumErr / checked, 100 * worst, 100 * sumCentreErr / checked);
}

}  // namespace
}  // namespace irbake
