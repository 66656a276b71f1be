#include "raytrace/ray_tracer.h"

#include <gtest/gtest.h>

#include "testing/scenes.h"

using namespace irbake;
using namespace irbake::testing;

namespace {
// An alpha-MASK material (cutoff 0.5) whose base colour is factor × a 2×1 clamped texture (left, right texels;
// uv0.x < 0.25 reads left only, > 0.75 right only).
int addMaskedMaterial(Scene& s, glm::vec4 factor, glm::vec4 left, glm::vec4 right) {
  const int m = addMaterial(s, glm::vec3(1.0f));
  s.materials[m].baseColorFactor = factor;
  s.materials[m].alphaMode = AlphaMode::Mask;
  s.materials[m].alphaCutoff = 0.5f;
  Texture t;
  t.width = 2;
  t.height = 1;
  t.wrapS = t.wrapT = WrapMode::ClampToEdge;
  t.texels = {left, right};
  s.materials[m].baseColorTexture = static_cast<int>(s.textures.size());
  s.textures.push_back(t);
  return m;
}
}  // namespace

TEST(RayTracer, HitsQuadWithExactDistanceBarycentricsAndNormals) {
  Scene s;
  int m = addMaterial(s, glm::vec3(0.25f, 0.5f, 0.75f));
  addQuad(s, m, glm::vec3(0, 0, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));  // z = 0, normal +z
  RayTracer rt(s);
  RayHit h = rt.intersect(glm::vec3(0.5f, 0.25f, 3.0f), glm::vec3(0, 0, -1), 0.0f, 1e30f);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.t, 3.0f, 1e-6f);
  EXPECT_NEAR(h.position.x, 0.5f, 1e-6f);
  EXPECT_NEAR(h.position.y, 0.25f, 1e-6f);
  EXPECT_NEAR(h.geometricNormal.z, 1.0f, 1e-6f);
  EXPECT_NEAR(h.shadingNormal.z, 1.0f, 1e-6f);
  EXPECT_FALSE(h.backFace);
  EXPECT_EQ(h.primitive, 0u);
  // Triangle 0 is (0,0),(2,0),(2,2): p = u·(2,0) + v·(2,2) → v = y/2, u = x/2 − v.
  EXPECT_EQ(h.triangle, 0u);
  EXPECT_NEAR(h.barycentric.y, 0.125f, 1e-6f);
  EXPECT_NEAR(h.barycentric.x, 0.125f, 1e-6f);
  glm::vec3 a = rt.albedoAt(h);
  EXPECT_FLOAT_EQ(a.x, 0.25f);
  EXPECT_FLOAT_EQ(a.z, 0.75f);

  RayHit back = rt.intersect(glm::vec3(1.0f, 1.5f, -2.0f), glm::vec3(0, 0, 1), 0.0f, 1e30f);
  ASSERT_TRUE(back.hit);
  EXPECT_TRUE(back.backFace);
  EXPECT_NEAR(back.t, 2.0f, 1e-6f);
  // tmax shorter than the distance: no hit; outside the quad: no hit.
  EXPECT_FALSE(rt.intersect(glm::vec3(0.5f, 0.5f, 3.0f), glm::vec3(0, 0, -1), 0.0f, 2.9f).hit);
  EXPECT_FALSE(rt.intersect(glm::vec3(2.5f, 0.5f, 3.0f), glm::vec3(0, 0, -1), 0.0f, 1e30f).hit);
}

TEST(RayTracer, OcclusionAndVisibilityAcrossAWall) {
  Scene s;
  int m = addMaterial(s, glm::vec3(0.5f));
  addQuad(s, m, glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));  // floor z = 0
  addQuad(s, m, glm::vec3(0, -1, 0), glm::vec3(0, 2, 0), glm::vec3(0, 0, 1));   // wall x = 0, normal +x (y × z)
  RayTracer rt(s);
  glm::vec3 up(0, 0, 1);
  EXPECT_TRUE(rt.occluded(glm::vec3(-0.5f, 0, 0.5f), glm::vec3(1, 0, 0), 0.0f, 1.0f));
  EXPECT_FALSE(rt.occluded(glm::vec3(-0.5f, 0, 0.5f), glm::vec3(1, 0, 0), 0.0f, 0.4f));
  EXPECT_FALSE(rt.occluded(glm::vec3(-0.5f, 0, 1.5f), glm::vec3(1, 0, 0), 0.0f, 1.0f));  // above the wall
  // Two floor points on either side of the wall, right at floor level: the wall hides them.
  EXPECT_FALSE(rt.visible(glm::vec3(-0.01f, 0, 0), up, glm::vec3(0.01f, 0, 0), up));
  EXPECT_TRUE(rt.visible(glm::vec3(0.2f, 0, 0), up, glm::vec3(0.6f, 0.3f, 0), up));
  // A point on the wall's front and one on the floor in front of it see each other.
  EXPECT_TRUE(rt.visible(glm::vec3(0, 0, 0.5f), glm::vec3(1, 0, 0), glm::vec3(0.5f, 0, 0), up));
}

