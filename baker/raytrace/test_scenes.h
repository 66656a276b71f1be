// Hand-built scenes and texel-sample grids for the light-transport tests (header only, test use).
// Plain geometry with closed-form answers: a quad is two triangles, boxes are six quads.
#pragma once
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "atlas/atlas.h"
#include "raytrace/ray_tracer.h"
#include "scene/scene.h"
#include "texels/texel_samples.h"

namespace irbake::testing {

inline int addMaterial(Scene& s, glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f)) {
  Material m;
  m.name = std::to_string(s.materials.size());
  m.name.insert(0, 1, 'm');  // not "m" + to_string(): GCC 12 warns falsely (-Wrestrict) on that inlined operator+
  m.baseColorFactor = glm::vec4(albedo, 1.0f);
  m.emissiveFactor = emission;
  s.materials.push_back(m);
  return static_cast<int>(s.materials.size()) - 1;
}

// Quad p0, p0+e1, p0+e1+e2, p0+e2 split into `div`×`div` cells; front face normal = normalize(e1 × e2).
inline int addQuad(Scene& s, int material, glm::vec3 p0, glm::vec3 e1, glm::vec3 e2, int div = 1) {
  Primitive p;
  p.name = "quad" + std::to_string(s.primitives.size());
  p.material = material;
  glm::vec3 n = glm::normalize(glm::cross(e1, e2));
  for (int j = 0; j <= div; ++j)
    for (int i = 0; i <= div; ++i) {
      p.positions.push_back(p0 + e1 * (float(i) / div) + e2 * (float(j) / div));
      p.normals.push_back(n);
      p.uv0.push_back(glm::vec2(float(i) / div, float(j) / div));
    }
  for (int j = 0; j < div; ++j)
    for (int i = 0; i < div; ++i) {
      uint32_t a = j * (div + 1) + i, b = a + 1, c = a + div + 2, d = a + div + 1;
      p.indices.insert(p.indices.end(), {a, b, c, a, c, d});
    }
  s.primitives.push_back(p);
  return static_cast<int>(s.primitives.size()) - 1;
}

// Axis-aligned box from six quads; inward = true for a room (normals point inside).
inline void addBox(Scene& s, int material, glm::vec3 lo, glm::vec3 hi, bool inward, int div = 1) {
  glm::vec3 d = hi - lo;
  glm::vec3 X(d.x, 0, 0), Y(0, d.y, 0), Z(0, 0, d.z);
  // Outward-facing quads (e1 × e2 points out); swap edges for inward.
  struct F { glm::vec3 p0, e1, e2; };
  F faces[6] = {{lo, Y, X}, {lo + Z, X, Y}, {lo, X, Z}, {lo + Y, Z, X}, {lo, Z, Y}, {lo + X, Y, Z}};
  for (const F& f : faces) {
    if (inward) addQuad(s, material, f.p0, f.e2, f.e1, div);
    else addQuad(s, material, f.p0, f.e1, f.e2, div);
  }
}

inline Light pointLight(glm::vec3 position, float intensity) {
  Light l;
  l.type = LightType::Point;
  l.position = position;
  l.intensity = intensity;
  return l;
}

// A directional light shining along `direction` (normalized here) with irradiance `intensity` (W/m²).
inline Light directionalLight(glm::vec3 direction, float intensity) {
  Light l;
  l.type = LightType::Directional;
  l.direction = glm::normalize(direction);
  l.intensity = intensity;
  return l;
}

// A W×H grid of texel samples (supersample 1) over the rectangle p0 + [0,1]e1 + [0,1]e2, texel centres,
// all valid, normal = normalize(e1 × e2). Texel (x, y) sits at p0 + (x+0.5)/W e1 + (y+0.5)/H e2.
// The samples name no triangle (primitive UINT32_MAX), so backends use the positions as given.
inline TexelSamples gridSamples(glm::vec3 p0, glm::vec3 e1, glm::vec3 e2, int W, int H, uint32_t primitive = UINT32_MAX) {
  TexelSamples t;
  t.width = W;
  t.height = H;
  t.supersample = 1;
  glm::vec3 n = glm::normalize(glm::cross(e1, e2));
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      glm::vec3 p = p0 + e1 * ((x + 0.5f) / W) + e2 * ((y + 0.5f) / H);
      t.positionWeight.push_back(glm::vec4(p, 1.0f));
      t.normal.push_back(glm::vec4(n, 0.0f));
      t.primitive.push_back(primitive);
      t.triangle.push_back(0);
    }
  t.covered.assign(t.layerSize(), 1);
  t.valid.assign(t.layerSize(), 1);
  return t;
}

