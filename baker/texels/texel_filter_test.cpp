// The texel filter over several value sets at once (the map and its directional L1 pages) gives each set
// the bits of a filter of that set alone; a plan made once gives the bits of the filter it was made from.
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <random>

#include <gtest/gtest.h>

#include "texels/surface_filter_cache.h"
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
  TexelFilterOptions widestOptions;
  widestOptions.radius = SurfaceFilterPlan::kMaxRadius;
  const SurfaceFilterPlan widest(filter, valid, widestOptions);
  for (int radius : {1, 2, 3, 4, 5})
    for (int mode = 0; mode < 4; ++mode) {
      const bool tent = mode & 1, symmetric = mode & 2;
      TexelFilterOptions o;
      o.radius = radius;
      o.tent = tent;
      o.symmetric = symmetric;
      const std::vector<glm::vec3> direct = filter.apply(values, valid, o);
      const std::vector<glm::vec3> planned = SurfaceFilterPlan(filter, valid, o).apply(values);
      ASSERT_EQ(direct.size(), planned.size());
      EXPECT_EQ(std::memcmp(direct.data(), planned.data(), direct.size() * sizeof(glm::vec3)), 0) << radius << mode;
      // One plan at the widest radius serves every narrower window, either mode (the bake's shared plans).
      ASSERT_TRUE(widest.serves(valid, o));
      const std::vector<glm::vec3> fromWidest = widest.apply(values, o);
      EXPECT_EQ(std::memcmp(direct.data(), fromWidest.data(), direct.size() * sizeof(glm::vec3)), 0) << radius << mode;
      EXPECT_EQ(planned[300], values[300]);  // invalid: unchanged
      // Texel (11, 12) is beside the fold: its window holds texels of the tilted half, which must not count;
      // symmetric, their mirror images (dx < 0) do not count either, so the window is its own column.
      const size_t edge = 12 * 24 + 11;
      glm::vec3 flatOnly(0.0f);
      float count = 0.0f;
      for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = symmetric ? 0 : -radius; dx <= 0; ++dx) {
          const size_t j = static_cast<size_t>(12 + dy) * 24 + 11 + dx;
          const float w = tent ? static_cast<float>((radius + 1 - std::abs(dx)) * (radius + 1 - std::abs(dy))) : 1.0f;
          if (valid[j]) flatOnly += w * values[j], count += w;
        }
      EXPECT_NEAR(planned[edge].x, flatOnly.x / count, 1e-5f) << radius << mode;
    }
  TexelFilterOptions tooWide;
  tooWide.radius = SurfaceFilterPlan::kMaxRadius + 1;
  EXPECT_THROW(SurfaceFilterPlan(filter, valid, tooWide), std::invalid_argument);
  EXPECT_FALSE(widest.serves(valid, tooWide));
  EXPECT_THROW(widest.apply(values, tooWide), std::invalid_argument);
  // Another mask or other thresholds: the plan does not serve them.
  std::vector<uint8_t> other = valid;
  other[77] = 0;
  EXPECT_FALSE(widest.serves(other, widestOptions));
  TexelFilterOptions looser = widestOptions;
  looser.minNormalCos = 0.5f;
  EXPECT_FALSE(widest.serves(valid, looser));
}

