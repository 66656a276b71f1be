#include "evaluators/embree/embree_backend.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "common/maths.h"
#include "samples/sample_scenes.h"
#include "transport/geometry_term.h"
#include "vpl/light_sources.h"
#include "testing/probe_bake.h"
#include "testing/scenes.h"

using namespace irbake;
using namespace irbake::testing;

namespace {

struct Baked {
  std::vector<Lightmap> maps;
  VplSet vpls;
};

Baked bakeWith(const Scene& s, const std::vector<TexelSamples>& texels, const WalkOptions& walk, VplEvalOptions eval,
               bool autoClamp, const EmbreeOptions& embreeOptions = {}) {
  RayTracer rt(s);
  Baked b;
  b.vpls = generateVpls(s, rt, walk);
  if (autoClamp) eval.clampBound = deriveClampBound(s, b.vpls);
  BakeInputs in{s, rt, texels, b.vpls, eval, {}};
  b.maps = bakeEmbree(in, embreeOptions);
  return b;
}

// The probes baked with the derived clamp and ClampGather's compensation.
Baked bakeCompensated(Scene s, const std::vector<TexelSamples>& probes, const WalkOptions& walk) {
  const AtlasedScene atlased(std::move(s), 64);
  Baked b;
  b.vpls = generateVpls(atlased.scene, *atlased.rayTracer, walk);
  VplEvalOptions eval;
  eval.clampBound = deriveClampBound(atlased.scene, b.vpls);
  b.maps = bakeProbesCompensated(atlased, probes, b.vpls, eval).compensated;
  return b;
}

double mean(const Lightmap& m, int channel = 0) {
  double s = 0.0;
  int n = 0;
  for (size_t i = 0; i < m.size(); ++i)
    if (m.valid[i]) { s += m.texels[i][channel]; ++n; }
  return s / std::max(1, n);
}

// Square emitter (side 1, Le = 1, facing down) at height h over a 2×2 floor; both black.
Scene quadOverPlane(float h) {
  Scene s;
  int lamp = addMaterial(s, glm::vec3(0.0f), glm::vec3(1.0f));
  int floor = addMaterial(s, glm::vec3(0.0f));
  addQuad(s, lamp, glm::vec3(-0.5f, -0.5f, h), glm::vec3(0, 1, 0), glm::vec3(1, 0, 0));
  addQuad(s, floor, glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  return s;
}

// Relative RMSE of a baked floor grid against the form factor of the emitter square (Le = 1).
double quadRelativeRmse(const Lightmap& m, const TexelSamples& t, float h) {
  std::vector<glm::dvec3> poly = {{-0.5, -0.5, h}, {0.5, -0.5, h}, {0.5, 0.5, h}, {-0.5, 0.5, h}};
  double se = 0.0, ref2 = 0.0;
  for (size_t i = 0; i < m.size(); ++i) {
    double exact = polygonFormFactor(glm::dvec3(glm::vec3(t.positionWeight[i])), glm::dvec3(0, 0, 1), poly);
    double d = m.texels[i].x - exact;
    se += d * d;
    ref2 += exact * exact;
  }
  return std::sqrt(se / ref2);
}

}  // namespace

// Point light over a black plane, every texel within 0.5% of I cosθ / (π r²).
TEST(EmbreeBackend, PointLightOverPlaneMatchesInverseSquareEverywhere) {
  Scene s;
  addQuad(s, addMaterial(s, glm::vec3(0.0f)), glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  glm::vec3 L(0.3f, -0.2f, 0.7f);
  s.lights.push_back(pointLight(L, 5.0f));
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), 32, 32)};
  WalkOptions w;
  w.paths = 64;
  Baked b = bakeWith(s, texels, w, VplEvalOptions{}, true);
  EXPECT_EQ(b.vpls.vpls.size(), 0u);  // black floor: no bounce, and no VPL for the point light itself
  double worst = 0.0;
  for (size_t i = 0; i < b.maps[0].size(); ++i) {
    glm::dvec3 x(glm::vec3(texels[0].positionWeight[i]));
    glm::dvec3 d = glm::dvec3(L) - x;
    double r2 = glm::dot(d, d), exact = 5.0 * (d.z / std::sqrt(r2)) / (kPi * r2);
    ASSERT_TRUE(b.maps[0].valid[i]);
    worst = std::max(worst, std::abs(b.maps[0].texels[i].x / exact - 1.0));
  }
  std::printf("[ figure ] point over plane: max relative error %.2e\n", worst);
  EXPECT_LT(worst, 0.005);
}

