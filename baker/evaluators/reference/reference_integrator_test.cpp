#include "evaluators/reference/reference_integrator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "evaluators/embree/embree_backend.h"
#include "common/error.h"
#include "common/maths.h"
#include "transport/geometry_term.h"
#include "testing/probe_bake.h"
#include "testing/scenes.h"

using namespace irbake;
using namespace irbake::testing;

namespace {

struct RefResult {
  std::vector<Lightmap> maps, err;
};

RefResult reference(const Scene& s, const std::vector<TexelSamples>& texels, int spp, uint32_t seed = 1) {
  RayTracer rt(s);
  VplSet none;
  BakeInputs in{s, rt, texels, none, VplEvalOptions{}, {}};
  ReferenceOptions o;
  o.spp = spp;
  o.seed = seed;
  RefResult r;
  r.maps = bakeReference(in, o, &r.err);
  return r;
}

double mean(const Lightmap& m) {
  double s = 0.0;
  int n = 0;
  for (size_t i = 0; i < m.size(); ++i)
    if (m.valid[i]) { s += m.texels[i].x; ++n; }
  return s / std::max(1, n);
}
}  // namespace

TEST(Reference, PointLightOverBlackPlaneIsExact) {
  Scene s;
  addQuad(s, addMaterial(s, glm::vec3(0.0f)), glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  glm::vec3 L(-0.2f, 0.1f, 0.5f);
  s.lights.push_back(pointLight(L, 3.0f));
  std::vector<TexelSamples> t = {gridSamples(glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), 16, 16)};
  RefResult r = reference(s, t, 4);
  for (size_t i = 0; i < r.maps[0].size(); ++i) {
    glm::dvec3 d = glm::dvec3(L) - glm::dvec3(glm::vec3(t[0].positionWeight[i]));
    double r2 = glm::dot(d, d), exact = 3.0 * (d.z / std::sqrt(r2)) / (kPi * r2);
    EXPECT_NEAR(r.maps[0].texels[i].x / exact, 1.0, 1e-5);
    EXPECT_EQ(r.err[0].texels[i].x, 0.0f);  // deterministic: no variance
  }
}

// Reference against closed forms within 0.5% (quad emitter over a black plane), and its
// standard error is honest: errors / standard error have an RMS near 1.
TEST(Reference, QuadOverPlaneMatchesFormFactorWithHonestErrorBars) {
  Scene s;
  int lamp = addMaterial(s, glm::vec3(0.0f), glm::vec3(1.0f));
  addQuad(s, lamp, glm::vec3(-0.5f, -0.5f, 0.5f), glm::vec3(0, 1, 0), glm::vec3(1, 0, 0));
  addQuad(s, addMaterial(s, glm::vec3(0.0f)), glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  std::vector<TexelSamples> t = {gridSamples(glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), 16, 16)};
  RefResult r = reference(s, t, 256);
  std::vector<glm::dvec3> poly = {{-0.5, -0.5, 0.5}, {0.5, -0.5, 0.5}, {0.5, 0.5, 0.5}, {-0.5, 0.5, 0.5}};
  double sumRef = 0, sumExact = 0, z2 = 0, se = 0, ref2 = 0;
  for (size_t i = 0; i < r.maps[0].size(); ++i) {
    double exact = polygonFormFactor(glm::dvec3(glm::vec3(t[0].positionWeight[i])), glm::dvec3(0, 0, 1), poly);
    double v = r.maps[0].texels[i].x, e = r.err[0].texels[i].x;
    sumRef += v;
    sumExact += exact;
    ASSERT_GT(e, 0.0);
    z2 += (v - exact) * (v - exact) / (e * e);
    se += (v - exact) * (v - exact);
    ref2 += exact * exact;
  }
  double zRms = std::sqrt(z2 / r.maps[0].size()), rmse = std::sqrt(se / ref2);
  std::printf("[ figure ] reference quad over plane (256 spp): mean error %+.3f%%, relative RMSE %.3f%%, RMS(err/stderr) %.2f\n",
              100 * (sumRef / sumExact - 1), 100 * rmse, zRms);
  EXPECT_NEAR(sumRef / sumExact, 1.0, 0.005);
  EXPECT_GT(zRms, 0.7);
  EXPECT_LT(zRms, 1.4);
}

