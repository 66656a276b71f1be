// The least squares on the clients' blend (blend_fit.h) and the probes' volume fit (ProbeOptions::volumeFitSamples)
// against known fields: a linear field, which the trilinear blend holds exactly, and the sky under a roof's edge,
// whose light changes across a cell in a way no blend of point samples follows.
#include <gtest/gtest.h>

#include <cstdio>

#include "lightmap/probe_grid.h"
#include "sampling/sampling.h"
#include "stages/probes/blend_fit.h"
#include "stages/probes/light_probes.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

using namespace testing;

LightProbeGrid validGrid(const Bounds3& box, float spacing) {
  LightProbeGrid g = probeGridOver(box, spacing, 1 << 14);
  g.coefficients.assign(g.size(), ShCoefficients{});
  g.offsets.assign(g.size(), glm::vec3(0.0f));
  g.valid.assign(g.size(), 1);
  return g;
}

TEST(BlendFit, RecoversALinearFieldFromSamplesAloneAndKeepsItsBounds) {
  Bounds3 box;
  box.extend(glm::vec3(-1.0f, 0.0f, -0.5f));
  box.extend(glm::vec3(1.0f, 1.0f, 0.5f));
  const LightProbeGrid g = validGrid(box, 0.5f);  // 4 × 2 × 2
  const auto field = [](const glm::vec3& p) { return glm::vec2(0.3f + 0.2f * p.x - 0.1f * p.y + 0.05f * p.z, 2.0f * p.x); };
  Rng rng(7);
  std::vector<BlendSample> samples;
  std::vector<float> targets;
  const glm::vec3 lo = g.origin, hi = g.gridPoint(g.counts.x - 1, g.counts.y - 1, g.counts.z - 1);
  for (int s = 0; s < 400; ++s) {
    const glm::vec3 p = lo + (hi - lo) * glm::vec3(rng.uniform(), rng.uniform(), rng.uniform());
    samples.push_back(blendSampleAt(g, p));
    const glm::vec2 f = field(p);
    targets.push_back(f.x), targets.push_back(f.y);
  }
  // Anchors all 0 with a small weight: the samples alone set the values, within about λ / (samples per probe).
  const std::vector<float> anchors(g.size() * 2, 0.0f);
  std::vector<float> x(g.size() * 2, 0.0f);
  const BlendFitResult r = solveBlendFit(g, samples, targets, anchors, 2, 1e-4, std::nullopt, 1e-7, 5000, x);
  EXPECT_EQ(r.samples, 400u);
  EXPECT_LT(r.sweeps, 5000);  // converged
  double worst = 0.0;
  for (size_t i = 0; i < g.size(); ++i) {
    const glm::vec2 f = field(g.position(i));
    worst = std::max({worst, std::abs(double(x[2 * i]) - f.x), std::abs(double(x[2 * i + 1]) - f.y)});
  }
  std::printf("linear field: worst probe error %.2e after %d sweeps\n", worst, r.sweeps);
  EXPECT_LT(worst, 1e-3);
  // Bounded to [0, 1]: the second channel (2x, from −2 to 2 over the probes) is clamped, the first stays exact.
  std::vector<float> b(g.size() * 2, 0.0f);
  solveBlendFit(g, samples, targets, anchors, 2, 1e-4, std::make_pair(0.0f, 1.0f), 1e-7, 5000, b);
  for (size_t i = 0; i < g.size(); ++i) {
    EXPECT_GE(b[2 * i + 1], 0.0f);
    EXPECT_LE(b[2 * i + 1], 1.0f);
    EXPECT_NEAR(b[2 * i], field(g.position(i)).x, 0.02);
  }
}

// A floor (y = 0) under a uniform sky of radiance 1, and a roof at y = 2 over x < 0.1 (facing down); every map
// texel holds 0.2. Under the roof's edge the sky a point sees changes with x as the angle to the edge does.
struct RoofEdge {
  AtlasedScene s;
  VplSet none;
  std::vector<Lightmap> maps;
  RoofEdge() : s(makeScene(), 16) {
    for (const TexelSamples& ts : s.pages) {
      Lightmap m = blankLightmap(ts);
      m.valid = ts.valid;
      for (size_t t = 0; t < m.size(); ++t)
        if (m.valid[t]) m.texels[t] = glm::vec3(0.2f);
      maps.push_back(std::move(m));
    }
  }
  BakeInputs inputs() const { return BakeInputs{s.scene, *s.rayTracer, s.pages, none, VplEvalOptions{}, {}}; }
  static Scene makeScene() {
    Scene scene;
    const int m = addMaterial(scene, glm::vec3(0.5f));
    addQuad(scene, m, glm::vec3(-6, 0, -6), glm::vec3(0, 0, 12), glm::vec3(12, 0, 0));     // floor, facing up
    addQuad(scene, m, glm::vec3(-6, 2, -6), glm::vec3(6.1f, 0, 0), glm::vec3(0, 0, 12));  // roof, facing down
    scene.environment = Environment::uniform(glm::vec3(1.0f));
    return scene;
  }
  LightProbeGrid bake(float spacing, int rays, int volumeFit) const {
    Bounds3 box;
    box.extend(glm::vec3(-1.5f, 0.25f, -0.75f));
    box.extend(glm::vec3(1.5f, 1.75f, 0.75f));
    LightProbeGrid g = probeGridOver(box, spacing, 1 << 14);
    ProbeOptions o;
    o.rays = rays;
    o.volumeFitSamples = volumeFit;
    bakeLightProbes(inputs(), maps, g, o);
    return g;
  }
};

