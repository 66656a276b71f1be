// The cost model and the preflight: more work predicts more time and memory, the lights' reach is the
// surface within their range, and the prediction of a sample scene is complete.
#include "pipeline/cost_model.h"
#include "pipeline/bake_prediction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/error.h"
#include "samples/sample_scenes.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

using testing::addMaterial;
using testing::addQuad;
using testing::pointLight;

CostInputs levelInputs() {
  CostInputs in;
  in.triangles = 2e5;
  in.texels = 2e6;
  in.pageTexels = 2.5e6;
  in.pages = 1;
  in.paths = 3072;
  in.punctualLights = 100;
  in.lightTexels = 100 * in.texels;
  in.skyRays = 16 * in.texels;
  in.compensationRays = 2e6;
  in.gatherRays = 16 * in.texels;
  in.shadowEdgeRays = 64;
  in.probes = 2048;
  in.probeRays = 256;
  in.probeLights = 100 * in.probes;
  in.cores = 2;
  return in;
}

TEST(CostModel, MoreTexelsCostMoreTimeAndMemory) {
  const CostInputs small = levelInputs();
  CostInputs large = small;
  for (double* v : {&large.texels, &large.pageTexels, &large.lightTexels, &large.skyRays, &large.gatherRays}) *v *= 4.0;
  const CostPrediction a = predictCost(small), b = predictCost(large);
  EXPECT_GT(b.seconds, a.seconds);
  EXPECT_GT(b.memoryPeakMiB, a.memoryPeakMiB);
  for (const char* stage : {"texels", "backend", "post", "finalGather", "sky", "shadowEdges", "write"})
    EXPECT_GE(b.perStage.at(stage), a.perStage.at(stage)) << stage;
  // Each texel-bound stage that costs anything costs more; none costs less.
  size_t grew = 0;
  for (const auto& [stage, s] : a.perStage) grew += b.perStage.at(stage) > s;
  EXPECT_GE(grew, 3u);
}

TEST(CostModel, WallTimeIsTheCpuTimeOverTheBusyCores) {
  CostInputs one = levelInputs();
  one.cores = 1;
  CostInputs four = one;
  four.cores = 4;
  const CostPrediction a = predictCost(one), b = predictCost(four);
  EXPECT_NEAR(a.cpuSeconds, b.cpuSeconds, 1e-9 * a.cpuSeconds);
  EXPECT_NEAR(a.seconds / b.seconds, 4.0, 1e-9);
  EXPECT_GT(a.seconds, 0.0);
  double sum = 0.0;
  for (const auto& [stage, s] : a.perStage) sum += s;
  EXPECT_NEAR(sum, a.seconds, 1e-9 * a.seconds);
}

// Coefficients of round values, one per term the closed forms below read.
CostCoefficients roundCoefficients() {
  CostCoefficients c;
  c.gatherPerRay = 1e-7;
  c.gatherPerTexel = 1e-6;
  c.skyPerRay = 2e-7;
  c.compensationPerRay = 3e-7;
  c.compensationPerTexel = 2e-6;
  c.probesPerRay = 4e-6;
  c.probesPerProbeLight = 5e-5;
  c.texelsPerPageTexel = 1e-6;
  c.texelsPerTracedPageTexel = 2e-6;
  c.backendFixed = 0.5;
  c.backendGlFixed = 0.25;
  c.backendPerTexelPath = 1e-10;
  c.backendGlPerTexelPath = 4e-10;
  c.backendPerLightTexel = 1e-6;
  c.writeFixed = 0.75;
  c.writePerPageTexel = 1e-7;
  c.parallelShare = 1.0;
  c.memoryBaseMiB = 100.0;
  c.memoryGlContextMiB = 40.0;
  c.memoryPerTexel = 1e-4;
  c.memoryPerPageTexel = 1e-5;
  return c;
}

