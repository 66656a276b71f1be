#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <set>

#include "lights/light_kind.h"
#include "vpl/light_sources.h"
#include "sampling/sampling.h"
#include "vpl/vpl.h"
#include "testing/scenes.h"

using namespace irbake;
using namespace irbake::testing;

namespace {

double sumPower(const VplSet& set, int fromBounce = 0) {
  double s = 0.0;
  for (const Vpl& v : set.vpls)
    if (v.bounce >= fromBounce) s += channelMean(glm::dvec3(v.power));
  return s;
}
}  // namespace

TEST(MeanReflectivity, AreaWeighted) {
  Scene s;
  int a = addMaterial(s, glm::vec3(0.2f)), b = addMaterial(s, glm::vec3(0.8f, 0.5f, 0.2f));
  addQuad(s, a, glm::vec3(0), glm::vec3(3, 0, 0), glm::vec3(0, 1, 0));  // area 3, ρ 0.2
  addQuad(s, b, glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1));  // area 1, largest channel 0.8
  EXPECT_NEAR(meanReflectivity(s), (3 * 0.2 + 1 * 0.8) / 4.0, 1e-7);
}

// Closed grey room: every path stays inside, so the bookkeeping must give exactly Φ Σ_j ρ̄^j.
TEST(Walk, EnergyOfAreaEmitterWalkIsExactInAClosedRoom) {
  Scene s;
  int wall = addMaterial(s, glm::vec3(0.6f));
  int lamp = addMaterial(s, glm::vec3(0.6f), glm::vec3(3.0f));
  addBox(s, wall, glm::vec3(0), glm::vec3(2, 1.5f, 1), true, 2);
  addQuad(s, lamp, glm::vec3(0.8f, 0.6f, 0.999f), glm::vec3(0.4f, 0, 0), glm::vec3(0, 0.3f, 0));  // faces up...
  s.primitives.back().indices = {0, 2, 1, 0, 3, 2};  // ...flipped to face down into the room
  RayTracer rt(s);
  WalkOptions o;
  o.paths = 1000;
  o.geometricTail = false;  // the bounces as walked; the tail has its own test
  VplSet set = generateVpls(s, rt, o);
  double rho = set.meanReflectivity;
  EXPECT_NEAR(rho, 0.6, 1e-6);
  double Phi = kPi * 3.0 * 0.4 * 0.3;
  EXPECT_NEAR(set.emittedPower.x, Phi, 1e-5 * Phi);
  ASSERT_GE(set.bounces, 5);
  double expected = 0.0;
  for (int j = 0; j <= set.bounces; ++j) {
    expected += Phi * std::pow(rho, j);
    EXPECT_EQ(set.countPerBounce[j], static_cast<size_t>(std::floor(1000 * std::pow(rho, j) + 1e-9))) << "bounce " << j;
    EXPECT_NEAR(set.powerPerBounce[j].x, Phi * std::pow(rho, j), 1e-6 * Phi) << "bounce " << j;
  }
  EXPECT_NEAR(sumPower(set), expected, 1e-6 * expected);
  EXPECT_EQ(set.bounces, static_cast<int>(std::floor(std::log(1000.0) / -std::log(0.6) + 1e-9)));
  for (const Vpl& v : set.vpls) {  // VPLs lie inside the room, facing into it
    ASSERT_GE(v.position.x, -1e-4f);
    ASSERT_LE(v.position.z, 1.0f + 1e-4f);
    if (v.position.z > 0.99f) continue;  // the lamp's back and the ceiling above it face each other
    glm::vec3 toCentre = glm::vec3(1, 0.75f, 0.5f) - v.position;
    ASSERT_GT(glm::dot(toCentre, v.normal), 0.0f);
  }
}

