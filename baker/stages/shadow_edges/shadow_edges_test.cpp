// Shadow edges area-averaged, against closed forms: a straight sun shadow over a floor gives each edge texel the
// lit share of its own square (to the S×S sub-points' granularity, where the centre alone is off by up to a whole
// texel), texels off the edge keep their bits, and the part of a texel under a box resting on the floor is
// covered, not shadowed.
#include "stages/shadow_edges/shadow_edges.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <vector>

#include "atlas/atlas.h"
#include "evaluators/embree/embree_backend.h"
#include "common/maths.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

using namespace testing;
constexpr float kEdgeX = 0.1234f;  // the occluder covers x < kEdgeX over the floor
constexpr float kBoxY[] = {-0.77f, -0.43f, -0.08f, 0.27f, 0.61f};  // box centres (y) on the floor

// Evaluation options for the lights' direct term alone (no VPLs), and the edge stage with S×S sub-points.
VplEvalOptions directOnly() {
  VplEvalOptions e;
  e.includeVpls = false;
  return e;
}
ShadowEdgeOptions subPoints(int n) {
  ShadowEdgeOptions o;
  o.subSamples = n;
  return o;
}

struct SunOverFloor {
  Scene s;
  std::unique_ptr<RayTracer> rt;
  std::vector<TexelSamples> texels;
  VplSet none;
  uint32_t floor = 0;
  explicit SunOverFloor(bool box) {
    const int white = addMaterial(s, glm::vec3(0.5f));
    addQuad(s, white, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0});  // the floor, facing +z
    floor = 0;
    addQuad(s, white, {-2, -2, 0.5f}, {2 + kEdgeX, 0, 0}, {0, 4, 0});  // a roof at z = 0.5 over x < kEdgeX
    if (box)  // closed boxes resting on the floor (bottom faces on z = 0) across the roof's shadow edge
      for (float y : kBoxY) addBox(s, white, {-0.1f, y - 0.1f, 0.0f}, {0.3f, y + 0.1f, 0.4f}, false);
    // Straight down, irradiance π: a lit texel's map value (E/π) is exactly 1.
    s.lights.push_back(directionalLight({0, 0, -1}, kPiF));
    AtlasOptions atlas;
    atlas.targetPageSize = atlas.maxPageSize = 64;
    buildAtlas(s, atlas);
    rt = std::make_unique<RayTracer>(s);
    texels = buildTexelSamples(s, *rt, {});
  }
  BakeInputs inputs() { return BakeInputs{s, *rt, texels, none, directOnly(), {}}; }
};

TEST(ShadowEdges, EdgeTexelsGetTheLitShareOfTheirSquare) {
  SunOverFloor f(false);
  const BakeInputs in = f.inputs();
  const std::vector<Lightmap> centre = bakeEmbree(in);
  std::vector<Lightmap> refined = centre;
  ShadowEdgeOptions o;
  o.subSamples = 8;
  const ShadowEdgeStats st = refineShadowEdges(in, refined, o);
  ASSERT_GT(st.edgeTexels, 10u);
  EXPECT_EQ(st.droppedInside, 0u);
  auto lit = [](glm::vec3 p) { return p.x >= kEdgeX; };
  double errCentre = 0, errRefined = 0;
  size_t straddling = 0, changed = 0;
  for (size_t p = 0; p < f.texels.size(); ++p)
  for (size_t t = 0; t < f.texels[p].layerSize(); ++t) {
    const TexelSamples& ts = f.texels[p];
    if (!ts.valid[t] || ts.primitive[t] != f.floor) continue;
    // Off the floor's own border, where samples of texels half outside it are pulled inwards (and may sit
    // on the other side of the edge from their neighbours, which then find no jump).
    if (std::abs(ts.positionWeight[t].y) > 0.9f) continue;
    const double exact = exactLitShare(f.s, ts, t, lit);
    if (exact < 0) continue;
    const float r = refined[p].texels[t].x, c = centre[p].texels[t].x;
    if (r != c) ++changed;
    if (exact > 0.0 && exact < 1.0) {
      ++straddling;
      // 8×8 sub-points: the share to within one column of them (1/8) and the grid's own rounding.
      ASSERT_NEAR(r, exact, 0.13) << "page " << p << " texel " << t % ts.width << "," << t / ts.width << " of "
                                   << ts.width << "x" << ts.height << " at " << ts.positionWeight[t].x << ","
                                   << ts.positionWeight[t].y;
      errCentre += std::abs(c - exact);
      errRefined += std::abs(r - exact);
    } else {
      ASSERT_EQ(r, c) << t;  // no edge in the square: the centre's bits
    }
  }
  ASSERT_GT(straddling, 20u);
  EXPECT_LE(changed, st.edgeTexels);
  errCentre /= straddling;
  errRefined /= straddling;
  // The centre alone: about a quarter of a texel's light on average (the edge's offset from the centre).
  EXPECT_GT(errCentre, 0.15);
  EXPECT_LT(errRefined, 0.04);
  std::printf("[ figure ] straight sun edge: %zu texels straddle it, mean |error| centre %.3f, 8x8 sub-points %.4f\n",
              straddling, errCentre, errRefined);
}

