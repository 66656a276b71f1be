// The probes' field over an object (probe_field.h) against closed forms: exact on light that is linear in
// position, and a point light's change across a sphere near it, which one blend at the centre misses.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "lightmap/probe_field.h"

namespace irbake {
namespace {

LightProbeGrid gridOver(glm::vec3 lo, glm::vec3 hi, float spacing) {
  LightProbeGrid g;
  g.spacing = spacing;
  g.counts = glm::ivec3(glm::floor((hi - lo) / spacing + 1e-4f)) + 1;
  g.origin = lo;
  g.coefficients.assign(g.size(), ShCoefficients{});
  g.valid.assign(g.size(), 1);
  return g;
}

TEST(ProbeField, ExactOnLinearLight) {
  // c_k = a_k + b_k·p at every probe: the blends at c ± r are exact, so is their secant, and the field
  // reproduces the light at every point of the object.
  LightProbeGrid g = gridOver(glm::vec3(0.0f), glm::vec3(2.0f), 0.5f);
  const auto f = [](glm::vec3 p, int k) { return 0.3f + 0.1f * k + (1.0f + k) * p.x - 0.5f * p.y + 0.25f * k * p.z; };
  for (size_t i = 0; i < g.size(); ++i)
    for (int k = 0; k < kShCoefficients; ++k) g.coefficients[i][k] = glm::vec3(f(g.position(i), k));
  const glm::vec3 centre(0.8f, 1.1f, 0.9f);
  const float r = 0.3f;
  const ProbeField field = probeFieldOver(g, centre, r);
  ASSERT_EQ(field.probes, 8);
  for (int k = 0; k < kShCoefficients; ++k) {
    EXPECT_NEAR(field.gradient[0][k].x, 1.0f + k, 1e-4f);
    EXPECT_NEAR(field.gradient[1][k].x, -0.5f, 1e-4f);
    EXPECT_NEAR(field.gradient[2][k].x, 0.25f * k, 1e-4f);
  }
  for (const glm::vec3 o : {glm::vec3(0.3f, 0.0f, 0.0f), glm::vec3(-0.1f, 0.2f, -0.2f), glm::vec3(0.0f, -0.3f, 0.0f)})
    for (int k = 0; k < kShCoefficients; ++k) EXPECT_NEAR(field.at(o)[k].x, f(centre + o, k), 1e-4f) << k;
  // No probe at either end of an axis (the far layer invalid): that axis keeps a zero gradient.
  LightProbeGrid two = gridOver(glm::vec3(0.0f), glm::vec3(1.0f, 0.0f, 0.0f), 1.0f);
  two.coefficients[0][0] = glm::vec3(1.0f);
  two.valid[1] = 0;
  const ProbeField one = probeFieldOver(two, glm::vec3(0.5f, 0.0f, 0.0f), 0.2f);
  EXPECT_EQ(one.probes, 1);
  EXPECT_EQ(one.gradient[0][0], glm::vec3(0.0f));
  EXPECT_EQ(one.at(glm::vec3(0.2f, 0.0f, 0.0f))[0], glm::vec3(1.0f));
}

TEST(ProbeField, FollowsANearPointLightAcrossASphere) {
  // A point light of intensity I at the origin; each probe holds its exact L2 projection, value I/(π d²) from
  // direction l (shAddDirectional). A sphere of radius 0.1 m, 1.1 m below the light and 0.4 m to the side, seen
  // from a direction at right angles to the light, as the Cornell box's spheres are: the mean over its visible
  // half (weighted by n·v, the projected area) of the L2 irradiance at each surface point p (the light from
  // p's own direction and distance) is what the sphere should show. One blend at the centre misses how the
  // light's angle changes across the sphere near its terminator; the field follows it.
  const float I = 3.0f, spacing = 0.2f, R = 0.1f;
  LightProbeGrid g = gridOver(glm::vec3(-1.0f, -2.0f, -1.0f), glm::vec3(1.0f, -0.4f, 1.0f), spacing);
  const auto exact = [&](glm::vec3 p) {
    ShCoefficients c{};
    shAddDirectional(c, glm::normalize(-p), glm::vec3(I / (3.14159265f * glm::dot(p, p))));
    return c;
  };
  for (size_t i = 0; i < g.size(); ++i) g.coefficients[i] = exact(g.position(i));
  const glm::vec3 centre(0.4f, -1.1f, 0.05f);
  const glm::vec3 toLight = glm::normalize(-centre);
  const glm::vec3 view = glm::normalize(glm::cross(toLight, glm::vec3(0.0f, 0.0f, 1.0f)));  // ⊥ the light
  const ProbeField field = probeFieldOver(g, centre, R);
  double truth = 0.0, atCentre = 0.0, withField = 0.0, weight = 0.0;
  const int n = 4096;
  for (int i = 0; i < n; ++i) {  // a spherical Fibonacci set of normals, the visible half kept
    const double z = 1.0 - (2.0 * i + 1.0) / n, phi = i * 2.39996322972865332, s = std::sqrt(1.0 - z * z);
    const glm::vec3 nrm(static_cast<float>(s * std::cos(phi)), static_cast<float>(s * std::sin(phi)), static_cast<float>(z));
    const double w = glm::dot(nrm, view);
    if (!(w > 0.0)) continue;
    truth += w * std::max(0.0f, shIrradiance(exact(centre + R * nrm), nrm).x);
    atCentre += w * std::max(0.0f, shIrradiance(field.centre, nrm).x);
    withField += w * std::max(0.0f, shIrradiance(field.at(R * nrm), nrm).x);
    weight += w;
  }
  truth /= weight, atCentre /= weight, withField /= weight;
  std::printf("visible mean: surface %.5f, one blend at the centre %.5f (%+.2f%%), field %.5f (%+.2f%%)\n", truth,
              atCentre, 100.0 * (atCentre / truth - 1.0), withField, 100.0 * (withField / truth - 1.0));
  EXPECT_GT(std::abs(atCentre / truth - 1.0), 0.03);  // 5%: the centre's blend is off at this distance
  EXPECT_LT(std::abs(withField / truth - 1.0), 0.01);
}

}  // namespace
}  // namespace irbake
