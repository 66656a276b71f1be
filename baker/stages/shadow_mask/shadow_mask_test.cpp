// Shadow masks against closed forms: a box over a floor under a point light gives 0 in the umbra, 1 in the
// lit region and, over the texels the shadow's edge crosses, the lit share of each texel's square; four
// overlapping lights take the four channels and a fifth gets none, while lights whose ranges never meet share one.
#include "stages/shadow_mask/shadow_mask.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "atlas/atlas.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

using namespace testing;

// Light at (0, 0, 2) over the floor z = 0, [-1, 1]²; a box [-0.2, 0.2]² × [0.5, 0.7] between: its top face
// (nearest the light) casts the umbra |x|, |y| < 0.2 · 2 / 1.3 on the floor.
constexpr float kHalfShadow = 0.2f * 2.0f / 1.3f;

struct BoxUnderPointLight {
  Scene s;
  std::unique_ptr<RayTracer> rt;
  std::vector<TexelSamples> texels;
  VplSet none;
  BoxUnderPointLight() {
    const int white = addMaterial(s, glm::vec3(0.5f));
    addQuad(s, white, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0});  // the floor, primitive 0
    addBox(s, white, {-0.2f, -0.2f, 0.5f}, {0.2f, 0.2f, 0.7f}, false);
    s.lights.push_back(pointLight({0, 0, 2}, 10.0f));
    AtlasOptions atlas;
    atlas.targetPageSize = atlas.maxPageSize = 128;
    buildAtlas(s, atlas);
    rt = std::make_unique<RayTracer>(s);
    texels = buildTexelSamples(s, *rt, {});
  }
  BakeInputs inputs() { return BakeInputs{s, *rt, texels, none, VplEvalOptions{}, {}}; }
};

TEST(ShadowMask, UmbraZeroLitOneEdgesTheLitShare) {
  BoxUnderPointLight scene;
  const ShadowMaskChannels channels = assignShadowMaskChannels(scene.s, scene.texels, {1}, {});
  ASSERT_EQ(channels.channel[0], 0);
  ShadowMaskStats stats;
  const ShadowMaskPages mask = bakeShadowMask(scene.inputs(), channels, {}, &stats);
  ASSERT_EQ(mask.rgb.size(), scene.texels.size());
  EXPECT_TRUE(mask.alpha.empty());  // one channel used
  ShadowMaskOptions centreOnly;
  centreOnly.subSamples = 1;
  const ShadowMaskPages centre = bakeShadowMask(scene.inputs(), channels, centreOnly);
  size_t umbra = 0, lit = 0, edges = 0;
  double maskSum = 0.0, exactSum = 0.0, worst = 0.0, absErr = 0.0, centreErr = 0.0;
  for (size_t p = 0; p < scene.texels.size(); ++p) {
    const TexelSamples& ts = scene.texels[p];
    for (size_t t = 0; t < ts.layerSize(); ++t) {
      if (!ts.valid[t] || ts.primitive[t] != 0) continue;  // the floor's texels
      const double exact = exactLitShare(scene.s, ts, t, [](glm::vec3 p) {  // outside the umbra
        return !(std::abs(p.x) < kHalfShadow && std::abs(p.y) < kHalfShadow);
      });
      const float m = mask.rgb[p].texels[t].x;
      EXPECT_EQ(mask.rgb[p].texels[t].y, 1.0f);  // unused channels: nothing shadows
      if (exact == 0.0) {
        EXPECT_EQ(m, 0.0f) << "umbra texel " << t;
        ++umbra;
      } else if (exact == 1.0) {
        EXPECT_EQ(m, 1.0f) << "lit texel " << t;
        ++lit;
      } else if (exact > 0.0) {
        maskSum += m;
        exactSum += exact;
        worst = std::max(worst, std::abs(m - exact));
        absErr += std::abs(m - exact);
        centreErr += std::abs(centre.rgb[p].texels[t].x - exact);
        ++edges;
      }
    }
  }
  ASSERT_GT(umbra, 100u);
  ASSERT_GT(lit, 1000u);
  ASSERT_GT(edges, 40u);
  // 8×8 rays per edge texel: each texel within 1/8 (a straight edge across the sub-point grid), the mean
  // |error| under 0.04 as the shadow-edge stage's, the mean within 1/16 (an edge along the sub-point rows
  // rounds every texel alike, by at most half a row); the centre alone is off by up to a whole texel.
  EXPECT_LT(worst, 0.13);
  EXPECT_LT(absErr / edges, 0.04);
  EXPECT_NEAR(maskSum / edges, exactSum / edges, 1.0 / 16.0);
  EXPECT_GT(centreErr, 4.0 * absErr);
  std::printf("[ figure ] box shadow: %zu edge texels, mean mask %.4f, exact lit share %.4f, mean |error| %.4f "
              "(centre only %.4f)\n", edges, maskSum / edges, exactSum / edges, absErr / edges, centreErr / edges);
  EXPECT_GT(stats.edgeTexels, 0u);
}