// A faint second sun (3% of the first's light, tilted along the roof's edge, so its shadow edge is the first's)
// is under the faint budget (half the jump): on the edge texels it counts with its visibility at the centre, so
// the refined pair is exactly the first sun refined alone plus the faint one's centre value; refined as a bright
// light (faintShare 0) it gets its lit share instead, and the two differ by at most its own light.
TEST(ShadowEdges, FaintLightsCountWithTheirCentresVisibility) {
  const Light faint = directionalLight(glm::normalize(glm::vec3(0.0f, 0.6f, -0.8f)), 0.03f * kPiF);
  auto bake = [&](int lights, float faintShare, bool refine) {  // lights: 1 the sun, 2 the faint one, 3 both
    SunOverFloor f(false);
    if (lights == 2) f.s.lights.clear();
    if (lights & 2) f.s.lights.push_back(faint);
    const BakeInputs in = f.inputs();
    std::vector<Lightmap> maps = bakeEmbree(in);
    ShadowEdgeOptions o;
    o.subSamples = 8, o.faintShare = faintShare;
    if (refine) refineShadowEdges(in, maps, o);
    return maps;
  };
  const std::vector<Lightmap> both = bake(3, ShadowEdgeOptions{}.faintShare, true), sun = bake(1, 0.0f, true);
  const std::vector<Lightmap> faintCentre = bake(2, 0.0f, false), traced = bake(3, 0.0f, true),
                              sunCentre = bake(1, 0.0f, false);
  size_t edges = 0, differ = 0;
  double largest = 0.0;
  for (size_t p = 0; p < both.size(); ++p)
    for (size_t t = 0; t < both[p].size(); ++t) {
      if (!both[p].valid[t] || sun[p].texels[t] == sunCentre[p].texels[t]) continue;  // the sun's edge texels
      ++edges;
      EXPECT_NEAR(both[p].texels[t].x, sun[p].texels[t].x + faintCentre[p].texels[t].x, 1e-5) << "texel " << t;
      const double gap = std::abs(double(traced[p].texels[t].x) - double(both[p].texels[t].x));
      largest = std::max(largest, gap);
      differ += gap > 1e-4 ? 1 : 0;
    }
  std::printf("[ figure ] %zu edge texels, %zu of them off the fully traced value, by at most %.4f (the faint "
              "light: %.4f)\n", edges, differ, largest, 0.03 * 0.8);
  EXPECT_GT(edges, 10u);
  EXPECT_GT(differ, 5u);                // the faint light's edge crosses these texels too
  EXPECT_LE(largest, 0.03 * 0.8 + 1e-4);  // at most the faint light's own value (irradiance 0.03π at cos 0.8)
}

