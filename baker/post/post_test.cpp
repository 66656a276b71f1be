#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "common/error.h"
#include "post/post.h"

using namespace irbake;

namespace {
Lightmap blankMap(int w, int h, int page = 0) {
  Lightmap m;
  m.page = page;
  m.width = w;
  m.height = h;
  m.texels.assign(m.size(), glm::vec3(0.0f));
  m.valid.assign(m.size(), 0);
  return m;
}

// A unit quad (two triangles) with given corner positions, one normal, and uv1 corners.
Primitive quad(const std::array<glm::vec3, 4>& p, const glm::vec3& n, const std::array<glm::vec2, 4>& uv) {
  Primitive prim;
  prim.positions.assign(p.begin(), p.end());
  prim.normals.assign(4, n);
  prim.uv1.assign(uv.begin(), uv.end());
  prim.indices = {0, 1, 2, 0, 2, 3};
  prim.lightmap = {0, 16, 16};
  return prim;
}

std::array<glm::vec2, 4> rect(float u0, float v0, float u1, float v1) {
  return {glm::vec2(u0, v0), glm::vec2(u1, v0), glm::vec2(u1, v1), glm::vec2(u0, v1)};
}

// Two coplanar unit quads sharing the edge x = 1, mapped to two separate charts of one 16×16 page.
Scene twoChartPlane(bool crease) {
  Scene s;
  s.materials.emplace_back();
  s.primitives.push_back(quad({glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(1, 1, 0), glm::vec3(0, 1, 0)},
                              glm::vec3(0, 0, 1), rect(0.125f, 0.125f, 0.375f, 0.375f)));
  if (!crease) {
    s.primitives.push_back(quad({glm::vec3(1, 0, 0), glm::vec3(2, 0, 0), glm::vec3(2, 1, 0), glm::vec3(1, 1, 0)},
                                glm::vec3(0, 0, 1), rect(0.625f, 0.5f, 0.875f, 0.75f)));
  } else {  // folded up by 90°: flat normals differ, so the shared edge is a crease, not a seam
    s.primitives.push_back(quad({glm::vec3(1, 0, 0), glm::vec3(1, 0, 1), glm::vec3(1, 1, 1), glm::vec3(1, 1, 0)},
                                glm::vec3(-1, 0, 0), rect(0.625f, 0.5f, 0.875f, 0.75f)));
  }
  return s;
}

// Left half of the page 1, right half 3: the two charts disagree by 2 along their seam.
Lightmap halvesMap() {
  Lightmap m = blankMap(16, 16);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      m.texels[y * 16 + x] = glm::vec3(x < 8 ? 1.0f : 3.0f);
      m.valid[y * 16 + x] = 1;
    }
  return m;
}
}  // namespace

TEST(Dilate, OneValidTexelFillsThePage) {
  Lightmap m = blankMap(8, 8);
  m.texels[2 * 8 + 2] = glm::vec3(1, 2, 3);
  m.valid[2 * 8 + 2] = 1;
  EXPECT_EQ(dilate(m), 63u);
  for (const auto& t : m.texels) EXPECT_EQ(t, glm::vec3(1, 2, 3));
  EXPECT_EQ(m.valid[2 * 8 + 2], 1);
  EXPECT_EQ(m.valid[0], 0);  // valid keeps meaning "computed", not "filled"
}

TEST(Dilate, GapTakesTheMeanOfBothSidesAndValidTexelsStay) {
  Lightmap m = blankMap(3, 1);
  m.texels[0] = glm::vec3(1.0f);
  m.texels[2] = glm::vec3(3.0f);
  m.valid[0] = m.valid[2] = 1;
  EXPECT_EQ(dilate(m), 1u);
  EXPECT_FLOAT_EQ(m.texels[1].x, 2.0f);
  EXPECT_FLOAT_EQ(m.texels[0].x, 1.0f);
  EXPECT_FLOAT_EQ(m.texels[2].x, 3.0f);
}

TEST(Dilate, MaxDistanceLimitsTheRings) {
  Lightmap m = blankMap(6, 1);
  m.texels[0] = glm::vec3(5.0f);
  m.valid[0] = 1;
  EXPECT_EQ(dilate(m, DilateOptions{2}), 2u);
  EXPECT_FLOAT_EQ(m.texels[2].x, 5.0f);
  EXPECT_FLOAT_EQ(m.texels[3].x, 0.0f);
}