// Square emitter over a parallel plane. 1024 VPLs: RMSE < 1%; QMC slope ≤ −0.75.
TEST(EmbreeBackend, QuadOverPlaneConvergesAtQuasiMonteCarloRate) {
  const float h = 0.5f;
  Scene s = quadOverPlane(h);
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), 16, 16)};
  std::vector<double> logN, logE;
  double at1024 = 0.0;
  for (int n = 64; n <= 4096; n *= 2) {
    WalkOptions w;
    w.paths = n;
    Baked b = bakeWith(s, texels, w, VplEvalOptions{}, false);  // no clamp: the emitter is 0.5 m away
    ASSERT_EQ(b.vpls.vpls.size(), static_cast<size_t>(n));
    double e = quadRelativeRmse(b.maps[0], texels[0], h);
    std::printf("[ figure ] quad over plane: N=%d relative RMSE %.3e\n", n, e);
    logN.push_back(std::log(double(n)));
    logE.push_back(std::log(e));
    if (n == 1024) at1024 = e;
  }
  double mx = 0, my = 0;
  for (size_t i = 0; i < logN.size(); ++i) { mx += logN[i]; my += logE[i]; }
  mx /= logN.size();
  my /= logN.size();
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < logN.size(); ++i) { sxy += (logN[i] - mx) * (logE[i] - my); sxx += (logN[i] - mx) * (logN[i] - mx); }
  double slope = sxy / sxx;
  std::printf("[ figure ] quad over plane: log-log slope %.3f\n", slope);
  EXPECT_LT(at1024, 0.01);
  EXPECT_LE(slope, -0.75);
}

namespace {
// Closed cube, every face emitting Le and reflecting ρ: the radiance is Le/(1−ρ) everywhere.
Scene furnace(float rho, float Le) {
  Scene s;
  addBox(s, addMaterial(s, glm::vec3(rho), glm::vec3(Le)), glm::vec3(0), glm::vec3(1), true, 2);
  return s;
}

// The Embree backend's clamped sum with ClampGather's compensation, on probe grids of a furnace.
void runFurnace(float rho, int paths, int grid, float fixedBound = 0.0f) {
  const AtlasedScene room(furnace(rho, 1.0f), 32);
  const Scene& s = room.scene;
  // Floor and one wall (its grid faces +x, into the room); the outer rows of texels lie within the
  // clamp radius of the neighbouring faces, where the clamp bites.
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), grid, grid),
                                      gridSamples(glm::vec3(0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1), grid, grid)};
  WalkOptions w;
  w.paths = paths;
  // Default auto depth: the VPL budget binds at ρ = 0.9 and the geometric tail carries the rest.
  w.seed = std::getenv("IRBAKE_TEST_SEED") ? std::atoi(std::getenv("IRBAKE_TEST_SEED")) : 0;
  VplSet vpls = generateVpls(s, *room.rayTracer, w);
  VplEvalOptions eval;
  eval.clampBound = fixedBound > 0.0f ? fixedBound : deriveClampBound(s, vpls);
  auto both = [&](const std::vector<Lightmap>& m) { return 0.5 * (mean(m[0]) + mean(m[1])); };
  const ProbeBake probes = bakeProbesCompensated(room, texels, vpls, eval);
  double mc = both(probes.clamped), mk = both(probes.compensated);
  BakeInputs in{s, *room.rayTracer, texels, vpls, eval, {}};
  in.eval.clampBound = 0.0f;
  double mu = both(bakeEmbree(in));
  double exact = 1.0 / (1.0 - rho);
  double walkTail = vpls.tailFactor.x;  // bounce J's VPLs carry the bounces beyond it
  std::printf("[ figure ] furnace rho=%.1f B=%.1f%s: exact %.4f, unclamped %.4f (%+.2f%%), clamped %.4f (%+.2f%%), "
              "compensated %.4f (%+.2f%%), %zu VPLs, %d bounces, tail factor %.2f\n",
              rho, eval.clampBound, fixedBound > 0.0f ? " (fixed)" : " (derived)", exact, mu, 100 * (mu / exact - 1), mc,
              100 * (mc / exact - 1), mk, 100 * (mk / exact - 1), vpls.vpls.size(), vpls.bounces, walkTail);
  EXPECT_NEAR(mk / exact, 1.0, 0.01);
  EXPECT_NEAR(mk / mu, 1.0, 0.01);  // compensation gives back what the clamp took from this VPL set
  EXPECT_LE(mc, mk + 1e-6);        // the clamp only removes energy
}
}  // namespace