TEST(ShadowEdges, UnderABoxRestingOnTheFloorIsCoveredNotShadowed) {
  SunOverFloor f(true);
  const BakeInputs in = f.inputs();
  std::vector<Lightmap> refined = bakeEmbree(in);
  ShadowEdgeOptions o;
  o.subSamples = 8;
  const ShadowEdgeStats st = refineShadowEdges(in, refined, o);
  ASSERT_GT(st.edgeTexels, 0u);
  EXPECT_GT(st.droppedInside, 0u);
  auto lit = [](glm::vec3 p) { return p.x >= kEdgeX; };
  auto outsideBox = [](glm::vec3 p) {
    for (float y : kBoxY)
      if (p.x > -0.1f && p.x < 0.3f && std::abs(p.y - y) < 0.1f) return false;
    return true;
  };
  size_t checked = 0;
  double errRefined = 0, errAsShadow = 0;
  for (size_t p = 0; p < f.texels.size(); ++p)
  for (size_t t = 0; t < f.texels[p].layerSize(); ++t) {
    const TexelSamples& ts = f.texels[p];
    if (!ts.valid[t] || ts.primitive[t] != f.floor || std::abs(ts.positionWeight[t].y) > 0.9f) continue;
    const double covered = 1.0 - std::max(0.0, exactLitShare(f.s, ts, t, outsideBox));
    const double visibleLit = exactLitShare(f.s, ts, t, lit, outsideBox);
    // Texels the shadow edge crosses on a box's contact line: the lit share of the part the box leaves free.
    // Counting the covered part as shadow would darken a line along each box's foot.
    if (!(covered > 0.1 && covered < 0.9 && visibleLit > 0.0 && visibleLit < 1.0)) continue;
    ++checked;
    const float r = refined[p].texels[t].x;
    // Per texel within 0.2 (8×8 sub-points; one texel on the floor's diagonal, the box's side and the edge at
    // once comes out 0.19 off), on average within a third of what counting the covered part as shadow gives.
    EXPECT_NEAR(r, visibleLit, 0.2) << "covered " << covered << " texel " << t % ts.width << "," << t / ts.width;
    errRefined += std::abs(r - visibleLit);
    errAsShadow += std::abs(visibleLit * (1.0 - covered) - visibleLit);
  }
  ASSERT_GE(checked, 5u);
  EXPECT_LT(errRefined, errAsShadow / 3.0);
  std::printf("[ figure ] %zu contact texels on the edge: mean |error| %.3f, %.3f if the covered part were shadow\n",
              checked, errRefined / checked, errAsShadow / checked);
}

// A roof with a slit a quarter of a texel wide, the sun tilted so that its lit strip on the floor falls between
// two rows of texel centres (0.1 to 0.35 of a texel past one): every centre is dark, no neighbour sees a jump,
// and only the 2×2 probe of each square finds the strip. Each texel it crosses gets its lit share, 1/4.
TEST(ShadowEdges, AStripNarrowerThanATexelBetweenCentresIsFound) {
  constexpr double kTexelsPerUnit = 16.0, h = 1.0 / kTexelsPerUnit, slitLo = 0.0, slitHi = 0.25 * h;
  Scene s;
  const int white = addMaterial(s, glm::vec3(0.5f));
  addQuad(s, white, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0});  // the floor, facing +z
  addQuad(s, white, {-2, -2, 0.5f}, {2 + float(slitLo), 0, 0}, {0, 4, 0});
  addQuad(s, white, {float(slitHi), -2, 0.5f}, {2 - float(slitHi), 0, 0}, {0, 4, 0});
  AtlasOptions atlas;
  atlas.texelsPerUnit = kTexelsPerUnit;
  buildAtlas(s, atlas);
  RayTracer rt(s);
  std::vector<TexelSamples> texels = buildTexelSamples(s, rt, {});
  // The floor's texel centres in x sit on a grid of pitch h: the centre nearest x = 0 (away from the floor's
  // border, where samples are pulled inside their triangle).
  double c = 1e9;
  for (const TexelSamples& ts : texels)
    for (size_t t = 0; t < ts.layerSize(); ++t)
      if (ts.valid[t] && ts.primitive[t] == 0 && std::abs(ts.positionWeight[t].y) < 0.5f &&
          std::abs(ts.positionWeight[t].x) < std::abs(c))
        c = ts.positionWeight[t].x;
  ASSERT_LT(std::abs(c), 0.51 * h);
  // Light leaving the slit along (dx, 0, -1) lands at x + 0.5 dx: the strip [c + 0.1h, c + 0.35h].
  const double dx = 2.0 * (c + 0.1 * h - slitLo);
  const glm::vec3 dir = glm::normalize(glm::vec3(float(dx), 0.0f, -1.0f));
  s.lights.push_back(directionalLight(dir, kPiF));
  const float cosine = -dir.z;
  VplSet none;
  const BakeInputs in{s, rt, texels, none, directOnly(), {}};
  const std::vector<Lightmap> centre = bakeEmbree(in);
  std::vector<Lightmap> refined = centre;
  refineShadowEdges(in, refined, subPoints(8));
  auto lit = [&](glm::vec3 p) { return p.x >= c + 0.1 * h && p.x <= c + 0.35 * h; };
  size_t crossed = 0;
  for (size_t p = 0; p < texels.size(); ++p)
    for (size_t t = 0; t < texels[p].layerSize(); ++t) {
      const TexelSamples& ts = texels[p];
      if (!ts.valid[t] || ts.primitive[t] != 0 || std::abs(ts.positionWeight[t].y) > 0.9f) continue;
      const double exact = exactLitShare(s, ts, t, lit);
      if (exact < 0) continue;
      ASSERT_EQ(centre[p].texels[t].x, 0.0f) << "a centre in the strip";
      if (exact > 0.0) {
        ++crossed;
        // 8×8 sub-points: two of their columns fall in the strip, exactly its quarter of the square.
        ASSERT_NEAR(refined[p].texels[t].x / cosine, exact, 0.07) << "texel " << t % ts.width << "," << t / ts.width;
      } else {
        ASSERT_EQ(refined[p].texels[t].x, 0.0f) << "texel " << t % ts.width << "," << t / ts.width;
      }
    }
  EXPECT_GE(crossed, 20u);
  std::printf("[ figure ] strip a quarter of a texel wide between centres: %zu texels crossed, each at its share\n",
              crossed);
}