TEST(Dilate, PageWithoutValidTexelsIsLeftAlone) {
  Lightmap m = blankMap(4, 4);
  EXPECT_EQ(dilate(m), 0u);
  for (const auto& t : m.texels) EXPECT_EQ(t, glm::vec3(0.0f));
}

TEST(Finite, NaNAndInfAreNumericErrorsNamingTheTexel) {
  Lightmap m = blankMap(4, 4, 3);
  EXPECT_NO_THROW(checkFinite(m, "x"));
  m.texels[1 * 4 + 2].y = std::numeric_limits<float>::quiet_NaN();
  try {
    checkFinite(m, "bake");
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NumericError);
    EXPECT_NE(std::string(e.what()).find("page 3 texel (2, 1) is NaN"), std::string::npos) << e.what();
  }
  m.texels[1 * 4 + 2].y = std::numeric_limits<float>::infinity();
  EXPECT_THROW(checkFinite(m, "bake"), Error);
}

TEST(Bilinear, TexelCentresAndMidpoints) {
  Lightmap m = blankMap(2, 1);
  m.texels[0] = glm::vec3(1.0f);
  m.texels[1] = glm::vec3(3.0f);
  EXPECT_FLOAT_EQ(sampleLightmap(m, {0.25f, 0.5f}).x, 1.0f);
  EXPECT_FLOAT_EQ(sampleLightmap(m, {0.5f, 0.5f}).x, 2.0f);
  EXPECT_FLOAT_EQ(sampleLightmap(m, {1.0f, 0.5f}).x, 3.0f);  // clamped at the edge
}

TEST(Seams, SharedEdgeOfTwoChartsIsOneSeam) {
  Scene s = twoChartPlane(false);
  auto seams = findSeams(s);
  ASSERT_EQ(seams.size(), 1u);  // the diagonals and outer edges are not seams
  // The seam is x = 1: uv u = 0.375 on chart A and u = 0.625 on chart B.
  EXPECT_FLOAT_EQ(seams[0].uvA0.x, 0.375f);
  EXPECT_FLOAT_EQ(seams[0].uvA1.x, 0.375f);
  EXPECT_FLOAT_EQ(seams[0].uvB0.x, 0.625f);
  EXPECT_FLOAT_EQ(seams[0].uvB1.x, 0.625f);
  EXPECT_TRUE(findSeams(twoChartPlane(true)).empty());
}

TEST(Seams, StitchingMakesBothSidesAgree) {
  Scene s = twoChartPlane(false);
  auto seams = findSeams(s);
  std::vector<Lightmap> maps{halvesMap()};
  EXPECT_NEAR(seamMismatch(maps, seams), 2.0, 1e-9);
  double after = stitchSeams(maps, seams);
  EXPECT_LT(after, 0.02);  // from 2.0: at least 100× less
  // Both sides meet half way, as the symmetric least-squares weights demand.
  glm::vec3 a = sampleLightmap(maps[0], {0.375f, 0.25f}), b = sampleLightmap(maps[0], {0.625f, 0.625f});
  EXPECT_NEAR(a.x, 2.0, 0.05);
  EXPECT_NEAR(b.x, 2.0, 0.05);
  // Texels away from the seam keep their baked values exactly.
  EXPECT_FLOAT_EQ(maps[0].texels[4 * 16 + 2].x, 1.0f);
  EXPECT_FLOAT_EQ(maps[0].texels[12 * 16 + 14].x, 3.0f);
}

TEST(Post, DilatesStitchesAndRejectsNaN) {
  Scene s = twoChartPlane(false);
  std::vector<Lightmap> maps{halvesMap()};
  for (int x = 0; x < 16; ++x) maps[0].valid[15 * 16 + x] = 0, maps[0].texels[15 * 16 + x] = glm::vec3(0.0f);
  PostStats stats = postProcess(s, maps);
  EXPECT_EQ(stats.texelsFilled, 16u);
  EXPECT_EQ(stats.seamEdges, 1u);
  EXPECT_NEAR(stats.seamMismatchBefore, 2.0, 1e-9);
  EXPECT_LT(stats.seamMismatchAfter, 0.02);
  EXPECT_FLOAT_EQ(maps[0].texels[15 * 16 + 0].x, 1.0f);  // filled from the row above
  maps[0].texels[0].x = std::nanf("");
  EXPECT_THROW(postProcess(s, maps), Error);
}