TEST(ProbeVolumeFit, FollowsTheSkyUnderARoofsEdgeBetterThanPointProbes) {
  const RoofEdge r;
  // The reference: probes every 0.1875 m with 4096 rays each, their own values (no fit).
  const LightProbeGrid fine = r.bake(0.1875f, 4096, 0);
  const LightProbeGrid points = r.bake(0.75f, 1024, 0), fitted = r.bake(0.75f, 1024, 3);
  ASSERT_EQ(points.counts, glm::ivec3(4, 2, 2));
  const auto meanSquared = [&](const LightProbeGrid& g) {
    double sum = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < fine.size(); ++i) {
      const glm::vec3 p = fine.position(i);
      const ProbeBlend b = interpolateProbes(g, p);
      for (const glm::vec3& n : {glm::vec3(0, 1, 0), glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0)}) {
        const double d = shIrradiance(b.coefficients, n).x - shIrradiance(fine.coefficients[i], n).x;
        sum += d * d, ++count;
      }
    }
    return sum / count;
  };
  const double mPoints = meanSquared(points), mFitted = meanSquared(fitted);
  std::printf("mean squared error of the blend against the 0.1875 m probes: point probes %.3e, volume fit %.3e\n",
              mPoints, mFitted);
  EXPECT_LT(mFitted, 0.6 * mPoints);
  for (size_t i = 0; i < fitted.size(); ++i) EXPECT_GT(shAverage(fitted.coefficients[i]).x, 0.0f);
}

// A slab (top y = 1 facing up, bottom y = 0.99 facing down, 400 m square) over a floor (y = 0) under a sky of 1,
// every map texel 0.2 (albedo 0.5: surfaces send 0.1). Probes every 0.5 m at y = 0.75 (under the slab) and 1.25
// (over it): over the slab the light is the sky above and 0.1 below wherever the point is, mean E/π over normals
// (1 + 0.1)/2 = 0.55 (the slab's edge 200 m away: under 0.2% more). The cells between the layers cross the slab;
// their points over it are left out of the fit (the probes under it do not see them), so the dark under the
// slab does not bend the probes over it.
TEST(ProbeVolumeFit, ASlabBetweenTwoLayersLeavesTheLayerOverItExact) {
  Scene scene;
  const int m = addMaterial(scene, glm::vec3(0.5f));
  addQuad(scene, m, glm::vec3(-200, 0, -200), glm::vec3(0, 0, 400), glm::vec3(400, 0, 0));
  addQuad(scene, m, glm::vec3(-200, 1, -200), glm::vec3(0, 0, 400), glm::vec3(400, 0, 0));
  addQuad(scene, m, glm::vec3(-200, 0.99f, -200), glm::vec3(400, 0, 0), glm::vec3(0, 0, 400));
  scene.environment = Environment::uniform(glm::vec3(1.0f));
  AtlasedScene s(std::move(scene), 16);
  std::vector<Lightmap> maps;
  for (const TexelSamples& ts : s.pages) {
    Lightmap lm = blankLightmap(ts);
    lm.valid = ts.valid;
    for (size_t t = 0; t < lm.size(); ++t)
      if (lm.valid[t]) lm.texels[t] = glm::vec3(0.2f);
    maps.push_back(std::move(lm));
  }
  const VplSet none;
  const BakeInputs in{s.scene, *s.rayTracer, s.pages, none, VplEvalOptions{}, {}};
  Bounds3 box;
  box.extend(glm::vec3(-1.0f, 0.5f, -1.0f));
  box.extend(glm::vec3(1.0f, 1.5f, 1.0f));
  LightProbeGrid g = probeGridOver(box, 0.5f, 1 << 10);
  ASSERT_EQ(g.counts, glm::ivec3(4, 2, 4));
  ProbeOptions o;
  o.volumeFitSamples = 3;
  ProbeStats stats;
  bakeLightProbes(in, maps, g, o, &stats);
  EXPECT_GT(stats.volumeFitSamples, 0u);
  double worst = 0.0;
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 4; ++i) {
      const size_t idx = g.index(i, 1, k);
      ASSERT_EQ(g.valid[idx], 1);
      worst = std::max(worst, std::abs(shAverage(g.coefficients[idx]).x / 0.55 - 1.0));
    }
  std::printf("over the slab: worst mean E/pi %.2f%% from 0.55 (%zu samples kept)\n", 100.0 * worst, stats.volumeFitSamples);
  EXPECT_LT(worst, 0.01);
}