// The cut lights' left-out light counts as visible on both sides of an edge: with c times a lit texel's value
// added, the sun edge's jump of 1 in the visible share becomes 1 / (1 + c). At c = 8 (1/9 > 0.1, the default jump)
// its texels are still refined, to the same values; at c = 10 (1/11 < 0.1) none is.
TEST(ShadowEdges, CutLightWeighsTheJumpAgainstAllOfTheLight) {
  SunOverFloor f(false);
  const BakeInputs in = f.inputs();
  const std::vector<Lightmap> centre = bakeEmbree(in);
  auto refine = [&](float c, std::vector<Lightmap>& maps) {
    std::vector<std::vector<float>> unshadowed;
    std::vector<std::vector<glm::vec3>> shadowed;
    for (const TexelSamples& ts : f.texels) unshadowed.emplace_back(ts.layerSize(), c), shadowed.emplace_back(ts.layerSize(), glm::vec3(c));
    maps = centre;
    const CutLightPages cut{&shadowed, &unshadowed};
    return refineShadowEdges(in, maps, subPoints(8), nullptr, &cut).edgeTexels;
  };
  std::vector<Lightmap> none = centre, eight, ten;
  const size_t plain = refineShadowEdges(in, none, subPoints(8)).edgeTexels;
  const size_t atEight = refine(8.0f, eight), atTen = refine(10.0f, ten);
  std::printf("[ figure ] sun edge texels refined: %zu alone, %zu with 8x its light cut, %zu with 10x\n", plain, atEight,
              atTen);
  ASSERT_GT(plain, 10u);
  EXPECT_GT(atEight, plain / 2);  // the neighbours' jump of 1/9 still finds the edge (the 2×2 probes' smaller
  EXPECT_LE(atEight, plain);      // jumps of a quarter no longer do)
  EXPECT_EQ(atTen, 0u);
  for (size_t p = 0; p < centre.size(); ++p) {
    EXPECT_EQ(ten[p].texels, centre[p].texels);
    for (size_t t = 0; t < centre[p].size(); ++t)  // a texel refined at c = 8 gets what it gets alone
      if (eight[p].texels[t] != centre[p].texels[t]) ASSERT_EQ(eight[p].texels[t], none[p].texels[t]) << "texel " << t;
  }
}

TEST(ShadowEdges, OffWithOneSubSampleOrSupersampledTexels) {
  SunOverFloor f(false);
  const BakeInputs in = f.inputs();
  const std::vector<Lightmap> centre = bakeEmbree(in);
  std::vector<Lightmap> maps = centre;
  ShadowEdgeOptions o;
  o.subSamples = 1;
  EXPECT_EQ(refineShadowEdges(in, maps, o).edgeTexels, 0u);
  for (size_t p = 0; p < maps.size(); ++p) EXPECT_EQ(maps[p].texels, centre[p].texels);
  for (TexelSamples& ts : f.texels) ts.supersample = 2;  // as if supersampled: left alone
  EXPECT_EQ(refineShadowEdges(in, maps, {}).edgeTexels, 0u);
}

}  // namespace
}  // namespace irbake