TEST(RayTracer, EpsilonScalesWithTheScene) {
  Scene small, big;
  int m1 = addMaterial(small, glm::vec3(0.5f)), m2 = addMaterial(big, glm::vec3(0.5f));
  addQuad(small, m1, glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0));
  addQuad(big, m2, glm::vec3(0), glm::vec3(1000, 0, 0), glm::vec3(0, 1000, 0));
  RayTracer a(small), b(big);
  EXPECT_NEAR(b.epsilon() / a.epsilon(), 1000.0f, 1.0f);
  EXPECT_GT(a.epsilon(), 0.0f);
  EXPECT_LT(a.epsilon(), 1e-3f);
}

TEST(RayTracer, TexturedAlbedoAndAlphaMaskHoles) {
  Scene s;
  const int m = addMaskedMaterial(s, glm::vec4(0.5f, 1.0f, 1.0f, 1.0f), glm::vec4(0.2f, 0.2f, 0.2f, 0.0f),
                                  glm::vec4(0.8f, 0.8f, 0.8f, 1.0f));  // left: hole
  addQuad(s, m, glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0));  // uv0 = (x, y)
  // A floor below to catch rays through the hole.
  int f = addMaterial(s, glm::vec3(0.3f));
  addQuad(s, f, glm::vec3(-1, -1, -1), glm::vec3(3, 0, 0), glm::vec3(0, 3, 0));
  RayTracer rt(s);
  RayHit solid = rt.intersect(glm::vec3(0.9f, 0.5f, 1), glm::vec3(0, 0, -1), 0.0f, 1e30f);
  ASSERT_TRUE(solid.hit);
  EXPECT_EQ(solid.primitive, 0u);
  // Bilinear between texel centres 0.25 and 0.75 (clamped beyond): at u = 0.9 the right texel only.
  EXPECT_NEAR(rt.albedoAt(solid).x, 0.5f * 0.8f, 1e-5f);
  RayHit mid = rt.intersect(glm::vec3(0.625f, 0.5f, 1), glm::vec3(0, 0, -1), 0.0f, 1e30f);
  ASSERT_TRUE(mid.hit);
  EXPECT_EQ(mid.primitive, 0u);  // alpha 0.75 ≥ cutoff
  EXPECT_NEAR(rt.albedoAt(mid).y, 0.2f * 0.25f + 0.8f * 0.75f, 1e-5f);
  RayHit hole = rt.intersect(glm::vec3(0.1f, 0.5f, 1), glm::vec3(0, 0, -1), 0.0f, 1e30f);
  ASSERT_TRUE(hole.hit);
  EXPECT_EQ(hole.primitive, 1u);  // fell through the cut-out onto the floor
  EXPECT_NEAR(hole.t, 2.0f, 1e-5f);
  EXPECT_FALSE(rt.occluded(glm::vec3(0.1f, 0.5f, 1), glm::vec3(0, 0, -1), 0.0f, 1.5f));
  EXPECT_TRUE(rt.occluded(glm::vec3(0.9f, 0.5f, 1), glm::vec3(0, 0, -1), 0.0f, 1.5f));
}

TEST(RayTracer, ClosedBoxDoesNotLeakRays) {
  Scene s;
  int m = addMaterial(s, glm::vec3(0.5f));
  addBox(s, m, glm::vec3(0), glm::vec3(1), true, 3);
  RayTracer rt(s);
  // Rays from the centre through a fine grid of directions, many through edges and corners.
  int misses = 0, backHits = 0;
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 64; ++j) {
      float z = -1.0f + (i + 0.5f) / 32.0f, phi = 6.2831853f * j / 64.0f;
      float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
      glm::vec3 d(r * std::cos(phi), r * std::sin(phi), z);
      RayHit h = rt.intersect(glm::vec3(0.5f), d, 0.0f, 1e30f);
      misses += !h.hit;
      backHits += h.hit && h.backFace;
    }
  for (int k = 0; k < 8; ++k) {  // exactly at the corners
    glm::vec3 c((k & 1) ? 1.0f : 0.0f, (k & 2) ? 1.0f : 0.0f, (k & 4) ? 1.0f : 0.0f);
    misses += !rt.intersect(glm::vec3(0.5f), glm::normalize(c - glm::vec3(0.5f)), 0.0f, 1e30f).hit;
  }
  EXPECT_EQ(misses, 0);
  EXPECT_EQ(backHits, 0);
}