TEST(CostModel, ScenesTwiceAsCostlyPerRayCostTwiceAsMuchInTheirRays) {
  // The pilot's rayCost multiplies every traced count: at 2 the gather costs its rays twice and its texels once.
  const CostCoefficients c = roundCoefficients();
  CostInputs one = levelInputs();
  one.cores = 1;
  CostInputs two = one;
  two.rayCost = 2.0;
  const CostPrediction a = predictCost(one, c), b = predictCost(two, c);
  const double gatherRays = c.gatherPerRay * one.gatherRays, gatherTexels = c.gatherPerTexel * one.texels;
  EXPECT_NEAR(a.perStage.at("finalGather"), gatherRays + gatherTexels, 1e-9);
  EXPECT_NEAR(b.perStage.at("finalGather"), 2.0 * gatherRays + gatherTexels, 1e-9);
  EXPECT_NEAR(b.perStage.at("sky") / a.perStage.at("sky"), 2.0, 1e-12);
  EXPECT_NEAR(b.perStage.at("probes") / a.perStage.at("probes"), 2.0, 1e-12);
  EXPECT_NEAR(b.perStage.at("compensation") - a.perStage.at("compensation"), c.compensationPerRay * one.compensationRays,
              1e-9);
  EXPECT_NEAR(b.perStage.at("texels") - a.perStage.at("texels"), c.texelsPerTracedPageTexel * one.pageTexels, 1e-9);
  for (const char* stage : {"backend", "shadowEdges", "write"})  // the lights' short shadow rays, and nothing traced
    EXPECT_DOUBLE_EQ(b.perStage.at(stage), a.perStage.at(stage)) << stage;
  EXPECT_DOUBLE_EQ(b.memoryPeakMiB, a.memoryPeakMiB);
  // With the exponent 1.5 the same scene's rays weigh 2^1.5; at rayCost 1 nothing changes.
  CostCoefficients steeper = c;
  steeper.rayCostExponent = 1.5;
  EXPECT_NEAR(predictCost(two, steeper).perStage.at("finalGather"), std::pow(2.0, 1.5) * gatherRays + gatherTexels, 1e-9);
  EXPECT_NEAR(predictCost(one, steeper).perStage.at("finalGather"), a.perStage.at("finalGather"), 1e-12);
}

TEST(CostModel, GlEvaluatorHasItsOwnSetUpCostAndMemory) {
  const CostCoefficients c = roundCoefficients();
  CostInputs embree = levelInputs();
  embree.cores = 1;
  embree.lightTexels = 0.0;
  CostInputs gl = embree;
  gl.glBackend = 1.0;
  const double texelPaths = embree.texels * embree.paths;
  EXPECT_NEAR(predictCost(embree, c).perStage.at("backend"), 0.5 + 1e-10 * texelPaths, 1e-9);
  EXPECT_NEAR(predictCost(gl, c).perStage.at("backend"), 0.5 + 0.25 + 4e-10 * texelPaths, 1e-9);
  EXPECT_NEAR(predictCost(gl, c).memoryPeakMiB - predictCost(embree, c).memoryPeakMiB, 40.0, 1e-9);
  EXPECT_NEAR(predictCost(embree, c).perStage.at("write"), 0.75 + 1e-7 * embree.pageTexels, 1e-9);  // per bake + per texel
}

TEST(CostModel, MemoryFollowsTheChartTexelsOnAPartlyFilledPage) {
  // The same 16.8M-texel page filled with 2.5M or 10M chart texels: the peak grows by memoryPerTexel per chart texel.
  const CostCoefficients c = roundCoefficients();
  CostInputs sparse;
  sparse.pageTexels = 4096.0 * 4096.0;
  sparse.texels = 2.5e6;
  CostInputs full = sparse;
  full.texels = 1e7;
  EXPECT_NEAR(predictCost(sparse, c).memoryPeakMiB, 100.0 + 1e-4 * 2.5e6 + 1e-5 * sparse.pageTexels, 1e-9);
  EXPECT_NEAR(predictCost(full, c).memoryPeakMiB - predictCost(sparse, c).memoryPeakMiB, 1e-4 * 7.5e6, 1e-9);
}

TEST(CostModel, LightReachIsTheSurfaceWithinTheRange) {
  // A 100 m floor in 0.5 m quads; a lamp of range 6 m on it lights a disc of π 6² m², a lamp of range 6 m 4 m
  // above it a disc of π (6² − 4²) m², a lamp without range all of it. The area is binned in cubes of a third of
  // the smallest range, counted where a cube's area-weighted centroid lies in the sphere: within 20% of the disc.
  Scene s;
  const int m = addMaterial(s, glm::vec3(0.5f));
  addQuad(s, m, glm::vec3(-50, 0, -50), glm::vec3(100, 0, 0), glm::vec3(0, 0, 100), 200);
  Light onFloor = pointLight(glm::vec3(0.3f, 0.0f, 0.2f), 1.0f), above = pointLight(glm::vec3(10, 4, 10), 1.0f);
  onFloor.range = above.range = 6.0f;
  s.lights = {onFloor, above};
  AtlasEstimate atlas;
  atlas.texelsPerUnit = 4.0;
  atlas.texels = 1e4 * 16.0;
  const double perArea = 16.0, pi = std::acos(-1.0);
  const double inf = std::numeric_limits<float>::infinity();
  LightReach reach;
  reach.reach = {6.0f, 6.0f};
  const double both = lightTexelReach(s, atlas, &reach);
  s.lights = {onFloor};
  reach.reach = {6.0f};
  EXPECT_NEAR(lightTexelReach(s, atlas, &reach) / (pi * 36.0 * perArea), 1.0, 0.2);
  EXPECT_NEAR((both - lightTexelReach(s, atlas, &reach)) / (pi * 20.0 * perArea), 1.0, 0.2);
  s.lights.push_back(pointLight(glm::vec3(0, 3, 0), 1.0f));  // reaching everywhere: every texel
  reach.reach = {6.0f, float(inf)};
  EXPECT_NEAR(lightTexelReach(s, atlas, &reach) - lightTexelReach(s, atlas, nullptr) / 2.0, pi * 36.0 * perArea,
              0.2 * pi * 36.0 * perArea);
  EXPECT_DOUBLE_EQ(lightTexelReach(s, atlas, nullptr), 2.0 * atlas.texels);  // every light at every texel
}

