// The sky's part of the directional maps (addSkyLightDirectional, skyDirectionalAt) against closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "stages/sky/sky_light.h"
#include "scene/environment.h"
#include "testing/scenes.h"

using namespace irbake;
using namespace irbake::testing;

// A uniform sky L over a floor (+z) at the foot of a tall wall (the plane x = 0, facing +x): the visible sky
// is the quarter sphere x > 0, z > 0, where ∫ω_x dω = ∫ω_z dω = π/2, so g/π = L (1/2, 0, 1/2): the map is L/2
// and t = (L/2, 0, 0), pointing away from the wall. On the open floor t = 0.
TEST(SkyDirectional, WallFootQuarterSkyAndOpenFloor) {
  Scene s;
  const int grey = addMaterial(s, glm::vec3(0.0f));
  addQuad(s, grey, glm::vec3(-500, -500, 0), glm::vec3(1000, 0, 0), glm::vec3(0, 1000, 0));
  addQuad(s, grey, glm::vec3(0, -500, 0), glm::vec3(0, 1000, 0), glm::vec3(0, 0, 1000));
  const glm::vec3 L(0.4f, 0.6f, 0.8f);
  s.environment = Environment::uniform(L);
  RayTracer rt(s);
  std::vector<TexelSamples> pages = {gridSamples(glm::vec3(0.001f, -0.0005f, 0.0f), glm::vec3(0.001f, 0, 0),
                                                 glm::vec3(0, 0.001f, 0), 1, 1)};
  VplSet none;
  BakeInputs in{s, rt, pages, none, VplEvalOptions{}, {}};
  const glm::vec3 foot(0.0015f, 0.0f, 0.0f), n(0, 0, 1);
  const int rays = 4096;
  const glm::vec3 l0 = skyLightAt(in, foot, n, rays, 0.3, 0.7);
  const L1Vectors t = skyDirectionalAt(in, foot, n, rays, 0.3, 0.7);
  std::printf("[ figure ] sky at a wall's foot: L0/L %.4f (exact 0.5), t_x/L %.4f (exact 0.5), t_y/L %.1e\n",
              l0.z / L.z, t[0].z / L.z, t[1].z / L.z);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(l0[c], 0.5f * L[c], 0.01f * L[c]);
    EXPECT_NEAR(t[0][c], 0.5f * L[c], 0.01f * L[c]);
    EXPECT_NEAR(t[1][c], 0.0f, 0.01f * L[c]);
    EXPECT_EQ(t[2][c], 0.0f);
  }
  {  // the floor alone
    Scene floor;
    addQuad(floor, addMaterial(floor, glm::vec3(0.0f)), glm::vec3(-500, -500, 0), glm::vec3(1000, 0, 0),
            glm::vec3(0, 1000, 0));
    floor.environment = Environment::uniform(L);
    RayTracer floorRt(floor);
    BakeInputs openIn{floor, floorRt, pages, none, VplEvalOptions{}, {}};
    const L1Vectors openT = skyDirectionalAt(openIn, glm::vec3(0.0f), n, rays, 0.3, 0.7);
    std::printf("[ figure ] sky over the open floor: |t|/L %.1e\n",
                glm::length(glm::vec3(openT[0].z, openT[1].z, openT[2].z)) / L.z);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(openT[k].z, 0.0f, 1e-3f * L.z) << k;
  }

  // Through the page: the same value (one texel, the filter has nothing to mix) added to what is there.
  std::array<std::vector<Lightmap>, 3> axes;
  for (auto& a : axes) {
    a.push_back(blankLightmap(pages[0]));
    a[0].valid.assign(1, 1);
    a[0].texels[0] = glm::vec3(1.0f);
  }
  SkyLightOptions o;
  o.raysPerSample = rays;
  addSkyLightDirectional(in, axes, o);
  EXPECT_NEAR(axes[0][0].texels[0].z, 1.0f + 0.5f * L.z, 0.01f * L.z);
  EXPECT_NEAR(axes[1][0].texels[0].z, 1.0f, 0.01f * L.z);
}
