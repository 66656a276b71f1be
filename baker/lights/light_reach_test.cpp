// The lights' reach and their grid: no light that reaches a point is left out of its lookup, the cut's fade
// changes a light only in the last quarter of its reach and by at most its value there, and a light that
// reaches the whole scene is never cut.
#include "lights/light_reach.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "common/maths.h"
#include "lights/light_kind.h"
#include "sampling/sampling.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

// A 100 m square floor (y = 0, normal +y) lit by a sun and a 10×10 grid of lamps 2 m up, every other one with a
// range of 6 m.
Scene lampGrid() {
  Scene s;
  testing::addQuad(s, testing::addMaterial(s, glm::vec3(0.5f)), glm::vec3(-50, 0, 50), glm::vec3(100, 0, 0),
                   glm::vec3(0, 0, -100));
  s.lights.push_back(testing::directionalLight(glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f)), 3.0f));
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 10; ++i) {
      Light l = testing::pointLight(glm::vec3(-45.0f + 10.0f * i, 2.0f, -45.0f + 10.0f * j), 40.0f);
      if ((i + j) % 2) l.range = 6.0f;
      s.lights.push_back(l);
    }
  return s;
}

glm::vec3 floorPoint(uint32_t k) {
  const double u = radicalInverse(2, k), v = radicalInverse(3, k);
  return glm::vec3(-50.0f + 100.0f * float(u), 0.0f, -50.0f + 100.0f * float(v));
}

}  // namespace

// The reference is the sun's E/π or the lamps' light at their spacing, whichever is brighter; a lamp without
// range reaches where I/(π d²) falls to fraction × reference, a lamp with range its range.
TEST(LightReach, ReachFollowsTheStatedThreshold) {
  Scene s = lampGrid();
  LightCullOptions o;
  o.fraction = 0.02f;
  const LightReach r = settleLightReach(s, s.bounds(), o);
  const float sun = 3.0f / kPiF, lamps = 40.0f / (kPiF * 100.0f);  // nearest neighbour 10 m away
  EXPECT_NEAR(r.reference, std::max(sun, lamps), 1e-5f);
  EXPECT_NEAR(r.threshold, 0.02f * r.reference, 1e-7f);
  EXPECT_TRUE(std::isinf(r.reach[0]));  // the sun
  EXPECT_FLOAT_EQ(r.reach[2], 6.0f);    // (1, 0): with range
  EXPECT_EQ(r.cut[2], 0);
  EXPECT_NEAR(r.reach[1], std::sqrt(40.0f / (kPiF * r.threshold)), 1e-3f);
  EXPECT_EQ(r.cut[1], 1);
  EXPECT_EQ(r.cutLights(), 50u);
}

