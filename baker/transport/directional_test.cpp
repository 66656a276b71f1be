// Closed forms of the directional (L1) light-map maths (directional.h).
#include "transport/directional.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/maths.h"

namespace irbake {
namespace {

glm::vec3 tilted(float degrees, float azimuth = 0.0f) {
  const float a = glm::radians(degrees), b = glm::radians(azimuth);
  return {std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), std::cos(a)};
}

TEST(Directional, ShProjectionIsRamamoorthiHanrahan) {
  // One source along +z: E_SH(n) = E/4 + E/2 · n·ω (Â0 = π, Â1 = 2π/3).
  const ShL1 sh = shIrradiance(2.0f, glm::vec3(0, 0, 1));
  EXPECT_NEAR(evalShIrradiance(sh, glm::vec3(0, 0, 1)), 2.0f * 0.75f, 1e-5f);
  EXPECT_NEAR(evalShIrradiance(sh, glm::vec3(1, 0, 0)), 2.0f * 0.25f, 1e-5f);
  EXPECT_NEAR(evalShIrradiance(sh, glm::vec3(0, 0, -1)), 2.0f * -0.25f, 1e-5f);
  // The stored irradiance vector is twice the band-1 gradient: g·n = 2 (E_SH(n) − E_SH band 0).
  L1Vectors g{};
  addIrradianceVector(g, glm::vec3(2.0f), glm::vec3(0, 0, 1), 1.0f);
  const glm::vec3 n = tilted(30.0f, 40.0f);
  const float gn = g[0].x * n.x + g[1].x * n.y + g[2].x * n.z;
  EXPECT_NEAR(gn, 2.0f * (evalShIrradiance(sh, n) - 2.0f * 0.25f), 1e-5f);
}

// A point light of intensity I at height h over a plane, offset d: a texel at the origin with ng = +z.
// For tilted normals the reconstruction is cosθ/r² (one source never falls below n's horizon unless
// cosθ < 0, where both are 0).
TEST(Directional, PointLightOverPlaneTiltedNormalsExact) {
  const float intensity = 10.0f, h = 2.0f, d = 1.5f;
  const glm::vec3 light(d, 0.0f, h), ng(0, 0, 1);
  const float r2 = glm::dot(light, light);
  const glm::vec3 w = light / std::sqrt(r2);
  const float e = intensity / r2;                    // irradiance facing the light
  const glm::vec3 map(e * w.z / kPiF);               // today's map at ng
  L1Vectors g{};
  addIrradianceVector(g, map, w, w.z);
  const L1Vectors t = tangentialPart(g, ng);
  EXPECT_NEAR(t[2].x, 0.0f, 1e-7f);                  // nothing along ng
  EXPECT_NEAR(t[0].x, e * w.x / kPiF, 1e-6f);
  for (float tilt : {0.0f, 10.0f, 30.0f, 60.0f, 85.0f, 120.0f})
    for (float az : {0.0f, 90.0f, 180.0f, 250.0f}) {
      const glm::vec3 n = tilted(tilt, az);
      const float exact = intensity * std::max(0.0f, glm::dot(n, w)) / r2 / kPiF;
      const glm::vec3 rec = reconstructDirectional(map, t, ng, n);
      EXPECT_NEAR(rec.x, exact, 1e-6f) << tilt << " " << az;
      EXPECT_GE(rec.x, 0.0f);
    }
  EXPECT_EQ(reconstructDirectional(map, t, ng, ng), map);
}

// Two lights on opposite sides: a tilted normal loses one below its horizon; the linear reconstruction is
// off by exactly that light's E·|n·ω| (before the clamp to 0), within the bound (ΣE)|n − ng|.
TEST(Directional, TwoLightsWithinTruncationBound) {
  const glm::vec3 ng(0, 0, 1), w1 = glm::normalize(glm::vec3(1, 0, 0.3f)), w2 = glm::normalize(glm::vec3(-1, 0, 1));
  const float e1 = 3.0f, e2 = 1.0f;
  L1Vectors g{};
  glm::vec3 map(0.0f);
  for (auto [e, w] : {std::pair{e1, w1}, std::pair{e2, w2}}) {
    const glm::vec3 m(e * w.z / kPiF);
    map += m;
    addIrradianceVector(g, m, w, w.z);
  }
  const L1Vectors t = tangentialPart(g, ng);
  float worst = 0.0f;
  for (float tilt = 0.0f; tilt <= 80.0f; tilt += 5.0f) {
    const glm::vec3 n = tilted(tilt);
    const float c1 = glm::dot(n, w1), c2 = glm::dot(n, w2);
    const float exact = (e1 * std::max(0.0f, c1) + e2 * std::max(0.0f, c2)) / kPiF;
    const float rec = reconstructDirectional(map, t, ng, n).x;
    const float below = (e1 * std::max(0.0f, -c1) + e2 * std::max(0.0f, -c2)) / kPiF;
    const float bound = (e1 + e2) * glm::length(n - ng) / kPiF;
    EXPECT_LE(std::abs(rec - exact), below + 1e-6f) << tilt;
    EXPECT_LE(below, bound + 1e-6f) << tilt;
    // Light 2 (45° the other way) drops below the horizon beyond 45°: the error is then exactly its share.
    if (c2 < 0.0f && rec > 0.0f) {
      EXPECT_NEAR(exact - rec, e2 * -c2 / kPiF, 1e-5f) << tilt;
    }
    worst = std::max(worst, std::abs(rec - exact));
  }
  EXPECT_GT(worst, 0.01f);  // the bound is reached, not trivially zero
}

// A uniform sky of radiance L over an open plane, integrated over the hemisphere (midpoint rule in cos θ
// and φ): L0 = L (E = πL), t = 0; a tilted normal gets L cos(tilt) against the exact L (1 + cos tilt)/2.
TEST(Directional, UniformSkyConstantL0ZeroL1) {
  const float radiance = 0.8f;
  const glm::vec3 ng(0, 0, 1);
  L1Vectors g{};
  glm::vec3 map(0.0f);
  const int nu = 256, nphi = 256;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nphi; ++j) {
      const float u = (i + 0.5f) / nu, phi = 2.0f * kPiF * (j + 0.5f) / nphi;  // u = cos θ
      const float s = std::sqrt(1.0f - u * u);
      const glm::vec3 w(s * std::cos(phi), s * std::sin(phi), u);
      const float dOmega = 2.0f * kPiF / (nu * nphi);
      const glm::vec3 m(radiance * dOmega * u / kPiF);
      map += m;
      addIrradianceVector(g, m, w, u);
    }
  EXPECT_NEAR(map.x, radiance, 1e-4f);
  const L1Vectors t = tangentialPart(g, ng);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(t[k].x, 0.0f, 1e-5f) << k;
  const glm::vec3 n = tilted(40.0f);
  const float rec = reconstructDirectional(map, t, ng, n).x;
  EXPECT_NEAR(rec, radiance * std::cos(glm::radians(40.0f)), 1e-4f);
  // Exact for the open plane (the lower hemisphere is the plane itself, unlit): L (1 + cos)/2; the gap is
  // the part of the sky below n's horizon, within the bound.
  const float exactTilted = radiance * (1.0f + std::cos(glm::radians(40.0f))) / 2.0f;
  EXPECT_LE(exactTilted - rec, radiance * glm::length(n - ng) + 1e-4f);
}

}  // namespace
}  // namespace irbake