// Every face emits: quasi-random start points land exactly on cube edges and corners (Halton index 0
// is a vertex). Without insetting those points, paths escape through the corners and energy is lost.
TEST(Walk, EnergyIsExactWhenStartsLieOnEdges) {
  for (float rho : {0.5f, 0.9f}) {
    Scene s;
    addBox(s, addMaterial(s, glm::vec3(rho), glm::vec3(1.0f)), glm::vec3(0), glm::vec3(1), true, 2);
    RayTracer rt(s);
    WalkOptions o;
    o.paths = 1024;
    o.tailEnergy = 0.0;       // walk until ρ̄^j N < 1
    o.maxVplsPerPath = 1e9;
    o.geometricTail = false;
    VplSet set = generateVpls(s, rt, o);
    double Phi = kPi * 6.0, expected = 0.0;
    for (int j = 0; j <= set.bounces; ++j) expected += Phi * std::pow(double(rho), j);
    EXPECT_NEAR(sumPower(set), expected, 1e-6 * expected) << "rho " << rho;
    EXPECT_EQ(set.bounces, static_cast<int>(std::floor(std::log(1024.0) / -std::log(double(rho)) + 1e-9)));
  }
}

// The auto depth: the energy rule, the VPL budget, and the survivor rule, each where it binds.
TEST(Walk, AutoBounceDepthFollowsEnergyAndBudget) {
  WalkOptions o;  // tailEnergy 1e-3, budget 8 VPLs per path
  // ρ̄ = 0.5: 0.5^9 = 2.0e-3 ≥ 1e-3 > 0.5^10; the budget (Σ ≤ 2N) never binds.
  EXPECT_EQ(autoBounceDepth(1024, 0.5, o), 9);
  // ρ̄ = 0.9: Σ_{j≤J} 0.9^j ≤ 8 ⇔ 1 − 0.9^(J+1) ≤ 0.8 ⇔ J ≤ 14.3 (survivor floors shift it by < 1 path).
  EXPECT_EQ(autoBounceDepth(1 << 20, 0.9, o), 14);
  // ρ̄ = 0.99: Σ 0.99^j ≤ 8 ⇔ J ≤ 7.3.
  EXPECT_EQ(autoBounceDepth(1 << 20, 0.99, o), 7);
  // Few paths: ⌊N ρ̄^J⌋ ≥ 1 binds first (4 · 0.5^2 = 1).
  EXPECT_EQ(autoBounceDepth(4, 0.5, o), 2);
  o.maxVplsPerPath = 1e9;
  o.tailEnergy = 0.0;
  EXPECT_EQ(autoBounceDepth(1024, 0.9, o), static_cast<int>(std::floor(std::log(1024.0) / -std::log(0.9) + 1e-9)));
}

TEST(Walk, GeometricTailFactorIsOneOverOneMinusRatio) {
  const glm::dvec3 f = geometricTailFactor(glm::dvec3(0.9, 0.5, 0.0), glm::dvec3(1.0, 1.0, 1.0));
  EXPECT_NEAR(f.x, 10.0, 1e-9);
  EXPECT_NEAR(f.y, 2.0, 1e-9);
  EXPECT_NEAR(f.z, 1.0, 1e-12);  // nothing left in that channel
  EXPECT_NEAR(geometricTailFactor(glm::dvec3(2.0), glm::dvec3(1.0)).x, 1000.0, 1e-6);  // r clamped to 0.999
}

