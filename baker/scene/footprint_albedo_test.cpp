#include <gtest/gtest.h>

#include <random>

#include "scene/footprint_albedo.h"

namespace irbake {
namespace {

Texture randomTexture(int w, int h, unsigned seed) {
  Texture t;
  t.width = w;
  t.height = h;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < w * h; ++i) t.texels.emplace_back(u(rng), u(rng), u(rng), 1.0f);
  return t;
}

// A 1 m quad in z = 0 (two triangles) whose texture UVs span `repeats` copies of the texture, on a light-map page
// of mapSize² texels that it covers whole.
Scene texturedQuad(const Texture& tex, float repeats, int mapSize) {
  Scene s;
  s.textures.push_back(tex);
  Material m;
  m.baseColorFactor = glm::vec4(0.5f, 1.0f, 1.0f, 1.0f);
  m.baseColorTexture = 0;
  s.materials.push_back(m);
  Primitive p;
  p.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  p.normals.assign(4, glm::vec3(0, 0, 1));
  p.uv1 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (const glm::vec2& uv : p.uv1) p.uv0.push_back(uv * repeats);
  p.indices = {0, 1, 2, 0, 2, 3};
  p.lightmap.page = 0;
  p.lightmap.width = p.lightmap.height = mapSize;
  s.primitives.push_back(p);
  return s;
}

TEST(FootprintAlbedo, EveryLevelTexelIsTheExactMeanOfTheTexelsItCovers) {
  for (glm::ivec2 size : {glm::ivec2(8, 8), glm::ivec2(5, 3), glm::ivec2(1, 7)}) {
    const Texture t = randomTexture(size.x, size.y, 3);
    const Texture d = downsampleTexture(t);
    ASSERT_EQ(d.width, std::max(1, size.x / 2));
    ASSERT_EQ(d.height, std::max(1, size.y / 2));
    // Every source texel lies in exactly one destination texel: the per-texel means, weighted by their
    // counts, give back the source's sum.
    glm::dvec4 sum(0.0), weighted(0.0);
    for (const glm::vec4& v : t.texels) sum += glm::dvec4(v);
    for (int y = 0; y < d.height; ++y)
      for (int x = 0; x < d.width; ++x) {
        const int x0 = x * t.width / d.width, x1 = (x + 1) * t.width / d.width;
        const int y0 = y * t.height / d.height, y1 = (y + 1) * t.height / d.height;
        glm::dvec4 block(0.0);
        for (int sy = y0; sy < y1; ++sy)
          for (int sx = x0; sx < x1; ++sx) block += glm::dvec4(t.texels[sy * t.width + sx]);
        const glm::dvec4 mean = block / double((x1 - x0) * (y1 - y0));
        for (int c = 0; c < 4; ++c) EXPECT_NEAR(d.texels[y * d.width + x][c], mean[c], 1e-6);
        weighted += mean * double((x1 - x0) * (y1 - y0));
      }
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(weighted[c], sum[c], 1e-4);
  }
}

TEST(FootprintAlbedo, ReadsTheLevelOfOneMapTexel) {
  // 256² texture once over the quad on a 32² page: 8 texture texels per map texel → level 3 (a 32² level), and a
  // read there is the mean of the 8×8 source block around it. A checkerboard of 1-texel squares reads 0.5.
  Texture checker;
  checker.width = checker.height = 256;
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) checker.texels.push_back(glm::vec4(float((x + y) & 1)));
  const Scene s = texturedQuad(checker, 1.0f, 32);
  const FootprintAlbedo albedo(s);
  EXPECT_EQ(albedo.level(0, 0), 3);
  EXPECT_EQ(albedo.level(0, 1), 3);
  for (glm::vec2 b : {glm::vec2(0.2f, 0.3f), glm::vec2(0.6f, 0.1f), glm::vec2(0.05f, 0.9f)}) {
    const glm::vec3 a = albedo.at(0, 1, b);
    EXPECT_NEAR(a.x, 0.25f, 1e-6f);  // factor 0.5 × mean 0.5
    EXPECT_NEAR(a.y, 0.5f, 1e-6f);
    // The point read (Scene::baseColorAt) lands on 0 or 1 or between: it is what the level averages.
    const glm::vec4 point = s.baseColorAt(s.primitives[0], 1, b);
    EXPECT_GE(point.y, 0.0f);
    EXPECT_LE(point.y, 1.0f);
  }
  // Repeated 4 times over the quad: 32 texels per map texel → level 5.
  EXPECT_EQ(FootprintAlbedo(texturedQuad(checker, 4.0f, 32)).level(0, 0), 5);
}

TEST(FootprintAlbedo, AMapFinerThanTheTextureReadsTheTextureItself) {
  const Texture t = randomTexture(16, 16, 5);
  const Scene s = texturedQuad(t, 1.0f, 64);  // a quarter texture texel per map texel
  const FootprintAlbedo albedo(s);
  EXPECT_EQ(albedo.level(0, 0), 0);
  for (glm::vec2 b : {glm::vec2(0.2f, 0.3f), glm::vec2(0.6f, 0.1f)}) {
    const glm::vec3 want(s.baseColorAt(s.primitives[0], 0, b)), got = albedo.at(0, 0, b);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(got[c], want[c]);
  }
  // Without a light-map page (not baked): level 0 as well.
  Scene unmapped = texturedQuad(t, 4.0f, 64);
  unmapped.primitives[0].lightmap.page = -1;
  EXPECT_EQ(FootprintAlbedo(unmapped).level(0, 0), 0);
}

}  // namespace
}  // namespace irbake