// Illuminance of a Lambertian polygon of radiance 1 seen from (x, n), divided by π: the point-to-polygon
// form factor (Lambert's edge formula). The polygon must lie entirely above x's tangent plane.
// Its irradiance vector g/π (Lambert: ½ Σ edge angle · unit edge-plane normal, / π), oriented towards the
// polygon (up to its sign the sum's direction depends on the winding). n·(this) = polygonFormFactor(x, n, poly).
inline glm::dvec3 polygonIrradianceVector(glm::dvec3 x, const std::vector<glm::dvec3>& poly) {
  glm::dvec3 sum(0.0), centre(0.0);
  for (size_t i = 0; i < poly.size(); ++i) {
    glm::dvec3 a = glm::normalize(poly[i] - x), b = glm::normalize(poly[(i + 1) % poly.size()] - x);
    glm::dvec3 c = glm::cross(a, b);
    double len = glm::length(c);
    centre += poly[i];
    if (len < 1e-15) continue;
    sum += std::atan2(len, glm::dot(a, b)) * c / len;
  }
  sum /= 2.0 * 3.14159265358979323846;
  return glm::dot(sum, centre / double(poly.size()) - x) < 0.0 ? -sum : sum;
}

inline double polygonFormFactor(glm::dvec3 x, glm::dvec3 n, const std::vector<glm::dvec3>& poly) {
  return std::abs(glm::dot(n, polygonIrradianceVector(x, poly)));
}

// A floor point d from a long wall of height h sees (1 + d/√(d² + h²))/2 of a uniform sky, cosine-weighted
// (view factor from a strip element to a parallel infinite strip, Hottel's crossed strings).
inline double skyFractionBesideWall(double d, double h) { return 0.5 * (1.0 + d / std::sqrt(d * d + h * h)); }

// Relative errors value/exact − 1 over a set of texels: their RMS and mean.
struct RelativeErrors {
  double squares = 0.0, sum = 0.0;
  size_t count = 0;
  void add(double value, double exact) {
    const double e = value / exact - 1.0;
    squares += e * e;
    sum += e;
    ++count;
  }
  double rms() const { return count ? std::sqrt(squares / count) : 0.0; }
  double mean() const { return count ? sum / count : 0.0; }
};

// A floor beside a wall traced with independent lattice rotations (errors[0]) and interleaved ones (errors[1])
// at 4 rays and a 5×5 filter: prints the figure; the interleaved RMS error must be below 0.7 of the independent
// one, and both means within 0.3% (interleaving stratifies each window without biasing any texel).
inline void expectInterleavingBeatsIndependent(const RelativeErrors errors[2]) {
  std::printf("[ figure ] floor beside a wall, %zu texels, 4 rays, 5x5 filter: relative RMS error independent %.4f, "
              "interleaved %.4f; mean error %.5f / %.5f\n",
              errors[1].count, errors[0].rms(), errors[1].rms(), errors[0].mean(), errors[1].mean());
  EXPECT_LT(errors[1].rms(), 0.7 * errors[0].rms());
  EXPECT_LT(std::abs(errors[0].mean()), 0.003);
  EXPECT_LT(std::abs(errors[1].mean()), 0.003);
}

// A scene with its light-map atlas (pages of pageSize² texels), the ray tracer and the pages' samples.
struct AtlasedScene {
  Scene scene;
  std::unique_ptr<RayTracer> rayTracer;
  std::vector<TexelSamples> pages;
  AtlasedScene(Scene s, int pageSize) : scene(std::move(s)) {
    AtlasOptions atlas;
    atlas.targetPageSize = atlas.maxPageSize = pageSize;
    buildAtlas(scene, atlas);
    rayTracer = std::make_unique<RayTracer>(scene);
    pages = buildTexelSamples(scene, *rayTracer, {});
  }
};

}  // namespace irbake::testing