// A trap: the few paths alive at depth stay among bright surfaces, so their bounces do not decay (here
// one VPL per bounce from bounce 6 on, each as bright as all of bounce 5), while every bounce many paths
// reach halves. The tail must follow the populated bounces (r = 1/2: P_J r/(1 − r) = P_J), not the
// deep path, whose r = 1 would have multiplied its VPLs by about 1000 (r is clamped at 0.999).
TEST(Walk, TailRatioComesFromBouncesManyPathsReach) {
  VplSet set;
  const size_t counts[] = {0, 1024, 512, 256, 128, 64, 1, 1, 1, 1, 1, 1, 1};
  const double powers[] = {0, 64, 32, 16, 8, 4, 4, 4, 4, 4, 4, 4, 4};
  set.emittedPower = glm::dvec3(128.0);
  for (int j = 0; j <= 12; ++j) {
    set.countPerBounce.push_back(counts[j]);
    set.powerPerBounce.push_back(glm::dvec3(powers[j]));
    for (size_t k = 0; k < counts[j]; ++k)
      set.vpls.push_back(Vpl{glm::vec3(0.0f), glm::vec3(0, 1, 0), glm::vec3(float(powers[j] / counts[j])), j});
  }
  set.bounces = 12;
  addGeometricTail(set);
  // Carriers: bounces 6…12 (⌈12/2⌉ = 6), power 7 · 4 = 28; tail P_12 · 1 = 4.
  EXPECT_NEAR(set.tailFactor.x, 1.0 + 4.0 / 28.0, 1e-9);
  EXPECT_NEAR(sumPower(set), 64 + 32 + 16 + 8 + 4 + 28 + 4, 1e-4);
  // With the deep bounces populated (the furnace case) the pool is the deeper half itself.
  VplSet furnace;
  furnace.emittedPower = glm::dvec3(1.0);
  for (int j = 0; j <= 8; ++j) {
    furnace.countPerBounce.push_back(j == 0 ? 0 : 1024);
    furnace.powerPerBounce.push_back(glm::dvec3(j == 0 ? 1.0 : std::pow(0.8, j)));
    if (j > 0)
      for (int k = 0; k < 1024; ++k)
        furnace.vpls.push_back(Vpl{glm::vec3(0.0f), glm::vec3(0, 1, 0), glm::vec3(float(std::pow(0.8, j) / 1024)), j});
  }
  furnace.bounces = 8;
  addGeometricTail(furnace);
  double carriers = 0.0;
  for (int j = 4; j <= 8; ++j) carriers += std::pow(0.8, j);
  EXPECT_NEAR(furnace.tailFactor.x, 1.0 + std::pow(0.8, 8) * 4.0 / carriers, 1e-6);  // r = 0.8: r/(1 − r) = 4
}

// High-albedo furnaces: the auto walk stops at the VPL budget and adds the rest as a geometric tail;
// in a closed grey box every bounce is the previous one times ρ, so the total is Φ/(1−ρ) exactly.
TEST(Walk, TailMakesHighAlbedoFurnaceEnergyExact) {
  for (float rho : {0.9f, 0.99f}) {
    Scene s;
    addBox(s, addMaterial(s, glm::vec3(rho), glm::vec3(1.0f)), glm::vec3(0), glm::vec3(1), true, 2);
    RayTracer rt(s);
    WalkOptions o;
    o.paths = 1024;
    VplSet set = generateVpls(s, rt, o);
    const double Phi = kPi * 6.0, exact = Phi / (1.0 - rho);
    EXPECT_NEAR(sumPower(set), exact, 1e-5 * exact) << "rho " << rho;
    // Bounces ⌈J/2⌉…J (power Φ Σ ρ^j) also carry the tail Φ ρ^(J+1)/(1−ρ).
    const int J = set.bounces;
    double carriers = 0.0;
    for (int j = std::max(1, (J + 1) / 2); j <= J; ++j) carriers += std::pow(double(rho), j);
    EXPECT_NEAR(set.tailFactor.x, 1.0 + std::pow(double(rho), J + 1) / (1.0 - rho) / carriers, 1e-4) << "rho " << rho;
    EXPECT_LE(static_cast<double>(set.vpls.size()), o.maxVplsPerPath * o.paths);
    std::printf("[ figure ] furnace walk rho=%.2f: %d bounces, %zu VPLs, tail factor %.2f, power %.6f of exact\n", rho,
                set.bounces, set.vpls.size(), set.tailFactor.x, sumPower(set) / exact);
  }
}

TEST(Walk, PointLightStartsAtBounceOneWithExactEnergy) {
  Scene s;
  int wall = addMaterial(s, glm::vec3(0.5f));
  addBox(s, wall, glm::vec3(-1), glm::vec3(1), true);
  s.lights.push_back(pointLight(glm::vec3(0.1f, 0.2f, 0.3f), 2.0f));
  RayTracer rt(s);
  WalkOptions o;
  o.paths = 512;
  o.maxBounces = 4;
  VplSet set = generateVpls(s, rt, o);
  double Phi = 4.0 * kPi * 2.0;
  EXPECT_EQ(set.countPerBounce[0], 0u);
  EXPECT_EQ(set.bounces, 4);
  double expected = 0.0;
  for (int j = 1; j <= 4; ++j) expected += Phi * std::pow(0.5, j);
  EXPECT_NEAR(sumPower(set), expected, 1e-6 * expected);
  EXPECT_EQ(set.countPerBounce[1], 256u);
  EXPECT_EQ(set.countPerBounce[4], 32u);
}

