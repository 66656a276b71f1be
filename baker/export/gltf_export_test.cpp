// Export with light maps: reload through our loader (TEXCOORD_1, extras.lightmap, MOZ_lightmap, PNG
// values × intensity, EXR pages), the source-scene path (images, cameras, lights kept), the unwrap
// case without maps, and atomicity when a write fails half way.
#include <fstream>

#include <gtest/gtest.h>

#include "common/error.h"
#include "export/exr_io.h"
#include "export/gltf_export.h"
#include "export/gltf_writer.h"
#include "scene/gltf_loader.h"
#include "scene/test_gltf_builder.h"

using namespace irbake;
using json = nlohmann::json;

namespace {

// Two unit quads side by side sharing one material; quad i is on light-map page i, its uv1 covering
// that page's [0.1, 0.9]² square.
Scene twoQuadScene() {
  Scene s;
  Material m;
  m.name = "grey";
  m.baseColorFactor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  s.materials.push_back(m);
  for (int i = 0; i < 2; ++i) {
    Primitive p;
    p.name = "quad" + std::to_string(i);
    float x = static_cast<float>(i);
    p.positions = {{x, 0, 0}, {x + 1, 0, 0}, {x + 1, 0, -1}, {x, 0, -1}};
    p.normals.assign(4, glm::vec3(0, 1, 0));
    p.uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    p.uv1 = {{0.1f, 0.1f}, {0.9f, 0.1f}, {0.9f, 0.9f}, {0.1f, 0.9f}};
    p.indices = {0, 1, 2, 0, 2, 3};
    p.lightmap = {i, 8, 4};
    s.primitives.push_back(p);
  }
  Light l;
  l.name = "sun";
  l.type = LightType::Directional;
  l.direction = {0, -1, 0};
  l.intensity = 3.0f;
  s.lights.push_back(l);
  return s;
}

// Page p: a ramp whose largest value is (p + 1) × 2.5 (the expected MOZ_lightmap intensity).
std::vector<Lightmap> ramps() {
  std::vector<Lightmap> maps;
  for (int page = 0; page < 2; ++page) {
    Lightmap m;
    m.page = page;
    m.width = 8;
    m.height = 4;
    for (int i = 0; i < 32; ++i) m.texels.push_back(glm::vec3(i / 31.0f, 0.5f * i / 31.0f, 0.25f) * (2.5f * (page + 1)));
    m.valid.assign(32, 1);
    maps.push_back(m);
  }
  return maps;
}

std::vector<std::string> filesIn(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    if (e.is_regular_file()) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

json readJson(const std::filesystem::path& p) { return json::parse(std::ifstream(p)); }

}  // namespace

TEST(GltfExport, GeneratedSceneReloadsWithTexcoord1MozLightmapAndPng) {
  auto dir = irbake::testing::testFolder("export_generated");
  Scene s = twoQuadScene();
  std::vector<Lightmap> maps = ramps();
  ExportOptions o;
  o.output = dir / "baked.gltf";
  exportGltf(s, maps, o);
  EXPECT_EQ(filesIn(dir), (std::vector<std::string>{"baked.bin", "baked.gltf", "lightmap_0.exr", "lightmap_1.exr"}));
  json j = readJson(o.output);
  EXPECT_NE(std::find(j["extensionsUsed"].begin(), j["extensionsUsed"].end(), "MOZ_lightmap"), j["extensionsUsed"].end());

  Scene r = loadScene(o.output);
  ASSERT_EQ(r.primitives.size(), 2u);
  // One material per page: the shared "grey" was duplicated.
  EXPECT_EQ(r.materials.size(), 2u);
  ASSERT_EQ(r.lightmapExrPaths.size(), 2u);
  for (int page = 0; page < 2; ++page) {
    const Primitive& p = r.primitives[page];
    EXPECT_EQ(p.lightmap.page, page);
    EXPECT_EQ(p.lightmap.width, 8);
    EXPECT_EQ(p.lightmap.height, 4);
    ASSERT_EQ(p.uv1.size(), 4u);
    EXPECT_FLOAT_EQ(p.uv1[2].x, 0.9f);
    const Material& m = r.materials[p.material];
    EXPECT_NEAR(m.baseColorFactor.r, 0.5f, 1e-6f);
    ASSERT_GE(m.lightmapTexture, 0);
    EXPECT_NEAR(m.lightmapIntensity, 2.5f * (page + 1), 1e-5f);
    const Texture& png = r.textures[m.lightmapTexture];
    ASSERT_EQ(png.width, 8);
    ASSERT_EQ(png.height, 4);
    // PNG × intensity reproduces the map within half an 8-bit step of the intensity.
    float step = m.lightmapIntensity / 255.0f;
    for (size_t i = 0; i < 32; ++i)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(png.texels[i][c] * m.lightmapIntensity, maps[page].texels[i][c], 0.5f * step + 1e-6f);
    EXPECT_NEAR(png.texels[31].r, 1.0f, 1e-6f);  // the brightest texel uses the full range
    Lightmap exr = readExr(r.lightmapExrPaths[page]);
    ASSERT_EQ(exr.texels.size(), 32u);
    for (size_t i = 0; i < 32; ++i) EXPECT_EQ(exr.texels[i], maps[page].texels[i]);
  }
  ASSERT_EQ(r.lights.size(), 1u);
  EXPECT_FLOAT_EQ(r.lights[0].intensity, 3.0f);
}

TEST(GltfExport, SourceSceneKeepsImagesCamerasLightsAndReplacesMeshes) {
  auto dir = irbake::testing::testFolder("export_source");
  // Source: the two quads with a 2×2 base-colour texture, a camera and a light, as a .gltf + .bin.
  Scene src = twoQuadScene();
  Texture t;
  t.name = "albedo";
  t.width = t.height = 2;
  t.texels = {glm::vec4(0.2f, 0.2f, 0.2f, 1), glm::vec4(0.8f, 0.8f, 0.8f, 1), glm::vec4(0.8f, 0.8f, 0.8f, 1), glm::vec4(0.2f, 0.2f, 0.2f, 1)};
  src.textures.push_back(t);
  src.materials[0].baseColorTexture = 0;
  for (auto& p : src.primitives) {
    p.uv1.clear();
    p.lightmap = {};
  }
  Camera cam;
  cam.name = "cam";
  cam.cameraToWorld[3] = glm::vec4(0, 1, 5, 1);
  src.cameras.push_back(cam);
  std::filesystem::create_directories(dir / "in");
  writeGltf(src, dir / "in" / "source.gltf");

  // What the atlas would hand over: the loaded scene with uv1 and pages.
  Scene loaded = loadScene(dir / "in" / "source.gltf");
  ASSERT_EQ(loaded.primitives.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    loaded.primitives[i].uv1 = {{0.1f, 0.1f}, {0.9f, 0.1f}, {0.9f, 0.9f}, {0.1f, 0.9f}};
    loaded.primitives[i].lightmap = {i, 8, 4};
  }
  ExportOptions o;
  o.output = dir / "out" / "baked.glb";
  exportGltf(loaded, ramps(), o);
  EXPECT_EQ(filesIn(dir / "out"), (std::vector<std::string>{"baked.glb", "lightmap_0.exr", "lightmap_1.exr"}));

  Scene r = loadScene(o.output);
  ASSERT_EQ(r.primitives.size(), 2u);  // the source meshes were replaced, not duplicated
  EXPECT_EQ(r.triangleCount(), 4u);
  ASSERT_EQ(r.cameras.size(), 1u);
  EXPECT_NEAR(r.cameras[0].cameraToWorld[3].z, 5.0f, 1e-6f);
  ASSERT_EQ(r.lights.size(), 1u);
  for (int i = 0; i < 2; ++i) {
    const Primitive& p = r.primitives[i];
    for (size_t v = 0; v < 4; ++v) EXPECT_LT(glm::length(p.positions[v] - loaded.primitives[i].positions[v]), 1e-6f);
    EXPECT_EQ(p.lightmap.page, i);
    const Material& m = r.materials[p.material];
    ASSERT_GE(m.baseColorTexture, 0);  // the source image came along, embedded
    const Texture& albedo = r.textures[m.baseColorTexture];
    ASSERT_EQ(albedo.width, 2);
    EXPECT_NEAR(albedo.texels[1].r, 0.8f, 3e-3f);
    ASSERT_GE(m.lightmapTexture, 0);
    EXPECT_NEAR(m.lightmapIntensity, 2.5f * (i + 1), 1e-5f);
  }
  ASSERT_EQ(r.lightmapExrPaths.size(), 2u);
  EXPECT_TRUE(std::filesystem::exists(r.lightmapExrPaths[1]));
}

TEST(GltfExport, UnwrapExportWithoutMapsHasOnlyTexcoord1AndRecords) {
  auto dir = irbake::testing::testFolder("export_unwrap");
  ExportOptions o;
  o.output = dir / "unwrapped.gltf";
  exportGltf(twoQuadScene(), {}, o);
  EXPECT_EQ(filesIn(dir), (std::vector<std::string>{"unwrapped.bin", "unwrapped.gltf"}));
  json j = readJson(o.output);
  EXPECT_FALSE(j.contains("extensionsUsed") &&
               std::find(j["extensionsUsed"].begin(), j["extensionsUsed"].end(), "MOZ_lightmap") != j["extensionsUsed"].end());
  Scene r = loadScene(o.output);
  ASSERT_EQ(r.primitives.size(), 2u);
  EXPECT_EQ(r.primitives[1].lightmap.page, 1);
  EXPECT_EQ(r.primitives[1].uv1.size(), 4u);
  EXPECT_EQ(r.materials[0].lightmapTexture, -1);
  EXPECT_TRUE(r.lightmapExrPaths.empty());
}

TEST(GltfExport, WriteFailingHalfWayLeavesNoFile) {
  auto dir = irbake::testing::testFolder("export_fail");
  // The EXR pages go under "blocker/", which is a file: the glTF and .bin temps are written, then
  // the first EXR cannot be created. Nothing may remain, not even a temp file.
  std::ofstream(dir / "blocker") << "x";
  ExportOptions o;
  o.output = dir / "baked.gltf";
  o.exrPrefix = "blocker/lightmap";
  EXPECT_THROW(exportGltf(twoQuadScene(), ramps(), o), Error);
  EXPECT_EQ(filesIn(dir), (std::vector<std::string>{"blocker"}));
}

TEST(GltfExport, NanMapIsRefusedBeforeWritingAnything) {
  auto dir = irbake::testing::testFolder("export_nan");
  std::vector<Lightmap> maps = ramps();
  maps[1].texels[5].y = std::nanf("");
  ExportOptions o;
  o.output = dir / "baked.glb";
  try {
    exportGltf(twoQuadScene(), maps, o);
    FAIL() << "expected NumericError";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NumericError);
    EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos);
  }
  EXPECT_TRUE(filesIn(dir).empty());
}
