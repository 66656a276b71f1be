// The viewer on real bakes (pipeline bake(), Embree backend, small budgets so each test stays short):
// the furnace has an exact answer (Le/(1−ρ) = 1 everywhere), the Cornell box is checked for its walls.
// The per-pixel 2% check against the exact map is view_renderer_test (a converged, closed-form map);
// here the map carries the bake's own VPL noise, so the mean and the mean absolute error are held to
// the exact answer, and 95% of pixels to 3% (the worst pixels lie along the cube edges, where the
// bake itself is off by up to ~13%: see docs/viewer.md).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "common/maths.h"
#include "export/gltf_export.h"
#include "glcontext/gl_context.h"
#include "pipeline/bake.h"
#include "samples/sample_scenes.h"
#include "view_renderer.h"

namespace irbake::view {
namespace {

BakeOptions smallBake(int paths, float texelsPerUnit) {
  BakeOptions o;
  o.backend = BackendKind::Embree;
  o.atlas.texelsPerUnit = texelsPerUnit;
  o.walk.paths = paths;
  return o;
}

// ρ = 0.5, Le = 0.5: the converged radiance is Le/(1−ρ) = 1 and every pixel shows ρ·map + Le = 1.
// Pixel errors over seven views from inside the furnace baked with `options`.
struct FurnaceView {
  double mean = 0, meanAbs = 0;
  float p95 = 0, worst = 0;
};
FurnaceView viewBakedFurnace(const BakeOptions& options) {
  BakeResult baked = bake(samples::makeFurnace(0.5f, 0.5f), options);
  ViewerScene v = makeViewerScene(std::move(baked.scene), std::move(baked.maps));
  EXPECT_TRUE(v.warnings.empty());
  GlContext gl;
  ViewRenderer r(v);
  const Bounds3 b = v.scene.bounds();
  const glm::vec3 eye = 0.5f * (b.min + b.max) + glm::vec3(0.05f, -0.1f, 0.08f);
  const glm::vec3 dirs[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0.6f, 0.5f, -0.7f}};
  double sum = 0.0, absError = 0.0;
  std::vector<float> errors;
  for (const auto& d : dirs) {
    RgbaImage img = r.render(lookAt(eye, eye + d, 100.0f, b), 96, 64, {});
    for (const auto& p : img.pixels)
      for (int c = 0; c < 3; ++c) {
        sum += p[c];
        absError += std::abs(p[c] - 1.0f);
        errors.push_back(std::abs(p[c] - 1.0f));
      }
  }
  std::sort(errors.begin(), errors.end());
  FurnaceView f;
  f.mean = sum / errors.size();
  f.meanAbs = absError / errors.size();
  f.p95 = errors[errors.size() * 95 / 100];
  f.worst = errors.back();
  return f;
}

// Every pixel 1.0 within 2%. The bake is converged for this purpose: a tight clamp (k = 4096,
// clamp radius ≈ the box) leaves nearly all transport to the compensation gather, which in a furnace reads
// a uniform map and is almost noise-free. Measured: worst pixel 1.39%.
TEST(BakedView, FurnaceSeenFromInsideIsOne) {
  BakeOptions options = smallBake(4096, 4.0f);
  options.clampVplsPerMean = 4096.0;
  const FurnaceView f = viewBakedFurnace(options);
  EXPECT_NEAR(f.mean, 1.0, 0.01);
  EXPECT_LT(f.worst, 0.02f) << "p95 " << f.p95 << ", mean |error| " << f.meanAbs;
  RecordProperty("worstAbsoluteError", std::to_string(f.worst));
}

// The same with the default estimator (k = 256 + gather, 4096 paths): VPL noise at the clamp-radius scale
// remains: the mean, the mean |error| and the 95th percentile are held tight, the worst pixel looser.
TEST(BakedView, FurnaceWithDefaultEstimatorIsOneOnAverage) {
  const FurnaceView f = viewBakedFurnace(smallBake(4096, 4.0f));
  EXPECT_NEAR(f.mean, 1.0, 0.01);  // unbiased: the mean over every view is 1
  EXPECT_LT(f.meanAbs, 0.01);      // mean absolute error within 1%
  EXPECT_LT(f.p95, 0.02f);         // 95% of pixels within 2%
  EXPECT_LT(f.worst, 0.06f);
  RecordProperty("meanAbsoluteError", std::to_string(f.meanAbs));
  RecordProperty("p95AbsoluteError", std::to_string(f.p95));
  RecordProperty("worstAbsoluteError", std::to_string(f.worst));
}

TEST(BakedView, CornellBoxFromSampleCameraHasRedLeftAndGreenRightWalls) {
  BakeResult baked = bake(samples::makeCornellBox(), smallBake(512, 16.0f));
  ViewerScene v = makeViewerScene(std::move(baked.scene), std::move(baked.maps));
  ASSERT_FALSE(v.scene.cameras.empty());
  GlContext gl;
  ViewRenderer r(v);
  const int w = 160, h = 160;
  RgbaImage img = r.render(fromGltfCamera(v.scene.cameras[0], v.scene.bounds()), w, h, {});
  double mean = 0.0;
  for (const auto& p : img.pixels) mean += (p.r + p.g + p.b) / 3.0;
  mean /= img.pixels.size();
  EXPECT_GT(mean, 0.02) << "image is black";
  // A band at mid height near each side: the side walls fill the image edges from this camera.
  auto bandMean = [&](int x0, int x1) {
    glm::dvec3 s(0.0);
    int count = 0;
    for (int y = h * 2 / 5; y < h * 3 / 5; ++y)
      for (int x = x0; x < x1; ++x, ++count) s += glm::dvec3(img.at(x, y));
    return s / double(count);
  };
  glm::dvec3 left = bandMean(w / 20, w / 8), right = bandMean(w - w / 8, w - w / 20);
  EXPECT_GT(left.r, 2.0 * left.g) << "left wall not red: " << left.r << "," << left.g << "," << left.b;
  EXPECT_GT(left.r, 2.0 * left.b);
  EXPECT_GT(right.g, 1.5 * right.r) << "right wall not green: " << right.r << "," << right.g << "," << right.b;
  EXPECT_GT(right.g, 1.5 * right.b);
}

// What irbake writes is what irview shows: the exported glTF with its float EXR pages renders exactly
// like the in-memory bake; without the EXRs the MOZ_lightmap PNG × intensity is used (8-bit, so a
// looser tolerance).
TEST(BakedView, ExportedGltfShowsTheSameLightAsTheBake) {
  BakeResult baked = bake(samples::makeFurnace(0.5f, 0.5f), smallBake(1024, 4.0f));
  const char* dir = std::getenv("IRBAKE_BINARY_DIR");
  const std::filesystem::path out = std::filesystem::path(dir ? dir : ".") / "runtime_bake_test";
  ExportOptions withExr;
  withExr.output = out / "furnace.gltf";
  exportGltf(baked.scene, baked.maps, withExr);
  ExportOptions pngOnly;
  pngOnly.output = out / "png_only" / "furnace.gltf";
  pngOnly.writeExrPages = false;
  exportGltf(baked.scene, baked.maps, pngOnly);

  ViewerScene memory = makeViewerScene(baked.scene, baked.maps);
  ViewerScene fromExr = loadViewerScene(withExr.output);
  ViewerScene fromPng = loadViewerScene(pngOnly.output);
  ASSERT_EQ(fromExr.pages.size(), baked.maps.size());
  EXPECT_TRUE(fromPng.pages.empty());
  for (const auto& p : fromExr.scene.primitives) EXPECT_EQ(lightmapSourceOf(fromExr, p), LightmapSource::Page);
  for (const auto& p : fromPng.scene.primitives) EXPECT_EQ(lightmapSourceOf(fromPng, p), LightmapSource::MaterialTexture);

  GlContext gl;
  const Bounds3 b = memory.scene.bounds();
  const glm::vec3 eye = 0.5f * (b.min + b.max);
  const ViewCamera cam = lookAt(eye, eye + glm::vec3(0.7f, -0.4f, 0.6f), 100.0f, b);
  auto renderOf = [&](const ViewerScene& v) {
    ViewRenderer r(v);
    return r.render(cam, 64, 48, {});
  };
  RgbaImage a = renderOf(memory), e = renderOf(fromExr), p = renderOf(fromPng);
  float exrDiff = 0.0f, pngDiff = 0.0f;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      exrDiff = std::max(exrDiff, std::abs(e.pixels[i][c] - a.pixels[i][c]));
      pngDiff = std::max(pngDiff, std::abs(p.pixels[i][c] - a.pixels[i][c]));
    }
  EXPECT_LT(exrDiff, 1e-4f);  // float pages: the same numbers
  EXPECT_LT(pngDiff, 0.03f);  // 8-bit PNG × intensity
  RecordProperty("pngMaxDifference", std::to_string(pngDiff));
}