// Reference furnace within 0.5% of Le/(1−ρ).
TEST(Reference, FurnaceMatchesClosedForm) {
  for (float rho : {0.5f, 0.9f}) {
    Scene s;
    addBox(s, addMaterial(s, glm::vec3(rho), glm::vec3(1.0f)), glm::vec3(0), glm::vec3(1), true, 2);
    std::vector<TexelSamples> t = {gridSamples(glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), 12, 12)};
    RefResult r = reference(s, t, 512);
    double exact = 1.0 / (1.0 - rho), m = mean(r.maps[0]);
    std::printf("[ figure ] reference furnace rho=%.1f (512 spp): %.4f vs %.4f (%+.3f%%), median texel stderr %.3f%%\n", rho,
                m, exact, 100 * (m / exact - 1), 100 * r.err[0].texels[70].x / exact);
    EXPECT_NEAR(m / exact, 1.0, 0.005);
  }
}

// Corner (floor and two walls, a point light). The clamped VPL estimate loses energy
// near the edges; ClampGather's compensation brings the mean within 2% of the reference.
TEST(Reference, CornerCompensationMatchesReference) {
  Scene s;
  int grey = addMaterial(s, glm::vec3(0.75f));
  addQuad(s, grey, glm::vec3(0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), 2);   // floor z = 0
  addQuad(s, grey, glm::vec3(0), glm::vec3(0, 0, 2), glm::vec3(2, 0, 0), 2);   // wall y = 0, normal +y
  addQuad(s, grey, glm::vec3(0), glm::vec3(0, 2, 0), glm::vec3(0, 0, 2), 2);   // wall x = 0, normal +x
  s.lights.push_back(pointLight(glm::vec3(1.2f, 1.0f, 1.3f), 4.0f));
  // Floor texels near the corner, where the walls' VPLs are close.
  std::vector<TexelSamples> t = {gridSamples(glm::vec3(0), glm::vec3(0.6f, 0, 0), glm::vec3(0, 0.6f, 0), 12, 12)};
  RefResult ref = reference(s, t, 256);
  double refErr = 0.0;  // standard error of the reference's mean over texels
  for (const glm::vec3& e : ref.err[0].texels) refErr += double(e.x) * e.x;
  refErr = std::sqrt(refErr) / ref.err[0].texels.size();

  RayTracer rt(s);
  VplEvalOptions direct;
  direct.includeVpls = false;
  VplSet none;
  BakeInputs din{s, rt, t, none, direct, {}};
  std::vector<Lightmap> dmap = bakeEmbree(din);
  // The corner's indirect light comes from few wall VPLs, so one walk is noise-bound at ±2%: average
  // eight independently scrambled walks (seeds) to see the bias of the estimator itself.
  // The compensation reads the walls' radiance from their maps: the VPL bakes run on the scene with an atlas.
  const AtlasedScene atlased(s, 64);
  double c = 0.0, k = 0.0, u = 0.0, bound = 0.0;
  size_t count = 0;
  const int seeds = 8;
  for (int seed = 0; seed < seeds; ++seed) {
    WalkOptions w;
    w.paths = 16384;
    w.seed = seed;
    VplSet vpls = generateVpls(atlased.scene, *atlased.rayTracer, w);
    // Compare the indirect part only (direct is exact in both): the gather reads the walls' whole radiance
    // from their maps, direct light included, so the direct part is taken off the probes afterwards.
    VplEvalOptions eval;
    eval.clampBound = deriveClampBound(atlased.scene, vpls);
    const ProbeBake probes = bakeProbesCompensated(atlased, t, vpls, eval);
    c += (mean(probes.clamped[0]) - mean(dmap[0])) / seeds;
    k += (mean(probes.compensated[0]) - mean(dmap[0])) / seeds;
    BakeInputs in{atlased.scene, *atlased.rayTracer, t, vpls, eval, {}};
    in.eval.includeDirect = false;
    in.eval.clampBound = 0.0f;
    u += mean(bakeEmbree(in)[0]) / seeds;
    bound += eval.clampBound / seeds;
    count += vpls.vpls.size();
  }
  double r = mean(ref.maps[0]) - mean(dmap[0]);  // the reference's indirect part
  std::printf("[ figure ] corner indirect: reference %.5f ± %.5f, unclamped %.5f (%+.2f%%), clamped %.5f (bias %+.2f%%), "
              "compensated %.5f (%+.2f%%), clamp B=%.1f (r_c=%.3f m), %zu VPLs per walk, %d walks\n",
              r, refErr, u, 100 * (u / r - 1), c, 100 * (c / r - 1), k, 100 * (k / r - 1), bound, 1.0 / std::sqrt(bound),
              count / seeds, seeds);
  EXPECT_LT(c, u);                     // the clamp removes energy
  EXPECT_NEAR(k / u, 1.0, 0.01);       // compensation gives back what the clamp took from these VPL sets
  EXPECT_NEAR(k / r, 1.0, 0.03);
}

