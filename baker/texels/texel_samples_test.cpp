#include <cmath>

#include <gtest/gtest.h>

#include "raytrace/ray_tracer.h"
#include "texels/texel_samples.h"

using namespace irbake;

namespace {
constexpr uint32_t kNone = 0xffffffffu;

// The unit floor z = 0 (normal +z) with uv1 = (x, y) over a size×size page; optionally only the
// triangle with texel-space legs `leg` (a right triangle at the origin).
Primitive floorPrimitive(int size, float leg = -1.0f) {
  Primitive p;
  p.name = "floor";
  if (leg < 0) {
    p.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    p.indices = {0, 1, 2, 0, 2, 3};
  } else {
    float l = leg / size;
    p.positions = {{0, 0, 0}, {l, 0, 0}, {0, l, 0}};
    p.indices = {0, 1, 2};
  }
  for (auto& q : p.positions) {
    p.normals.push_back({0, 0, 1});
    p.uv1.push_back({q.x, q.y});
  }
  p.lightmap = {0, size, size};
  return p;
}

// A closed box with outward-facing, counter-clockwise triangles (not lightmapped).
Primitive box(glm::vec3 lo, glm::vec3 hi) {
  Primitive p;
  p.name = "wall";
  const glm::vec3 n[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  glm::vec3 c = 0.5f * (lo + hi), e = 0.5f * (hi - lo);
  for (const auto& nn : n) {
    // Two tangents spanning the face; corners c + e∘(n ± t ± b).
    glm::vec3 t = std::abs(nn.x) > 0 ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    glm::vec3 b = glm::cross(nn, t);
    uint32_t base = static_cast<uint32_t>(p.positions.size());
    for (auto [s, u] : {std::pair{-1.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {-1.f, 1.f}}) {
      p.positions.push_back(c + e * (nn + s * t + u * b));
      p.normals.push_back(nn);
    }
    uint32_t q[6] = {base, base + 1, base + 2, base, base + 2, base + 3};
    glm::vec3 g = glm::cross(p.positions[q[1]] - p.positions[q[0]], p.positions[q[2]] - p.positions[q[0]]);
    if (glm::dot(g, nn) < 0) std::swap(q[1], q[2]), std::swap(q[4], q[5]);
    p.indices.insert(p.indices.end(), q, q + 6);
  }
  return p;
}

Scene sceneOf(std::vector<Primitive> prims) {
  Scene s;
  s.materials.emplace_back();
  s.primitives = std::move(prims);
  return s;
}

size_t count(const std::vector<uint8_t>& v) {
  size_t n = 0;
  for (auto x : v) n += x != 0;
  return n;
}
}  // namespace

TEST(TexelSamples, FullPlaneSamplesSitExactlyAtTexelCentres) {
  Scene s = sceneOf({floorPrimitive(16)});
  RayTracer rt(s);
  auto pages = buildTexelSamples(s, rt, {});
  ASSERT_EQ(pages.size(), 1u);
  const TexelSamples& ts = pages[0];
  EXPECT_EQ(ts.width, 16);
  EXPECT_EQ(count(ts.covered), 256u);
  EXPECT_EQ(count(ts.valid), 256u);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      size_t i = y * 16 + x;
      EXPECT_NEAR(ts.positionWeight[i].x, (x + 0.5f) / 16.0f, 1e-6f);
      EXPECT_NEAR(ts.positionWeight[i].y, (y + 0.5f) / 16.0f, 1e-6f);
      EXPECT_NEAR(ts.positionWeight[i].z, 0.0f, 1e-7f);
      EXPECT_FLOAT_EQ(ts.positionWeight[i].w, 1.0f);
      EXPECT_EQ(glm::vec3(ts.normal[i]), glm::vec3(0, 0, 1));
      EXPECT_EQ(ts.primitive[i], 0u);
    }
}

TEST(TexelSamples, ConservativeCoverageUsesTheNearestPointOnTheTriangle) {
  // Legs of 15.8 texels: 136 texels overlap the triangle (x + y ≤ 15), 120 have their centre
  // inside (x + y ≤ 14); the 16 on the diagonal take the nearest point of the hypotenuse.
  Scene s = sceneOf({floorPrimitive(16, 15.8f)});
  RayTracer rt(s);
  const TexelSamples ts = buildTexelSamples(s, rt, {})[0];
  EXPECT_EQ(count(ts.covered), 136u);
  EXPECT_EQ(count(ts.valid), 136u);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      size_t i = y * 16 + x;
      EXPECT_EQ(ts.covered[i], x + y <= 15 ? 1 : 0) << x << "," << y;
      if (x + y == 15) {
        // Centre sum 16 → nearest point (x + 0.4, y + 0.4) on x + y = 15.8, then pulled half a texel
        // towards the centroid (15.8/3, 15.8/3), off the edge.
        const glm::vec2 nearest(x + 0.4f, y + 0.4f), centroid(15.8f / 3.0f);
        const glm::vec2 expected = nearest + 0.5f * glm::normalize(centroid - nearest);
        EXPECT_NEAR(ts.positionWeight[i].x * 16.0f, expected.x, 1e-3f);
        EXPECT_NEAR(ts.positionWeight[i].y * 16.0f, expected.y, 1e-3f);
        EXPECT_LT(ts.positionWeight[i].x * 16.0f + ts.positionWeight[i].y * 16.0f, 15.8f - 0.2f);  // off the edge
      } else if (x + y < 15) {
        EXPECT_NEAR(ts.positionWeight[i].x * 16.0f, x + 0.5f, 1e-4f);
      } else {
        EXPECT_EQ(ts.primitive[i], kNone);
        EXPECT_EQ(ts.positionWeight[i].w, 0.0f);
      }
    }
}