TEST(Walk, BounceVplsCarryTheTexturedAlbedoAtTheirHit) {
  Scene s;
  int lamp = addMaterial(s, glm::vec3(0.0f), glm::vec3(1.0f));
  int floor = addMaterial(s, glm::vec3(1.0f));
  Texture t;
  t.width = 2;
  t.height = 1;
  t.wrapS = t.wrapT = WrapMode::ClampToEdge;
  t.texels = {glm::vec4(0.9f, 0.3f, 0.1f, 1.0f), glm::vec4(0.1f, 0.3f, 0.9f, 1.0f)};
  s.textures.push_back(t);
  s.materials[floor].baseColorTexture = 0;
  addQuad(s, lamp, glm::vec3(-0.5f, -0.5f, 1), glm::vec3(0, 1, 0), glm::vec3(1, 0, 0));  // faces down
  addQuad(s, floor, glm::vec3(-5, -5, 0), glm::vec3(10, 0, 0), glm::vec3(0, 10, 0));
  RayTracer rt(s);
  WalkOptions o;
  o.paths = 256;
  o.maxBounces = 1;
  VplSet set = generateVpls(s, rt, o);
  ASSERT_EQ(set.countPerBounce.size(), 2u);
  double Phi = kPi * 1.0 * 1.0;
  size_t M1 = static_cast<size_t>(std::floor(256 * set.meanReflectivity));
  ASSERT_GT(set.countPerBounce[1], 0u);
  for (const Vpl& v : set.vpls) {
    if (v.bounce != 1) continue;
    glm::vec2 uv((v.position.x + 5) / 10, (v.position.y + 5) / 10);
    glm::vec3 albedo(sampleBilinear(t, uv));
    EXPECT_NEAR(v.power.x, Phi * albedo.x / M1, 1e-4 * Phi / M1);
    EXPECT_NEAR(v.power.z, Phi * albedo.z / M1, 1e-4 * Phi / M1);
    EXPECT_NEAR(v.position.z, 0.0f, 1e-5f);
  }
}

// glTF's range in the walk: a path leaving a point light I at height h over a wide floor (ρ) carries the light's
// window w(d) = clamp(1 − (d/R)⁴, 0, 1)² to its first hit, as the direct term does (Light::rangeWindow). So the
// first bounce holds ρ times the windowed flux onto the floor, 2π I ∫ from a to 1 of (1 − (a/μ)⁴)² dμ with a = h/R
// (μ = cos of the angle from the downward vertical) = 2π I ((1 − a) + (2/3)(a⁴ − a) − (1/7)(a⁸ − a)), and no
// VPL lies at or beyond the range.
TEST(Walk, FirstHitsOfALightWithARangeCarryItsWindow) {
  Scene s;
  const float rho = 0.5f, I = 3.0f, h = 1.0f, R = 2.0f;
  const int floor = addMaterial(s, glm::vec3(rho));
  addQuad(s, floor, glm::vec3(-5, 0, 5), glm::vec3(10, 0, 0), glm::vec3(0, 0, -10));  // faces +y
  Light l = pointLight(glm::vec3(0, h, 0), I);
  l.range = R;
  s.lights.push_back(l);
  RayTracer rt(s);
  WalkOptions o;
  o.paths = 8192;
  o.maxBounces = 1;
  const VplSet set = generateVpls(s, rt, o);
  const double a = h / R;
  const double flux = 2.0 * kPi * I * ((1.0 - a) + 2.0 / 3.0 * (std::pow(a, 4) - a) - (std::pow(a, 8) - a) / 7.0);
  // Before the window, every first-bounce VPL carries ρ Φ / M₁: Φ = 4π I, M₁ = N ρ̄ paths reach bounce 1.
  const double perVpl = rho * 4.0 * kPi * I / (o.paths * double(rho));
  double firstBounce = 0.0;
  size_t n = 0;
  for (const Vpl& v : set.vpls) {
    if (v.bounce != 1) continue;
    const float d = glm::length(v.position - l.position);
    EXPECT_LT(d, R);
    // (1e-3: the VPL sits inset from its hit by the ray tracer's epsilon, and the window falls by at most 2.42/R
    // per metre)
    EXPECT_NEAR(v.power.x, perVpl * l.rangeWindow(d), 1e-3 * perVpl) << "at " << d << " m";
    firstBounce += v.power.x;
    ++n;
  }
  std::printf("[ figure ] walk under a light with a range: first bounce %.5f W, closed form %.5f W (%zu VPLs)\n",
              firstBounce, rho * flux, n);
  EXPECT_GT(n, 500u);
  EXPECT_NEAR(firstBounce, rho * flux, 0.01 * rho * flux);
}

