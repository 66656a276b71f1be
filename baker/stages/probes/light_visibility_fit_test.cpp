// The punctual lights' visibility fitted over the probes' blend, against a shadow of known shape: a sun straight
// down and a roof over x < e, so the visibility under it is exactly 1 where x > e and 0 elsewhere.
#include <cmath>

#include <gtest/gtest.h>

#include <cstdio>

#include "lightmap/probe_grid.h"
#include "sampling/sampling.h"
#include "stages/probes/light_probes.h"
#include "stages/probes/light_visibility_fit.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

using namespace testing;

constexpr float kEdge = 0.1f;  // the shadow's edge: between the probe layers at x = −0.25 and 0.25, off centre

// A floor (y = 0) and a roof at y = 3 over x < kEdge (facing down), the sun straight down; probes at 0.5 m over
// x, z ∈ [−2, 2] × [−1, 1], y ∈ [0.25, 2.75]: x layers at ±0.25, ±0.75, … so the edge lies inside a cell.
struct RoofScene {
  AtlasedScene s;
  VplSet none;
  LightProbeGrid grid;
  RoofScene() : s(makeScene(), 16) {
    Bounds3 box;
    box.extend(glm::vec3(-2.0f, 0.25f, -1.0f));
    box.extend(glm::vec3(2.0f, 2.75f, 1.0f));
    grid = probeGridOver(box, 0.5f, 1 << 12);
    grid.offsets.assign(grid.size(), glm::vec3(0.0f));
    grid.valid.assign(grid.size(), 1);
  }
  BakeInputs inputs() const { return BakeInputs{s.scene, *s.rayTracer, s.pages, none, VplEvalOptions{}, {}}; }
  static Scene makeScene() {
    Scene scene;
    const int m = addMaterial(scene, glm::vec3(0.5f));
    addQuad(scene, m, glm::vec3(-4, 0, -3), glm::vec3(0, 0, 6), glm::vec3(8, 0, 0));           // floor, facing up
    addQuad(scene, m, glm::vec3(-4, 3, -3), glm::vec3(4 + kEdge, 0, 0), glm::vec3(0, 0, 6));  // roof, facing down
    scene.lights.push_back(directionalLight(glm::vec3(0, -1, 0), 2.0f));
    return scene;
  }
};

// The blend of per-probe values v at p, as the clients form it (trilinear, valid probes, renormalised).
double blended(const LightProbeGrid& g, const std::vector<float>& v, const glm::vec3& p) {
  LightProbeGrid scalar = g;
  for (size_t i = 0; i < g.size(); ++i) scalar.coefficients[i] = ShCoefficients{}, scalar.coefficients[i][0] = glm::vec3(v[i]);
  return interpolateProbes(scalar, p).coefficients[0].x;
}

TEST(LightVisibilityFit, BeatsThePointSamplesOnAShadowEdgeAndStaysWithinZeroAndOne) {
  RoofScene r;
  r.grid.coefficients.assign(r.grid.size(), ShCoefficients{});
  const BakeInputs in = r.inputs();
  const LightVisibilityFit fit = fitLightVisibility(in, r.grid, 3, 0);
  ASSERT_EQ(fit.lights, 1u);
  ASSERT_EQ(fit.visibility.size(), r.grid.size());
  EXPECT_EQ(fit.samples, r.grid.size() * 27);  // every probe sees its whole cube (under the roof, above the floor)
  EXPECT_LT(fit.sweeps, 400);                  // converged
  for (size_t i = 0; i < r.grid.size(); ++i) {
    const float x = r.grid.position(i).x;
    EXPECT_EQ(fit.pointVisibility[i], x > kEdge ? 1.0f : 0.0f) << i;
    EXPECT_GE(fit.visibility[i], 0.0f);
    EXPECT_LE(fit.visibility[i], 1.0f);
  }
  // The mean squared error of the blend against the true visibility, at points independent of the fit's.
  Rng rng(7);
  double errPoint = 0.0, errFit = 0.0, errPointEdge = 0.0, errFitEdge = 0.0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const glm::vec3 p(-2.0f + 4.0f * float(rng.uniform()), 0.25f + 2.5f * float(rng.uniform()), -1.0f + 2.0f * float(rng.uniform()));
    const double truth = p.x > kEdge ? 1.0 : 0.0;
    const double a = blended(r.grid, fit.pointVisibility, p) - truth, b = blended(r.grid, fit.visibility, p) - truth;
    errPoint += a * a, errFit += b * b;
    if (std::abs(p.x) < 0.25f) errPointEdge += a * a, errFitEdge += b * b;
  }
  std::printf("mean squared error of the blend: point samples %.5f, fitted %.5f (cell across the edge: %.5f, %.5f)\n",
              errPoint / n, errFit / n, errPointEdge / n, errFitEdge / n);
  // The fit minimises this very error (over its own samples): it must not lose, and across the edge it gains.
  EXPECT_LT(errFit, errPoint);
  EXPECT_LT(errFitEdge, 0.95 * errPointEdge);  // 0.903 of it with this seed and edge
}

