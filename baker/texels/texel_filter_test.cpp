// The texel filter over several value sets at once (the map and its directional L1 pages) gives each set
// the bits of a filter of that set alone.
#include <cstring>
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
