#include <numeric>

#include <gtest/gtest.h>

#include "texels/texel_area.h"

using namespace irbake;

TEST(TexelArea, StretchedPlaneSumsToItsArea) {
  // A 2 m × 1 m rectangle on a 16 × 8 page over its left half (u ∈ [0, 0.5]): 8 × 8 texels of
  // 2/64 m² each; the right half of the page is empty.
  Scene s;
  s.materials.emplace_back();
  Primitive p;
  p.positions = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}};
  p.uv1 = {{0, 0}, {0.5f, 0}, {0.5f, 1}, {0, 1}};
  p.indices = {0, 1, 2, 0, 2, 3};
  p.lightmap = {0, 16, 8};
  s.primitives.push_back(p);
  auto areas = texelWorldAreas(s);
  ASSERT_EQ(areas.size(), 1u);
  ASSERT_EQ(areas[0].size(), 128u);
  double sum = std::accumulate(areas[0].begin(), areas[0].end(), 0.0);
  EXPECT_NEAR(sum, 2.0, 1e-5);
  EXPECT_FLOAT_EQ(areas[0][3 * 16 + 2], 2.0f / 64.0f);
  EXPECT_EQ(areas[0][3 * 16 + 12], 0.0f);
}