TEST(CostModel, LightWithoutRangeReachesTheCutsDistance) {
  // Two lamps without range 2 m above a 100 m floor, 20 m apart, and a sun: the bake's cut (settleLightReach)
  // ends each at a distance R, so each lights a disc of π (R² − 2²) m² of the floor, within 20%.
  Scene s;
  const int m = addMaterial(s, glm::vec3(0.5f));
  addQuad(s, m, glm::vec3(-50, 0, -50), glm::vec3(100, 0, 0), glm::vec3(0, 0, 100), 200);
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = glm::vec3(0, -1, 0);
  sun.intensity = 2.0f;
  s.lights = {pointLight(glm::vec3(-10, 2, 0), 1.0f), pointLight(glm::vec3(10, 2, 0), 1.0f), sun};
  const LightReach reach = settleLightReach(s, s.bounds(), LightCullOptions{});
  ASSERT_EQ(reach.cutLights(), 2u);
  const double r = reach.reach[0], pi = std::acos(-1.0);
  ASSERT_GT(r, 4.0);
  ASSERT_LT(r, 10.0);
  AtlasEstimate atlas;
  atlas.texelsPerUnit = 4.0;
  atlas.texels = 1e4 * 16.0;
  const double disc = pi * (r * r - 4.0) * 16.0;
  EXPECT_NEAR((lightTexelReach(s, atlas, &reach) - atlas.texels) / (2.0 * disc), 1.0, 0.2);  // the sun: every texel
}

TEST(CostModel, ProbeLightsAreTheProbesWithinReach) {
  // A 10 x 2 x 10 m box at 1 m spacing: 10 x 2 x 10 probes, at half-integer coordinates. A light reaching
  // everywhere counts all 200, one reaching 0.1 m from a probe only that probe (its cell's half-diagonal is
  // 0.87 m, the next probe 1 m away), one reaching 0.2 m from a probe of the bottom layer (1.07 m with the
  // half-diagonal) that probe, its four neighbours in the layer and the one above it.
  Scene s;
  s.lights = {pointLight(glm::vec3(0.5f, 0.5f, 0.5f), 1.0f), pointLight(glm::vec3(-1.5f, 0.5f, 2.5f), 1.0f)};
  Bounds3 box;
  box.min = glm::vec3(-5, 0, -5);
  box.max = glm::vec3(5, 2, 5);
  EXPECT_DOUBLE_EQ(probeLightReach(s, box, 1.0f, nullptr), 400.0);
  LightReach reach;
  reach.reach = {std::numeric_limits<float>::infinity(), 0.1f};
  EXPECT_DOUBLE_EQ(probeLightReach(s, box, 1.0f, &reach), 201.0);
  reach.reach = {0.1f, 0.2f};
  EXPECT_DOUBLE_EQ(probeLightReach(s, box, 1.0f, &reach), 1.0 + 6.0);
}

TEST(BakePrediction, CornellBoxIsPredictedWithEveryPart) {
  const Scene box = samples::makeCornellBox();
  BakeOptions o;
  o.finalGather = FinalGatherMode::Auto;
  const BakePrediction p = predictBake(box, o, 2.0);
  EXPECT_EQ(p.atlas.pages, 1);
  EXPECT_GT(p.atlas.texels, 0.0);
  EXPECT_EQ(p.inputs.triangles, double(box.triangleCount()));
  EXPECT_TRUE(std::isfinite(p.cost.seconds) && p.cost.seconds > 0.0);
  EXPECT_TRUE(std::isfinite(p.cost.memoryPeakMiB) && p.cost.memoryPeakMiB > 0.0);
  EXPECT_EQ(p.plan.choices.at("clamp").value, kSettledAtBake);  // derived from the walk's VPLs
  EXPECT_EQ(p.plan.choices.at("final-gather").value, "off");    // an emissive quad: the bake's own rule
  EXPECT_TRUE(p.cost.perStage.count("backend"));
  EXPECT_FALSE(p.cost.perStage.count("finalGather"));
  EXPECT_THROW(checkMemoryLimit(p, 1e-6, "box.gltf"), Error);
  EXPECT_NO_THROW(checkMemoryLimit(p, 1e6, "box.gltf"));
  EXPECT_NO_THROW(checkMemoryLimit(p, 0.0, "box.gltf"));
}

}  // namespace
}  // namespace irbake
