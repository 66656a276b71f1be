// The 8-bit light-map PNG: range at a percentile, sRGB coding, and the error measure the docs quote.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "export/lightmap_png.h"
#include "scene/image_codec.h"

using namespace irbake;

namespace {

// 1000 covered texels whose value falls geometrically from 2 to 2e-3 (three decades, like a room lit
// by one lamp), plus one hot texel at 50 and one uncovered texel at 1000 (ignored).
Lightmap decades() {
  Lightmap m;
  m.width = 1002;
  m.height = 1;
  for (int i = 0; i < 1000; ++i) {
    const float v = 2.0f * std::pow(1e-3f, i / 999.0f);
    m.texels.push_back(glm::vec3(v, 0.5f * v, 0.25f * v));
    m.valid.push_back(1);
  }
  m.texels.push_back(glm::vec3(50.0f));
  m.valid.push_back(1);
  m.texels.push_back(glm::vec3(1000.0f));
  m.valid.push_back(0);
  return m;
}

}  // namespace

TEST(LightmapPng, RangeIsTheCoveredPercentile) {
  const Lightmap m = decades();
  // Maximum of the covered texels: the hot texel, not the uncovered 1000.
  EXPECT_FLOAT_EQ(encodeLightmapPng(m, {true, 100.0}).intensity, 50.0f);
  // 1001 covered texels: the 99.9th percentile (nearest rank 1000) is the brightest of the ramp, 2.
  EXPECT_FLOAT_EQ(encodeLightmapPng(m, {true, 99.9}).intensity, 2.0f);
  // The median (nearest rank 501 from the darkest): ramp texel 999 − 500 = 499.
  EXPECT_FLOAT_EQ(encodeLightmapPng(m, {true, 50.0}).intensity, 2.0f * std::pow(1e-3f, 499 / 999.0f));
}

TEST(LightmapPng, SrgbCodesDecodeWithinHalfAStep) {
  const Lightmap m = decades();
  const LightmapPng png = encodeLightmapPng(m, {});
  const Texture back = decodeImageToTexture(png.png.data(), png.png.size(), true, "lightmap");
  ASSERT_EQ(back.width, 1002);
  for (int i = 0; i < 1000; ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = m.texels[i][c] / png.intensity;
      const float s = linearToSrgb(v);
      // The decoded value lies between the decodes of the code's half-step neighbours.
      EXPECT_GE(back.texels[i][c], srgbToLinear(std::max(0.0f, s - 0.5f / 255.0f)) - 1e-6f) << i;
      EXPECT_LE(back.texels[i][c], srgbToLinear(std::min(1.0f, s + 0.5f / 255.0f)) + 1e-6f) << i;
    }
  EXPECT_FLOAT_EQ(back.texels[1000].r, 1.0f);  // the hot texel clips at the range
}

TEST(LightmapPng, SrgbAtAPercentileKeepsTheDarksThatLinearAtTheMaximumLoses) {
  const Lightmap m = decades();
  const LightmapPngError linearMax = measureLightmapPng(m, {false, 100.0});
  const LightmapPngError srgbP999 = measureLightmapPng(m, {true, 99.9});
  // Linear over [0, 50]: a code is 0.196; blue (v/4) rounds to 0 below 0.39, i.e. for the darkest
  // log(2·0.25/0.098)/log(1000) ≈ 76% of the ramp.
  EXPECT_NEAR(linearMax.zeroFraction, 0.76, 0.02);
  EXPECT_GT(linearMax.relErrorP90, 0.99);  // those channels are lost entirely
  // sRGB over [0, 2]: the smallest blue, 5e-4/2 = 2.5e-4 of the range, is 0.82 of a code: no zeros,
  // and 9 in 10 channels within 10% (the darkest tenth sits on the curve's linear toe, a few codes).
  EXPECT_EQ(srgbP999.zeroFraction, 0.0);
  EXPECT_LT(srgbP999.relErrorP90, 0.1);
  std::printf("decades: linear/max zero %.4f p90 %.4f | srgb/p99.9 zero %.4f p90 %.4f\n", linearMax.zeroFraction, linearMax.relErrorP90,
              srgbP999.zeroFraction, srgbP999.relErrorP90);
  EXPECT_NEAR(srgbP999.clippedFraction, 1.0 / 1001.0, 1e-9);  // only the hot texel
}
