// The texel filter over several value sets at once (the map and its directional L1 pages) gives each set
// the bits of a filter of that set alone; a plan made once gives the bits of the filter it was made from.
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <random>

#include <gtest/gtest.h>

#include "texels/texel_filter.h"

using namespace irbake;

namespace {
// A flat page of size² texels on the plane z = 0 (spacing 1/size), every texel valid with one sample.
TexelSamples flatPage(int size) {
  TexelSamples ts;
  ts.width = ts.height = size;
  ts.supersample = 1;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      ts.positionWeight.emplace_back((x + 0.5f) / size, (y + 0.5f) / size, 0.0f, 1.0f);
      ts.normal.emplace_back(0.0f, 0.0f, 1.0f, 0.0f);
    }
  ts.primitive.assign(ts.positionWeight.size(), 0);
  ts.triangle.assign(ts.positionWeight.size(), 0);
  ts.covered.assign(ts.positionWeight.size(), 1);
  ts.valid.assign(ts.positionWeight.size(), 1);
  return ts;
}
}  // namespace

TEST(SurfaceFilter, SeveralSetsAtOnceGiveTheBitsOfOneSetAtATime) {
  const TexelSamples ts = flatPage(24);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> value(-1.0f, 1.0f);
  std::vector<std::vector<glm::vec3>> sets(4, std::vector<glm::vec3>(ts.layerSize()));
  for (auto& set : sets)
    for (auto& v : set) v = glm::vec3(value(rng), value(rng), value(rng));
  std::vector<uint8_t> valid(ts.layerSize(), 1);
  valid[5] = valid[100] = 0;
  TexelFilterOptions o;
  o.radius = 3;
  o.tent = true;
  const SurfaceFilter filter(ts);
  const auto together = filter.apply({&sets[0], &sets[1], &sets[2], &sets[3]}, valid, o);
  ASSERT_EQ(together.size(), 4u);
  for (size_t s = 0; s < 4; ++s) {
    const std::vector<glm::vec3> alone = filter.apply(sets[s], valid, o);
    ASSERT_EQ(alone.size(), together[s].size());
    EXPECT_EQ(std::memcmp(alone.data(), together[s].data(), alone.size() * sizeof(glm::vec3)), 0) << s;
    EXPECT_EQ(together[s][5], sets[s][5]);  // invalid: unchanged
    EXPECT_NE(together[s][50], sets[s][50]);  // valid: mixed with its neighbours
  }
}

// A page with two surfaces (a fold along x = 12: the right half tilted 90°), a gap in the validity and a
// border: the plan's precomputed neighbour bits must give exactly SurfaceFilter::apply's result, box and tent.
TEST(SurfaceFilterPlan, GivesTheBitsOfTheFilterItWasMadeFrom) {
  TexelSamples ts = flatPage(24);
  for (int y = 0; y < 24; ++y)
    for (int x = 12; x < 24; ++x) {
      const size_t i = static_cast<size_t>(y) * 24 + x;
      ts.positionWeight[i] = glm::vec4(0.5f, (y + 0.5f) / 24, (x - 11.5f) / 24, 1.0f);
      ts.normal[i] = glm::vec4(1.0f, 0.0f, 0.0f, 0.0f);
    }
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> value(0.0f, 2.0f);
  std::vector<glm::vec3> values(ts.layerSize());
  for (auto& v : values) v = glm::vec3(value(rng), value(rng), value(rng));
  std::vector<uint8_t> valid(ts.layerSize(), 1);
  for (size_t i = 30; i < 40; ++i) valid[i] = 0;
  valid[300] = 0;
  const SurfaceFilter filter(ts);
  for (int radius : {1, 4, 5})
    for (bool tent : {false, true}) {
      TexelFilterOptions o;
      o.radius = radius;
      o.tent = tent;
      const std::vector<glm::vec3> direct = filter.apply(values, valid, o);
      const std::vector<glm::vec3> planned = SurfaceFilterPlan(filter, valid, o).apply(values);
      ASSERT_EQ(direct.size(), planned.size());
      EXPECT_EQ(std::memcmp(direct.data(), planned.data(), direct.size() * sizeof(glm::vec3)), 0) << radius << tent;
      EXPECT_EQ(planned[300], values[300]);  // invalid: unchanged
      // Texel (11, 12) is beside the fold: its window holds texels of the tilted half, which must not count.
      const size_t edge = 12 * 24 + 11;
      glm::vec3 flatOnly(0.0f);
      float count = 0.0f;
      for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= 0; ++dx) {
          const size_t j = static_cast<size_t>(12 + dy) * 24 + 11 + dx;
          const float w = tent ? static_cast<float>((radius + 1 - std::abs(dx)) * (radius + 1 - std::abs(dy))) : 1.0f;
          if (valid[j]) flatOnly += w * values[j], count += w;
        }
      EXPECT_NEAR(planned[edge].x, flatOnly.x / count, 1e-5f) << radius << tent;
    }
  TexelFilterOptions tooWide;
  tooWide.radius = SurfaceFilterPlan::kMaxRadius + 1;
  EXPECT_THROW(SurfaceFilterPlan(filter, valid, tooWide), std::invalid_argument);
}
