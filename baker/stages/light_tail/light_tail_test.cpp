// The sampled-back light tail on a closed case: a floor under 7×7 lamps without range and a wall between them,
// cut at 5% of the reference. Brute force (every lamp whole) against the culled bake with and without the tail:
// the tail removes the cut's bias (the mean difference falls within four standard errors of the estimate's own
// variance), its noise is what the stage reports, and it is smaller than the bias it replaces.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "evaluators/embree/embree_backend.h"
#include "stages/light_tail/light_tail.h"
#include "testing/cut_lights.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

// A 42 m floor (z = 0) under 7×7 lamps 1.5 m up, 6 m apart, and a wall across its middle; cut at 5%, sampled
// 64×64.
std::unique_ptr<testing::CutLightsCase> lampsAndWall() {
  Scene s;
  const int m = testing::addMaterial(s, glm::vec3(0.5f));
  testing::addQuad(s, m, {-21, -21, 0}, {42, 0, 0}, {0, 42, 0}, 8);
  testing::addQuad(s, m, {1, -12, 0}, {0, 24, 0}, {0, 0, 4}, 2);
  for (int j = 0; j < 7; ++j)
    for (int i = 0; i < 7; ++i) s.lights.push_back(testing::pointLight({-18.0f + 6.0f * i, -18.0f + 6.0f * j, 1.5f}, 30.0f));
  return testing::cutLightsCase(std::move(s), 0.05f, testing::gridSamples({-21, -21, 0}, {42, 0, 0}, {0, 42, 0}, 64, 64));
}

TEST(LightTail, SampledBackTailRemovesTheCutsBiasWithTheNoiseItReports) {
  const auto cc = lampsAndWall();
  const testing::CutLightsCase& c = *cc;
  ASSERT_TRUE(c.grid->culls());
  ASSERT_EQ(c.reach.cutLights(), 49u);
  const BakeInputs brute = c.bruteInputs(), culled = c.culledInputs();
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
  const auto cc = lampsAndWall();
  const testing::CutLightsCase& c = *cc;
  std::vector<Lightmap> maps = {blankLightmap(c.pages[0])};
  EXPECT_EQ(addLightTail(c.bruteInputs(), maps, LightTailOptions{}).texels, 0u);  // no light is cut
  const BakeInputs culled = c.culledInputs();
  LightTailOptions none;
  none.samples = 0;
  EXPECT_EQ(addLightTail(culled, maps, none).texels, 0u);
  std::vector<uint8_t> skipAll(c.culled.lights.size(), 1);
  EXPECT_EQ(addLightTail(culled, maps, LightTailOptions{}, skipAll).lights, 0u);
  for (const glm::vec3& v : maps[0].texels) ASSERT_EQ(v, glm::vec3(0.0f));
}

}  // namespace
}  // namespace irbake