TEST(Reference, StandardErrorFallsAsOneOverRootSpp) {
  Scene s;
  addBox(s, addMaterial(s, glm::vec3(0.5f), glm::vec3(1.0f)), glm::vec3(0), glm::vec3(1), true);
  std::vector<TexelSamples> t = {gridSamples(glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), 6, 6)};
  RefResult a = reference(s, t, 32), b = reference(s, t, 128);
  double ea = 0, eb = 0;
  for (size_t i = 0; i < 36; ++i) { ea += a.err[0].texels[i].x; eb += b.err[0].texels[i].x; }
  EXPECT_NEAR(ea / eb, 2.0, 0.3);
}

// Texel samples snapped onto a concave edge (floor meets wall) name their triangle; the backends move
// them ε into it. Without that, paths start on the wall's plane and half of them leave the furnace.
TEST(Reference, SamplesOnAConcaveEdgeStayInside) {
  Scene s;
  addBox(s, addMaterial(s, glm::vec3(0.5f), glm::vec3(1.0f)), glm::vec3(0), glm::vec3(1), true);
  // Floor = primitive 0: triangles (0, X, X+Y) and (0, X+Y, Y); the edge x = 0 belongs to triangle 1.
  TexelSamples t = gridSamples(glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), 16, 1);  // 16 slots, moved below
  for (size_t i = 0; i < t.slotCount(); ++i) {
    t.positionWeight[i] = glm::vec4(0.0f, (i + 0.5f) / 16.0f, 0.0f, 1.0f);
    t.normal[i] = glm::vec4(0, 0, 1, 0);
    t.primitive[i] = 0;
    t.triangle[i] = 1;
  }
  TexelSamples unnamed = t;
  for (auto& p : unnamed.primitive) p = UINT32_MAX;
  RefResult named = reference(s, {t}, 256), plain = reference(s, {unnamed}, 256);
  std::printf("[ figure ] furnace edge samples: with triangle %.4f, without %.4f (exact 2)\n", mean(named.maps[0]),
              mean(plain.maps[0]));
  EXPECT_NEAR(mean(named.maps[0]), 2.0, 0.04);
}

// The reference behind the evaluator interface: a texel subset traces those texels with the bits of the
// whole page (each sample's stream is its own), the rest come back invalid and 0; stats() holds the paths
// per sample and the mean standard error over the mean value; it makes no L1 pages.
TEST(ReferenceEvaluator, SubsetStatsAndNoDirectionalMaps) {
  Scene s;
  addBox(s, addMaterial(s, glm::vec3(0.5f), glm::vec3(1.0f)), glm::vec3(0), glm::vec3(1), true);
  const std::vector<TexelSamples> t = {gridSamples(glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), 8, 8)};
  RayTracer rt(s);
  const VplSet none;
  const BakeInputs in{s, rt, t, none, VplEvalOptions{}, {}};
  ReferenceOptions o;
  o.spp = 16;
  o.seed = 3;
  const ReferenceEvaluator reference(o);
  EXPECT_STREQ(reference.name(), "reference");
  std::vector<std::vector<uint8_t>> subset(1, std::vector<uint8_t>(64, 0));
  for (size_t i = 0; i < 64; i += 5) subset[0][i] = 1;
  EvaluationRequest part;
  part.texelSubset = &subset;
  const std::vector<Lightmap> b = reference.evaluate(in, part);
  const std::vector<Lightmap> a = reference.evaluate(in);
  std::vector<Lightmap> err;
  const std::vector<Lightmap> same = bakeReference(in, o, &err);
  double se = 0.0, value = 0.0;
  for (size_t i = 0; i < 64; ++i) {
    ASSERT_EQ(same[0].texels[i], a[0].texels[i]) << i;
    se += channelMean(err[0].texels[i]);
    value += channelMean(a[0].texels[i]);
    if (subset[0][i]) {
      EXPECT_EQ(b[0].valid[i], 1) << i;
      EXPECT_EQ(b[0].texels[i], a[0].texels[i]) << i;
    } else {
      EXPECT_EQ(b[0].valid[i], 0) << i;
      EXPECT_EQ(b[0].texels[i], glm::vec3(0.0f)) << i;
    }
  }
  const nlohmann::json stats = reference.stats();  // of the last evaluation, the whole page
  EXPECT_EQ(stats.at("spp"), 16);
  EXPECT_DOUBLE_EQ(stats.at("relativeStandardError").get<double>(), se / value);
  EXPECT_GT(se / value, 0.01);  // 16 paths: a few per cent
  EXPECT_LT(se / value, 0.2);
  L1Pages l1;
  EvaluationRequest directional;
  directional.directional = &l1;
  try {
    reference.evaluate(in, directional);
    FAIL() << "the reference made L1 pages";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Usage);
  }
}