TEST(TexelSamples, SupersamplesAreWeightedByCoverage) {
  Scene s = sceneOf({floorPrimitive(16, 15.8f)});
  RayTracer rt(s);
  TexelSampleOptions o;
  o.supersample = 2;
  const TexelSamples ts = buildTexelSamples(s, rt, o)[0];
  ASSERT_EQ(ts.slotCount(), 4u * 256u);
  auto samplesIn = [&](int x, int y, float& weightSum) {
    int n = 0;
    weightSum = 0;
    for (int l = 0; l < 4; ++l) {
      float w = ts.positionWeight[l * 256 + y * 16 + x].w;
      n += w > 0;
      weightSum += w;
    }
    return n;
  };
  float sum;
  EXPECT_EQ(samplesIn(3, 4, sum), 4);   // x + y = 7: fully inside
  EXPECT_FLOAT_EQ(sum, 1.0f);
  EXPECT_EQ(samplesIn(7, 7, sum), 4);   // x + y = 14: sub-centre sums 14.5…15.5 ≤ 15.8
  EXPECT_FLOAT_EQ(sum, 1.0f);
  EXPECT_EQ(samplesIn(8, 7, sum), 1);   // x + y = 15: only the (¼, ¼) sub-centre (15.5) is inside
  EXPECT_FLOAT_EQ(sum, 1.0f);
  EXPECT_EQ(samplesIn(9, 7, sum), 0);
  // Layer 1 (sx = 1, sy = 0) of texel (0, 0) sits at (0.75, 0.25) texels.
  EXPECT_NEAR(ts.positionWeight[256].x * 16.0f, 0.75f, 1e-5f);
  EXPECT_NEAR(ts.positionWeight[256].y * 16.0f, 0.25f, 1e-5f);
}

TEST(TexelSamples, WallCrossingTheFloorInvalidatesTheTexelsUnderIt) {
  // Wall x ∈ [0.45, 0.55] through the floor: texel columns 7 and 8 (centres 0.469, 0.531) lie under it.
  Scene s = sceneOf({floorPrimitive(16), box({0.45f, -0.1f, -0.5f}, {0.55f, 1.1f, 0.5f})});
  RayTracer rt(s);
  const TexelSamples ts = buildTexelSamples(s, rt, {})[0];
  EXPECT_EQ(count(ts.covered), 256u);
  EXPECT_EQ(count(ts.valid), 256u - 32u);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      bool under = x == 7 || x == 8;
      EXPECT_EQ(ts.valid[y * 16 + x], under ? 0 : 1) << x << "," << y;
      if (under) {
        EXPECT_EQ(ts.positionWeight[y * 16 + x].w, 0.0f);
      }
    }
  TexelSampleOptions off;
  off.leakControl = false;
  EXPECT_EQ(count(buildTexelSamples(s, rt, off)[0].valid), 256u);
}