// Every light that gives a floor point any light (after the cut's fade) is in that point's lookup; within 3/4 of
// its reach a cut light is unchanged, beyond it the fade takes at most its value at 3/4 of the reach,
// (16/9) × threshold, and the culled sum differs from the uncut one by exactly the faded parts.
TEST(LightReach, GridDropsNoLightThatReachesAPointAndTheSumKeepsItsBound) {
  Scene whole = lampGrid();
  Scene culled = whole;
  LightCullOptions o;
  o.fraction = 0.05f;
  const LightReach r = settleLightReach(culled, culled.bounds(), o);
  applyLightCutoffs(culled, r);
  const LightGrid grid(culled, r, culled.bounds());
  ASSERT_TRUE(grid.culls());
  const glm::vec3 n(0, 1, 0);
  size_t visited = 0, reaching = 0;
  double worstExcess = 0.0;
  for (uint32_t k = 0; k < 20000; ++k) {
    const glm::vec3 x = floorPoint(k);
    const LightSpan near = grid.near(x);
    std::vector<uint8_t> inList(culled.lights.size(), 0);
    for (uint32_t i : near) inList[i] = 1;
    visited += near.size();
    glm::vec3 culledSum(0.0f), wholeSum(0.0f), fadedAway(0.0f);
    for (size_t i = 0; i < culled.lights.size(); ++i) {
      const glm::vec3 c = lightKind(culled.lights[i]).direct(culled.lights[i], x, n).mapValue;
      const glm::vec3 w = lightKind(whole.lights[i]).direct(whole.lights[i], x, n).mapValue;
      wholeSum += w;
      if (c != glm::vec3(0.0f)) {
        ++reaching;
        ASSERT_TRUE(inList[i]) << "light " << i << " reaches (" << x.x << ", " << x.z << ") but is not listed";
      }
      if (inList[i]) culledSum += c;
      const float d = glm::length(culled.lights[i].position - x);
      if (!r.cut[i] || d <= 0.75f * r.reach[i]) {
        ASSERT_EQ(c, w);
      }
      ASSERT_LE(w.x - c.x, 16.0f / 9.0f * r.threshold * 1.0001f);
      fadedAway += w - c;
    }
    worstExcess = std::max(worstExcess, std::abs(double(wholeSum.x - culledSum.x - fadedAway.x)));
  }
  EXPECT_LT(worstExcess, 1e-5);
  EXPECT_EQ(grid.lookups(), 20000u);
  // The lookups visit a small share of the 101 lights.
  EXPECT_LT(double(visited) / 20000.0, 0.25 * 101.0);
  EXPECT_GT(reaching, 20000u);  // the sun reaches every point, lamps many
}

// A lamp alone (no light at infinity, no neighbour) has no reference and is never cut; one whose reach covers the
// scene is not cut either, and a grid of such lights culls nothing.
TEST(LightReach, ALightThatReachesTheWholeSceneIsNeverCut) {
  Scene s;
  testing::addQuad(s, testing::addMaterial(s, glm::vec3(0.5f)), glm::vec3(-1, 0, 1), glm::vec3(2, 0, 0),
                   glm::vec3(0, 0, -2));
  s.lights.push_back(testing::pointLight(glm::vec3(0, 1, 0), 5.0f));
  LightReach r = settleLightReach(s, s.bounds(), LightCullOptions{});
  EXPECT_EQ(r.reference, 0.0f);
  EXPECT_EQ(r.cutLights(), 0u);
  s.lights.push_back(testing::directionalLight(glm::vec3(0, -1, 0), 1.0f));
  r = settleLightReach(s, s.bounds(), LightCullOptions{});
  EXPECT_GT(r.reference, 0.0f);
  EXPECT_EQ(r.cutLights(), 0u);  // its reach, √(5 / (π · 0.01 / π)), covers the floor
  applyLightCutoffs(s, r);
  EXPECT_EQ(s.lights[0].cutoff, 0.0f);
  EXPECT_FALSE(LightGrid(s, r, s.bounds()).culls());
  LightCullOptions off;
  off.fraction = 0.0f;
  EXPECT_FALSE(LightGrid(s, settleLightReach(s, s.bounds(), off), s.bounds()).culls());
}

// The fade is smooth: continuous at 3/4 of the reach and at the reach, falling monotonically between.
TEST(LightReach, CutoffWindowFadesWithoutAStep) {
  Light l;
  l.cutoff = 8.0f;
  EXPECT_EQ(l.cutoffWindow(5.99f), 1.0f);
  EXPECT_NEAR(l.cutoffWindow(6.0001f), 1.0f, 1e-4f);
  EXPECT_NEAR(l.cutoffWindow(7.9999f), 0.0f, 1e-4f);
  EXPECT_EQ(l.cutoffWindow(8.0f), 0.0f);
  EXPECT_NEAR(l.cutoffWindow(7.0f), 0.5f, 1e-6f);
  float last = 1.0f;
  for (float d = 6.0f; d <= 8.0f; d += 0.01f) {
    EXPECT_LE(l.cutoffWindow(d), last);
    last = l.cutoffWindow(d);
  }
}

}  // namespace irbake