// Furnace, mean within 1% of Le/(1−ρ) with the clamp compensation; clamped-only bias printed.
TEST(EmbreeBackend, FurnaceHalfAlbedo) { runFurnace(0.5f, 4096, 16); }
TEST(EmbreeBackend, FurnaceHighAlbedo) { runFurnace(0.9f, 1024, 12); }
// A deliberately coarse clamp (B = 25/m², r_c = 0.2 m: a fifth of the room) removes a large part of the
// light; compensation must give it back.
TEST(EmbreeBackend, FurnaceCoarseClampIsCompensated) {
  runFurnace(0.5f, 4096, 12, 25.0f);
  runFurnace(0.9f, 4096, 12, 25.0f);
}

// Thin wall. Light on one side; the floor on the other side, right against the wall,
// stays dark (< 1e-3 of the lit side) with VPL bounces and the clamp compensation on.
TEST(EmbreeBackend, ThinWallDoesNotLeak) {
  Scene s;
  int grey = addMaterial(s, glm::vec3(0.7f));
  addQuad(s, grey, glm::vec3(-2, -1, 0), glm::vec3(4, 0, 0), glm::vec3(0, 2, 0));
  addBox(s, grey, glm::vec3(-0.001f, -1, 0), glm::vec3(0.001f, 1, 1), false);  // 2 mm wall, full width
  addQuad(s, addMaterial(s, glm::vec3(0.0f), glm::vec3(5.0f)), glm::vec3(-1.2f, -0.2f, 0.6f), glm::vec3(0, 0.4f, 0),
          glm::vec3(0.4f, 0, 0));  // small emitter facing down on the lit side
  s.lights.push_back(pointLight(glm::vec3(-0.5f, 0.3f, 0.4f), 2.0f));
  // Lit and dark strips of floor hugging the wall (texel centres 0.5 mm … 5 cm from it).
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(-0.0515f, -1, 0), glm::vec3(0.05f, 0, 0), glm::vec3(0, 2, 0), 8, 16),
                                      gridSamples(glm::vec3(0.0015f, -1, 0), glm::vec3(0.05f, 0, 0), glm::vec3(0, 2, 0), 8, 16)};
  WalkOptions w;
  w.paths = 1024;
  const Baked b = bakeCompensated(std::move(s), texels, w);
  double lit = mean(b.maps[0]), darkMax = 0.0;
  for (const glm::vec3& v : b.maps[1].texels) darkMax = std::max(darkMax, double(std::max(v.x, std::max(v.y, v.z))));
  std::printf("[ figure ] thin wall: lit mean %.4f, dark max %.3e (ratio %.1e)\n", lit, darkMax, darkMax / lit);
  EXPECT_GT(lit, 0.05);
  EXPECT_LT(darkMax, 1e-3 * lit);
}

// 1e5 VPLs accumulated in float stay within 1e-5 relative of a double sum.
TEST(EmbreeBackend, HundredThousandVplsSumLikeDouble) {
  Scene s;
  addQuad(s, addMaterial(s, glm::vec3(0.0f)), glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  VplSet set;
  Rng rng(42);
  for (int i = 0; i < 100000; ++i) {
    // Powers over six orders of magnitude, positions on a hemisphere shell above the receivers.
    glm::vec3 p(float(rng.uniform() * 4 - 2), float(rng.uniform() * 4 - 2), float(0.2 + rng.uniform() * 3));
    float power = float(std::pow(10.0, rng.uniform() * 6 - 3));
    set.vpls.push_back(Vpl{p, glm::normalize(glm::vec3(0.1f, -0.2f, -1.0f)), glm::vec3(power, 0.5f * power, 1.0f), 1});
  }
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(-0.5f, -0.5f, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), 2, 2)};
  RayTracer rt(s);
  BakeInputs in{s, rt, texels, set, VplEvalOptions{}, {}};
  std::vector<Lightmap> maps = bakeEmbree(in);
  double worst = 0.0, worstNaive = 0.0;
  for (size_t t = 0; t < 4; ++t) {
    glm::vec3 x(texels[0].positionWeight[t]);
    glm::dvec3 exact(0.0);
    for (const Vpl& v : set.vpls) {
      glm::dvec3 d = glm::dvec3(v.position) - glm::dvec3(x);
      double r2 = glm::dot(d, d), r = std::sqrt(r2);
      double cx = d.z / r, cy = -glm::dot(glm::dvec3(v.normal), d) / r;
      if (cx > 0 && cy > 0) exact += glm::dvec3(v.power) * (cx * cy / r2 / (kPi * kPi));
    }
    glm::vec3 naive(0.0f);  // what a plain float loop would give, for the figure
    for (const Vpl& v : set.vpls) {
      float g = vplGeometryTerm(x, glm::vec3(0, 0, 1), v.position, v.normal);
      if (g > 0.0f) naive += vplMapValue(v.power, g);
    }
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(maps[0].texels[t][c] / exact[c], 1.0, 1e-5) << "texel " << t << " channel " << c;
      worst = std::max(worst, std::abs(maps[0].texels[t][c] / exact[c] - 1.0));
      worstNaive = std::max(worstNaive, std::abs(naive[c] / exact[c] - 1.0));
    }
  }
  std::printf("[ figure ] 1e5 VPLs: max relative deviation from the double sum %.2e (plain float loop: %.2e)\n", worst,
              worstNaive);
}