TEST(TexelSamples, ThinWallNextToTheTexelCentreIsFoundByTheNearRays) {
  // A wall 0.01 thick at x ∈ [0.465, 0.475] covers no texel centre of column 7 (x = 0.469 is inside
  // it, so column 7 goes) but column 6 (0.406) and 8 (0.531) are clear of it and stay valid.
  Scene s = sceneOf({floorPrimitive(16), box({0.465f, -0.1f, -0.5f}, {0.475f, 1.1f, 0.5f})});
  RayTracer rt(s);
  const TexelSamples ts = buildTexelSamples(s, rt, {})[0];
  for (int y = 0; y < 16; ++y) {
    EXPECT_EQ(ts.valid[y * 16 + 7], 0) << y;
    EXPECT_EQ(ts.valid[y * 16 + 6], 1) << y;
    EXPECT_EQ(ts.valid[y * 16 + 8], 1) << y;
  }
  EXPECT_EQ(count(ts.valid), 256u - 16u);
}

TEST(TexelSamples, DoubleSidedPlaneAboveIsNotALeak) {
  // A single quad 0.01 above the floor facing up (+z): every floor texel sees its back face.
  Primitive lid;
  lid.positions = {{0, 0, 0.01f}, {0, 1, 0.01f}, {1, 1, 0.01f}, {1, 0, 0.01f}};
  lid.indices = {0, 2, 1, 0, 3, 2};
  Scene s = sceneOf({floorPrimitive(8), lid});
  s.primitives[1].material = 1;
  s.materials.emplace_back();
  {
    RayTracer rt(s);
    // Single-sided: a surface seen from behind is a leak.
    glm::vec3 g = glm::cross(lid.positions[2] - lid.positions[0], lid.positions[1] - lid.positions[0]);
    ASSERT_GT(g.z, 0.0f);
    EXPECT_EQ(count(buildTexelSamples(s, rt, {})[0].valid), 0u);
  }
  s.materials[1].doubleSided = true;
  RayTracer rt2(s);
  EXPECT_EQ(count(buildTexelSamples(s, rt2, {})[0].valid), 64u);
}

TEST(TexelSamples, GapUnderAOneSidedSheetIsLitNearItsEdge) {
  // A one-sided sheet (an emitter under a ceiling, seen from above) 3 cm over the floor, over x, y ∈
  // [0.25, 0.75], its back towards the floor. Texels under it within two texels (3.1 cm) of its edge see
  // the room through the gap (up to 45° elevation) and are computed; texels more than 12 cm inside,
  // where even the 14° leak rays meet the sheet's back, are inside and dropped; every texel outside is
  // valid.
  const int size = 64;
  Primitive sheet;
  sheet.positions = {{0.25f, 0.25f, 0.03f}, {0.25f, 0.75f, 0.03f}, {0.75f, 0.75f, 0.03f}, {0.75f, 0.25f, 0.03f}};
  sheet.indices = {0, 2, 1, 0, 3, 2};
  Scene s = sceneOf({floorPrimitive(size), sheet});
  RayTracer rt(s);
  const TexelSamples ts = buildTexelSamples(s, rt, {})[0];
  int nearEdge = 0, nearEdgeValid = 0, deep = 0, deepValid = 0, outside = 0, outsideValid = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float px = (x + 0.5f) / size, py = (y + 0.5f) / size;
      const float inside = std::min(std::min(px - 0.25f, 0.75f - px), std::min(py - 0.25f, 0.75f - py));
      const bool valid = ts.valid[y * size + x] != 0;
      if (inside < 0.0f) {
        ++outside, outsideValid += valid;
      } else if (inside < 2.0f / size) {
        ++nearEdge, nearEdgeValid += valid;
      } else if (inside > 0.12f) {
        ++deep, deepValid += valid;
      }
    }
  EXPECT_EQ(outsideValid, outside);
  EXPECT_GT(nearEdge, 0);
  EXPECT_EQ(nearEdgeValid, nearEdge);
  EXPECT_GT(deep, 0);
  EXPECT_EQ(deepValid, 0);
}