// Solid angle of the rectangle [x0, x1] × [z0, z1] of the plane y = 0 from p (p.y > 0): the signed sum of four
// rectangles with a corner under p, each atan(ab / (h sqrt(a² + b² + h²))).
double rectangleSolidAngle(const glm::dvec3& p, double x0, double x1, double z0, double z1) {
  const double h = p.y;
  const auto corner = [h](double a, double b) { return std::atan(a * b / (h * std::sqrt(a * a + b * b + h * h))); };
  return corner(x1 - p.x, z1 - p.z) - corner(x0 - p.x, z1 - p.z) - corner(x1 - p.x, z0 - p.z) + corner(x0 - p.x, z0 - p.z);
}

// A square emitter (Le = 1, 1 m, facing up) on a black floor, nothing else: at p the mean E/π over normals is
// Le Ω(p) / (4π). Probes every 0.5 m in two layers (y = 0.25, 0.75). Right over the emitter Ω nears 2π, against
// 3.7 sr a quarter of a metre up, where an object's centre can first be (0.5 spacings from the floor); the blend
// under the lower layer is that layer's alone, so those points, fitted, lift it wherever objects are. Kept out of
// the fit (ProbeOptions::volumeFitClearance), the fit follows the light where objects can be.
TEST(ProbeVolumeFit, PointsNoObjectsCentreReachesStayOutOfTheFit) {
  Scene scene;
  addQuad(scene, addMaterial(scene, glm::vec3(0.0f)), glm::vec3(-3, 0, -3), glm::vec3(0, 0, 6), glm::vec3(6, 0, 0));
  const float a = 0.5f, lift = 0.002f;
  addQuad(scene, addMaterial(scene, glm::vec3(0.0f), glm::vec3(1.0f)), glm::vec3(-a, lift, -a), glm::vec3(0, 0, 2 * a),
          glm::vec3(2 * a, 0, 0));
  AtlasedScene s(std::move(scene), 16);
  std::vector<Lightmap> maps;
  for (const TexelSamples& ts : s.pages) {
    Lightmap lm = blankLightmap(ts);
    lm.valid = ts.valid;
    maps.push_back(std::move(lm));
  }
  const VplSet none;
  const BakeInputs in{s.scene, *s.rayTracer, s.pages, none, VplEvalOptions{}, {}};
  Bounds3 box;
  box.extend(glm::vec3(-1.0f, 0.0f, -1.0f));
  box.extend(glm::vec3(1.0f, 1.0f, 1.0f));
  const auto bake = [&](float clearance) {
    LightProbeGrid g = probeGridOver(box, 0.5f, 1 << 10);
    ProbeOptions o;
    o.volumeFitSamples = 3;
    o.volumeFitClearance = clearance;
    o.exactEmitterTriangles = 0;  // the emitter in the SH, which the fit is about
    bakeLightProbes(in, maps, g, o);
    return g;
  };
  const LightProbeGrid everywhere = bake(0.0f), reachable = bake(ProbeOptions{}.volumeFitClearance);
  ASSERT_EQ(reachable.counts, glm::ivec3(4, 2, 4));
  // The blend's mean squared error against the closed form over points 0.25–0.75 m up within 0.5 m of the
  // emitter's axis; and the same for the probes' own values (no fit).
  LightProbeGrid own = probeGridOver(box, 0.5f, 1 << 10);
  ProbeOptions o;
  o.volumeFitSamples = 0;
  o.exactEmitterTriangles = 0;
  bakeLightProbes(in, maps, own, o);
  const auto meanSquared = [&](const LightProbeGrid& g) {
    double sum = 0.0;
    int count = 0;
    for (int k = 0; k <= 10; ++k)
      for (int j = 0; j <= 10; ++j)
        for (int i = 0; i <= 10; ++i) {
          const glm::dvec3 p(-0.5 + 0.1 * i, 0.25 + 0.05 * j, -0.5 + 0.1 * k);
          const double exact = rectangleSolidAngle(p - glm::dvec3(0, lift, 0), -a, a, -a, a) / (4.0 * 3.14159265358979);
          const double d = shAverage(interpolateProbes(g, glm::vec3(p)).coefficients).x - exact;
          sum += d * d, ++count;
        }
    return sum / count;
  };
  const double mEverywhere = meanSquared(everywhere), mReachable = meanSquared(reachable), mOwn = meanSquared(own);
  std::printf("mean squared error of E/pi where objects can be: every point fitted %.3e, reachable points %.3e, "
              "own values %.3e\n", mEverywhere, mReachable, mOwn);
  EXPECT_LT(mReachable, 0.2 * mEverywhere);
  EXPECT_LT(mReachable, mOwn);
}

}  // namespace
}  // namespace irbake
