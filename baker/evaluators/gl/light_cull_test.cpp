// Light culling (lights/light_reach.h) in both evaluators, direct light only: a floor under a grid of lamps, half
// of them with range, and a sun, baked culled and brute force. Every texel differs by at most what the cut's fade
// takes from it (each cut lamp's unshadowed light less its faded light: the closed form), and a lamp whose reach
// misses the floor is in no texel's lookup.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "evaluators/embree/embree_backend.h"
#include "evaluators/gl/gl_backend.h"
#include "lights/light_kind.h"
#include "lights/light_reach.h"
#include "testing/cut_lights.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

// A 40 m floor (z = 0) under 5×5 lamps 1.5 m up, 8 m apart, every other one with a range of 5 m, a sun, and one
// lamp 1 km away with a range of 2 m (the last light); cut at 5%, sampled 64×64.
std::unique_ptr<testing::CutLightsCase> lampsOverFloor() {
  Scene s;
  testing::addQuad(s, testing::addMaterial(s, glm::vec3(0.0f)), {-20, -20, 0}, {40, 0, 0}, {0, 40, 0}, 8);
  s.lights.push_back(testing::directionalLight(glm::normalize(glm::vec3(0.2f, 0.1f, -1.0f)), 2.0f));
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i) {
      Light l = testing::pointLight({-16.0f + 8.0f * i, -16.0f + 8.0f * j, 1.5f}, 30.0f);
      if ((i + j) % 2) l.range = 5.0f;
      s.lights.push_back(l);
    }
  Light far = testing::pointLight({1000.0f, 1000.0f, 1.0f}, 30.0f);
  far.range = 2.0f;
  s.lights.push_back(far);
  return testing::cutLightsCase(std::move(s), 0.05f, testing::gridSamples({-20, -20, 0}, {40, 0, 0}, {0, 40, 0}, 64, 64));
}

// What the cut's fade takes from texel t: the cut lamps' light without the cut less their light with it.
double cutBound(const testing::CutLightsCase& c, size_t t) {
  const glm::vec3 x(c.pages[0].positionWeight[t]), n(c.pages[0].normal[t]);
  double bound = 0.0;
  for (size_t i = 0; i < c.culled.lights.size(); ++i) {
    if (!c.reach.cut[i]) continue;
    const glm::vec3 w = lightKind(c.whole.lights[i]).direct(c.whole.lights[i], x, n).mapValue;
    const glm::vec3 f = lightKind(c.culled.lights[i]).direct(c.culled.lights[i], x, n).mapValue;
    bound += double(w.x - f.x);
  }
  return bound;
}

template <typename Bake>
void expectWithinTheCutBound(const char* name, Bake bake) {
  const auto cc = lampsOverFloor();
  const testing::CutLightsCase& c = *cc;
  const size_t farLamp = c.whole.lights.size() - 1;
  ASSERT_TRUE(c.grid->culls());
  ASSERT_EQ(c.reach.cutLights(), 13u);
  const std::vector<Lightmap> a = bake(c.bruteInputs()), b = bake(c.culledInputs());
  double worst = 0.0, faded = 0.0, sum = 0.0;
  for (size_t t = 0; t < a[0].size(); ++t) {
    if (!a[0].valid[t]) continue;
    const double bound = cutBound(c, t), diff = double(a[0].texels[t].x) - double(b[0].texels[t].x);
    ASSERT_GE(diff, -1e-5 * a[0].texels[t].x) << "texel " << t;
    ASSERT_LE(diff, bound * 1.02 + 1e-5 * a[0].texels[t].x) << "texel " << t;
    worst = std::max(worst, diff / a[0].texels[t].x);
    faded += bound;
    sum += a[0].texels[t].x;
    for (uint32_t i : c.grid->near(glm::vec3(c.pages[0].positionWeight[t]))) ASSERT_NE(i, farLamp);
  }
  std::printf("[ figure ] %s: largest relative change %.2e, faded share %.2e\n", name, worst, faded / sum);
  EXPECT_GT(faded, 0.0);  // the fade takes something: the bound is exercised
  EXPECT_GT(c.grid->lookups(), 0u);
}

}  // namespace

TEST(LightCull, EmbreeKeepsEveryTexelWithinTheCutBound) {
  expectWithinTheCutBound("embree", [](const BakeInputs& in) { return bakeEmbree(in, EmbreeOptions{}); });
}

TEST(LightCull, GlKeepsEveryTexelWithinTheCutBound) {
  expectWithinTheCutBound("gl", [](const BakeInputs& in) {
    const EmbreeEvaluator contacts;
    return GlEvaluator(GlBackendOptions{}, &contacts).evaluate(in, EvaluationRequest{});
  });
}

}  // namespace irbake
