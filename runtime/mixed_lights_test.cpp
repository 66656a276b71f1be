// irview's mixed lighting on real bakes (pipeline bake(), Embree backend): a 10 × 10 m plane (ρ = 0.5) under a
// point light (I = 10 W/sr at 1 m) with a 0.8 m square occluder at half height, baked twice with the same seed,
// fully baked and with the light in shadowmask mode. irview draws the shadowmask bake's light in real time
// times the mask; both are exported and loaded as irview loads them.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "common/maths.h"
#include "glcontext/gl_context.h"
#include "pipeline/bake.h"
#include "samples/sample_scenes.h"
#include "screenshot.h"
#include "mixed_lights.h"
#include "view_renderer.h"

namespace irbake::view {
namespace {

constexpr float kAlbedo = 0.5f, kIntensity = 10.0f, kHeight = 1.0f;

// makePointOverPlane plus a square occluder (x, z ∈ [−0.4, 0.4], y = 0.5, facing the light): its shadow on
// the plane is x, z ∈ [−0.8, 0.8].
Scene occludedPointOverPlane() {
  Scene s = samples::makePointOverPlane();
  Primitive occluder = s.primitives.at(0);
  occluder.name = "occluder";
  for (glm::vec3& p : occluder.positions) p = glm::vec3(p.x * 0.08f, 0.5f, p.z * 0.08f);
  s.primitives.push_back(occluder);
  return s;
}

std::filesystem::path outDir(const std::string& name) {
  const char* dir = std::getenv("IRBAKE_BINARY_DIR");
  const std::filesystem::path out = std::filesystem::path(dir ? dir : ".") / "runtime_bake_test" / "mixed" / name;
  std::filesystem::remove_all(out);
  return out;
}

// Bakes the scene with the point light in `mode` and writes it as the command does; returns the glTF.
std::filesystem::path bakeAndExport(LightMode mode, const std::string& name) {
  BakeOptions o;
  o.backend = BackendKind::Embree;
  o.atlas.texelsPerUnit = 6.0f;
  o.walk.paths = 256;
  if (mode != LightMode::Baked) o.lightModes = {{"*", mode}};
  const BakeResult baked = bake(occludedPointOverPlane(), o);
  OutputOptions out;
  out.outDir = outDir(name);
  writeBakeOutputs(baked, out);
  return out.outDir / "scene.gltf";
}

ViewCamera downView(const Bounds3& b) { return lookAt({0.3f, 3.2f, 2.6f}, {0.0f, 0.0f, -0.3f}, 70.0f, b); }

// The world point on the plane y = 0 seen through pixel (x, y), if the pixel sees it from above.
bool planeHit(const ViewCamera& cam, int w, int h, int x, int y, glm::vec3& hit) {
  const glm::mat4 inv = glm::inverse(cam.projection(float(w) / h) * cam.view());
  const glm::vec2 ndc((x + 0.5f) / w * 2 - 1, 1 - (y + 0.5f) / h * 2);
  const glm::vec4 a = inv * glm::vec4(ndc, -1, 1), b = inv * glm::vec4(ndc, 0, 1);
  const glm::vec3 origin = glm::vec3(a) / a.w, d = glm::vec3(b) / b.w - origin;
  if (d.y >= 0) return false;
  hit = origin + d * (-origin.y / d.y);
  return std::abs(hit.x) < 5.0f && std::abs(hit.z) < 5.0f;
}

// The exports record the light for the client: the shadowmask bake with its channel, the indirect bake
// without one (extras.irbake.mode on the KHR light), the baked one not at all.
TEST(MixedLights, ExportsRecordTheLightsLeftToTheClient) {
  const ViewerScene baked = loadViewerScene(bakeAndExport(LightMode::Baked, "record_baked"));
  const ViewerScene masked = loadViewerScene(bakeAndExport(LightMode::ShadowMask, "record_mask"));
  const ViewerScene indirect = loadViewerScene(bakeAndExport(LightMode::Indirect, "record_indirect"));
  EXPECT_TRUE(baked.scene.runtimeLights.empty());
  ASSERT_EQ(masked.scene.runtimeLights.size(), 1u);
  EXPECT_EQ(masked.scene.runtimeLights[0].maskChannel, 0);
  EXPECT_EQ(masked.scene.runtimeLights[0].mode, LightMode::ShadowMask);
  for (const Material& m : masked.scene.materials) EXPECT_GE(m.shadowMaskTexture, 0) << m.name;
  ASSERT_EQ(indirect.scene.runtimeLights.size(), 1u);
  EXPECT_EQ(indirect.scene.runtimeLights[0].maskChannel, -1);
  EXPECT_EQ(indirect.scene.runtimeLights[0].mode, LightMode::Indirect);
  EXPECT_FLOAT_EQ(indirect.scene.runtimeLights[0].light.intensity, kIntensity);
}

// The shadowmask bake drawn with the real-time light × mask matches the fully baked one: mean absolute
// difference ≤ 3 in 8-bit sRGB over the whole image (no emitters, no pixel excluded). And where the plane is
// lit (outside the shadow, |x|, |z| ≤ 0.8 m, and its edge texels), the real-time term alone is ρ/π · I h / r³.
TEST(MixedLights, ShadowmaskBakeInIrviewMatchesTheFullBake) {
  const ViewerScene baked = loadViewerScene(bakeAndExport(LightMode::Baked, "baked"));
  ViewerScene masked = loadViewerScene(bakeAndExport(LightMode::ShadowMask, "mask"));
  ASSERT_EQ(masked.scene.runtimeLights.size(), 1u);
  GlContext gl;
  const int w = 192, h = 144;
  const ViewCamera cam = downView(baked.scene.bounds());
  const RgbaImage full = ViewRenderer(baked).render(cam, w, h, {});
  const RgbaImage mixed = ViewRenderer(masked).render(cam, w, h, {});
  ViewerScene mapOnly = masked;
  mapOnly.scene.runtimeLights.clear();
  const RgbaImage map = ViewRenderer(mapOnly).render(cam, w, h, {});
  double sum = 0.0, mapSum = 0.0;
  for (size_t i = 0; i < full.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const auto code = [](float v) { return std::lround(255.0f * encodeSrgb(std::min(1.0f, std::max(0.0f, v)))); };
      sum += std::abs(code(mixed.pixels[i][c]) - code(full.pixels[i][c]));
      mapSum += std::abs(code(map.pixels[i][c]) - code(full.pixels[i][c]));
    }
  const double mad = sum / (3.0 * full.pixels.size()), mapMad = mapSum / (3.0 * full.pixels.size());
  std::printf("[ figure ] irview shadowmask bake vs full bake: MAD %.3f (8-bit sRGB); without the real-time light %.2f\n",
              mad, mapMad);
  EXPECT_LE(mad, 3.0);
  EXPECT_GT(mapMad, 20.0);  // the real-time light is most of the image: leaving it out fails

  float worst = 0.0f;
  size_t checked = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::vec3 p;
      if (!planeHit(cam, w, h, x, y, p) || (std::abs(p.x) < 1.2f && std::abs(p.z) < 1.2f)) continue;
      const float r = glm::length(glm::vec3(0, kHeight, 0) - p);
      const float expected = kAlbedo / kPi * kIntensity * kHeight / (r * r * r);
      const float term = mixed.at(x, y).r - map.at(x, y).r;
      worst = std::max(worst, std::abs(term - expected) / expected);
      ++checked;
    }
  std::printf("[ figure ] real-time term vs ρ/π · I h / r³ on %zu lit pixels: worst relative error %.2e\n", checked, worst);
  EXPECT_GT(checked, 10000u);
  EXPECT_LT(worst, 2e-3f);
}

}  // namespace
}  // namespace irbake::view