TEST(LightVisibilityFit, SamplesTheProbeCannotSeeAreLeftOut) {
  // A point light 0.5 m above a floor and one layer of probes at its height, 2 m apart: each probe's cube reaches
  // 1 m under the floor, where the light never shines. Those samples are hidden from the probe and left out, so
  // the probe under nothing keeps the whole light (v = 1), as its own shadow ray says; counted, they would pull
  // it to about 3/4 (the floor cuts a quarter of the cube off).
  Scene scene;
  const int m = addMaterial(scene, glm::vec3(0.5f));
  addQuad(scene, m, glm::vec3(-5, 0, -5), glm::vec3(0, 0, 10), glm::vec3(10, 0, 0));  // floor, facing up
  scene.lights.push_back(pointLight(glm::vec3(0.0f, 1.0f, 0.0f), 10.0f));
  AtlasedScene s(std::move(scene), 16);
  const VplSet none;
  const BakeInputs in{s.scene, *s.rayTracer, s.pages, none, VplEvalOptions{}, {}};
  Bounds3 box;
  box.extend(glm::vec3(-5.0f, 0.25f, -5.0f));
  box.extend(glm::vec3(5.0f, 0.75f, 5.0f));
  LightProbeGrid g = probeGridOver(box, 2.0f, 1 << 12);  // 5 × 1 × 5 at y = 0.5
  g.offsets.assign(g.size(), glm::vec3(0.0f));
  g.valid.assign(g.size(), 1);
  const LightVisibilityFit fit = fitLightVisibility(in, g, 4, 0);
  const double kept = double(fit.samples) / (64.0 * g.size());
  EXPECT_NEAR(kept, 0.75, 0.03);  // the cubes span y ∈ [−0.5, 1.5]: the quarter under the floor is hidden
  for (size_t i = 0; i < g.size(); ++i) EXPECT_NEAR(fit.visibility[i], 1.0f, 1e-5f) << i;
}

TEST(LightVisibilityFit, NoFitKeepsEachProbesOwnShadowRay) {
  RoofScene r;
  const BakeInputs in = r.inputs();
  const LightVisibilityFit fit = fitLightVisibility(in, r.grid, 0, 0);
  EXPECT_EQ(fit.samples, 0u);
  EXPECT_EQ(fit.visibility, fit.pointVisibility);
  // And the baked probes carry the sun as the fit says, rounded to the sun level's steps of 1/255 (what the export
  // stores and the clients subtract): L0 = 0.282095 · v · E/π, E = 2 W/m².
  std::vector<Lightmap> maps;
  for (const TexelSamples& ts : r.s.pages) maps.push_back(blankLightmap(ts));
  for (int samples : {0, 3}) {
    LightProbeGrid g = r.grid;
    ProbeOptions o;
    o.rays = 16;
    o.lightFitSamples = samples;
    bakeLightProbes(in, maps, g, o);
    const LightVisibilityFit expect = fitLightVisibility(in, g, samples, o.seed);
    for (size_t i = 0; i < g.size(); ++i) {
      if (g.valid[i]) {
        const double v = std::round(expect.visibility[i] * 255.0) / 255.0;
        EXPECT_NEAR(g.coefficients[i][0].x, 0.282095 * v * 2.0 / 3.14159265, 1e-5) << i;
        ASSERT_EQ(g.sun.visibility.size(), g.size());
        EXPECT_NEAR(g.sun.visibility[i], v, 1e-6) << i;
      }
    }
  }
}

}  // namespace
}  // namespace irbake
