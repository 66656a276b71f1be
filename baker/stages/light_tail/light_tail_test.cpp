// The sampled-back light tail on a closed case: a floor under 7×7 lamps without range and a wall between them,
// cut at 5% of the reference. Brute force (every lamp whole) against the culled bake with and without the tail:
// the tail removes the cut's bias (the mean difference falls within four standard errors of the estimate's own
// variance), its noise is what the stage reports, and it is smaller than the bias it replaces.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "evaluators/embree/embree_backend.h"
#include "lights/light_reach.h"
#include "raytrace/ray_tracer.h"
#include "stages/light_tail/light_tail.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

struct TailCase {
  Scene whole, culled;
  LightReach reach;
  std::unique_ptr<LightGrid> grid;
  std::vector<TexelSamples> pages;
  VplSet vpls;
};

TailCase lampsAndWall() {
  TailCase c;
  Scene& s = c.whole;
  const int m = testing::addMaterial(s, glm::vec3(0.5f));
  testing::addQuad(s, m, {-21, -21, 0}, {42, 0, 0}, {0, 42, 0}, 8);
  testing::addQuad(s, m, {1, -12, 0}, {0, 24, 0}, {0, 0, 4}, 2);
  for (int j = 0; j < 7; ++j)
    for (int i = 0; i < 7; ++i) s.lights.push_back(testing::pointLight({-18.0f + 6.0f * i, -18.0f + 6.0f * j, 1.5f}, 30.0f));
  c.culled = s;
  LightCullOptions o;
  o.fraction = 0.05f;
  c.reach = settleLightReach(c.culled, c.culled.bounds(), o);
  applyLightCutoffs(c.culled, c.reach);
  c.grid = std::make_unique<LightGrid>(c.culled, c.reach, c.culled.bounds());
  c.pages.push_back(testing::gridSamples({-21, -21, 0}, {42, 0, 0}, {0, 42, 0}, 64, 64));
  return c;
}

TEST(LightTail, SampledBackTailRemovesTheCutsBiasWithTheNoiseItReports) {
  TailCase c = lampsAndWall();
  ASSERT_TRUE(c.grid->culls());
  ASSERT_EQ(c.reach.cutLights(), 49u);
  VplEvalOptions eval;
  eval.includeVpls = false;
  RayTracer wholeRt(c.whole), culledRt(c.culled);
  BakeInputs brute{c.whole, wholeRt, c.pages, c.vpls, eval, {}};
  BakeInputs culled{c.culled, culledRt, c.pages, c.vpls, eval, {}};
  culled.lightGrid = c.grid.get();
  const std::vector<Lightmap> a = bakeEmbree(brute, EmbreeOptions{}), b = bakeEmbree(culled, EmbreeOptions{});
  std::vector<Lightmap> tail = b;
  LightTailOptions options;
  options.samples = 8;
  options.seed = 3;
  const LightTailStats stats = addLightTail(culled, tail, options);
  EXPECT_EQ(stats.lights, 49u);
  size_t n = 0;
  double bias = 0.0, biasSquares = 0.0, left = 0.0, leftSquares = 0.0, signal = 0.0;
  for (size_t t = 0; t < a[0].size(); ++t) {
    if (!a[0].valid[t]) continue;
    const double whole = a[0].texels[t].x, cut = b[0].texels[t].x, back = tail[0].texels[t].x;
    ASSERT_TRUE(std::isfinite(back));
    ASSERT_GE(back, cut - 1e-6 * whole) << "texel " << t;  // the tail only adds
    ++n;
    bias += whole - cut, biasSquares += (whole - cut) * (whole - cut);
    left += back - whole, leftSquares += (back - whole) * (back - whole);
    signal += whole;
  }
  ASSERT_EQ(stats.texels, n);
  const double standardError = std::sqrt(stats.variance) / double(n);
  const double reportedRms = std::sqrt(stats.variance / double(n)), measuredRms = std::sqrt(leftSquares / double(n));
  std::printf("[ figure ] mean map %.4g: cut bias %.4g (RMS %.4g), after the tail %.4g ± %.2g (RMS %.4g, reported %.4g), "
              "%zu rays\n", signal / n, bias / n, std::sqrt(biasSquares / n), left / n, standardError, measuredRms,
              reportedRms, stats.rays);
  EXPECT_GT(bias / double(n), 10.0 * standardError);           // the cut leaves a bias the test can see
  EXPECT_LT(std::abs(left / double(n)), 4.0 * standardError);  // and the tail takes it away
  EXPECT_GT(measuredRms, 0.5 * reportedRms);                   // the reported noise is the noise
  EXPECT_LT(measuredRms, 2.0 * reportedRms);
  EXPECT_LT(measuredRms, 0.7 * std::sqrt(biasSquares / double(n)));
}

TEST(LightTail, NothingCutNothingAddedAndNoSamplesLeaveTheCut) {
  TailCase c = lampsAndWall();
  VplEvalOptions eval;
  eval.includeVpls = false;
  RayTracer wholeRt(c.whole), culledRt(c.culled);
  std::vector<Lightmap> maps = {blankLightmap(c.pages[0])};
  BakeInputs brute{c.whole, wholeRt, c.pages, c.vpls, eval, {}};
  EXPECT_EQ(addLightTail(brute, maps, LightTailOptions{}).texels, 0u);  // no light is cut
  BakeInputs culled{c.culled, culledRt, c.pages, c.vpls, eval, {}};
  LightTailOptions none;
  none.samples = 0;
  EXPECT_EQ(addLightTail(culled, maps, none).texels, 0u);
  std::vector<uint8_t> skipAll(c.culled.lights.size(), 1);
  EXPECT_EQ(addLightTail(culled, maps, LightTailOptions{}, skipAll).lights, 0u);
  for (const glm::vec3& v : maps[0].texels) ASSERT_EQ(v, glm::vec3(0.0f));
}

}  // namespace
}  // namespace irbake