// The bake's cache: every request gives SurfaceFilter's bits; one plan per page, made once; a mask the plan was
// not made for is filtered without it (counted), with the same bits.
TEST(SurfaceFilterCache, GivesTheFiltersBitsWithOnePlanPerPage) {
  std::vector<TexelSamples> pages = {flatPage(20), flatPage(16)};
  pages[1].positionWeight[40].z = 0.3f;  // a texel off the plane: its neighbours must not take it
  SurfaceFilterCache cache(pages);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> value(0.0f, 1.0f);
  for (size_t p = 0; p < pages.size(); ++p) {
    const TexelSamples& ts = pages[p];
    std::vector<glm::vec3> values(ts.layerSize());
    for (auto& v : values) v = glm::vec3(value(rng), value(rng), value(rng));
    EXPECT_EQ(cache.spacing(ts), SurfaceFilter(ts).spacing());
    for (int radius : {1, 3, 5, 6})
      for (bool symmetric : {false, true}) {
        TexelFilterOptions o;
        o.radius = radius;
        o.symmetric = symmetric;
        o.tent = !symmetric;
        const std::vector<glm::vec3> direct = SurfaceFilter(ts).apply(values, ts.valid, o);
        const std::vector<glm::vec3> cached = cache.apply(ts, values, ts.valid, o);
        EXPECT_EQ(std::memcmp(direct.data(), cached.data(), direct.size() * sizeof(glm::vec3)), 0) << p << radius;
      }
  }
  EXPECT_EQ(cache.plansMade(), 2u);
  EXPECT_EQ(cache.fallbacks(), 4u);  // radius 6, both modes, both pages: wider than the plans
  std::vector<uint8_t> holes = pages[0].valid;
  holes[33] = 0;
  TexelFilterOptions o;
  o.radius = 2;
  std::vector<glm::vec3> values(pages[0].layerSize(), glm::vec3(1.0f));
  values[34] = glm::vec3(5.0f);
  const std::vector<glm::vec3> direct = SurfaceFilter(pages[0]).apply(values, holes, o);
  const std::vector<glm::vec3> cached = cache.apply(pages[0], values, holes, o);
  EXPECT_EQ(std::memcmp(direct.data(), cached.data(), direct.size() * sizeof(glm::vec3)), 0);
  EXPECT_EQ(cache.fallbacks(), 5u);
  EXPECT_EQ(cache.plansMade(), 2u);
  // A page the cache does not hold is filtered all the same.
  const TexelSamples stranger = flatPage(8);
  const std::vector<glm::vec3> strangerValues(stranger.layerSize(), glm::vec3(2.0f));
  const std::vector<glm::vec3> alone = cache.apply(stranger, strangerValues, stranger.valid, o);
  EXPECT_FLOAT_EQ(alone[10].x, 2.0f);
}

// A light gradient running into a contact line (the texels left of x = 8 invalid, as under a wall standing
// on the floor): the symmetric window keeps a linear gradient exact up to the line; the one-sided window of
// the same radius reads the far side only and is biased by radius/2 texels of gradient (what brightened the
// feet of Sponza's columns).
TEST(SurfaceFilter, SymmetricWindowKeepsAGradientAtAContactLine) {
  const int size = 24, cut = 8;
  TexelSamples ts = flatPage(size);
  std::vector<uint8_t> valid(ts.layerSize(), 1);
  std::vector<glm::vec3> values(ts.layerSize(), glm::vec3(0.0f));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const size_t i = static_cast<size_t>(y) * size + x;
      valid[i] = x >= cut;
      values[i] = glm::vec3(0.1f + 0.05f * (x - cut) + 0.01f * y);  // brighter away from the line
    }
  const SurfaceFilter filter(ts);
  for (int radius : {1, 3, 5}) {
    TexelFilterOptions symmetric, oneSided;
    symmetric.radius = oneSided.radius = radius;
    oneSided.symmetric = false;
    const std::vector<glm::vec3> a = filter.apply(values, valid, symmetric);
    const std::vector<glm::vec3> b = filter.apply(values, valid, oneSided);
    for (int x = cut; x < cut + radius; ++x) {
      const size_t i = static_cast<size_t>(12) * size + x;
      EXPECT_NEAR(a[i].x, values[i].x, 1e-5f) << radius << " " << x;
      // One-sided: the window's mean column lies (radius − (x − cut)) / 2 texels too far from the line, each
      // 0.05 brighter; a bias that grows with the texel size in world units.
      const float biasTexels = 0.5f * static_cast<float>(radius - (x - cut));
      EXPECT_NEAR(b[i].x - values[i].x, 0.05f * biasTexels, 1e-5f) << radius << " " << x;
      EXPECT_GT(b[i].x, values[i].x + 0.01f);
    }
  }
}
