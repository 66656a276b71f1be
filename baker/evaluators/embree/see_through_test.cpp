// See-through surfaces against closed forms: a pane of BLEND α = 0.5 halves a point
// light's irradiance behind it, a red pane lets red light through, KHR_materials_transmission passes its
// factor; MASK holes let the light through where the texture says so. Embree backend and reference.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "evaluators/embree/embree_backend.h"
#include "common/maths.h"
#include "evaluators/reference/reference_integrator.h"
#include "vpl/vpl.h"
#include "testing/scenes.h"

namespace irbake {
namespace {
using namespace testing;

// A black floor (z = 0) under a 1 m pane at z = 1 and a point light of 4 W/sr at z = 2: under the pane
// the floor gets T · I / r² / π (the pane's own reflection goes up, the floor reflects nothing).
struct PaneScene {
  Scene scene;
  std::unique_ptr<RayTracer> rt;
  std::vector<TexelSamples> pages;
  PaneScene(glm::vec4 paneColour, AlphaMode mode, float transmission = 0.0f) {
    addQuad(scene, addMaterial(scene, glm::vec3(0.0f)), {-2, -2, 0}, {4, 0, 0}, {0, 4, 0}, 2);
    const int pane = addMaterial(scene, glm::vec3(paneColour));
    scene.materials[pane].baseColorFactor.a = paneColour.a;
    scene.materials[pane].alphaMode = mode;
    scene.materials[pane].transmission = transmission;
    addQuad(scene, pane, {-0.5f, -0.5f, 1}, {1, 0, 0}, {0, 1, 0});
    scene.lights.push_back(pointLight({0, 0, 2}, 4.0f));
    rt = std::make_unique<RayTracer>(scene);
    pages.push_back(gridSamples({-0.2f, -0.2f, 0}, {0.4f, 0, 0}, {0, 0.4f, 0}, 8, 8, 0));  // under the pane
  }
  // The floor's mean map value over the grid with the Embree backend (direct + VPLs).
  glm::dvec3 embreeMean(int paths) {
    WalkOptions w;
    w.paths = paths;
    const VplSet vpls = generateVpls(scene, *rt, w);
    BakeInputs in{scene, *rt, pages, vpls, VplEvalOptions{}, {}};
    const std::vector<Lightmap> maps = bakeEmbree(in);
    glm::dvec3 sum(0.0);
    for (const glm::vec3& v : maps[0].texels) sum += glm::dvec3(v);
    return sum / static_cast<double>(maps[0].size());
  }
  // The unshadowed closed form I cosθ / (π r²) averaged over the same grid.
  double openMean() const {
    double sum = 0.0;
    for (size_t i = 0; i < pages[0].layerSize(); ++i) {
      const glm::vec3 x(pages[0].positionWeight[i]);
      const glm::vec3 d = glm::vec3(0, 0, 2) - x;
      const double r2 = glm::dot(d, d);
      sum += 4.0 * (2.0 / std::sqrt(r2)) / (r2 * kPi);
    }
    return sum / static_cast<double>(pages[0].layerSize());
  }
};

TEST(SeeThrough, BlendPaneOfAlphaHalfHalvesTheIrradiance) {
  PaneScene s({1, 1, 1, 0.5f}, AlphaMode::Blend);
  const glm::dvec3 m = s.embreeMean(256);
  const double open = s.openMean();
  std::printf("[ figure ] α = 0.5 pane: %.5f of the open value (exact 0.5)\n", m.x / open);
  EXPECT_NEAR(m.x / open, 0.5, 1e-4);
  EXPECT_NEAR(m.z / open, 0.5, 1e-4);
}

TEST(SeeThrough, RedPaneGivesRedLight) {
  PaneScene s({1, 0, 0, 0.5f}, AlphaMode::Blend);
  const glm::dvec3 m = s.embreeMean(256);
  const double open = s.openMean();
  EXPECT_NEAR(m.x / open, 0.5, 1e-4);
  EXPECT_NEAR(m.y, 0.0, 1e-9);
  EXPECT_NEAR(m.z, 0.0, 1e-9);
}

TEST(SeeThrough, TransmissionFactorPassesThatFraction) {
  PaneScene s({0.9f, 0.9f, 0.9f, 1.0f}, AlphaMode::Opaque, 0.8f);
  const glm::dvec3 m = s.embreeMean(256);
  EXPECT_NEAR(m.y / s.openMean(), 0.8 * 0.9, 1e-4);
}

// The reference integrator, through the same pane (its hemisphere paths pass it stochastically).
TEST(SeeThrough, ReferenceAgreesThroughAPane) {
  PaneScene s({1, 0.5f, 0.25f, 0.4f}, AlphaMode::Blend);
  VplSet none;
  BakeInputs in{s.scene, *s.rt, s.pages, none, VplEvalOptions{}, {}};
  ReferenceOptions ro;
  ro.spp = 64;
  const std::vector<Lightmap> ref = bakeReference(in, ro);
  glm::dvec3 sum(0.0);
  for (const glm::vec3& v : ref[0].texels) sum += glm::dvec3(v);
  sum /= static_cast<double>(ref[0].size());
  const double open = s.openMean();
  EXPECT_NEAR(sum.x / open, 0.6, 1e-3);
  EXPECT_NEAR(sum.y / open, 0.3, 1e-3);
  EXPECT_NEAR(sum.z / open, 0.15, 1e-3);
}

// The walk's paths cross a pane: a closed grey box with a pane across its middle keeps its energy
// (transmitted light is no bounce and no loss beyond the tint).
TEST(SeeThrough, WalkThroughAClearPaneKeepsTheEnergy) {
  Scene scene;
  addBox(scene, addMaterial(scene, glm::vec3(0.5f), glm::vec3(1.0f)), glm::vec3(0), glm::vec3(1), true, 2);
  const int pane = addMaterial(scene, glm::vec3(1.0f));
  scene.materials[pane].transmission = 1.0f;  // clear: everything passes, white tint
  addQuad(scene, pane, {0, 0, 0.5f}, {1, 0, 0}, {0, 1, 0});
  RayTracer rt(scene);
  WalkOptions w;
  w.paths = 1024;
  w.maxBounces = 6;
  const VplSet set = generateVpls(scene, rt, w);
  const double Phi = kPi * 6.0;
  for (int j = 0; j <= 6; ++j) EXPECT_NEAR(set.powerPerBounce[j].x, Phi * std::pow(0.5, j), 1e-4 * Phi) << j;
}

}  // namespace
}  // namespace irbake
