// irview's mixed lighting on real bakes (pipeline bake(), Embree backend): a 10 × 10 m plane (ρ = 0.5) under a
// point light (I = 10 W/sr at 1 m) with a 0.8 m square occluder at half height, baked twice with the same seed,
// fully baked and with the light in shadowmask mode. irview draws the shadowmask bake's light in real time
// times the mask; both are exported and loaded as irview loads them.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <vector>

#include <gtest/gtest.h>

#include "common/maths.h"
#include "glcontext/gl_context.h"
#include "pipeline/bake.h"
#include "raytrace/ray_tracer.h"
#include "samples/sample_scenes.h"
#include "screenshot.h"
#include "texels/texel_samples.h"
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

// Bakes the scene with the point light in `mode` (and glTF's `range`, 0: none) and writes it as the command
// does; returns the glTF.
std::filesystem::path bakeAndExport(LightMode mode, const std::string& name, float range = 0.0f) {
  BakeOptions o;
  o.backend = BackendKind::Embree;
  o.atlas.texelsPerUnit = 6.0f;
  o.walk.paths = 256;
  if (mode != LightMode::Baked) o.lightModes = {{"*", mode}};
  Scene scene = occludedPointOverPlane();
  scene.lights.at(0).range = range;
  const BakeResult baked = bake(std::move(scene), o);
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
// A display's 8-bit sRGB code of a linear value.
long srgbCode(float v) { return std::lround(255.0f * encodeSrgb(std::min(1.0f, std::max(0.0f, v)))); }

// The fully baked scene, the shadowmask bake with its real-time lights, and that bake's map alone, from one camera.
struct MixedRenders {
  RgbaImage full, mixed, map;
};
MixedRenders renderFullMixedAndMap(const ViewerScene& baked, const ViewerScene& masked, const ViewCamera& cam, int w,
                                   int h) {
  ViewerScene mapOnly = masked;
  mapOnly.scene.runtimeLights.clear();
  return {ViewRenderer(baked).render(cam, w, h, {}), ViewRenderer(masked).render(cam, w, h, {}),
          ViewRenderer(mapOnly).render(cam, w, h, {})};
}

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
  const auto [full, mixed, map] = renderFullMixedAndMap(baked, masked, cam, w, h);
  double sum = 0.0, mapSum = 0.0;
  for (size_t i = 0; i < full.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      sum += std::abs(srgbCode(mixed.pixels[i][c]) - srgbCode(full.pixels[i][c]));
      mapSum += std::abs(srgbCode(map.pixels[i][c]) - srgbCode(full.pixels[i][c]));
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


// glTF's range: the window the bake and every client apply, w(d) = clamp(1 − (d/R)⁴, 0, 1)² (Light::rangeWindow),
// in double here.
double rangeWindowAt(double d, double range) {
  const double q = d / range, w = 1.0 - q * q * q * q;
  return w > 0.0 ? w * w : 0.0;
}
// The plane's direct term under the light with that range, as irradiance / π at distance d from it.
double planeValue(double d, double range) { return kIntensity * kHeight * rangeWindowAt(d, range) / (kPi * d * d * d); }
// Its first and second derivatives in d, by central differences.
double planeSlope(double d, double range) {
  const double h = 1e-4;
  return (planeValue(d + h, range) - planeValue(d - h, range)) / (2.0 * h);
}
double planeCurvature(double d, double range) {
  const double h = 1e-3;
  return (planeValue(d + h, range) - 2.0 * planeValue(d, range) + planeValue(d - h, range)) / (h * h);
}
// The largest of |f| over [lo, hi] for f = planeSlope or planeCurvature (64 steps).
double largestOver(double (*f)(double, double), double lo, double hi, double range) {
  double m = 0.0;
  for (int k = 0; k <= 64; ++k) m = std::max(m, std::abs(f(lo + (hi - lo) * k / 64.0, range)));
  return m;
}

// The plane of makePointOverPlane alone (nothing else lights it: its map is the light's direct term) under the
// light with range R = 2 m, whose edge on the plane is the circle of radius √3 m, baked on the GL and Embree
// evaluators at 8 texels per metre. Each texel against the closed form at its centre, I h w(d) / (π d³): within
// 1% plus what a texel's mean over its square may differ from its centre's value (the curvature's share, a²/12 ×
// (|f″| + |f′|/ρ) with a the texel's diagonal). No step: two neighbouring texels near the range differ by no more
// than the closed form's largest slope over their distances times their distance apart (plus both tolerances),
// a bound below a quarter of the step a hard cutoff makes there, I h / (π R³).
TEST(RangeWindow, BakedPlaneFollowsTheClosedFormAcrossTheRangeOnBothEvaluators) {
  constexpr double R = 2.0, texel = 1.0 / 8.0, a2 = 2.0 * texel * texel;
  for (BackendKind backend : {BackendKind::Gl, BackendKind::Embree}) {
    Scene s = samples::makePointOverPlane();
    s.lights.at(0).range = static_cast<float>(R);
    BakeOptions o;
    o.backend = backend;
    o.atlas.texelsPerUnit = 1.0f / static_cast<float>(texel);
    o.walk.paths = 256;
    const BakeResult r = bake(std::move(s), o);
    RayTracer rt(r.scene);
    TexelSampleOptions to;
    to.leakControl = false;  // every covered texel gets its centre
    const std::vector<TexelSamples> texels = buildTexelSamples(r.scene, rt, to);
    ASSERT_EQ(texels.size(), r.maps.size());
    const glm::dvec3 light(0.0, kHeight, 0.0);
    size_t checked = 0, nearEdge = 0, pairs = 0;
    double worstShare = 0.0, worstStepShare = 0.0, boundAtEdge = 0.0;
    for (size_t p = 0; p < texels.size(); ++p) {
      const Lightmap& m = r.maps[p];
      auto distanceOf = [&](int x, int y, double& d) {
        if (x >= m.width || y >= m.height) return false;
        const size_t i = static_cast<size_t>(y) * m.width + x;
        const glm::vec4 pw = texels[p].positionWeight[i];
        if (pw.w <= 0.0f || !m.valid[i]) return false;
        d = glm::length(glm::dvec3(glm::vec3(pw)) - light);
        return true;
      };
      auto tolerance = [&](double d) {
        const double rho = std::sqrt(std::max(d * d - kHeight * kHeight, 1e-6));
        const double lo = d - std::sqrt(a2), hi = d + std::sqrt(a2);
        return 0.01 * planeValue(d, R) +
               a2 / 12.0 * (largestOver(planeCurvature, lo, hi, R) + largestOver(planeSlope, lo, hi, R) / rho) + 1e-4;
      };
      for (int y = 0; y < m.height; ++y)
        for (int x = 0; x < m.width; ++x) {
          double d = 0.0;
          if (!distanceOf(x, y, d)) continue;
          const double v = m.texels[static_cast<size_t>(y) * m.width + x].x, tol = tolerance(d);
          EXPECT_NEAR(v, planeValue(d, R), tol) << toString(backend) << " page " << p << " texel " << x << ", " << y
                                                << " at " << d << " m";
          worstShare = std::max(worstShare, std::abs(v - planeValue(d, R)) / tol);
          ++checked;
          if (d > 0.75 * R && d < 1.15 * R) ++nearEdge;
          for (const glm::ivec2 step : {glm::ivec2(1, 0), glm::ivec2(0, 1)}) {
            double dn = 0.0;
            if (!distanceOf(x + step.x, y + step.y, dn)) continue;
            const double lo = std::min(d, dn), hi = std::max(d, dn);
            if (hi < 0.75 * R || lo > 1.15 * R) continue;
            const double vn = m.texels[static_cast<size_t>(y + step.y) * m.width + x + step.x].x;
            const double bound = largestOver(planeSlope, lo, hi, R) * (hi - lo) + tol + tolerance(dn);
            EXPECT_LE(std::abs(v - vn), bound) << toString(backend) << " texels " << x << ", " << y << " at " << d
                                               << " m and " << dn << " m";
            worstStepShare = std::max(worstStepShare, std::abs(v - vn) / bound);
            if (lo < R && hi >= R) boundAtEdge = std::max(boundAtEdge, bound);
            ++pairs;
          }
        }
    }
    const double hardStep = kIntensity * kHeight / (kPi * R * R * R);
    std::printf("[ figure ] range window, %s: %zu texels (%zu within 0.75-1.15 R), worst |map - closed form| %.2f of "
                "its tolerance; %zu neighbour pairs near R, worst step %.2f of its bound; bound across R %.2e, a hard "
                "cutoff steps %.3f\n",
                toString(backend), checked, nearEdge, worstShare, pairs, worstStepShare, boundAtEdge, hardStep);
    EXPECT_GT(nearEdge, 300u) << toString(backend);
    EXPECT_GT(pairs, 500u) << toString(backend);
    EXPECT_GT(boundAtEdge, 0.0) << toString(backend);
    EXPECT_LT(boundAtEdge, 0.25 * hardStep) << toString(backend);  // the step check would catch a hard cutoff
  }
}

// The same light with R = 2 m in shadowmask mode, drawn by irview in real time × its mask, against the full bake,
// over the pixels of the plane around the range's edge (distances 0.75 R to 1.15 R from the light, off the
// occluder's shadow): mean absolute difference ≤ 2 in 8-bit sRGB. And there the real-time term alone is
// ρ/π · I h w(d) / d³, within 0.2% of its value at a distance within 2 mm of the pixel's (where the window falls
// fast, a pixel's point and the fragment's differ by that much).
TEST(RangeWindow, ShadowmaskBakeInIrviewMatchesTheFullBakeAcrossTheRange) {
  constexpr float R = 2.0f;
  const ViewerScene baked = loadViewerScene(bakeAndExport(LightMode::Baked, "range_baked", R));
  ViewerScene masked = loadViewerScene(bakeAndExport(LightMode::ShadowMask, "range_mask", R));
  ASSERT_EQ(masked.scene.runtimeLights.size(), 1u);
  EXPECT_FLOAT_EQ(masked.scene.runtimeLights[0].light.range, R);
  GlContext gl;
  const int w = 192, h = 144;
  const ViewCamera cam = downView(baked.scene.bounds());
  const auto [full, mixed, map] = renderFullMixedAndMap(baked, masked, cam, w, h);
  double sum = 0.0, mapSum = 0.0, worst = -1.0;
  size_t pixels = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::vec3 p;
      if (!planeHit(cam, w, h, x, y, p) || (std::abs(p.x) < 1.2f && std::abs(p.z) < 1.2f)) continue;
      const float d = glm::length(glm::vec3(0, kHeight, 0) - p);
      if (d < 0.75f * R || d > 1.15f * R) continue;
      for (int c = 0; c < 3; ++c) {
        sum += std::abs(srgbCode(mixed.at(x, y)[c]) - srgbCode(full.at(x, y)[c]));
        mapSum += std::abs(srgbCode(map.at(x, y)[c]) - srgbCode(full.at(x, y)[c]));
      }
      // ρ/π · E, the map value being E/π
      const double near = kAlbedo * planeValue(d - 2e-3, R), far = kAlbedo * planeValue(d + 2e-3, R);
      const double term = mixed.at(x, y).r - map.at(x, y).r;
      const double lo = std::min(near, far) * (1.0 - 2e-3), hi = std::max(near, far) * (1.0 + 2e-3);
      worst = std::max(worst, std::max(lo - term, term - hi) / (kAlbedo * planeValue(d, R) + 1e-6));
      ++pixels;
    }
  const double mad = sum / (3.0 * std::max<size_t>(pixels, 1)), mapMad = mapSum / (3.0 * std::max<size_t>(pixels, 1));
  std::printf("[ figure ] irview shadowmask bake vs full bake around the range's edge (%zu pixels): MAD %.3f (8-bit "
              "sRGB); without the real-time light %.2f; real-time term outside the closed form's band by at most %.2e of it\n",
              pixels, mad, mapMad, worst);
  EXPECT_GT(pixels, 2000u);
  EXPECT_LE(mad, 2.0);
  EXPECT_GT(mapMad, 5.0);  // the real-time light is much of the region: leaving it out fails
  EXPECT_LE(worst, 0.0);
}

}  // namespace
}  // namespace irbake::view
