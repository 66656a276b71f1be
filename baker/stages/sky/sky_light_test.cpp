// The sky's direct light against closed forms: an open plane under a uniform sky gets L
// exactly, a closed box nothing, a floor beside a long wall the view-factor answer, an environment whose
// power sits in one texel what a sun of the same irradiance gives; the walk's sky paths carry the
// sky's power onto the scene.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "evaluators/embree/embree_backend.h"
#include "stages/sky/sky_light.h"
#include "vpl/light_sources.h"
#include "vpl/vpl.h"
#include "testing/scenes.h"

namespace irbake {
namespace {

using namespace testing;
constexpr double kPi = 3.14159265358979323846;

struct SkyFixture {
  Scene scene;
  std::unique_ptr<RayTracer> rt;
  std::vector<TexelSamples> pages;
  VplSet none;
  BakeInputs inputs() { return BakeInputs{scene, *rt, pages, none, VplEvalOptions{}, {}}; }
};

std::vector<Lightmap> blankMaps(const std::vector<TexelSamples>& pages) {
  std::vector<Lightmap> maps;
  for (const TexelSamples& ts : pages) {
    maps.push_back(blankLightmap(ts));
    maps.back().valid = ts.valid;
  }
  return maps;
}

TEST(SkyLight, OpenPlaneUnderAUniformSkyGetsExactlyL) {
  SkyFixture f;
  addQuad(f.scene, addMaterial(f.scene, glm::vec3(0.5f)), {-2, -2, 0}, {4, 0, 0}, {0, 4, 0});
  f.scene.environment = Environment::uniform({0.8f, 1.0f, 1.3f});
  f.rt = std::make_unique<RayTracer>(f.scene);
  f.pages.push_back(gridSamples({-2, -2, 0}, {4, 0, 0}, {0, 4, 0}, 16, 16, 0));
  std::vector<Lightmap> maps = blankMaps(f.pages);
  SkyLightStats st;
  addSkyLight(f.inputs(), maps, {}, &st);
  size_t n = 0;
  for (size_t i = 0; i < maps[0].size(); ++i)
    if (maps[0].valid[i]) {
      ++n;
      // Exact up to the float rounding of the surface filter's mean of 49 equal values (≈ 5 ulp).
      ASSERT_NEAR(maps[0].texels[i].x, 0.8f, 1e-6f) << i;
      ASSERT_NEAR(maps[0].texels[i].y, 1.0f, 1e-6f) << i;
      ASSERT_NEAR(maps[0].texels[i].z, 1.3f, 2e-6f) << i;
    }
  EXPECT_EQ(n, 256u);
  EXPECT_GT(st.rays, 0u);
}

TEST(SkyLight, ClosedBoxUnderASkyIsDarkInside) {
  SkyFixture f;
  addBox(f.scene, addMaterial(f.scene, glm::vec3(0.7f)), glm::vec3(0), glm::vec3(1), true, 2);
  f.scene.environment = Environment::uniform(glm::vec3(5.0f));
  f.rt = std::make_unique<RayTracer>(f.scene);
  f.pages.push_back(gridSamples({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 12, 12, 0));  // the floor, facing +z
  std::vector<Lightmap> maps = blankMaps(f.pages);
  addSkyLight(f.inputs(), maps);
  for (size_t i = 0; i < maps[0].size(); ++i) ASSERT_EQ(maps[0].texels[i], glm::vec3(0.0f)) << i;
  // ...and the walk places no VPL inside: every sky path hits the box's outside (its back faces).
  WalkOptions w;
  w.paths = 256;
  const VplSet set = generateVpls(f.scene, *f.rt, w);
  for (const Vpl& v : set.vpls) {
    const bool inside = v.position.x > 0.01f && v.position.x < 0.99f && v.position.y > 0.01f && v.position.y < 0.99f &&
                        v.position.z > 0.01f && v.position.z < 0.99f;
    ASSERT_FALSE(inside);
  }
}

// A floor beside a wall of height h, long in y: the wall hides (1 − d/√(d² + h²))/2 of the cosine-weighted
// sky at distance d (view factor from a strip element to a parallel infinite strip, Hottel's crossed
// strings); the rest arrives, so map = L (1 + d/√(d² + h²))/2.
TEST(SkyLight, FloorBesideALongWallMatchesTheViewFactor) {
  SkyFixture f;
  const int black = addMaterial(f.scene, glm::vec3(0.0f));
  const float h = 2.0f;
  addQuad(f.scene, black, {0, -200, 0}, {10, 0, 0}, {0, 400, 0});  // floor x ∈ [0, 10]
  addQuad(f.scene, black, {0, -200, 0}, {0, 400, 0}, {0, 0, h});   // wall x = 0, facing +x
  f.scene.environment = Environment::uniform(glm::vec3(1.0f));
  f.rt = std::make_unique<RayTracer>(f.scene);
  BakeInputs in = f.inputs();
  for (float d : {0.25f, 1.0f, 3.0f}) {
    const glm::vec3 v = skyLightAt(in, {d, 0.0f, 0.0f}, {0, 0, 1}, 8192, 0.37, 0.61);
    const double exact = skyFractionBesideWall(d, h);
    std::printf("[ figure ] floor %.2f m from a %.0f m wall: sky %.5f, view factor %.5f\n", d, h, v.x, exact);
    EXPECT_NEAR(v.x, exact, 0.005 * exact) << d;
  }
}

// The same floor with few rays and a 5×5 filter: with the lattices of a filter window interleaved
// (sample_lattice.h) the texels' error against the view factor is well below that of independent rotations,
// and neither is biased.
TEST(SkyLight, InterleavedLatticesBeatIndependentRotationsBesideAWall) {
  SkyFixture f;
  const int black = addMaterial(f.scene, glm::vec3(0.0f));
  const float h = 2.0f;
  addQuad(f.scene, black, {0, -1, 0}, {4, 0, 0}, {0, 2, 0});      // floor x ∈ [0, 4], y ∈ [−1, 1]
  addQuad(f.scene, black, {0, -20, 0}, {0, 40, 0}, {0, 0, h});    // wall x = 0, facing +x, 40 m long
  f.scene.environment = Environment::uniform(glm::vec3(1.0f));
  f.rt = std::make_unique<RayTracer>(f.scene);
  f.pages.push_back(gridSamples({0, -1, 0}, {4, 0, 0}, {0, 2, 0}, 200, 100, 0));
  RelativeErrors errors[2];
  for (int interleave = 0; interleave < 2; ++interleave) {
    std::vector<Lightmap> maps = blankMaps(f.pages);
    SkyLightOptions o;
    o.raysPerSample = o.minRays = 4;
    o.filterRadius = 2;
    o.interleave = interleave == 1;
    addSkyLight(f.inputs(), maps, o);
    for (size_t t = 0; t < maps[0].size(); ++t)
      if (maps[0].valid[t])
        errors[interleave].add(maps[0].texels[t].x, skyFractionBesideWall(f.pages[0].positionWeight[t].x, h));
  }
  ASSERT_EQ(errors[1].count, 20000u);
  expectInterleavingBeatsIndependent(errors);  // measured 0.0285 against 0.0420
}

// An equirectangular sky dark but for one texel of radiance Ls: the irradiance is Ls Ω cosθ (Ω the
// texel's solid angle), as from a sun of E = Ls Ω in the texel's direction; shadows included.
TEST(SkyLight, OneTexelEnvironmentMatchesTheSun) {
  const int W = 64, H = 32, tx = 40, ty = 9;
  std::vector<glm::vec3> texels(W * H, glm::vec3(0.0f));
  texels[ty * W + tx] = glm::vec3(1000.0f, 800.0f, 600.0f);
  // A floor (+Y up, the environment's convention) and a box casting a shadow on it.
  Scene s;
  const int m = addMaterial(s, glm::vec3(0.0f));
  addQuad(s, m, {-3, 0, 3}, {6, 0, 0}, {0, 0, -6}, 4);  // floor y = 0 facing +y
  addBox(s, m, {-0.5f, 0.0f, -0.5f}, {0.5f, 1.0f, 0.5f}, false);
  s.environment = Environment::fromEquirect(W, H, texels);
  RayTracer rt(s);
  std::vector<TexelSamples> none;
  VplSet noVpls;
  BakeInputs in{s, rt, none, noVpls, VplEvalOptions{}, {}};
  // The texel's centre direction and solid angle.
  const double theta = kPi * (ty + 0.5) / H, phi = 2.0 * kPi * (tx + 0.5) / W - kPi;
  const glm::vec3 toSun(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
  const double omega = (2.0 * kPi / W) * (kPi / H) * std::sin(theta);
  Scene sunScene = s;
  sunScene.environment = Environment();
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = -toSun;
  sun.color = glm::vec3(1.0f, 0.8f, 0.6f);
  sun.intensity = static_cast<float>(1000.0 * omega);
  sunScene.lights.push_back(sun);
  RayTracer sunRt(sunScene);
  BakeInputs sunIn{sunScene, sunRt, none, noVpls, VplEvalOptions{}, {}};
  Rng rng(5);
  double sumSky = 0.0, sumSun = 0.0, worst = 0.0;
  int points = 0;
  for (int i = 0; i < 200; ++i) {
    const glm::vec3 x(-2.9f + 5.8f * static_cast<float>(rng.uniform()), 0.0f, -2.9f + 5.8f * static_cast<float>(rng.uniform()));
    if (std::abs(x.x) < 0.55f && std::abs(x.z) < 0.55f) continue;  // under the box
    const glm::vec3 a = skyLightAt(in, x, {0, 1, 0}, 256, rng.uniform(), rng.uniform());
    Rng unused(1);
    const glm::vec3 b = shadePointEmbree(sunIn, x, {0, 1, 0}, unused).direct;
    sumSky += a.x;
    sumSun += b.x;
    // Away from the shadow's edge (the texel spans 5.6° × 5.6°: a penumbra the sun does not have).
    if (std::abs(a.x - b.x) > 0.02 * std::max(b.x, 1e-3f)) worst = std::max(worst, std::abs(double(a.x) - b.x));
    if (a.x > 0.0f) {
      EXPECT_NEAR(a.y / a.x, 0.8, 1e-3);  // the texel's colour
    }
    ++points;
  }
  ASSERT_GT(points, 150);
  std::printf("[ figure ] one-texel environment vs sun: mean %.5f vs %.5f (%+.2f%%)\n", sumSky / points, sumSun / points,
              100.0 * (sumSky / sumSun - 1.0));
  EXPECT_NEAR(sumSky / sumSun, 1.0, 0.02);  // shadow penumbrae of the 5.6° texel differ at a few points
}

// The walk starts paths on the sky: a sheet of albedo ρ hanging under a uniform sky L receives π L A on
// each side (the walk's surfaces reflect from both sides), so its bounce-1 VPLs carry 2 ρ π L A.
TEST(SkyLight, WalkCarriesTheSkysPowerOntoTheScene) {
  Scene s;
  const float rho = 0.5f, L = 2.0f, side = 10.0f;
  addQuad(s, addMaterial(s, glm::vec3(rho)), {-5, 0, 5}, {side, 0, 0}, {0, 0, -side});  // y = 0 facing +y
  s.environment = Environment::uniform(glm::vec3(L));
  RayTracer rt(s);
  WalkOptions w;
  w.paths = 16384;
  w.maxBounces = 1;
  const VplSet set = generateVpls(s, rt, w);
  ASSERT_GE(set.powerPerBounce.size(), 2u);
  const double expected = 2.0 * rho * kPi * L * side * side;
  std::printf("[ figure ] sky walk: bounce-1 power %.3f, expected %.3f (%+.2f%%), %zu VPLs\n", set.powerPerBounce[1].x,
              expected, 100.0 * (set.powerPerBounce[1].x / expected - 1.0), set.countPerBounce[1]);
  EXPECT_NEAR(set.powerPerBounce[1].x / expected, 1.0, 0.02);
  EXPECT_EQ(set.countPerBounce[0], 0u);  // the sky leaves no bounce-0 VPL
}

}  // namespace
}  // namespace irbake