TEST(ShadowMask, FourOverlappingLightsTakeFourChannelsAFifthNone) {
  BoxUnderPointLight scene;
  scene.s.lights.clear();
  for (int i = 0; i < 5; ++i) scene.s.lights.push_back(pointLight({0.1f * i, 0, 2}, 10.0f - i));  // all reach the floor
  const ShadowMaskChannels c = assignShadowMaskChannels(scene.s, scene.texels, {1, 1, 1, 1, 1}, {});
  EXPECT_EQ(c.channel, (std::vector<int>{0, 1, 2, 3, -1}));  // brightest first: the dimmest falls back
  EXPECT_EQ(c.fellBack, (std::vector<size_t>{4}));
  EXPECT_EQ(c.used(), 4);
  const ShadowMaskPages mask = bakeShadowMask(scene.inputs(), c, {});
  EXPECT_EQ(mask.alpha.size(), mask.rgb.size());  // channel 3 in use
}

TEST(ShadowMask, LightsThatNeverMeetShareAChannel) {
  BoxUnderPointLight scene;
  scene.s.lights.clear();
  for (float x : {-0.8f, 0.8f}) {
    Light l = pointLight({x, 0, 0.3f}, 10.0f);
    l.range = 0.5f;  // each reaches only its own end of the floor
    scene.s.lights.push_back(l);
  }
  const ShadowMaskChannels c = assignShadowMaskChannels(scene.s, scene.texels, {1, 1}, {});
  EXPECT_EQ(c.channel, (std::vector<int>{0, 0}));
  // Without a range, the threshold decides: I / (π d²) ≥ 1e-3 reaches sqrt(10 / (π 1e-3)) ≈ 56 m: they meet.
  for (Light& l : scene.s.lights) l.range = 0.0f;
  EXPECT_EQ(assignShadowMaskChannels(scene.s, scene.texels, {1, 1}, {}).channel, (std::vector<int>{0, 1}));
}

TEST(ShadowMask, InfluenceEndsAtTheThresholdRangeAndCone) {
  Light l = pointLight({0, 0, 0}, 1.0f);
  const float reach = std::sqrt(1.0f / (3.14159265f * 1e-3f));  // ≈ 17.84 m
  EXPECT_TRUE(lightInfluences(l, {reach * 0.99f, 0, 0}, 1e-3f));
  EXPECT_FALSE(lightInfluences(l, {reach * 1.01f, 0, 0}, 1e-3f));
  l.range = 2.0f;
  EXPECT_FALSE(lightInfluences(l, {2.1f, 0, 0}, 1e-3f));
  l.type = LightType::Spot;
  l.direction = {0, 0, -1};
  l.outerConeAngle = 0.5f;
  EXPECT_TRUE(lightInfluences(l, {0.1f, 0, -1.0f}, 1e-3f));
  EXPECT_FALSE(lightInfluences(l, {1.0f, 0, -1.0f}, 1e-3f));  // 45° off the axis, outside 0.5 rad
  EXPECT_TRUE(lightInfluences(directionalLight({0, 0, -1}, 1.0f), {1e6f, 0, 0}, 1e-3f));
}

}  // namespace
}  // namespace irbake