// The project's thin-wall sample: two closed rooms sharing a zero-thickness partition (coincident
// quads facing −X and +X). Floor strips hugging the partition on both sides: the dark room stays
// dark with bounces and the clamp compensation.
TEST(EmbreeBackend, ZeroThicknessPartitionDoesNotLeak) {
  Scene s = samples::makeThinWall();  // y up, partition at x = 0, light at (−1, 1, 0)
  // Floor (y = 0, normal +Y = Z × X): texel centres 0.5 mm … 5 cm from the partition.
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(-0.0505f, 0, -1), glm::vec3(0, 0, 2), glm::vec3(0.05f, 0, 0), 16, 8),
                                      gridSamples(glm::vec3(0.0005f, 0, -1), glm::vec3(0, 0, 2), glm::vec3(0.05f, 0, 0), 16, 8)};
  WalkOptions w;
  w.paths = 2048;
  const Baked b = bakeCompensated(std::move(s), texels, w);
  double lit = mean(b.maps[0]), darkMax = 0.0;
  for (const glm::vec3& v : b.maps[1].texels) darkMax = std::max(darkMax, double(std::max(v.x, std::max(v.y, v.z))));
  std::printf("[ figure ] zero-thickness partition: lit mean %.4f, dark max %.3e, %zu VPLs\n", lit, darkMax, b.vpls.vpls.size());
  EXPECT_GT(lit, 0.1);
  EXPECT_LT(darkMax, 1e-3 * lit);
}

// Packets of 8 shadow rays (rtcOccluded8) must give what single rays give, occluders included.
TEST(EmbreeBackend, PacketShadowRaysMatchSingleRays) {
  Scene s = samples::makeThinWall();
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(-2, 0, -1), glm::vec3(0, 0, 2), glm::vec3(4, 0, 0), 8, 16)};
  RayTracer rt(s);
  WalkOptions w;
  w.paths = 512;
  VplSet vpls = generateVpls(s, rt, w);
  VplEvalOptions eval;
  eval.clampBound = deriveClampBound(s, vpls);
  BakeInputs in{s, rt, texels, vpls, eval, {}};
  EmbreeOptions single, packets;
  single.packets = false;
  packets.packets = true;
  std::vector<Lightmap> a = bakeEmbree(in, single), b = bakeEmbree(in, packets);
  int lit = 0;
  for (size_t i = 0; i < a[0].size(); ++i) {
    EXPECT_NEAR(b[0].texels[i].x, a[0].texels[i].x, 1e-6f * std::max(1.0f, a[0].texels[i].x)) << "texel " << i;
    lit += a[0].texels[i].x > 0.0f;
  }
  EXPECT_GT(lit, 32);                       // the lit room
  EXPECT_LT(lit, int(a[0].size()) - 32);   // and the dark one
}

