// The final gather against closed forms: a furnace's exact map is its fixed point (no noise: every ray
// reads the same value), a floor under a parallel square gathers ρ·M·F with F the point-to-square view
// factor, and rays that leave the scene add nothing (the sky is D's, not the gather's).
#include "stages/gather/final_gather.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "atlas/atlas.h"
#include "lightmap/lightmap_read.h"
#include "texels/sample_lattice.h"
#include "common/maths.h"
#include "samples/sample_scenes.h"
#include "testing/scenes.h"

namespace irbake {
namespace {
using namespace irbake::testing;

// A scene with its atlas and texel pages, no VPLs, and maps written by hand.
struct Atlased : AtlasedScene {
  VplSet none;
  Atlased(Scene s, int pageSize) : AtlasedScene(std::move(s), pageSize) {}
  BakeInputs inputs() const { return BakeInputs{scene, *rayTracer, pages, none, VplEvalOptions{}, {}}; }
  // Maps with value(primitive) at every valid texel whose first sample lies on that primitive.
  template <class Value>
  std::vector<Lightmap> maps(Value&& value) const {
    std::vector<Lightmap> out;
    for (const TexelSamples& ts : pages) {
      Lightmap m = blankLightmap(ts);
      m.valid = ts.valid;
      for (size_t t = 0; t < m.size(); ++t)
        if (m.valid[t] && t < ts.primitive.size()) m.texels[t] = value(ts.primitive[t]);
      out.push_back(std::move(m));
    }
    return out;
  }
};

// Closed cube, ρ = 0.6, Le = 0.4: the exact map is Le/(1 − ρ) = 1 everywhere. Every ray of the gather
// reads Le + ρ·1 = 1, so over any set of rays M' = D + 1 exactly, texel for texel (D = 0.25 here, so a
// stage that left the map alone fails; with D = 0 the exact map is the gather's fixed point).
TEST(FinalGather, FurnaceGathersLePlusRhoTimesTheMap) {
  const float rho = 0.6f, Le = 0.4f;
  Atlased a(samples::makeFurnace(rho, Le), 64);
  std::vector<Lightmap> maps = a.maps([](uint32_t) { return glm::vec3(1.0f); });
  const std::vector<Lightmap> direct = a.maps([](uint32_t) { return glm::vec3(0.25f); });
  FinalGatherOptions o;
  o.rays = 8;
  o.preRays = 0;  // one pass (the two passes: the next test)
  FinalGatherStats stats;
  finalGather(a.inputs(), direct, maps, o, &stats);
  double worst = 0.0;
  size_t n = 0;
  for (const Lightmap& m : maps)
    for (size_t t = 0; t < m.size(); ++t)
      if (m.valid[t]) worst = std::max(worst, std::abs(channelMean(m.texels[t]) - 1.25)), ++n;
  std::printf("[ figure ] furnace: %zu texels, worst |M' − 1.25| %.2e, gathered share %.4f\n", n, worst,
              stats.gatheredFraction);
  ASSERT_GT(n, 1000u);
  EXPECT_LT(worst, 2e-3);  // hits on a chart's border texel read a neighbour's value: still 1
  // The gather reads ρM packed to 9-bit mantissas (lightmap_read.h): ρM = 0.6 is stored as 307/512 (−0.07%).
  EXPECT_NEAR(stats.gatheredFraction, 0.8, 2e-4);
  EXPECT_EQ(stats.raysPerSample, 8);
}

// The two passes compose: the first gives M1 = D + Le + ρM, the final pass reads it, so in the furnace every
// texel ends at D + Le + ρ(D + Le + ρM) exactly (1.4 here), and at the exact map with D = 0 (the fixed point).
TEST(FinalGather, TwoPassesComposeInTheFurnace) {
  const float rho = 0.6f, Le = 0.4f;
  Atlased a(samples::makeFurnace(rho, Le), 64);
  for (float d : {0.25f, 0.0f}) {
    std::vector<Lightmap> maps = a.maps([](uint32_t) { return glm::vec3(1.0f); });
    const std::vector<Lightmap> direct = a.maps([&](uint32_t) { return glm::vec3(d); });
    FinalGatherOptions o;
    o.rays = 8;
    o.preRays = 2;
    FinalGatherStats stats;
    finalGather(a.inputs(), direct, maps, o, &stats);
    const double expected = d + Le + rho * (d + Le + rho * 1.0);
    double worst = 0.0;
    size_t n = 0;
    for (const Lightmap& m : maps)
      for (size_t t = 0; t < m.size(); ++t)
        if (m.valid[t]) worst = std::max(worst, std::abs(channelMean(m.texels[t]) - expected)), ++n;
    ASSERT_GT(n, 1000u);
    EXPECT_LT(worst, 2e-3) << "D = " << d << ", expected " << expected;
    EXPECT_EQ(stats.raysPerSample, 8);
    EXPECT_EQ(stats.preRaysPerSample, 2);
    EXPECT_EQ(stats.rays, weightedSampleCount(a.pages) * 10);
  }
}

// A point under a parallel square (side 2a, height h, map value m, albedo ρ): the gather is ρ m F, F the
// differential-area-to-parallel-square view factor, four corner rectangles of
// F_c = 1/(2π) [X/√(1+X²) atan(Y/√(1+X²)) + Y/√(1+Y²) atan(X/√(1+Y²))], X = Y = a/h.
TEST(FinalGather, FloorUnderASquareGathersItsViewFactor) {
  const float a = 0.5f, h = 0.4f, rho = 0.7f, m = 2.0f;
  Scene s;
  const int grey = addMaterial(s, glm::vec3(rho));
  const int floorPrim = addQuad(s, grey, glm::vec3(-2, -2, 0), glm::vec3(4, 0, 0), glm::vec3(0, 4, 0));
  const int squarePrim = addQuad(s, grey, glm::vec3(-a, -a, h), glm::vec3(0, 2 * a, 0), glm::vec3(2 * a, 0, 0));
  Atlased at(std::move(s), 128);
  const std::vector<Lightmap> maps =
      at.maps([&](uint32_t p) { return p == static_cast<uint32_t>(squarePrim) ? glm::vec3(m) : glm::vec3(0.0f); });
  const double X = a / h, q = std::sqrt(1.0 + X * X);
  const double F = 4.0 * (2.0 * X / q * std::atan(X / q)) / (2.0 * kPi);
  const glm::vec3 g = gatherAt(at.inputs(), maps, mapIndexOfPages(at.pages), glm::vec3(0, 0, 0), glm::vec3(0, 0, 1),
                               1 << 16, 0.25, 0.5);
  std::printf("[ figure ] floor under a square: gathered %.5f, ρ m F = %.5f (F = %.5f)\n", g.x, rho * m * F, F);
  EXPECT_NEAR(g.x / (rho * m * F), 1.0, 0.01);
  (void)floorPrim;

  // The whole stage on the floor's texels near the centre (filter off): the same within the rays' noise.
  std::vector<Lightmap> gathered = maps;
  const std::vector<Lightmap> direct = at.maps([](uint32_t) { return glm::vec3(0.0f); });
  FinalGatherOptions o;
  o.rays = 256;
  o.filterRadius = 0;
  o.preRays = 0;  // one gather of this M
  finalGather(at.inputs(), direct, gathered, o);
  double sum = 0.0;
  size_t n = 0;
  for (size_t p = 0; p < at.pages.size(); ++p) {
    const TexelSamples& ts = at.pages[p];
    for (size_t t = 0; t < ts.layerSize(); ++t) {
      if (!ts.valid[t] || ts.primitive[t] != static_cast<uint32_t>(floorPrim)) continue;
      const glm::vec3 x(ts.positionWeight[t]);
      if (glm::length(glm::vec2(x)) > 0.05f) continue;
      sum += gathered[p].texels[t].x;
      ++n;
    }
  }
  ASSERT_GT(n, 3u);
  std::printf("[ figure ] floor under a square, %zu texels within 5 cm of the centre: mean %.5f\n", n, sum / n);
  EXPECT_NEAR(sum / n / (rho * m * F), 1.0, 0.02);  // F moves by < 0.5% within 5 cm
}

// The same square seen from 0.3 m off its axis: the gathered tangential irradiance vector is ρ m times the
// tangential part of the square's irradiance vector (Lambert's edge formula, polygonIrradianceVector).
TEST(FinalGather, OffAxisFloorPointGathersTheSquaresIrradianceVector) {
  const float a = 0.5f, h = 0.4f, rho = 0.7f, m = 2.0f;
  Scene s;
  const int grey = addMaterial(s, glm::vec3(rho));
  addQuad(s, grey, glm::vec3(-2, -2, 0), glm::vec3(4, 0, 0), glm::vec3(0, 4, 0));
  const int squarePrim = addQuad(s, grey, glm::vec3(-a, -a, h), glm::vec3(0, 2 * a, 0), glm::vec3(2 * a, 0, 0));
  Atlased at(std::move(s), 128);
  const std::vector<Lightmap> maps =
      at.maps([&](uint32_t p) { return p == static_cast<uint32_t>(squarePrim) ? glm::vec3(m) : glm::vec3(0.0f); });
  const glm::dvec3 x(0.3, 0.1, 0.0);
  const std::vector<glm::dvec3> square = {{-a, -a, h}, {a, -a, h}, {a, a, h}, {-a, a, h}};
  const glm::dvec3 g = polygonIrradianceVector(x, square) * double(rho * m);
  L1Vectors t{};
  const glm::vec3 e = gatherAt(at.inputs(), maps, mapIndexOfPages(at.pages), glm::vec3(x), glm::vec3(0, 0, 1), 1 << 16,
                               0.25, 0.5, glm::vec3(0.0f), &t);
  std::printf("[ figure ] off-axis floor point: gathered %.5f (ρ m F %.5f), t = (%.5f, %.5f, %.5f), exact (%.5f, %.5f, 0)\n",
              e.x, g.z, t[0].x, t[1].x, t[2].x, g.x, g.y);
  EXPECT_NEAR(e.x / g.z, 1.0, 0.01);
  EXPECT_NEAR(t[0].x / g.x, 1.0, 0.02);  // towards the square: −x, −y
  EXPECT_NEAR(t[1].x / g.y, 1.0, 0.03);
  EXPECT_NEAR(t[2].x, 0.0, 1e-6);  // tangential only
  EXPECT_LT(g.x, -0.05);
}

// A floor beside a long black wall of height h under a uniform sky counted by the rays that leave: every floor
// texel gathers L (1 + d/√(d² + h²))/2 (the view factor, as SkyLight's test; the wall's 19–21 m beyond the
// floor's ends hide < 0.1% less than an infinite one). Few rays per texel and a 5×5 filter:
// with the lattices of a window interleaved (one lattice of 25 × 4 points, stratified as a whole) the texels'
// error is well below that of independent rotations, and both are unbiased.
TEST(FinalGather, InterleavedLatticesBeatIndependentRotationsBesideAWall) {
  const float h = 2.0f;
  Scene s;
  const int black = addMaterial(s, glm::vec3(0.0f));
  const int floorPrim = addQuad(s, black, glm::vec3(0, -1, 0), glm::vec3(4, 0, 0), glm::vec3(0, 2, 0));
  addQuad(s, black, glm::vec3(0, -20, 0), glm::vec3(0, 40, 0), glm::vec3(0, 0, h));  // wall x = 0, facing +x
  Atlased at(std::move(s), 512);
  const std::vector<Lightmap> zero = at.maps([](uint32_t) { return glm::vec3(0.0f); });
  RelativeErrors errors[2];
  for (int interleave = 0; interleave < 2; ++interleave) {
    std::vector<Lightmap> maps = zero;
    FinalGatherOptions o;
    o.rays = 4;
    o.filterRadius = 2;
    o.missRadiance = glm::vec3(1.0f);
    o.interleave = interleave == 1;
    finalGather(at.inputs(), zero, maps, o);
    for (size_t p = 0; p < at.pages.size(); ++p) {
      const TexelSamples& ts = at.pages[p];
      for (size_t t = 0; t < ts.layerSize(); ++t)
        if (ts.valid[t] && ts.primitive[t] == static_cast<uint32_t>(floorPrim))
          errors[interleave].add(maps[p].texels[t].x, skyFractionBesideWall(ts.positionWeight[t].x, h));
    }
  }
  ASSERT_GT(errors[1].count, 2000u);
  expectInterleavingBeatsIndependent(errors);  // measured 0.0225 against 0.0409
}

// A closed room (4 × 4 × 3 m, ρ = 0.5, M = 1) with a 10 × 10 cm cap 0.5 m above the floor whose top holds
// M = 2000 (a lamp's post top just under the lamp). One gather pass: a ceiling point x gathers exactly
// ρ (1 + 1999 F(x)), F its view factor to the cap's top (5.1e-4 right above it: at most 2× the ρ it gathers
// elsewhere), but a texel whose ray meets the cap (one in ~60 of them there) brings ~ρ 2000 / 64. Without
// holding outliers the filter spreads each such texel into a 7 × 7 square (measured up to 14.7× the exact
// gather); held and spread wide, what is left is the hits' own sparseness blurred over ~31 texels: no ceiling
// texel above 2.5× its exact gather (measured 2.07), and the room's mean gather keeps the cap's light (within
// 1% of the unheld one; the cap brings ~19% of it).
TEST(FinalGather, ABrightTinyCapLeavesNoSquareAndKeepsItsLight) {
  const float rho = 0.5f, bright = 2000.0f;
  Scene s;
  const int grey = addMaterial(s, glm::vec3(rho));
  addBox(s, grey, glm::vec3(-2, -2, 0), glm::vec3(2, 2, 3), true);
  const int cap = addQuad(s, grey, glm::vec3(-0.05f, -0.05f, 0.5f), glm::vec3(0.1f, 0, 0), glm::vec3(0, 0.1f, 0));
  const std::vector<glm::dvec3> capTop = {{-0.05, -0.05, 0.5}, {0.05, -0.05, 0.5}, {0.05, 0.05, 0.5}, {-0.05, 0.05, 0.5}};
  Atlased at(std::move(s), 256);
  const std::vector<Lightmap> source =
      at.maps([&](uint32_t p) { return glm::vec3(p == static_cast<uint32_t>(cap) ? bright : 1.0f); });
  const std::vector<Lightmap> none = at.maps([](uint32_t) { return glm::vec3(0.0f); });
  struct Figures { double worst = 0, mean = 0; size_t ceiling = 0, held = 0; double moved = 0; };
  const auto gathered = [&](float outlierRatio) {
    std::vector<Lightmap> maps = source;
    FinalGatherOptions o;
    o.preRays = 0;  // one pass: the exact gather is ρ (1 + 1999 F)
    o.outlierRatio = outlierRatio;
    FinalGatherStats stats;
    finalGather(at.inputs(), none, maps, o, &stats);
    Figures f;
    size_t n = 0;
    for (size_t p = 0; p < at.pages.size(); ++p)
      for (size_t t = 0; t < maps[p].size(); ++t) {
        if (!maps[p].valid[t] || at.pages[p].primitive[t] == static_cast<uint32_t>(cap)) continue;
        const double g = channelMean(maps[p].texels[t]);
        f.mean += g, ++n;
        const glm::dvec3 x(at.pages[p].positionWeight[t]);
        if (x.z < 2.99) continue;
        const double exact = rho * (1.0 + (bright - 1.0) * polygonFormFactor(x, {0, 0, -1}, capTop));
        f.worst = std::max(f.worst, g / exact);
        ++f.ceiling;
      }
    f.mean /= std::max<size_t>(n, 1);
    f.held = stats.outlierTexels;
    f.moved = stats.outlierFraction;
    return f;
  };
  const Figures unheld = gathered(0.0f), held = gathered(FinalGatherOptions{}.outlierRatio);
  std::printf("[ figure ] bright cap: ceiling max gathered / exact %.3f unheld, %.3f held (%zu texels held, %.4f of "
              "the map moved); room mean gather %.5f unheld, %.5f held (ρ = %.2f without the cap)\n",
              unheld.worst, held.worst, held.held, held.moved, unheld.mean, held.mean, rho);
  ASSERT_GT(held.ceiling, 1000u);
  EXPECT_GT(unheld.worst, 5.0);  // the squares, without holding
  EXPECT_LT(held.worst, 2.5);
  EXPECT_GT(held.held, 0u);
  EXPECT_EQ(unheld.held, 0u);
  EXPECT_NEAR(held.mean / unheld.mean, 1.0, 0.01);
  EXPECT_GT(unheld.mean, rho * 1.03);  // the cap's light is in the mean to be kept
}

// A single plane: every ray leaves the scene, so the map is D exactly, whatever M held.
TEST(FinalGather, RaysThatLeaveTheSceneAddNothing) {
  Atlased a(samples::makePointOverPlane(), 64);
  std::vector<Lightmap> maps = a.maps([](uint32_t) { return glm::vec3(5.0f); });
  const std::vector<Lightmap> direct = a.maps([](uint32_t) { return glm::vec3(0.25f, 0.5f, 1.0f); });
  finalGather(a.inputs(), direct, maps);
  size_t n = 0;
  for (size_t p = 0; p < maps.size(); ++p)
    for (size_t t = 0; t < maps[p].size(); ++t)
      if (maps[p].valid[t]) {
        EXPECT_EQ(maps[p].texels[t], direct[p].texels[t]);
        ++n;
      }
  EXPECT_GT(n, 100u);
}

}  // namespace
// The packed map the gathers read: every valid texel within half a mantissa step (≤ 2^-9 of its largest channel),
// zero and invalid texels kept apart, values from 1e-3 to 1e3 on one page (full precision down to 2^-29 of the
// page's peak), and read() the bilinear
// read over valid texels that readLightmap gives on the decoded values.
TEST(PackedLightmap, RoundTripsWithinHalfAStepAndReadsLikeTheMap) {
  Lightmap m;
  m.width = 37;  // not a multiple of the 4×4 tiles
  m.height = 23;
  m.texels.resize(m.size());
  m.valid.resize(m.size());
  uint32_t state = 12345u;
  auto next = [&] { return (state = state * 1664525u + 1013904223u) / 4294967296.0f; };
  for (size_t i = 0; i < m.size(); ++i) {
    m.valid[i] = next() < 0.8f;
    const float scale = std::pow(10.0f, -3.0f + 6.0f * next());
    m.texels[i] = glm::vec3(next(), next(), next()) * scale;
  }
  m.texels[5] = glm::vec3(0.0f);
  m.valid[5] = 1;
  const PackedLightmap packed(m, m.texels);
  std::vector<glm::vec3> decoded(m.size(), glm::vec3(0.0f));
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) {
      const size_t i = static_cast<size_t>(y) * m.width + x;
      ASSERT_EQ(packed.valid(x, y), m.valid[i] != 0) << x << "," << y;
      if (!m.valid[i]) continue;
      decoded[i] = packed.at(x, y);
      const glm::vec3 v = m.texels[i];
      const float peak = std::max({v.x, v.y, v.z});
      for (int k = 0; k < 3; ++k) EXPECT_LE(std::abs(decoded[i][k] - v[k]), peak * (1.0f / 512.0f) * 1.0001f) << i;
    }
  EXPECT_EQ(packed.at(5, 0), glm::vec3(0.0f));
  for (int k = 0; k < 2000; ++k) {
    const glm::vec2 t(next() * (m.width + 2) - 1.5f, next() * (m.height + 2) - 1.5f);
    const glm::vec3 a = packed.read(t), b = readLightmap(m, decoded, t);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-6f * std::max(1.0f, std::abs(b[c]))) << t.x << "," << t.y;
  }
  const PackedLightmap moved = PackedLightmap(m, m.texels);  // moved, not copied: the words keep their tiles
  EXPECT_EQ(moved.at(1, 1), packed.at(1, 1));
}

}  // namespace irbake
