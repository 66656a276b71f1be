// Importance-driven VPL selection (vpl_importance.h): what it keeps and that the light stays the walk's.
#include "transport/vpl_importance.h"

#include <gtest/gtest.h>

#include <cmath>

#include "atlas/atlas.h"
#include "samples/sample_scenes.h"
#include "texels/texel_samples.h"
#include "transport/geometry_term.h"
#include "vpl/vpl.h"

namespace irbake {
namespace {

struct Prepared {
  Scene scene;
  std::unique_ptr<RayTracer> rt;
  std::vector<TexelSamples> pages;
  explicit Prepared(Scene s, int pageSize = 128) : scene(std::move(s)) {
    AtlasOptions atlas;
    atlas.targetPageSize = atlas.maxPageSize = pageSize;
    buildAtlas(scene, atlas);
    rt = std::make_unique<RayTracer>(scene);
    pages = buildTexelSamples(scene, *rt, {});
  }
};

// Two groups of VPLs over a 10 × 10 m floor (no light of its own), one bounce, 1 W each, facing down 0.5 m
// up: 1000 over x = −4, 10 over x = +4. The floor under the ten receives about 1/100 of what the floor under
// the thousand does, so each of the ten carries a hundred times the relative importance. Thinned to a
// quarter (2530 candidates → ≈ 252), all ten must stay (p = 1) and the thousand share the rest; the
// bounce's power is the candidates' (the kept carry Φ/p, rescaled to the walk's total exactly).
VplSet twoGroups() {
  VplSet set;
  auto add = [&](float x, int count) {
    for (int i = 0; i < count; ++i) {
      const float a = 0.37f * static_cast<float>(i % 31) / 31.0f - 0.18f, b = 0.37f * static_cast<float>(i / 31) / 33.0f - 0.18f;
      set.vpls.push_back(Vpl{glm::vec3(x + a, 0.5f, b), glm::vec3(0, -1, 0), glm::vec3(1.0f, 0.5f, 0.25f), 1});
    }
  };
  add(-4.0f, 1000);
  add(4.0f, 10);
  set.countPerBounce = {0, set.vpls.size()};
  set.powerPerBounce = {glm::dvec3(0.0), glm::dvec3(set.vpls.size()) * glm::dvec3(1.0, 0.5, 0.25)};
  set.bounces = 1;
  return set;
}

TEST(VplImportance, DimRegionsKeepTheirFewVplsAndTheBouncesPowerIsKept) {
  Scene s = samples::makePointOverPlane();
  s.lights.clear();
  Prepared p(std::move(s));
  VplSet set = twoGroups();
  const size_t candidates = set.vpls.size();
  VplImportanceOptions options;
  VplSelection selection;
  selection.keepFraction = 0.25;
  selection.seed = 3;
  VplImportanceStats stats;
  selectVplsByImportance(p.scene, *p.rt, p.pages, set, options, selection, &stats);
  EXPECT_EQ(stats.candidates, candidates);
  EXPECT_GT(stats.litProbes, 900u);  // the whole floor is lit by one group or the other
  // Systematic sampling keeps Σp within one: the expected count.
  EXPECT_NEAR(static_cast<double>(set.vpls.size()), 0.25 * candidates, 1.0);
  size_t right = 0;
  glm::dvec3 power(0.0);
  for (const Vpl& v : set.vpls) {
    right += v.position.x > 0.0f;
    power += glm::dvec3(v.power);
  }
  EXPECT_EQ(right, 10u);  // every one of the few, against 1/4 of them under uniform thinning
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(power[c], set.powerPerBounce[1][c], 1e-4 * set.powerPerBounce[1][c]);
  EXPECT_NEAR(set.powerPerBounce[1].x, double(candidates), 1e-6 * candidates);  // float powers
  EXPECT_EQ(set.countPerBounce[1], set.vpls.size());
  // The pilot sees the same unevenness: far below a closed box's.
  EXPECT_LT(vplImportanceEvenness(p.scene, *p.rt, p.pages, twoGroups().vpls, options, 0.0f, 3), options.maxEvenness);
  // Deterministic: the same seed keeps the same VPLs.
  VplSet again = twoGroups();
  selectVplsByImportance(p.scene, *p.rt, p.pages, again, options, selection);
  ASSERT_EQ(again.vpls.size(), set.vpls.size());
  for (size_t i = 0; i < set.vpls.size(); ++i) EXPECT_EQ(again.vpls[i].position, set.vpls[i].position);
}

// Unbiased: the kept VPLs carry Φ/p, so what they give a receiver is, over the draws, what the candidates
// give. At a probe point under the thousand (where the thinning is heavy), the mean over 64 seeds of the
// kept set's unshadowed, unclamped sum matches the candidates' within 1% (each draw alone: ±10%).
TEST(VplImportance, KeptSetGivesTheCandidatesLightOnAverage) {
  Scene s = samples::makePointOverPlane();
  s.lights.clear();
  Prepared p(std::move(s));
  const glm::vec3 x(-3.0f, 0.0f, 0.7f), n(0, 1, 0);
  auto sumAt = [&](const VplSet& set) {
    double e = 0.0;
    for (const Vpl& v : set.vpls) {
      const float g = vplGeometryTerm(x, n, v.position, v.normal);
      if (g > 0.0f) e += vplMapValue(v.power, g).x;
    }
    return e;
  };
  const double exact = sumAt(twoGroups());
  double mean = 0.0, spread = 0.0;
  const int draws = 64;
  for (int seed = 0; seed < draws; ++seed) {
    VplSet set = twoGroups();
    VplSelection selection;
    selection.keepFraction = 0.25;
    selection.seed = static_cast<uint64_t>(seed);
    selectVplsByImportance(p.scene, *p.rt, p.pages, set, {}, selection);
    const double e = sumAt(set);
    mean += e / draws;
    spread = std::max(spread, std::abs(e / exact - 1.0));
  }
  EXPECT_NEAR(mean / exact, 1.0, 0.01);
  EXPECT_GT(spread, 0.002);  // the draws differ: the test measures an average, not one fixed set
}

// A closed box spreads the walk's usefulness evenly: auto stays with the plain walk there (the Cornell
// sample's default bake: evenness 0.43, Sponza's 0.18–0.20).
TEST(VplImportance, ClosedBoxIsEvenSoAutoKeepsThePlainWalk) {
  Prepared p(samples::makeCornellBox(), 256);
  WalkOptions walk;
  walk.paths = 2048;
  const VplSet set = generateVpls(p.scene, *p.rt, walk);
  VplImportanceOptions options;
  options.candidateFactor.reset();  // auto (the default is off)
  // With the bound a compensated bake derives for a scene with emitters (k = 256): unclamped, a VPL's
  // singular near field makes any walk look uneven.
  const float bound = deriveClampBound(p.scene, set, 256.0);
  const double evenness = vplImportanceEvenness(p.scene, *p.rt, p.pages, set.vpls, options, bound, 0);
  EXPECT_GT(evenness, options.maxEvenness);
  EXPECT_EQ(chooseCandidateFactor(options, set.vpls.size(), evenness), 1.0);
  // Where it is uneven, the factor follows the probes × candidates budget.
  EXPECT_EQ(chooseCandidateFactor(options, 3000, 0.2), std::min(options.maxFactor, std::floor(64.0e6 / (1024.0 * 3000))));
  EXPECT_EQ(chooseCandidateFactor(options, 40000, 0.2), 1.0);  // 64M / (1024 · 40k) < 2
  options.candidateFactor = 3.0;
  EXPECT_EQ(chooseCandidateFactor(options, 40000, 0.9), 3.0);
}

}  // namespace
}  // namespace irbake
