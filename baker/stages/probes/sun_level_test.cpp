// The clients' sun-level rule (lightmap/probe_grid.h, ProbeSunLevel) on a hand-made grid with closed forms: two
// probes 1 m apart along x, the first shaded (v = 0, no light), the second fully sunlit (v = 1, the sun's SH
// alone); the cell's lattice (S = 4) lit from x = 0.5 on. A point takes the lattice's trilinear visibility of the
// sun instead of the probes' blend of it, and so does the field over an object. The clients shade that sun as an
// exact clamped cosine at the visibility the blend carries (shadeProbeLambert), not through L2.
#include <gtest/gtest.h>

#include "lightmap/probe_field.h"

namespace irbake {
namespace {

LightProbeGrid litEdgeGrid() {
  LightProbeGrid g;
  g.spacing = 1.0f;
  g.counts = glm::ivec3(2, 1, 1);
  g.coefficients.assign(2, ShCoefficients{});
  g.valid.assign(2, 1);
  g.sun.subdivisions = 4;
  g.sun.direction = glm::vec3(0.0f, -1.0f, 0.0f);  // straight down: toward it is +y
  g.sun.irradiance = glm::vec3(1.0f, 0.5f, 0.25f);
  shAddDirectional(g.sun.sh, glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(1.0f, 0.5f, 0.25f));
  g.coefficients[1] = g.sun.sh;
  g.sun.visibility = {0.0f, 1.0f};
  g.sun.cells = {0};
  g.sun.fine.assign(static_cast<size_t>(g.sun.wordsPerCell()), 0u);
  for (int d = 0; d <= 4; ++d)
    for (int b = 0; b <= 4; ++b)
      for (int a = 2; a <= 4; ++a) {  // x = 0.5, 0.75, 1 lit
        const int n = a + 5 * (b + 5 * d);
        g.sun.fine[n / 32] |= 1u << (n % 32);
      }
  return g;
}

// The share of the sun's SH in the blend at x (its L0 coefficient's red over the sun's).
float sunShare(const LightProbeGrid& g, float x) {
  return interpolateProbes(g, glm::vec3(x, 0.0f, 0.0f)).coefficients[0].r / g.sun.sh[0].r;
}

TEST(ProbeSunLevel, BlendTakesTheLatticesSun) {
  LightProbeGrid g = litEdgeGrid();
  EXPECT_NEAR(sunShare(g, 0.6f), 1.0f, 1e-6f);   // between lit lattice points 0.5 and 0.75
  EXPECT_NEAR(sunShare(g, 0.3f), 0.2f, 1e-6f);   // 0.2 of the way from 0.25 (shaded) to 0.5 (lit)
  EXPECT_NEAR(sunShare(g, 0.1f), 0.0f, 1e-6f);   // between shaded points
  // Every coefficient follows: the blend is the sun's SH times the lattice's visibility.
  const ProbeBlend b = interpolateProbes(g, glm::vec3(0.3f, 0.0f, 0.0f));
  for (int k = 0; k < kShCoefficients; ++k) EXPECT_NEAR(b.coefficients[k].g, 0.2f * g.sun.sh[k].g, 1e-6f) << k;
  // A client that ignores the level reads the probes' blend: x itself.
  LightProbeGrid plain = g;
  plain.sun = ProbeSunLevel{};
  EXPECT_NEAR(sunShare(g, 0.6f) - 0.4f, interpolateProbes(plain, glm::vec3(0.6f, 0, 0)).coefficients[0].r / g.sun.sh[0].r, 1e-6f);
  // A cell not in the list is left alone.
  g.sun.cells = {};
  g.sun.fine.clear();
  EXPECT_NEAR(sunShare(g, 0.6f), 0.6f, 1e-6f);
}

TEST(ProbeSunLevel, FieldOverAnObjectInTheLightIsFlat) {
  // An object of radius 0.1 at x = 0.65 lies wholly in the lattice's light: its blends at 0.55 and 0.75 both
  // carry the whole sun, so the field is the sun's SH with no gradient (the probes alone: a gradient of one sun
  // per metre along x).
  const LightProbeGrid g = litEdgeGrid();
  const ProbeField f = probeFieldOver(g, glm::vec3(0.65f, 0.0f, 0.0f), 0.1f);
  EXPECT_NEAR(f.centre[0].r, g.sun.sh[0].r, 1e-6f);
  EXPECT_NEAR(f.gradient[0][0].r, 0.0f, 1e-5f);
  EXPECT_NEAR(f.sunVisibility, 1.0f, 1e-6f);
  EXPECT_NEAR(f.sunGradient.x, 0.0f, 1e-5f);
  // Across the lattice's edge (x = 0.25 shaded, 0.5 lit) the visibility ramps 4 per metre, as the coefficients.
  const ProbeField edge = probeFieldOver(g, glm::vec3(0.375f, 0.0f, 0.0f), 0.1f);
  EXPECT_NEAR(edge.sunVisibility, 0.5f, 1e-6f);
  EXPECT_NEAR(edge.sunGradient.x, 4.0f, 1e-4f);
  EXPECT_NEAR(edge.sunAt(glm::vec3(0.05f, 0.0f, 0.0f)), 0.7f, 1e-5f);
  EXPECT_EQ(edge.sunAt(glm::vec3(1.0f, 0.0f, 0.0f)), 1.0f);  // clamped
}

TEST(ProbeSunLevel, BlendCarriesTheVisibilityItsCoefficientsHold) {
  LightProbeGrid g = litEdgeGrid();
  EXPECT_NEAR(interpolateProbes(g, glm::vec3(0.3f, 0.0f, 0.0f)).sunVisibility, 0.2f, 1e-6f);  // the lattice's
  g.sun.cells = {};
  g.sun.fine.clear();
  EXPECT_NEAR(interpolateProbes(g, glm::vec3(0.3f, 0.0f, 0.0f)).sunVisibility, 0.3f, 1e-6f);  // the probes' blend
  g.valid[1] = 0;  // the lit probe left out: the shaded one alone
  EXPECT_NEAR(interpolateProbes(g, glm::vec3(0.3f, 0.0f, 0.0f)).sunVisibility, 0.0f, 1e-6f);
  g.sun = ProbeSunLevel{};
  EXPECT_EQ(interpolateProbes(g, glm::vec3(0.3f, 0.0f, 0.0f)).sunVisibility, 0.0f);  // no sun level
}

// E(n)/π of the sun alone, v = 0.2 at x = 0.3, is 0.2 · irradiance · max(0, n·up) for every normal: facing the sun,
// at 60° from it, at 90° and facing away. L2 alone reads 17/16, 59/128, 3/32 and 1/16 of 0.2 · irradiance there.
TEST(ProbeSunLevel, ShadesTheSunAsAnExactClampedCosine) {
  const LightProbeGrid g = litEdgeGrid();
  const ProbeBlend b = interpolateProbes(g, glm::vec3(0.3f, 0.0f, 0.0f));
  const float s60 = std::sqrt(3.0f) / 2.0f;
  const std::pair<glm::vec3, float> cases[] = {{{0.0f, 1.0f, 0.0f}, 1.0f}, {{s60, 0.5f, 0.0f}, 0.5f},
                                               {{0.0f, 0.0f, 1.0f}, 0.0f}, {{0.0f, -1.0f, 0.0f}, 0.0f}};
  for (const auto& [n, cosine] : cases) {
    const glm::vec3 exact = 0.2f * g.sun.irradiance * cosine;
    const glm::vec3 shaded = shadeProbeLambert(b.coefficients, b.sunVisibility, g.sun, n);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(shaded[c], exact[c], 1e-6f) << n.x << "," << n.y << "," << n.z;
  }
  // Through L2 the same light rings: 3/32 of the sun at 90° from it.
  EXPECT_NEAR(shIrradiance(b.coefficients, glm::vec3(0.0f, 0.0f, 1.0f)).r, 0.2f * 3.0f / 32.0f, 1e-5f);
  // The rest of the light (here a uniform 0.5 added to both probes' L0) stays in L2 beside it.
  LightProbeGrid lit = g;
  for (auto& c : lit.coefficients) c[0] += glm::vec3(0.5f / 0.886227f);
  const ProbeBlend l = interpolateProbes(lit, glm::vec3(0.3f, 0.0f, 0.0f));
  EXPECT_NEAR(shadeProbeLambert(l.coefficients, l.sunVisibility, lit.sun, glm::vec3(0.0f, 1.0f, 0.0f)).r, 0.5f + 0.2f, 1e-5f);
  // Without a sun level: the L2 shading clamped at 0.
  LightProbeGrid plain = g;
  plain.sun = ProbeSunLevel{};
  EXPECT_NEAR(shadeProbeLambert(b.coefficients, 0.0f, plain.sun, glm::vec3(0.0f, 1.0f, 0.0f)).r, 0.2f * 17.0f / 16.0f, 1e-5f);
}

}  // namespace
}  // namespace irbake