// Directional maps end to end: bake with directional maps, export, load as irview does, render.
// A point light (I = 10 W/sr, 1 m) over a grey plane (ρ = 0.5; a single plane lights nothing of itself) with
// a constant normal map tilted 35° towards +x (TEXCOORD_0 planar: u along +x, v along +z, tangent generated):
// one source, so the L1 form is exact and every pixel within 1.5 m should show ρ I max(0, n·ω) / (π r²); the
// L0 view ρ I (n_g·ω) / (π r²). Errors are relative to ρ I / (π r²); what is left is the map's bilinear
// interpolation at 12 texels/m, the same with and without the normal map. Without the L1 EXRs the viewer reads
// the 8-bit L1 PNGs (scale and bias).
TEST(BakedView, DirectionalBakeShowsTheNormalMapsIrradiance) {
  Scene s = samples::makePointOverPlane();
  Texture normalMap;
  normalMap.name = "tilted normal";
  normalMap.width = normalMap.height = 4;
  const glm::vec3 codes(201.0f, 128.0f, 232.0f);  // 8-bit codes of (sin 35°, 0, cos 35°) × 0.5 + 0.5
  normalMap.texels.assign(16, glm::vec4(codes / 255.0f, 1.0f));
  s.materials[0].normalTexture = static_cast<int>(s.textures.size());
  s.textures.push_back(normalMap);
  for (Primitive& p : s.primitives) {
    p.uv0.clear();
    for (const glm::vec3& x : p.positions) p.uv0.emplace_back((x.x + 5.0f) / 10.0f, (x.z + 5.0f) / 10.0f);
  }
  BakeOptions options = smallBake(256, 12.0f);
  options.directional = true;
  const BakeResult baked = bake(std::move(s), options);
  const char* dir = std::getenv("IRBAKE_BINARY_DIR");
  const std::filesystem::path out = std::filesystem::path(dir ? dir : ".") / "runtime_bake_test" / "directional";
  std::filesystem::remove_all(out);
  OutputOptions o;
  o.outDir = out;
  writeBakeOutputs(baked, o);

  // Tangent space: x = +x (u grows), y = −z (v shrinks), z = +y.
  const glm::vec3 m = 2.0f * codes / 255.0f - 1.0f;
  const glm::vec3 n = glm::normalize(glm::vec3(m.x, m.z, -m.y));
  const glm::vec3 light(0, 1, 0), ng(0, 1, 0);
  const float albedo = 0.5f, intensity = 10.0f;
  GlContext gl;
  auto worstError = [&](const ViewerScene& v, LightmapMode mode, const glm::vec3& normal) {
    ViewRenderer r(v);
    EXPECT_EQ(r.directionalPrimitiveCount(), v.scene.primitives.size());
    const ViewCamera cam = lookAt({0.2f, 2.4f, 2.0f}, {0, 0, -0.2f}, 60.0f, v.scene.bounds());
    DrawSettings settings;
    settings.lightmapMode = mode;
    const RgbaImage img = r.render(cam, 160, 120, settings);
    const glm::mat4 inv = glm::inverse(cam.projection(160.0f / 120.0f) * cam.view());
    float worst = 0.0f;
    size_t checked = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const glm::vec2 ndc((x + 0.5f) / img.width * 2 - 1, 1 - (y + 0.5f) / img.height * 2);
        const glm::vec4 a = inv * glm::vec4(ndc, -1, 1), b = inv * glm::vec4(ndc, 0, 1);
        const glm::vec3 origin = glm::vec3(a) / a.w, d = glm::vec3(b) / b.w - origin;
        if (d.y >= 0) continue;
        const glm::vec3 hit = origin + d * (-origin.y / d.y);
        if (std::abs(hit.x) > 1.5f || std::abs(hit.z) > 1.5f) continue;
        const glm::vec3 toLight = light - hit;
        const float r2 = glm::dot(toLight, toLight), scale = albedo * intensity / (kPi * r2);
        const float expected = scale * std::max(0.0f, glm::dot(normal, toLight) / std::sqrt(r2));
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(img.at(x, y)[c] - expected) / scale);
        ++checked;
      }
    EXPECT_GT(checked, 6000u);
    return worst;
  };
  const ViewerScene fromExr = loadViewerScene(out / "scene.gltf");
  ASSERT_FALSE(fromExr.scene.primitives.empty());
  EXPECT_EQ(directionalSourceOf(fromExr, fromExr.scene.primitives[0]), DirectionalSource::Pages);
  const float exrSh = worstError(fromExr, LightmapMode::Sh, n), exrL0 = worstError(fromExr, LightmapMode::L0, ng);
  // Without the L1 EXR pages: the PNGs.
  for (int k = 0; k < 3; ++k) std::filesystem::remove(out / ("lightmap_0_l1" + std::string(1, "xyz"[k]) + ".exr"));
  const ViewerScene fromPng = loadViewerScene(out / "scene.gltf");
  EXPECT_EQ(directionalSourceOf(fromPng, fromPng.scene.primitives[0]), DirectionalSource::MaterialTextures);
  EXPECT_FALSE(fromPng.warnings.empty());
  const float pngSh = worstError(fromPng, LightmapMode::Sh, n);
  std::printf("[ figure ] directional bake in irview, worst error / (ρI/(πr²)): SH %.4f, L0 view %.4f, SH from PNGs %.4f\n",
              exrSh, exrL0, pngSh);
  EXPECT_LT(exrSh, 0.01f);  // measured 0.47%: bilinear interpolation of 12 texels/m under the light
  EXPECT_LT(exrL0, 0.01f);  // 0.51%
  EXPECT_LT(pngSh, 0.015f);  // 0.90%: 8-bit L1 (and the float L0)
}