// Punctual lights through the backend with shadows: a directional light (shadow ray to infinity) and a
// spot light over a black floor with a black square occluder; lit texels exact, shadowed texels 0.
TEST(EmbreeBackend, DirectionalAndSpotShadowsAreExact) {
  Scene s;
  int black = addMaterial(s, glm::vec3(0.0f));
  addQuad(s, black, glm::vec3(-2, -2, 0), glm::vec3(4, 0, 0), glm::vec3(0, 4, 0));
  addQuad(s, black, glm::vec3(-0.25f, -0.25f, 1), glm::vec3(0.5f, 0, 0), glm::vec3(0, 0.5f, 0));  // occluder at z = 1
  s.lights.push_back(directionalLight(glm::vec3(0.5f, 0.0f, -1.0f), 3.0f));
  Light spot;
  spot.type = LightType::Spot;
  spot.position = glm::vec3(0, 0, 3);
  spot.direction = glm::vec3(0, 0, -1);
  spot.intensity = 20.0f;
  spot.innerConeAngle = 0.3f;
  spot.outerConeAngle = 0.5f;
  s.lights.push_back(spot);
  std::vector<TexelSamples> t = {gridSamples(glm::vec3(-2, -2, 0), glm::vec3(4, 0, 0), glm::vec3(0, 4, 0), 32, 32)};
  WalkOptions w;
  w.paths = 16;
  Baked b = bakeWith(s, t, w, VplEvalOptions{}, true);
  int shadowedSun = 0, shadowedSpot = 0;
  for (size_t i = 0; i < b.maps[0].size(); ++i) {
    glm::dvec3 x(glm::vec3(t[0].positionWeight[i]));
    // Sun: the occluder's shadow is the square shifted by +0.5 in x (1 m above, direction 0.5 : −1).
    bool sunBlocked = std::abs(x.x - 0.5) < 0.25 && std::abs(x.y) < 0.25;
    double sunValue = sunBlocked ? 0.0 : 3.0 * (1.0 / std::sqrt(1.25)) / kPi;
    // Spot from (0,0,3): the occluder at z = 1 shadows |x|,|y| < 0.375 on the floor.
    bool spotBlocked = std::abs(x.x) < 0.375 && std::abs(x.y) < 0.375;
    glm::dvec3 d = glm::dvec3(0, 0, 3) - x;
    double r2 = glm::dot(d, d), c = d.z / std::sqrt(r2);
    double cosO = std::cos(0.5), cosI = std::cos(0.3), tt = std::clamp((c - cosO) / (cosI - cosO), 0.0, 1.0);
    double spotValue = spotBlocked ? 0.0 : 20.0 * tt * tt * c / r2 / kPi;
    // Texels whose centre is within half a texel of a shadow edge are skipped (the edge crosses them).
    auto nearEdge = [&](double a, double e) { return std::abs(std::abs(a) - e) < 0.07; };
    if (nearEdge(x.x - 0.5, 0.25) || nearEdge(x.x, 0.375) || nearEdge(x.y, 0.25) || nearEdge(x.y, 0.375)) continue;
    shadowedSun += sunBlocked;
    shadowedSpot += spotBlocked;
    EXPECT_NEAR(b.maps[0].texels[i].x, sunValue + spotValue, 1e-5 + 1e-5 * (sunValue + spotValue)) << "texel " << i;
  }
  EXPECT_GT(shadowedSun, 0);
  EXPECT_GT(shadowedSpot, 0);
}

// A texel subset: its texels get the bits of the whole page's bake, L1 pages included; every other texel
// comes back invalid and 0.
TEST(EmbreeEvaluator, TexelSubsetKeepsItsTexelsOnly) {
  Scene s = samples::makeThinWall();
  std::vector<TexelSamples> texels = {gridSamples(glm::vec3(-2, 0, -1), glm::vec3(0, 0, 2), glm::vec3(4, 0, 0), 8, 16)};
  RayTracer rt(s);
  WalkOptions w;
  w.paths = 256;
  const VplSet vpls = generateVpls(s, rt, w);
  const BakeInputs in{s, rt, texels, vpls, VplEvalOptions{}, {}};
  std::vector<std::vector<uint8_t>> subset(1, std::vector<uint8_t>(texels[0].layerSize(), 0));
  for (size_t t = 0; t < subset[0].size(); t += 3) subset[0][t] = 1;
  L1Pages wholeL1, partL1;
  EvaluationRequest whole, part;
  whole.directional = &wholeL1;
  part.directional = &partL1;
  part.texelSubset = &subset;
  const EmbreeEvaluator embree;
  EXPECT_STREQ(embree.name(), "embree");
  EXPECT_TRUE(embree.stats().empty());
  const std::vector<Lightmap> a = embree.evaluate(in, whole), b = embree.evaluate(in, part);
  int inside = 0, lit = 0;
  for (size_t t = 0; t < a[0].size(); ++t) {
    if (subset[0][t]) {
      ++inside;
      lit += b[0].texels[t].x > 0.0f;
      EXPECT_EQ(b[0].valid[t], a[0].valid[t]) << t;
      EXPECT_EQ(b[0].texels[t], a[0].texels[t]) << t;
      for (int k = 0; k < 3; ++k) EXPECT_EQ(partL1[k][0].texels[t], wholeL1[k][0].texels[t]) << t;
    } else {
      EXPECT_EQ(b[0].valid[t], 0) << t;
      EXPECT_EQ(b[0].texels[t], glm::vec3(0.0f)) << t;
      for (int k = 0; k < 3; ++k) EXPECT_EQ(partL1[k][0].valid[t], 0) << t;
    }
  }
  EXPECT_EQ(inside, 43);  // every third of 128 texels
  EXPECT_GT(lit, 10);
}
