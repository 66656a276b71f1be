#include "testing/scenes.h"

#include <cmath>

#include <cstdio>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "atlas/atlas.h"

namespace irbake::testing {

int addMaterial(Scene& s, glm::vec3 albedo, glm::vec3 emission) {
  Material m;
  m.name = std::to_string(s.materials.size());
  m.name.insert(0, 1, 'm');  // not "m" + to_string(): GCC 12 warns falsely (-Wrestrict) on that inlined operator+
  m.baseColorFactor = glm::vec4(albedo, 1.0f);
  m.emissiveFactor = emission;
  s.materials.push_back(m);
  return static_cast<int>(s.materials.size()) - 1;
}

int addQuad(Scene& s, int material, glm::vec3 p0, glm::vec3 e1, glm::vec3 e2, int div) {
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

void addBox(Scene& s, int material, glm::vec3 lo, glm::vec3 hi, bool inward, int div) {
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

Light pointLight(glm::vec3 position, float intensity) {
  Light l;
  l.type = LightType::Point;
  l.position = position;
  l.intensity = intensity;
  return l;
}

Light directionalLight(glm::vec3 direction, float intensity) {
  Light l;
  l.type = LightType::Directional;
  l.direction = glm::normalize(direction);
  l.intensity = intensity;
  return l;
}

TexelSamples gridSamples(glm::vec3 p0, glm::vec3 e1, glm::vec3 e2, int W, int H, uint32_t primitive) {
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

// Up to its sign the edge sum's direction depends on the winding: it is turned towards the polygon's centre.
glm::dvec3 polygonIrradianceVector(glm::dvec3 x, const std::vector<glm::dvec3>& poly) {
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

double polygonFormFactor(glm::dvec3 x, glm::dvec3 n, const std::vector<glm::dvec3>& poly) {
  return std::abs(glm::dot(n, polygonIrradianceVector(x, poly)));
}

double skyFractionBesideWall(double d, double h) { return 0.5 * (1.0 + d / std::sqrt(d * d + h * h)); }

void expectInterleavingBeatsIndependent(const RelativeErrors errors[2]) {
  std::printf("[ figure ] floor beside a wall, %zu texels, 4 rays, 5x5 filter: relative RMS error independent %.4f, "
              "interleaved %.4f; mean error %.5f / %.5f\n",
              errors[1].count, errors[0].rms(), errors[1].rms(), errors[0].mean(), errors[1].mean());
  EXPECT_LT(errors[1].rms(), 0.7 * errors[0].rms());
  EXPECT_LT(std::abs(errors[0].mean()), 0.003);
  EXPECT_LT(std::abs(errors[1].mean()), 0.003);
}

AtlasedScene::AtlasedScene(Scene s, int pageSize) : scene(std::move(s)) {
  AtlasOptions atlas;
  atlas.targetPageSize = atlas.maxPageSize = pageSize;
  buildAtlas(scene, atlas);
  rayTracer = std::make_unique<RayTracer>(scene);
  pages = buildTexelSamples(scene, *rayTracer, {});
}

double exactLitShare(const Scene& s, const TexelSamples& ts, size_t t, const std::function<bool(glm::vec3)>& lit,
                     const std::function<bool(glm::vec3)>& visible) {
  const Primitive& prim = s.primitives[ts.primitive[t]];
  const glm::vec2 size(ts.width, ts.height);
  auto cross2 = [](glm::vec2 u, glm::vec2 v) { return u.x * v.y - u.y * v.x; };
  const int x = static_cast<int>(t % ts.width), y = static_cast<int>(t / ts.width), K = 64;
  int inside = 0, litCount = 0;
  for (int j = 0; j < K; ++j)
    for (int i = 0; i < K; ++i) {
      const glm::vec2 q(x + (i + 0.5f) / K, y + (j + 0.5f) / K);
      for (size_t tri = 0; tri < prim.triangleCount(); ++tri) {  // the first triangle that holds q
        const uint32_t i0 = prim.indices[3 * tri], i1 = prim.indices[3 * tri + 1], i2 = prim.indices[3 * tri + 2];
        const glm::vec2 a = prim.uv1[i0] * size, b = prim.uv1[i1] * size, c = prim.uv1[i2] * size;
        const float area = cross2(b - a, c - a);
        if (!(std::abs(area) > 1e-12f)) continue;
        const float u = cross2(q - a, c - a) / area, v = cross2(b - a, q - a) / area;
        if (u < 0 || v < 0 || u + v > 1) continue;
        const glm::vec3 p = (1 - u - v) * prim.positions[i0] + u * prim.positions[i1] + v * prim.positions[i2];
        if (visible(p)) {
          ++inside;
          litCount += lit(p) ? 1 : 0;
        }
        break;
      }
    }
  return inside ? double(litCount) / inside : -1.0;
}

}  // namespace irbake::testing