// The whole path a user takes: bake, export, `irview --camera 0 --screenshot` (headless), read the PNG.
TEST(BakedView, IrviewScreenshotOfExportedCornellBox) {
  BakeResult baked = bake(samples::makeCornellBox(), smallBake(512, 16.0f));
  const char* dir = std::getenv("IRBAKE_BINARY_DIR");
  const std::filesystem::path out = std::filesystem::path(dir ? dir : ".") / "runtime_bake_test" / "cornell";
  ExportOptions ex;
  ex.output = out / "cornell_box.gltf";
  exportGltf(baked.scene, baked.maps, ex);
  const std::filesystem::path png = out / "cornell_camera0.png";
  std::filesystem::remove(png);
  const std::string cmd = "\"" IRVIEW_EXE "\" \"" + ex.output.string() + "\" --camera 0 --width 128 --height 128 --screenshot \"" +
                          png.string() + "\" > \"" + (out / "irview.log").string() + "\" 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  auto in = OIIO::ImageInput::open(png.string());
  ASSERT_TRUE(in) << png;
  const int w = in->spec().width, h = in->spec().height, nc = in->spec().nchannels;
  ASSERT_EQ(w, 128);
  ASSERT_EQ(h, 128);
  std::vector<unsigned char> px(static_cast<size_t>(w) * h * nc);
  ASSERT_TRUE(in->read_image(0, 0, 0, nc, OIIO::TypeDesc::UINT8, px.data()));
  auto band = [&](int x0, int x1) {
    glm::dvec3 s(0.0);
    int n = 0;
    for (int y = h * 2 / 5; y < h * 3 / 5; ++y)
      for (int x = x0; x < x1; ++x, ++n)
        for (int c = 0; c < 3; ++c) s[c] += px[(static_cast<size_t>(y) * w + x) * nc + c];
    return s / double(n);
  };
  double mean = 0.0;
  for (unsigned char v : px) mean += v;
  EXPECT_GT(mean / px.size(), 20.0) << "screenshot is black";
  glm::dvec3 left = band(w / 20, w / 8), right = band(w - w / 8, w - w / 20);
  EXPECT_GT(left.r, 1.5 * left.g) << "left wall not red";   // sRGB-encoded: ratios are smaller than in linear
  EXPECT_GT(right.g, 1.3 * right.r) << "right wall not green";
}

}  // namespace
}  // namespace irbake::view