// Traversal::Fast (the final gather's packets) on the box of ClosedBoxDoesNotLeakRays, from its centre. A grid of
// directions that passes near (not exactly through) its edges and corners: every ray hits where the robust
// scene's does. The same grid aimed exactly through the shared edges (as ClosedBoxDoesNotLeakRays aims it), and
// the eight corners: counted, not asserted, since non-robust traversal lets such rays slip (5 of 4096 here). A
// cosine ray of the gather leaves from a jittered texel sample in a rotated lattice: it is never aimed at an edge.
TEST(RayTracer, FastTraversalHitsWhereRobustDoesOffExactEdges) {
  Scene s;
  int m = addMaterial(s, glm::vec3(0.5f));
  addBox(s, m, glm::vec3(0), glm::vec3(1), true, 3);
  RayTracer rt(s);
  auto grid = [](float shift) {
    std::vector<glm::vec3> dirs;
    for (int i = 0; i < 64; ++i)
      for (int j = 0; j < 64; ++j) {
        float z = -1.0f + (i + 0.5f) / 32.0f, phi = 6.2831853f * (j + shift) / 64.0f;
        float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        dirs.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
      }
    return dirs;
  };
  auto leaks = [&](const std::vector<glm::vec3>& dirs, int* differ) {
    std::vector<RayHit> fast(dirs.size()), robust(dirs.size());
    rt.intersectPackets(glm::vec3(0.5f), dirs.data(), dirs.size(), fast.data(), RayTracer::HitDetail::Surface,
                        RayTracer::Traversal::Fast);
    rt.intersectPackets(glm::vec3(0.5f), dirs.data(), dirs.size(), robust.data(), RayTracer::HitDetail::Surface);
    int misses = 0;
    *differ = 0;
    for (size_t k = 0; k < dirs.size(); ++k) {
      EXPECT_TRUE(robust[k].hit) << k;
      misses += !fast[k].hit;
      *differ += fast[k].hit && (fast[k].primitive != robust[k].primitive || std::abs(fast[k].t - robust[k].t) > 1e-5f);
    }
    return misses;
  };
  int differ = 0;
  for (float shift : {0.37f, 0.81f}) {
    EXPECT_EQ(leaks(grid(shift), &differ), 0) << shift;
    EXPECT_EQ(differ, 0) << shift;
  }
  const int throughEdges = leaks(grid(0.0f), &differ);
  std::vector<glm::vec3> corners;
  for (int k = 0; k < 8; ++k)
    corners.push_back(glm::normalize(glm::vec3((k & 1) ? 1.0f : 0.0f, (k & 2) ? 1.0f : 0.0f, (k & 4) ? 1.0f : 0.0f) - 0.5f));
  const int throughCorners = leaks(corners, &differ);
  std::printf("[ figure ] fast traversal: %d of 4096 rays aimed exactly through edges slip, %d of 8 corners (robust: 0)\n",
              throughEdges, throughCorners);
}

// intersectPackets (the final gather's rays, 8 to a packet) gives what intersect gives ray by ray, MASK holes
// included: 37 rays (four full packets and a partial one) from inside a box with a cut-out pane in it.
TEST(RayTracer, PacketHitsEqualSingleRayHits) {
  Scene s;
  const int wall = addMaterial(s, glm::vec3(0.5f));
  addBox(s, wall, glm::vec3(-2.0f), glm::vec3(2.0f), true);
  const int pane = addMaskedMaterial(s, glm::vec4(1.0f), glm::vec4(1.0f, 1.0f, 1.0f, 0.0f), glm::vec4(1.0f));  // left: hole
  addQuad(s, pane, glm::vec3(-1, -1, 1), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  RayTracer rt(s);
  const glm::vec3 origin(0.1f, -0.2f, 0.0f);
  std::vector<glm::vec3> dirs;
  for (int i = 0; i < 37; ++i) {
    const float z = 1.0f - 2.0f * (i + 0.5f) / 37.0f, phi = 2.39996f * i, r = std::sqrt(1.0f - z * z);
    dirs.push_back(glm::vec3(r * std::cos(phi), r * std::sin(phi), z));
  }
  std::vector<RayHit> hits(dirs.size());
  rt.intersectPackets(origin, dirs.data(), dirs.size(), hits.data());
  int paneHits = 0;
  for (size_t i = 0; i < dirs.size(); ++i) {
    const RayHit one = rt.intersect(origin, dirs[i], 0.0f, 1e30f);
    ASSERT_EQ(hits[i].hit, one.hit) << i;
    EXPECT_EQ(hits[i].primitive, one.primitive) << i;
    EXPECT_EQ(hits[i].triangle, one.triangle) << i;
    EXPECT_NEAR(hits[i].t, one.t, 1e-5f) << i;
    EXPECT_NEAR(glm::length(hits[i].position - one.position), 0.0f, 1e-5f) << i;
    EXPECT_EQ(hits[i].backFace, one.backFace) << i;
    paneHits += one.primitive == 6u;
  }
  EXPECT_GT(paneHits, 0);  // some rays stop at the pane's solid half, others pass its hole
}
