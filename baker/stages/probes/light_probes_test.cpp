// Irradiance probes against closed forms. The maps the probes read are filled with their exact values, so each
// test measures the probes' own error: the rays' (N lattice rays; independent rays would have a standard
// deviation of at most 4·max L·sqrt(E[K²]) / √N = 1.63 max L / √N in map units, K the L2 kernel below, and
// the lattice does better, so 3 of those σ is a safe bound) and the L2 truncation, bounded after Ramamoorthi &
// Hanrahan 2001: the clamped cosine max(c, 0) against its L2 part K(c) = 1/4 + c/2 + (5/32)(3c² − 1) differs by
// at most 3/32 (at c = 0; 1/16 at c = ±1), so one directional light of map value V gives an L2 error ≤ 3V/32.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

#include "common/error.h"

#include "lightmap/probe_emitter_field.h"
#include "lightmap/probe_grid.h"
#include "testing/scenes.h"
#include "samples/sample_scenes.h"
#include "stages/probes/light_probes.h"

namespace irbake {
namespace {

using namespace testing;
constexpr double kPi = 3.14159265358979323846;
constexpr double kTruncation = 3.0 / 32.0;  // max |K(c) − max(c, 0)|

// 3σ of N independent rays for radiance at most maxL (map units).
double rayTolerance(int rays, double maxL) { return 3.0 * 1.63 * maxL / std::sqrt(static_cast<double>(rays)); }

// Maps whose valid texels hold `value` (the exact map of the scenes below).
std::vector<Lightmap> filledMaps(const std::vector<TexelSamples>& pages, glm::vec3 value) {
  std::vector<Lightmap> maps;
  for (const TexelSamples& ts : pages) {
    Lightmap m = blankLightmap(ts);
    m.valid = ts.valid;
    for (size_t t = 0; t < m.size(); ++t)
      if (m.valid[t]) m.texels[t] = value;
    maps.push_back(std::move(m));
  }
  return maps;
}

// One probe at p (a zero-extent box).
// exactEmitterTriangles 0: every emitter in the SH (the tests of the SH's own emitter sampling).
LightProbeGrid bakeOne(AtlasedScene& s, const std::vector<Lightmap>& maps, glm::vec3 p, int rays, int emitterSamples = 128,
                       uint32_t seed = 0, int exactEmitterTriangles = ProbeOptions{}.exactEmitterTriangles) {
  const VplSet none;
  const BakeInputs in{s.scene, *s.rayTracer, s.pages, none, VplEvalOptions{}, {}};
  Bounds3 box;
  box.extend(p);
  LightProbeGrid grid = probeGridOver(box, 1.0f, 1);
  ProbeOptions options;
  options.rays = rays;
  options.emitterSamples = emitterSamples;
  options.seed = seed;
  options.exactEmitterTriangles = exactEmitterTriangles;
  options.volumeFitSamples = 0;  // the probe's own value: one probe's volume fit is its cube's mean light
  bakeLightProbes(in, maps, grid, options);
  return grid;
}

// Point under the centre of a square of half-side a at distance h, facing it: the view factor (four
// corner-aligned a × a rectangles, the parallel-rectangle closed form).
double squareViewFactor(double a, double h) {
  const double x = a / h, sx = std::sqrt(1.0 + x * x);
  return 4.0 / (2.0 * kPi) * 2.0 * (x / sx) * std::atan(x / sx);
}

TEST(LightProbes, OpenPlaneUnderUniformSky) {
  // 10 × 10 m plane (ρ = 0.5) under a uniform sky L: its map is L. A probe h = 4 m above its centre facing up
  // sees the sky alone: L. Facing down it sees the plane (ρL) over the view factor F and the sky below the
  // horizon beyond the plane's edges over 1 − F: ρLF + L(1 − F); an infinite plane's ρL would be 0.17 L off.
  const float L = 0.8f, rho = 0.5f, h = 4.0f, a = 5.0f;
  Scene scene;
  addQuad(scene, addMaterial(scene, glm::vec3(rho)), glm::vec3(-a, 0, -a), glm::vec3(0, 0, 2 * a), glm::vec3(2 * a, 0, 0), 4);
  scene.environment = Environment::uniform(glm::vec3(L));
  AtlasedScene s(std::move(scene), 64);
  const int rays = 65536;
  const LightProbeGrid g = bakeOne(s, filledMaps(s.pages, glm::vec3(L)), glm::vec3(0, h, 0), rays);
  ASSERT_EQ(g.valid[0], 1);
  const double F = squareViewFactor(a, h);
  const double down = rho * L * F + L * (1.0 - F);
  // Truncation: the plane is the lower hemisphere (whose irradiance is linear in n: exact in L2) less the band
  // below the horizon it misses, inside θ > atan(a/h) from straight down: Ω ≤ 2π h/√(a²+h²).
  const double band = 2.0 * kPi * h / std::sqrt(a * a + h * h);
  const double tolerance = rayTolerance(rays, L) + (1.0 - rho) * L * kTruncation * band / kPi;
  const glm::vec3 up = shIrradiance(g.coefficients[0], glm::vec3(0, 1, 0));
  const glm::vec3 dn = shIrradiance(g.coefficients[0], glm::vec3(0, -1, 0));
  std::printf("up %.5f (L %.5f), down %.5f (finite plane %.5f, infinite %.5f, F %.4f), tolerance %.4f\n", up.x, L, dn.x,
              down, rho * L, F, tolerance);
  EXPECT_NEAR(up.x, L, tolerance);
  EXPECT_NEAR(dn.x, down, tolerance);
  EXPECT_GT(std::abs(dn.x - rho * L), tolerance);  // the finite-plane correction is needed
}

// A lone black square emitter of half-side a and radiance Le at height h over the origin, facing down.
AtlasedScene squareEmitter(float a, float h, float Le) {
  Scene scene;
  addQuad(scene, addMaterial(scene, glm::vec3(0.0f), glm::vec3(Le)), glm::vec3(-a, h, -a), glm::vec3(2 * a, 0, 0),
          glm::vec3(0, 0, 2 * a), 4);
  return AtlasedScene(std::move(scene), 16);
}

// The square's solid angle from under its centre, Ω = 4 asin(a²/(a² + h²)) (four corner-aligned a × a rectangles),
// and ∫ cos²θ dω = (Ω − h dΩ/dh)/3 (from d/dh of Ω = ∫ h/r³ dA), dΩ/dh = −8a²/((a² + h²)√(h² + 2a²)).
double squareSolidAngle(double a, double h) { return 4.0 * std::asin(a * a / (a * a + h * h)); }
double squareCos2(double a, double h) {
  return (squareSolidAngle(a, h) + 8.0 * a * a * h / ((a * a + h * h) * std::sqrt(h * h + 2.0 * a * a))) / 3.0;
}

TEST(LightProbes, SmallEmitterMatchesItsSolidAngleAndFormFactor) {
  // In the SH (no exact emitters: exact_emitters_test.cpp has those). A 0.4 × 0.4 m emitter 1 m above the probe: Ω = 0.154 sr, about 12 of the 1024 lattice rays. The mean over
  // normals (L0) is Le Ω/(4π) exactly; facing it, the L2 irradiance is (Le/π) ∫ K(cosθ) dω with the L2 kernel
  // K(c) = 1/4 + c/2 + (5/32)(3c² − 1): (Le/π)[(3/32) Ω + (π/2) F + (15/32) ∫cos²θ dω], F the form factor (the
  // true E/π = Le F differs by the L2 truncation, ≤ 3/32 of the peak). Above the emitter (its back) nothing.
  const float a = 0.2f, h = 1.0f, Le = 5.0f;
  AtlasedScene s = squareEmitter(a, h, Le);
  const std::vector<Lightmap> maps = filledMaps(s.pages, glm::vec3(0.0f));
  const double omega = squareSolidAngle(a, h), F = squareViewFactor(a, h);
  const double mean = Le * omega / (4.0 * kPi);
  const double up = Le / kPi * (3.0 / 32.0 * omega + 0.5 * kPi * F + 15.0 / 32.0 * squareCos2(a, h));
  const LightProbeGrid g = bakeOne(s, maps, glm::vec3(0.0f), 1024, 128, 0, 0);
  ASSERT_EQ(g.valid[0], 1);
  const double gotMean = shAverage(g.coefficients[0]).x, gotUp = shIrradiance(g.coefficients[0], glm::vec3(0, 1, 0)).x;
  std::printf("mean %.6f (exact %.6f), up %.6f (L2 exact %.6f, true Le F %.6f)\n", gotMean, mean, gotUp, up, Le * F);
  EXPECT_NEAR(gotMean, mean, 0.005 * mean);
  EXPECT_NEAR(gotUp, up, 0.005 * up);
  EXPECT_NEAR(gotUp, Le * F, kTruncation * Le * F);
  const LightProbeGrid above = bakeOne(s, maps, glm::vec3(0.0f, 2.0f * h, 0.0f), 1024, 128, 0, 0);
  ASSERT_EQ(above.valid[0], 1);
  EXPECT_EQ(shAverage(above.coefficients[0]).x, 0.0f);
}

TEST(LightProbes, EmitterSamplesCutTheSeedToSeedSpread) {
  // The same probe under 16 seeds: with the 128 shadow rays its L0 has a relative standard deviation under 0.2%
  // (0.05% measured) about the exact Le Ω/(4π); the lattice alone (emitterSamples 0) finds the emitter with about
  // 12 of its 1024 rays and spreads more than ten times as much (4.9%).
  const float a = 0.2f, h = 1.0f, Le = 5.0f;
  AtlasedScene s = squareEmitter(a, h, Le);
  const std::vector<Lightmap> maps = filledMaps(s.pages, glm::vec3(0.0f));
  const double mean = Le * squareSolidAngle(a, h) / (4.0 * kPi);
  auto spread = [&](int emitterSamples) {
    double sum = 0.0, sum2 = 0.0;
    const int seeds = 16;
    for (int seed = 0; seed < seeds; ++seed) {
      const double v = shAverage(bakeOne(s, maps, glm::vec3(0.0f), 1024, emitterSamples, seed, 0).coefficients[0]).x / mean;
      sum += v, sum2 += v * v;
    }
    const double m = sum / seeds;
    return std::make_pair(m, std::sqrt(std::max(0.0, sum2 / seeds - m * m)));
  };
  const auto [withSamples, spreadWith] = spread(128);
  const auto [latticeOnly, spreadLattice] = spread(0);
  std::printf("relative to exact: shadow rays mean %.5f sd %.5f; lattice alone mean %.5f sd %.5f\n", withSamples,
              spreadWith, latticeOnly, spreadLattice);
  EXPECT_NEAR(withSamples, 1.0, 0.005);
  EXPECT_LT(spreadWith, 0.002);
  EXPECT_GT(spreadLattice, 10.0 * spreadWith);
}

TEST(LightProbes, ExactEmitterLeavesTheShWithItsEnergyAndVisibility) {
  // The lone square (32 triangles, uniform, planar) is an exact emitter: its light is in neither the lattice nor
  // the shadow rays (every coefficient 0), the probe sees all of it (v = 1), and the clients' exact term's mean
  // over normals, Le Ω/(4π), is what the SH's L0 held before (within its 0.5%).
  const float a = 0.2f, h = 1.0f, Le = 5.0f;
  AtlasedScene s = squareEmitter(a, h, Le);
  const std::vector<Lightmap> black = filledMaps(s.pages, glm::vec3(0.0f));
  const LightProbeGrid g = bakeOne(s, black, glm::vec3(0.0f), 1024);
  ASSERT_EQ(g.emitters.size(), 1u);
  ASSERT_EQ(g.emitters[0].positions.size(), 96u);
  EXPECT_EQ(g.emitters[0].visibility[0], 1.0f);
  for (const glm::vec3& c : g.coefficients[0]) EXPECT_EQ(c, glm::vec3(0.0f));
  const double exact = exactEmitterMean(g.emitters, {1.0f}, glm::vec3(0.0f)).x, closed = Le * squareSolidAngle(a, h) / (4.0 * kPi);
  EXPECT_NEAR(exact, closed, 1e-5 * closed);
  const double old = shAverage(bakeOne(s, black, glm::vec3(0.0f), 1024, 128, 0, 0).coefficients[0]).x;
  EXPECT_NEAR(exact, old, 0.005 * old);
  // Over a grey floor (ρ 0.5, map 0.3): the floor's light stays in the SH, and SH + exact term = the old L0 (its
  // emitter part by 8192 shadow rays: off the square's axis 128 left it 0.9–1.2% from the exact value).
  Scene floorScene;
  addQuad(floorScene, addMaterial(floorScene, glm::vec3(0.0f), glm::vec3(Le)), glm::vec3(-a, h, -a), glm::vec3(2 * a, 0, 0),
          glm::vec3(0, 0, 2 * a), 4);
  addQuad(floorScene, addMaterial(floorScene, glm::vec3(0.5f)), glm::vec3(-2, 0, -2), glm::vec3(0, 0, 4), glm::vec3(4, 0, 0), 4);
  AtlasedScene f(std::move(floorScene), 32);
  const std::vector<Lightmap> lit = filledMaps(f.pages, glm::vec3(0.3f));
  for (const glm::vec3 p : {glm::vec3(0.1f, 0.4f, 0.2f), glm::vec3(-0.5f, 0.8f, 0.3f)}) {
    const LightProbeGrid now = bakeOne(f, lit, p, 1024), before = bakeOne(f, lit, p, 1024, 8192, 0, 0);
    ASSERT_EQ(now.emitters.size(), 1u);
    const double sum = shAverage(now.coefficients[0]).x + exactEmitterMean(now.emitters, {now.emitters[0].visibility[0]}, p).x;
    const double floorOnly = shAverage(now.coefficients[0]).x, was = shAverage(before.coefficients[0]).x;
    std::printf("at %.1f,%.1f,%.1f: SH %.5f + exact = %.5f, before %.5f\n", p.x, p.y, p.z, floorOnly, sum, was);
    EXPECT_GT(floorOnly, 0.0);
    EXPECT_NEAR(sum, was, 0.001 * was);
  }
  // A black plate halfway up over the x < 0 half of the square's footprint hides exactly that half from the
  // origin (by symmetry half the solid-angle-weighted samples): v = 1/2.
  Scene shaded;
  addQuad(shaded, addMaterial(shaded, glm::vec3(0.0f), glm::vec3(Le)), glm::vec3(-a, h, -a), glm::vec3(2 * a, 0, 0),
          glm::vec3(0, 0, 2 * a), 4);
  addQuad(shaded, addMaterial(shaded, glm::vec3(0.0f)), glm::vec3(-a / 2 - 0.01f, h / 2, -a / 2 - 0.01f),
          glm::vec3(a / 2 + 0.01f, 0, 0), glm::vec3(0, 0, a + 0.02f));
  AtlasedScene sh(std::move(shaded), 16);
  const LightProbeGrid half = bakeOne(sh, filledMaps(sh.pages, glm::vec3(0.0f)), glm::vec3(0.0f), 1024);
  ASSERT_EQ(half.emitters.size(), 1u);
  EXPECT_NEAR(half.emitters[0].visibility[0], 0.5, 0.03);
}

TEST(LightProbes, ClosedFurnaceGivesLeOverOneMinusRhoEverywhere) {
  // Every wall: Le + ρ M with M = Le/(1 − ρ), so every direction brings Le/(1 − ρ), and so does every normal.
  const float rho = 0.5f, Le = 1.0f, expected = Le / (1.0f - rho);
  AtlasedScene s(samples::makeFurnace(rho, Le), 32);
  const int rays = 65536;
  for (const glm::vec3 p : {glm::vec3(0.0f), glm::vec3(0.6f, -0.7f, 0.3f)}) {
    const LightProbeGrid g = bakeOne(s, filledMaps(s.pages, glm::vec3(expected)), p, rays);
    ASSERT_EQ(g.valid[0], 1);
    const double tolerance = rayTolerance(rays, expected);  // constant radiance: no truncation
    EXPECT_NEAR(shAverage(g.coefficients[0]).x, expected, tolerance);
    for (const glm::vec3 n : {glm::vec3(1, 0, 0), glm::vec3(0, -1, 0), glm::vec3(0, 0, 1), glm::normalize(glm::vec3(1, 1, -1)),
                              glm::normalize(glm::vec3(-0.3f, 0.2f, 0.9f))})
      EXPECT_NEAR(shIrradiance(g.coefficients[0], n).y, expected, tolerance) << n.x << "," << n.y << "," << n.z;
  }
}

TEST(LightProbes, PointLightMatchesTheClampedCosineWithinTheL2Bound) {
  // Empty space: one tiny quad far away (the ray tracer needs a triangle) and a point light I = 10 W/sr at
  // r = √5.25 m. E(n)/π = I max(n·l, 0)/(π r²) exactly; its L2 reconstruction differs by at most 3/32 of the
  // peak, reached at grazing normals; the mean over normals (L0) is exactly 1/4 of the peak.
  Scene scene;
  addQuad(scene, addMaterial(scene, glm::vec3(0.5f)), glm::vec3(100, 100, 100), glm::vec3(0.01f, 0, 0), glm::vec3(0, 0.01f, 0));
  Light light;
  light.intensity = 10.0f;
  light.position = glm::vec3(1.0f, 2.0f, 0.5f);
  scene.lights.push_back(light);
  AtlasedScene s(std::move(scene), 16);
  const LightProbeGrid g = bakeOne(s, filledMaps(s.pages, glm::vec3(0.0f)), glm::vec3(0.0f), 64);
  ASSERT_EQ(g.valid[0], 1);
  const glm::vec3 l = glm::normalize(light.position);
  const double peak = light.intensity / (kPi * glm::dot(light.position, light.position));
  double worst = 0.0;
  for (int i = 0; i < 2000; ++i) {  // normals on a Fibonacci sphere
    const double z = 1.0 - (i + 0.5) / 1000.0, phi = i * 2.399963229728653;
    const double rxy = std::sqrt(std::max(0.0, 1.0 - z * z));
    const glm::vec3 n(rxy * std::cos(phi), rxy * std::sin(phi), z);
    const double exact = peak * std::max(0.0f, glm::dot(n, l));
    worst = std::max(worst, std::abs(shIrradiance(g.coefficients[0], n).x - exact));
  }
  std::printf("peak %.5f, worst L2 error %.5f = %.4f of the peak (bound 3/32 = %.4f)\n", peak, worst, worst / peak, kTruncation);
  EXPECT_LE(worst, kTruncation * peak * (1.0 + 1e-4));
  EXPECT_GE(worst, 0.99 * kTruncation * peak);  // the bound is reached (grazing), so it is the right one
  EXPECT_NEAR(shAverage(g.coefficients[0]).x, 0.25 * peak, 1e-5 * peak);
  EXPECT_NEAR(shIrradiance(g.coefficients[0], l).x, peak * 17.0 / 16.0, 1e-5 * peak);  // K(1) = 17/16
}

TEST(LightProbes, NothingCrossesTheThinWall) {
  // makeThinWall: the point light lights the room x < 0 only. The probes see its light by shadow rays; the dark
  // room's must get none, and interpolation with visibility reads none at points on the dark side, even in
  // the cells whose corners lie on both sides of the wall.
  AtlasedScene s(samples::makeThinWall(), 64);
  const VplSet none;
  const BakeInputs in{s.scene, *s.rayTracer, s.pages, none, VplEvalOptions{}, {}};
  const std::vector<Lightmap> maps = filledMaps(s.pages, glm::vec3(0.0f));  // direct light alone: the map's bounces are 0
  Bounds3 room;
  room.extend(glm::vec3(-2, 0, -1));
  room.extend(glm::vec3(2, 2, 1));
  LightProbeGrid g = probeGridOver(room, 0.3f, 1 << 20);  // x layers at ±0.15, ±0.45, ...: cells straddle the wall
  ProbeStats stats;
  bakeLightProbes(in, maps, g, {}, &stats);
  EXPECT_EQ(stats.count, g.size());
  const RayTracer& rt = *s.rayTracer;
  auto visible = [&](const glm::vec3& from, const glm::vec3& to) {
    const glm::vec3 d = to - from;
    const float r = glm::length(d);
    return !(r > 0.0f) || !rt.occluded(from, d / r, 0.0f, r);
  };
  size_t darkProbes = 0;
  for (size_t i = 0; i < g.size(); ++i)
    if (g.position(i).x > 0.0f && g.valid[i]) {
      ++darkProbes;
      EXPECT_EQ(shAverage(g.coefficients[i]).x, 0.0f) << "probe " << i;
    }
  EXPECT_GT(darkProbes, g.size() / 3);
  double litMean = 0.0;
  int lit = 0;
  for (float x : {0.01f, 0.05f, 0.14f, 0.5f, 1.2f})
    for (float y : {0.2f, 1.0f, 1.7f})
      for (float z : {-0.8f, 0.0f, 0.6f}) {
        const ProbeBlend dark = interpolateProbes(g, glm::vec3(x, y, z), visible);
        EXPECT_GT(dark.probes, 0);
        EXPECT_EQ(shAverage(dark.coefficients).x, 0.0f) << x << "," << y << "," << z;
        const ProbeBlend bright = interpolateProbes(g, glm::vec3(-x, y, z), visible);
        litMean += shAverage(bright.coefficients).x, ++lit;
        // Without the visibility test, the straddling cells would carry the lit side's light over.
        if (x < 0.15f) {
          EXPECT_GT(shAverage(interpolateProbes(g, glm::vec3(x, y, z)).coefficients).x, 0.0f);
        }
      }
  EXPECT_GT(litMean / lit, 0.05);  // I/(π r²) · 1/4 ≈ 0.8 at 1 m: the lit side is lit
}

TEST(LightProbes, TrilinearBlendIsExactOnLinearDataAndSkipsInvalidProbes) {
  // c_0 = 1 + 2x − y + 0.5z at each probe: the trilinear blend reproduces a linear function exactly, inside
  // the grid; an invalid corner drops out and the other seven's weights are renormalised.
  Bounds3 b;
  b.extend(glm::vec3(0.0f));
  b.extend(glm::vec3(3.0f, 2.0f, 2.0f));
  LightProbeGrid g = probeGridOver(b, 1.0f, 100);  // 3 × 2 × 2 at 0.5 … 2.5, 0.5 … 1.5
  const auto f = [](glm::vec3 p) { return 1.0f + 2.0f * p.x - p.y + 0.5f * p.z; };
  g.coefficients.assign(g.size(), ShCoefficients{});
  g.valid.assign(g.size(), 1);
  for (size_t i = 0; i < g.size(); ++i) g.coefficients[i][0] = glm::vec3(f(g.position(i)));
  for (const glm::vec3 p : {glm::vec3(0.7f, 0.9f, 1.2f), glm::vec3(2.2f, 1.4f, 0.6f), glm::vec3(1.3f, 1.1f, 0.9f)}) {
    const ProbeBlend blend = interpolateProbes(g, p);
    EXPECT_EQ(blend.probes, 8);
    EXPECT_NEAR(blend.weight, 1.0f, 1e-5f);
    EXPECT_NEAR(blend.coefficients[0].x, f(p), 1e-5f);
  }
  // Outside the grid: clamped to its border.
  EXPECT_NEAR(interpolateProbes(g, glm::vec3(-4.0f, 1.0f, 1.0f)).coefficients[0].x, f(glm::vec3(0.5f, 1.0f, 1.0f)), 1e-5f);
  // Probe (0, 0, 0) invalid: at p the others carry weights 1 − w0, and the blend is their weighted mean.
  g.valid[g.index(0, 0, 0)] = 0;
  const glm::vec3 p(0.75f, 0.75f, 0.75f);  // t = (0.25, 0.25, 0.25): w0 = 0.75³
  const ProbeBlend blend = interpolateProbes(g, p);
  const float w0 = 0.421875f;
  EXPECT_EQ(blend.probes, 7);
  EXPECT_NEAR(blend.weight, 1.0f - w0, 1e-5f);
  EXPECT_NEAR(blend.coefficients[0].x, (f(p) - w0 * f(g.position(g.index(0, 0, 0)))) / (1.0f - w0), 1e-5f);
}

TEST(LightProbes, GridFollowsTheVolumeAndRefusesTooManyProbes) {
  Bounds3 b;
  b.extend(glm::vec3(-1, 0, 0));
  b.extend(glm::vec3(3, 1, 0.5f));
  EXPECT_FLOAT_EQ(chooseProbeSpacing(b, 1024), 0.125f);  // cbrt(4 · 1 · 0.5 / 1024)
  const LightProbeGrid g = probeGridOver(b, 0.25f, 1000);
  EXPECT_EQ(g.counts, glm::ivec3(16, 4, 2));
  EXPECT_NEAR(g.origin.x, -0.875f, 1e-6f);  // half a step in from the face
  EXPECT_NEAR(g.gridPoint(15, 3, 1).z, 0.375f, 1e-6f);
  Bounds3 flat;  // a 10 × 10 m plane: its thickness held to 10/16 m
  flat.extend(glm::vec3(-5, 0, -5));
  flat.extend(glm::vec3(5, 0, 5));
  EXPECT_NEAR(chooseProbeSpacing(flat, 1024), std::cbrt(62.5 / 1024.0), 1e-6);
  EXPECT_NEAR(chooseProbeSpacing(flat, 2048), std::cbrt(62.5 / 2048.0), 1e-6);
  EXPECT_THROW(probeGridOver(b, 0.01f, 1000), Error);
  EXPECT_THROW(probeGridOver(b, 0.0f, 1000), Error);
}

TEST(LightProbes, CountsWithoutOverflowAndVolumesWithinTheSceneRange) {
  Bounds3 widest;  // 2e9 m per axis: (2e11)³ = 8e33 probes at 0.01 m, past a 64-bit integer
  widest.extend(glm::vec3(-1e9f));
  widest.extend(glm::vec3(1e9f));
  EXPECT_NEAR(probeCountOver(widest, 0.01f) / 8e33, 1.0, 1e-3);
  EXPECT_EQ(probeCountText(8.0000001e33), "8e+33");
  EXPECT_EQ(probeCountText(64000.0), "64000");
  try {
    probeGridOver(widest, 0.01f, 1 << 20);
    ADD_FAILURE() << "8e33 probes accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Usage);
    EXPECT_NE(std::string(e.what()).find("a probe spacing of 0.01 m gives 8e+33 probes (at most 1048576)"), std::string::npos) << e.what();
  }
  Bounds3 beyond;  // a corner at 1e30 m: probes there would start rays where Embree aborts
  beyond.extend(glm::vec3(0.0f));
  beyond.extend(glm::vec3(1e30f, 1.0f, 1.0f));
  EXPECT_THROW(probeGridOver(beyond, 1e6f, 1 << 20), Error);
  Bounds3 inf;
  inf.extend(glm::vec3(0.0f));
  inf.extend(glm::vec3(std::numeric_limits<float>::infinity(), 1.0f, 1.0f));
  EXPECT_THROW(probeGridOver(inf, 1.0f, 1 << 20), Error);
}

TEST(LightProbes, AutomaticCountDoublesForADirectionalLightsShadows) {
  const ProbeOptions o;
  std::vector<Light> lights;
  EXPECT_EQ(autoProbeCount(o, lights), 1024.0);
  lights.push_back(pointLight(glm::vec3(0, 2, 0), 10.0f));
  EXPECT_EQ(autoProbeCount(o, lights), 1024.0);  // a point light's shadows stay near it
  lights.push_back(directionalLight(glm::vec3(0.35f, -1, 0.2f), 5.0f));
  EXPECT_EQ(autoProbeCount(o, lights), 2048.0);
  Bounds3 sponza;  // Sponza's bounds: 17 × 9 × 8 probes at 2.06 m without a sun, 22 × 11 × 10 at 1.64 m with one
  sponza.extend(glm::vec3(-17.4028f, -0.906689f, -7.79851f));
  sponza.extend(glm::vec3(17.4172f, 15.6533f, 7.80149f));
  EXPECT_EQ(probeGridOver(sponza, chooseProbeSpacing(sponza, 1024), 1 << 20).counts, glm::ivec3(17, 9, 8));
  EXPECT_EQ(probeGridOver(sponza, chooseProbeSpacing(sponza, 2048), 1 << 20).counts, glm::ivec3(22, 11, 10));
}

}  // namespace
}  // namespace irbake