TEST(Walk, SpotPathsFollowTheFalloffAndDirectionalCoversTheScene) {
  Scene s;
  int wall = addMaterial(s, glm::vec3(0.5f));
  addBox(s, wall, glm::vec3(-2), glm::vec3(2), true, 2);
  Light spot;
  spot.type = LightType::Spot;
  spot.position = glm::vec3(0, 0, 1.5f);
  spot.direction = glm::vec3(0, 0, -1);
  spot.innerConeAngle = 0.3f;
  spot.outerConeAngle = 0.6f;
  s.lights.push_back(spot);
  RayTracer rt(s);
  WalkOptions o;
  o.paths = 4096;
  o.maxBounces = 1;
  VplSet set = generateVpls(s, rt, o);
  double cosO = std::cos(0.6), cosI = std::cos(0.3);
  double inner = (1 - cosI) / ((1 - cosI) + (cosI - cosO) / 3.0);
  int in = 0, n = 0;
  for (const Vpl& v : set.vpls) {
    glm::vec3 d = glm::normalize(v.position - spot.position);
    ASSERT_GE(-d.z, cosO - 1e-4);
    in += -d.z >= cosI;
    ++n;
  }
  EXPECT_NEAR(double(in) / n, inner, 0.01);
  EXPECT_NEAR(set.emittedPower.x, lightKind(spot).power(spot).x, 1e-5);

  // Directional light onto an open floor: the flux reaching the floor is I · area (the disc covers it).
  Scene d;
  int f = addMaterial(d, glm::vec3(0.5f));
  addQuad(d, f, glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  d.lights.push_back(directionalLight(glm::vec3(0.3f, 0.0f, -1.0f), 2.0f));
  RayTracer rt2(d);
  o.paths = 8192;
  VplSet ds = generateVpls(d, rt2, o);
  // Bounce-1 power = albedo · (flux onto the floor) = 0.5 · I cosθ · 4.
  double expected = 0.5 * 2.0 * (1.0 / std::sqrt(1.09)) * 4.0;
  EXPECT_NEAR(sumPower(ds, 1), expected, 0.01 * expected);
}

namespace {
// An open-topped grey box (floor and four walls, 4 × 4 × 1.5, inward) under a tilted sun: light leaving
// the floor mostly escapes through the top, so few paths reach bounce 2 and beyond.
Scene courtyard(float rho) {
  Scene s;
  const int grey = addMaterial(s, glm::vec3(rho));
  const glm::vec3 lo(0.0f), hi(4.0f, 4.0f, 1.5f);
  addBox(s, grey, lo, hi, true, 2);
  s.primitives.erase(s.primitives.begin() + 1);  // addBox adds bottom, top, then the walls: drop the top
  s.lights.push_back(directionalLight(glm::vec3(0.3f, 0.2f, -1.0f), 2.0f));
  return s;
}
}  // namespace

// Splitting where paths leave bounce 1 keeps the bookkeeping exact: in a closed room each surviving path
// leaves s VPLs per deeper bounce of 1/s of the power, so bounce j still carries exactly Φ ρ̄^j.
TEST(Walk, SplitPathsKeepEveryBouncesEnergyExact) {
  Scene s;
  addBox(s, addMaterial(s, glm::vec3(0.6f), glm::vec3(1.0f)), glm::vec3(0), glm::vec3(1), true, 2);
  RayTracer rt(s);
  WalkOptions o;
  o.paths = 1000;
  o.geometricTail = false;
  o.split = 4;
  const VplSet set = generateVpls(s, rt, o);
  EXPECT_EQ(set.split, 4);
  const double Phi = set.emittedPower.x;
  ASSERT_GE(set.bounces, 5);
  for (int j = 0; j <= set.bounces; ++j) {
    const size_t m = static_cast<size_t>(std::floor(1000 * std::pow(0.6, j) + 1e-9));
    EXPECT_EQ(set.countPerBounce[j], j >= 2 ? 4 * m : m) << "bounce " << j;
    EXPECT_NEAR(set.powerPerBounce[j].x, Phi * std::pow(0.6, j), 1e-5 * Phi) << "bounce " << j;
  }
  // Auto in a closed room: every path leaving bounce 1 meets the room again, so no split.
  o.split.reset();
  const VplSet autoSet = generateVpls(s, rt, o);
  EXPECT_EQ(autoSet.split, 1);
  EXPECT_NEAR(autoSet.rehitFraction, 1.0, 0.02);
  // A least auto split (the bake plan's without the final gather) forks the closed room's paths too, with
  // every bounce's energy still exact.
  o.minAutoSplit = 2;
  const VplSet least = generateVpls(s, rt, o);
  EXPECT_EQ(least.split, 2);
  for (int j = 0; j <= least.bounces && j <= 5; ++j) {
    const size_t m = static_cast<size_t>(std::floor(1000 * std::pow(0.6, j) + 1e-9));
    EXPECT_EQ(least.countPerBounce[j], j >= 2 ? 2 * m : m) << "bounce " << j;
    EXPECT_NEAR(least.powerPerBounce[j].x, Phi * std::pow(0.6, j), 1e-5 * Phi) << "bounce " << j;
  }
}

// In an open court the auto split is 1 / (share of bounce-1 light meeting the scene again), and the split
// walk estimates the same deep bounces as a plain walk with many more paths (unbiased: the mean over 8
// seeds), with s times as many VPLs carrying them and less spread from seed to seed.
TEST(Walk, AutoSplitInAnOpenCourtMatchesAPlainWalkOfManyPaths) {
  const Scene s = courtyard(0.7f);
  RayTracer rt(s);
  WalkOptions o;
  o.paths = 4096;
  o.maxBounces = 6;  // the same bounces walked in all, no tail
  const VplSet first = generateVpls(s, rt, o);
  EXPECT_LT(first.rehitFraction, 0.5);
  EXPECT_EQ(first.split, std::clamp(static_cast<int>(std::floor(1.0 / first.rehitFraction)), 1, o.maxAutoSplit));
  ASSERT_GE(first.split, 2);
  constexpr int kSeeds = 8;
  std::array<double, 4> splitMean{}, spread{};
  for (int seed = 0; seed < kSeeds; ++seed) {
    o.seed = static_cast<uint32_t>(seed);
    o.split.reset();
    const VplSet split = generateVpls(s, rt, o);
    o.split = 1;
    const VplSet unsplit = generateVpls(s, rt, o);
    EXPECT_EQ(split.countPerBounce[1], unsplit.countPerBounce[1]);
    EXPECT_GE(split.countPerBounce[2], static_cast<size_t>(split.split - 1) * unsplit.countPerBounce[2]);
    for (int j = 1; j <= 3; ++j) {
      splitMean[j] += split.powerPerBounce[j].x / kSeeds;
      spread[j] += split.powerPerBounce[j].x * split.powerPerBounce[j].x / kSeeds;
    }
  }
  WalkOptions plainOptions = o;
  plainOptions.paths = 4096 * 64;
  plainOptions.split = 1;
  plainOptions.seed = 99;
  const VplSet plain = generateVpls(s, rt, plainOptions);
  for (int j = 1; j <= 3; ++j) {
    const double a = splitMean[j], b = plain.powerPerBounce[j].x;
    std::printf("[ figure ] open court, split %d: bounce %d %.5g W over %d seeds, plain walk of 64x the paths %.5g W "
                "(ratio %.4f)\n", first.split, j, a, kSeeds, b, a / b);
    EXPECT_NEAR(a / b, 1.0, j == 1 ? 0.01 : 0.04) << "bounce " << j;
  }
  // Seed-to-seed spread of bounce 3 (RMS about the plain walk's value): the split walk's is smaller.
  const double b3 = plain.powerPerBounce[3].x;
  const double splitRms = std::sqrt(std::max(0.0, spread[3] - 2 * b3 * splitMean[3] + b3 * b3)) / b3;
  std::printf("[ figure ] bounce 3 seed-to-seed spread: split %.2f%%\n", 100 * splitRms);
  EXPECT_LT(splitRms, 0.06);
}

// Budgets follow the light that reaches the scene: a sun 10^4 times the lamp's power that only meets the
// outside of a closed room (the backs of its inward walls) reaches nothing, takes about 1% of the paths,
// and the room's VPLs keep the lamp's exact energy per bounce; a sky over an open floor reaches it fully.
TEST(Walk, LightThatNeverEntersTakesNoBudget) {
  Scene s;
  int wall = addMaterial(s, glm::vec3(0.6f));
  int lamp = addMaterial(s, glm::vec3(0.6f), glm::vec3(3.0f));
  addBox(s, wall, glm::vec3(0), glm::vec3(2, 1.5f, 1), true, 2);
  addQuad(s, lamp, glm::vec3(0.8f, 0.6f, 0.999f), glm::vec3(0.4f, 0, 0), glm::vec3(0, 0.3f, 0));
  s.primitives.back().indices = {0, 2, 1, 0, 3, 2};  // facing down into the room
  WalkOptions o;
  o.paths = 1000;
  o.geometricTail = false;
  const VplSet alone = generateVpls(s, RayTracer(s), o);
  s.lights.push_back(directionalLight(glm::vec3(0.2f, -0.3f, -1.0f), 1e4f));
  const VplSet withSun = generateVpls(s, RayTracer(s), o);
  ASSERT_EQ(withSun.lightReach.size(), 1u);
  EXPECT_EQ(withSun.lightReach[0], 0.0);
  const double Phi = kPi * 3.0 * 0.4 * 0.3, rho = 0.6;
  ASSERT_GE(withSun.bounces, 5);
  EXPECT_EQ(withSun.bounces, alone.bounces);
  // Inside the room (VPLs facing into it), bounce by bounce: the lamp's energy, as without the sun, within
  // the paths the sun took (≈ 1%) and their share of the lamp's Halton points. All of it: the room is closed.
  // A VPL lights the room when a step along its normal stays in the box (the lamp's back is 1 mm under
  // the ceiling: the step is shorter).
  auto facesIn = [](const Vpl& v) {
    const glm::vec3 q = v.position + 5e-4f * v.normal;
    return q.x > 0.0f && q.y > 0.0f && q.z > 0.0f && q.x < 2.0f && q.y < 1.5f && q.z < 1.0f;
  };
  auto inside = [&](const VplSet& set, int j) {
    double sum = 0.0;
    for (const Vpl& v : set.vpls)
      if (v.bounce == j && facesIn(v)) sum += v.power.x;
    return sum;
  };
  for (int j = 1; j <= 5; ++j) {
    EXPECT_NEAR(inside(alone, j), Phi * std::pow(rho, j), 1e-5 * Phi) << "bounce " << j;
    EXPECT_NEAR(inside(withSun, j), Phi * std::pow(rho, j), 0.03 * Phi * std::pow(rho, j)) << "bounce " << j;
  }
  size_t outside = 0;  // the sun's: on the walls' backs, facing away from the room
  for (const Vpl& v : withSun.vpls) outside += v.bounce == 1 && !facesIn(v);
  EXPECT_GE(outside, 1u);
  EXPECT_LE(outside, 25u);  // ≈ 1% of 1000 paths start on the sun

  Scene open;
  addQuad(open, addMaterial(open, glm::vec3(0.5f)), glm::vec3(-1, -1, 0), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));
  open.environment = Environment::uniform(glm::vec3(1.0f));
  const VplSet sky = generateVpls(open, RayTracer(open), o);
  ASSERT_EQ(sky.lightReach.size(), 1u);
  // A uniform sky through a disc covering the bounding sphere (radius √2·1.001): the one-sided floor (area
  // 4) receives from the upper half of the directions, with mean cosine 1/2 there: 1/2 · 4 · 1/2 / (π R²).
  EXPECT_NEAR(sky.lightReach[0], 0.5 * 4.0 * 0.5 / (kPi * 2.0 * 1.001 * 1.001), 0.04);
}
