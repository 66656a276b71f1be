// Export with light maps: reload through our loader (TEXCOORD_1, extras.lightmap, MOZ_lightmap, PNG
// values × intensity, EXR pages), the source-scene path (images, cameras, lights kept), the unwrap
// case without maps, and atomicity when a write fails half way.
#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "common/error.h"
#include "common/maths.h"
#include "export/exr_io.h"
#include "export/gltf_export.h"
#include "export/gltf_writer.h"
#include "scene/gltf_loader.h"
#include "scene/image_codec.h"
#include "testing/gltf_builder.h"

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
std::vector<uint8_t> readWholeFileForTest(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace

TEST(GltfExport, GeneratedSceneReloadsWithTexcoord1MozLightmapAndPng) {
  auto dir = irbake::testing::testFolder("export_generated");
  Scene s = twoQuadScene();
  std::vector<Lightmap> maps = ramps();
  ExportOptions o;
  o.output = dir / "baked.gltf";
  exportGltf(s, maps, o);
  // A folder output: the images are files beside the .gltf.
  EXPECT_EQ(filesIn(dir), (std::vector<std::string>{"baked.bin", "baked.gltf", "lightmap_0.exr", "lightmap_0.png", "lightmap_1.exr",
                                                    "lightmap_1.png"}));
  json j = readJson(o.output);
  EXPECT_NE(std::find(j["extensionsUsed"].begin(), j["extensionsUsed"].end(), "MOZ_lightmap"), j["extensionsUsed"].end());
  EXPECT_EQ(j["materials"][0]["extensions"]["MOZ_lightmap"]["extras"]["colorSpace"], "srgb");
  // MOZ_lightmap's own units: intensity × texel is the irradiance, π × the map value's range (page 0: 2.5), marked.
  EXPECT_EQ(j["materials"][0]["extensions"]["MOZ_lightmap"]["extras"]["irbake"]["mozLightmap"], "irradiance");
  EXPECT_NEAR(j["materials"][0]["extensions"]["MOZ_lightmap"]["intensity"].get<double>(), 2.5 * kPi, 1e-5);

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
    // sRGB-decoded PNG × intensity reproduces the map within half an 8-bit step of the sRGB code,
    // i.e. 0.5/255 × the decode's slope (largest over that half step) × intensity.
    for (size_t i = 0; i < 32; ++i)
      for (int c = 0; c < 3; ++c) {
        const float v = maps[page].texels[i][c];
        const float s = std::min(1.0f, linearToSrgb(v / m.lightmapIntensity) + 0.5f / 255.0f);
        const float slope = s <= 0.04045f ? 1.0f / 12.92f : 2.4f / 1.055f * std::pow((s + 0.055f) / 1.055f, 1.4f);
        EXPECT_NEAR(png.texels[i][c] * m.lightmapIntensity, v, 0.5f / 255.0f * slope * m.lightmapIntensity + 1e-6f) << i << " " << c;
      }
    EXPECT_NEAR(png.texels[31].r, 1.0f, 1e-6f);  // 32 texels: the 99.9th percentile is the brightest
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

  // Baking the export again replaces its light maps: the old PNGs, their textures and samplers go.
  Scene again = loadScene(o.output);
  for (int i = 0; i < 2; ++i) {
    again.primitives[i].uv1 = {{0.1f, 0.1f}, {0.9f, 0.1f}, {0.9f, 0.9f}, {0.1f, 0.9f}};
    again.primitives[i].lightmap = {i, 8, 4};
  }
  ExportOptions o2;
  o2.output = dir / "again" / "baked.gltf";
  exportGltf(again, ramps(), o2);
  const json j = readJson(o2.output);
  EXPECT_EQ(j["images"].size(), 3u);    // albedo + two pages
  EXPECT_EQ(j["textures"].size(), 3u);
  EXPECT_EQ(j["materials"].size(), 2u);  // "grey" for page 0 in place, its page-1 copy
  EXPECT_EQ(filesIn(dir / "again"), (std::vector<std::string>{"albedo.png", "baked.bin", "baked.gltf", "lightmap_0.exr", "lightmap_0.png",
                                                              "lightmap_1.exr", "lightmap_1.png"}));
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

namespace {

// A hand-made source document an asset pipeline might hand us: a node tree (root → body, root →
// mirrored twin, both instancing mesh "box", a camera and a light under root), names, TRS and matrix
// transforms, COLOR_0 as normalised unsigned bytes (3-byte elements: stride padding), TEXCOORD_0,
// an unknown extension on a node, a material and the root, extras, and one mesh no node uses.
GltfDocument instancedSource() {
  GltfDocument doc;
  // A unit square in z = 0 facing +Z, two triangles.
  const std::vector<glm::vec3> pos = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const std::vector<glm::vec3> nrm(4, glm::vec3(0, 0, 1));
  const std::vector<glm::vec2> uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const uint8_t colour[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 0};
  std::vector<uint8_t> padded;  // 3-byte elements on a 4-byte stride
  for (int i = 0; i < 4; ++i) padded.insert(padded.end(), {colour[3 * i], colour[3 * i + 1], colour[3 * i + 2], 0});
  const int colourView = doc.addBufferView(padded.data(), padded.size(), 34962);
  doc.root["bufferViews"][colourView]["byteStride"] = 4;
  const int colourAccessor =
      doc.append("accessors", {{"bufferView", colourView}, {"componentType", 5121}, {"normalized", true}, {"count", 4}, {"type", "VEC3"}});
  json attributes = {{"POSITION", doc.addPositions(pos)}, {"NORMAL", doc.addVec3(nrm)}, {"TEXCOORD_0", doc.addVec2(uv0)}, {"COLOR_0", colourAccessor}};
  const int indices = doc.addIndices({0, 1, 2, 0, 2, 3});
  doc.append("materials", {{"name", "paint"},
                           {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1.0}}}},
                           {"extensions", {{"EXT_vendor_paint", {{"gloss", 0.25}}}}}});
  doc.append("meshes", {{"name", "box"}, {"primitives", json::array({{{"attributes", attributes}, {"indices", indices}, {"material", 0}}})}});
  const int unusedPositions = doc.addPositions(pos);
  doc.append("meshes", {{"name", "orphan"}, {"primitives", json::array({{{"attributes", {{"POSITION", unusedPositions}}}}})}});
  doc.append("cameras", {{"name", "eye"}, {"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.05}}}});
  doc.root["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"name", "bulb"}, {"type", "point"}, {"intensity", 4.0}}});
  doc.root["extensions"]["EXT_vendor_root"] = {{"answer", 42}};
  doc.useExtension("KHR_lights_punctual");
  doc.useExtension("EXT_vendor_paint");
  doc.useExtension("EXT_vendor_root");
  doc.append("nodes", {{"name", "root"}, {"translation", {1.0, 2.0, 3.0}}, {"children", {1, 2, 3, 4}}, {"extras", {{"tag", "keep me"}}}});
  doc.append("nodes", {{"name", "body"}, {"mesh", 0}, {"rotation", {0.0, 0.70710678, 0.0, 0.70710678}},
                       {"extensions", {{"EXT_vendor_node", {{"id", 7}}}}}});
  doc.append("nodes", {{"name", "twin"}, {"mesh", 0}, {"matrix", {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1}}});
  doc.append("nodes", {{"name", "camera"}, {"camera", 0}, {"translation", {0.0, 0.5, 4.0}}});
  doc.append("nodes", {{"name", "lamp"}, {"translation", {0.0, 3.0, 0.0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  doc.useExtension("EXT_vendor_node");
  doc.root["scenes"] = json::array({{{"name", "main"}, {"nodes", {0}}}});
  doc.root["scene"] = 0;
  return doc;
}

// Indices into root[key] that something references, found by walking every reference glTF defines.
std::set<int> referencedAccessors(const json& j) {
  std::set<int> used;
  for (const auto& m : j["meshes"])
    for (const auto& p : m["primitives"]) {
      for (const auto& [k, a] : p["attributes"].items()) used.insert(a.get<int>());
      if (p.contains("indices")) used.insert(p["indices"].get<int>());
    }
  return used;
}

// Bytes of one accessor element (tight) from a written .gltf + .bin.
std::vector<uint8_t> element(const json& j, const std::vector<uint8_t>& bin, int accessor, size_t i, size_t size) {
  const json& a = j["accessors"][accessor];
  const json& v = j["bufferViews"][a["bufferView"].get<int>()];
  const size_t stride = v.value("byteStride", size);
  const size_t at = v.value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0)) + i * stride;
  return std::vector<uint8_t>(bin.begin() + static_cast<long>(at), bin.begin() + static_cast<long>(at + size));
}

}  // namespace

// The export is the source document with only the light-map data added, nothing
// unused left behind, and one light-map region per instance of a shared mesh.
TEST(GltfExport, KeepsTheSourceDocumentAndGivesEachInstanceItsOwnRegion) {
  auto dir = irbake::testing::testFolder("export_keeps_source");
  std::filesystem::create_directories(dir / "in");
  irbake::testing::writeDocument(instancedSource(), dir / "in" / "source.gltf");
  const json source = readJson(dir / "in" / "source.gltf");

  // What the atlas hands over: every corner its own vertex (the vertex set grows from 4 to 6 per
  // instance), instance k's TEXCOORD_1 inside its own half of page 0.
  Scene loaded = loadScene(dir / "in" / "source.gltf");
  ASSERT_EQ(loaded.primitives.size(), 2u);
  for (size_t k = 0; k < loaded.primitives.size(); ++k) {
    Primitive& p = loaded.primitives[k];
    Primitive split = p;
    split.positions.clear();
    split.normals.clear();
    split.uv0.clear();
    split.indices.clear();
    split.sourceVertex.clear();
    for (size_t c = 0; c < p.indices.size(); ++c) {
      const uint32_t v = p.indices[c];
      split.positions.push_back(p.positions[v]);
      split.normals.push_back(p.normals[v]);
      split.uv0.push_back(p.uv0[v]);
      split.sourceVertex.push_back(p.sourceVertex.empty() ? v : p.sourceVertex[v]);
      split.uv1.push_back(glm::vec2(0.05f + 0.4f * p.uv0[v].x + 0.5f * float(k), 0.1f + 0.8f * p.uv0[v].y));
      split.indices.push_back(static_cast<uint32_t>(c));
    }
    split.lightmap = {0, 8, 4};
    p = split;
  }
  std::vector<Lightmap> maps = ramps();
  maps.resize(1);
  ExportOptions o;
  o.output = dir / "out" / "baked.gltf";
  exportGltf(loaded, maps, o);
  const json j = readJson(o.output);
  std::ifstream binFile(dir / "out" / "baked.bin", std::ios::binary);
  const std::vector<uint8_t> bin((std::istreambuf_iterator<char>(binFile)), std::istreambuf_iterator<char>());

  // Same node tree, names, transforms, cameras, lights, scene, unknown extensions and extras.
  ASSERT_EQ(j["nodes"].size(), source["nodes"].size());
  for (size_t n = 0; n < source["nodes"].size(); ++n) {
    json a = source["nodes"][n], b = j["nodes"][n];
    a.erase("mesh");
    b.erase("mesh");
    EXPECT_EQ(a, b) << "node " << n;
  }
  EXPECT_EQ(j["cameras"], source["cameras"]);
  EXPECT_EQ(j["scenes"], source["scenes"]);
  EXPECT_EQ(j["extensions"], source["extensions"]);
  for (const auto& e : source["extensionsUsed"])
    EXPECT_NE(std::find(j["extensionsUsed"].begin(), j["extensionsUsed"].end(), e), j["extensionsUsed"].end()) << e;
  // The material keeps its name, factor and unknown extension, and gains MOZ_lightmap.
  ASSERT_EQ(j["materials"].size(), 1u);
  EXPECT_EQ(j["materials"][0]["name"], "paint");
  EXPECT_EQ(j["materials"][0]["extensions"]["EXT_vendor_paint"], source["materials"][0]["extensions"]["EXT_vendor_paint"]);
  EXPECT_EQ(j["materials"][0]["extensions"]["MOZ_lightmap"]["texCoord"], 1);
  EXPECT_NEAR(j["materials"][0]["extensions"]["MOZ_lightmap"]["intensity"].get<double>(), 2.5 * kPi, 1e-5);

  // Instancing: body keeps mesh 0, twin gets a copy with the same name; nothing else is left.
  ASSERT_EQ(j["meshes"].size(), 2u);  // "orphan" (unused in the source) is gone
  const int bodyMesh = j["nodes"][1]["mesh"].get<int>(), twinMesh = j["nodes"][2]["mesh"].get<int>();
  EXPECT_EQ(bodyMesh, 0);
  EXPECT_NE(twinMesh, bodyMesh);
  EXPECT_EQ(j["meshes"][twinMesh]["name"], "box");
  // Nothing unused: every accessor, buffer view and image is referenced, the buffer holds only them.
  const std::set<int> accessors = referencedAccessors(j);
  EXPECT_EQ(accessors.size(), j["accessors"].size());
  std::set<int> views;
  for (const auto& a : j["accessors"]) views.insert(a["bufferView"].get<int>());
  EXPECT_EQ(views.size(), j["bufferViews"].size());
  size_t viewBytes = 0;
  for (const auto& v : j["bufferViews"]) viewBytes += v["byteLength"].get<size_t>();
  EXPECT_LE(bin.size(), viewBytes + 4 * j["bufferViews"].size());
  EXPECT_EQ(j["buffers"][0]["byteLength"].get<size_t>(), bin.size());
  ASSERT_EQ(j["images"].size(), 1u);  // the light map, as a file beside the glTF
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / j["images"][0]["uri"].get<std::string>()));

  // Each instance: 6 vertices in local space (the source square), every attribute carried over
  // through the split (COLOR_0 bytes included), winding as in the source (the twin's mirror is undone),
  // and its own TEXCOORD_1 region: the two regions do not overlap.
  const std::vector<uint32_t> sourceCorners = {0, 1, 2, 0, 2, 3};
  const uint8_t colour[4][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {255, 255, 0}};
  const glm::vec3 square[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  float uMax[2] = {-1, -1}, uMin[2] = {2, 2};
  for (int k = 0; k < 2; ++k) {
    const json& prim = j["meshes"][k == 0 ? bodyMesh : twinMesh]["primitives"][0];
    EXPECT_EQ(prim["material"], 0);
    EXPECT_EQ(prim["extras"]["lightmap"]["page"], 0);
    const json& at = prim["attributes"];
    for (const char* name : {"POSITION", "NORMAL", "TEXCOORD_0", "COLOR_0", "TEXCOORD_1"}) ASSERT_TRUE(at.contains(name)) << name;
    EXPECT_EQ(j["accessors"][at["POSITION"].get<int>()]["count"], 6);
    EXPECT_EQ(j["accessors"][at["COLOR_0"].get<int>()]["componentType"], 5121);
    EXPECT_EQ(j["accessors"][at["COLOR_0"].get<int>()]["normalized"], true);
    const int idx = prim["indices"].get<int>();
    ASSERT_EQ(j["accessors"][idx]["count"], 6);
    for (size_t c = 0; c < 6; ++c) {
      uint32_t v;
      std::memcpy(&v, element(j, bin, idx, c, 4).data(), 4);
      ASSERT_LT(v, 6u);
      glm::vec3 p;
      std::memcpy(&p, element(j, bin, at["POSITION"].get<int>(), v, 12).data(), 12);
      EXPECT_EQ(p, square[sourceCorners[c]]) << "instance " << k << " corner " << c;
      const std::vector<uint8_t> rgb = element(j, bin, at["COLOR_0"].get<int>(), v, 3);
      for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(rgb[ch], colour[sourceCorners[c]][ch]);
      glm::vec2 uv1;
      std::memcpy(&uv1, element(j, bin, at["TEXCOORD_1"].get<int>(), v, 8).data(), 8);
      uMin[k] = std::min(uMin[k], uv1.x);
      uMax[k] = std::max(uMax[k], uv1.x);
    }
  }
  EXPECT_LT(uMax[0], uMin[1]);

  // Reloaded, the world-space geometry is the input's (transforms and local positions agree).
  Scene r = loadScene(o.output);
  ASSERT_EQ(r.primitives.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    ASSERT_EQ(r.primitives[k].positions.size(), 6u);
    for (size_t v = 0; v < 6; ++v) EXPECT_LT(glm::length(r.primitives[k].positions[v] - loaded.primitives[k].positions[v]), 1e-5f);
    EXPECT_EQ(r.primitives[k].indices, loaded.primitives[k].indices);  // same world winding
  }
  ASSERT_EQ(r.cameras.size(), 1u);
  ASSERT_EQ(r.lights.size(), 1u);
  EXPECT_NEAR(r.lights[0].position.y, 5.0f, 1e-6f);
}

// The specification applies occlusionTexture to the light map, and the bake's own occlusion is in the map: a
// source material that gets MOZ_lightmap loses its occlusionTexture (and the texture and image nothing else uses).
TEST(GltfExport, LightMappedMaterialsDropTheirOcclusionTexture) {
  auto dir = irbake::testing::testFolder("export_occlusion");
  std::filesystem::create_directories(dir / "in");
  GltfDocument doc = instancedSource();
  Texture ao;
  ao.width = ao.height = 1;
  ao.texels = {glm::vec4(0.5f, 0.5f, 0.5f, 1.0f)};
  const int aoTexture = doc.addTexture(doc.addImage(encodePng(ao, false), "ao"), -1);
  doc.root["materials"][0]["occlusionTexture"] = {{"index", aoTexture}, {"strength", 1.0}};
  // Without an unknown root extension (which might name a texture) unused textures are collected.
  doc.root["extensions"].erase("EXT_vendor_root");
  auto& used = doc.root["extensionsUsed"];
  used.erase(std::remove(used.begin(), used.end(), "EXT_vendor_root"), used.end());
  irbake::testing::writeDocument(doc, dir / "in" / "source.gltf");
  Scene loaded = loadScene(dir / "in" / "source.gltf");
  for (auto& p : loaded.primitives) {
    p.uv1.assign(p.positions.size(), glm::vec2(0.5f));
    p.lightmap = {0, 8, 4};
  }
  std::vector<Lightmap> maps = ramps();
  maps.resize(1);
  ExportOptions o;
  o.output = dir / "out" / "baked.gltf";
  exportGltf(loaded, maps, o);
  const json j = readJson(o.output);
  ASSERT_EQ(j["materials"].size(), 1u);
  EXPECT_TRUE(j["materials"][0]["extensions"].contains("MOZ_lightmap"));
  EXPECT_FALSE(j["materials"][0].contains("occlusionTexture")) << j["materials"][0].dump();
  // Only the light-map texture is left.
  ASSERT_EQ(j["textures"].size(), 1u);
  EXPECT_EQ(j["materials"][0]["extensions"]["MOZ_lightmap"]["index"], 0);
}

// KHR_materials_pbrSpecularGlossiness becomes metal-rough as glTF-Transform's metalRough converts it
// (spec_gloss_conversion.h): diffuse → base colour, glossiness → roughness (a new texture: G = 1 − alpha ×
// glossiness), specular → KHR_materials_specular with KHR_materials_ior 1000; the extension leaves the lists.
TEST(GltfExport, SpecularGlossinessMaterialsBecomeMetalRough) {
  auto dir = irbake::testing::testFolder("export_spec_gloss");
  std::filesystem::create_directories(dir / "in");
  GltfDocument doc = instancedSource();
  doc.root["extensions"].erase("EXT_vendor_root");
  auto& used = doc.root["extensionsUsed"];
  used.erase(std::remove(used.begin(), used.end(), "EXT_vendor_root"), used.end());
  std::map<std::string, std::vector<uint8_t>> png;
  auto image = [&](std::vector<glm::vec4> texels, const std::string& name) {
    Texture t;
    t.width = static_cast<int>(texels.size());
    t.height = 1;
    t.texels = std::move(texels);
    png[name] = encodePng(t, false);
    return doc.addTexture(doc.addImage(png[name], name), -1);
  };
  const int diffuse = image({glm::vec4(0.8f, 0.6f, 0.4f, 1.0f)}, "diffuse");
  // Alpha codes 255 and 102: roughness codes 255 − round(255 × 0.5) = 127 and 255 − round(102 × 0.5) = 204.
  const int specGloss = image({glm::vec4(0.2f, 0.3f, 0.4f, 1.0f), glm::vec4(0.5f, 0.5f, 0.5f, 0.4f)}, "specgloss");
  const int fallbackMr = image({glm::vec4(0.0f, 0.9f, 1.0f, 1.0f)}, "fallback_mr");
  // Material 0 without a metal-rough fallback (its diffuse is the base colour); "glass" with one whose opacity
  // the diffuse factor lacks (the fallback's base colour is kept, as the bake read it).
  doc.root["materials"][0].erase("pbrMetallicRoughness");
  doc.root["materials"][0]["extensions"]["KHR_materials_pbrSpecularGlossiness"] = {
      {"diffuseFactor", {0.25, 0.5, 1.0, 1.0}}, {"diffuseTexture", {{"index", diffuse}, {"texCoord", 0}}},
      {"specularFactor", {0.1, 0.2, 0.3}}, {"glossinessFactor", 0.5}, {"specularGlossinessTexture", {{"index", specGloss}}}};
  doc.append("materials", {{"name", "matte"}, {"extensions", {{"KHR_materials_pbrSpecularGlossiness", {{"glossinessFactor", 0.25}}}}}});
  doc.append("materials", {{"name", "glass"},
                           {"pbrMetallicRoughness", {{"baseColorFactor", {0.9, 0.9, 1.0, 0.1}},
                                                     {"metallicRoughnessTexture", {{"index", fallbackMr}}}}},
                           {"extensions", {{"KHR_materials_pbrSpecularGlossiness", {{"diffuseFactor", {1, 1, 1, 1}}}}}}});
  doc.useExtension("KHR_materials_pbrSpecularGlossiness");
  doc.root["extensionsRequired"] = json::array({"KHR_materials_pbrSpecularGlossiness"});
  irbake::testing::writeDocument(doc, dir / "in" / "source.gltf");
  Scene loaded = loadScene(dir / "in" / "source.gltf");
  for (auto& p : loaded.primitives) {
    p.uv1.assign(p.positions.size(), glm::vec2(0.5f));
    p.lightmap = {0, 8, 4};
  }
  std::vector<Lightmap> maps = ramps();
  maps.resize(1);
  ExportOptions o;
  o.output = dir / "out" / "baked.gltf";
  exportGltf(loaded, maps, o);
  const json j = readJson(o.output);
  EXPECT_EQ(j.dump().find("KHR_materials_pbrSpecularGlossiness"), std::string::npos) << j.dump();
  for (const char* e : {"KHR_materials_specular", "KHR_materials_ior", "MOZ_lightmap"})
    EXPECT_NE(std::find(j["extensionsUsed"].begin(), j["extensionsUsed"].end(), e), j["extensionsUsed"].end()) << e;
  auto imageBytes = [&](const json& textureInfo) {
    const json& img = j["images"][j["textures"][textureInfo["index"].get<int>()]["source"].get<int>()];
    return readWholeFileForTest(dir / "out" / img["uri"].get<std::string>());
  };
  const json& m = j["materials"][0];
  ASSERT_TRUE(m["extensions"].contains("MOZ_lightmap")) << m.dump();
  const json& pbr = m["pbrMetallicRoughness"];
  EXPECT_EQ(pbr["baseColorFactor"], json::array({0.25, 0.5, 1.0, 1.0}));
  EXPECT_EQ(pbr["metallicFactor"], 0.0);
  EXPECT_EQ(pbr["roughnessFactor"], 1.0);
  EXPECT_EQ(pbr["baseColorTexture"]["texCoord"], 0);
  EXPECT_EQ(imageBytes(pbr["baseColorTexture"]), png["diffuse"]);
  const std::vector<uint8_t> mr = imageBytes(pbr["metallicRoughnessTexture"]);
  const Texture roughness = decodeImageToTexture(mr.data(), mr.size(), false, "roughness");
  ASSERT_EQ(roughness.width, 2);
  EXPECT_EQ(std::lround(roughness.texels[0].g * 255.0f), 127);
  EXPECT_EQ(std::lround(roughness.texels[1].g * 255.0f), 204);
  EXPECT_EQ(roughness.texels[1].r, 0.0f);
  EXPECT_EQ(roughness.texels[1].b, 0.0f);
  const json& specular = m["extensions"]["KHR_materials_specular"];
  EXPECT_EQ(specular["specularColorFactor"], json::array({0.1, 0.2, 0.3}));
  EXPECT_EQ(imageBytes(specular["specularColorTexture"]), png["specgloss"]);
  EXPECT_EQ(m["extensions"]["KHR_materials_ior"]["ior"], 1000.0);
  // The glass fallback's own metallic-roughness texture is gone with its image; diffuse, spec-gloss, roughness and
  // the light map are left.
  EXPECT_EQ(j["images"].size(), 4u) << j["images"].dump();
  const json& matte = j["materials"][1];
  EXPECT_EQ(matte["pbrMetallicRoughness"]["roughnessFactor"], 0.75);
  EXPECT_FALSE(matte["pbrMetallicRoughness"].contains("baseColorFactor"));
  EXPECT_EQ(matte["extensions"]["KHR_materials_specular"]["specularColorFactor"], json::array({1.0, 1.0, 1.0}));
  const json& glass = j["materials"][2];
  EXPECT_EQ(glass["pbrMetallicRoughness"]["baseColorFactor"], json::array({0.9, 0.9, 1.0, 0.1})) << glass.dump();
  EXPECT_FALSE(glass["pbrMetallicRoughness"].contains("metallicRoughnessTexture"));
  EXPECT_NO_THROW(loadScene(o.output));

  // A malformed factor (one the loader does not read) is refused naming the material and the field, before anything
  // is written.
  doc.root["materials"][1]["extensions"]["KHR_materials_pbrSpecularGlossiness"]["specularFactor"] = {0.5, 0.5};
  irbake::testing::writeDocument(doc, dir / "in" / "bad.gltf");
  Scene bad = loadScene(dir / "in" / "bad.gltf");
  for (auto& p : bad.primitives) {
    p.uv1.assign(p.positions.size(), glm::vec2(0.5f));
    p.lightmap = {0, 8, 4};
  }
  o.output = dir / "bad_out" / "baked.gltf";
  try {
    exportGltf(bad, maps, o);
    ADD_FAILURE() << "a 2-number specularFactor was exported";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("material 1 ('matte'): KHR_materials_pbrSpecularGlossiness.specularFactor must be 3 numbers"),
              std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(o.output));
}

// A .glb embeds every image: one file beside the EXR pages, the images in buffer views.
TEST(GltfExport, GlbEmbedsImages) {
  auto dir = irbake::testing::testFolder("export_glb");
  std::filesystem::create_directories(dir / "in");
  irbake::testing::writeDocument(instancedSource(), dir / "in" / "source.gltf");
  Scene loaded = loadScene(dir / "in" / "source.gltf");
  for (auto& p : loaded.primitives) {
    p.uv1 = p.uv0;
    p.lightmap = {0, 8, 4};
  }
  std::vector<Lightmap> maps = ramps();
  maps.resize(1);
  ExportOptions o;
  o.output = dir / "baked.glb";
  o.writeExrPages = false;
  exportGltf(loaded, maps, o);
  EXPECT_EQ(filesIn(dir), (std::vector<std::string>{"baked.glb", "source.bin", "source.gltf"}));
  Scene r = loadScene(o.output);
  ASSERT_EQ(r.primitives.size(), 2u);
  const Material& m = r.materials[r.primitives[0].material];
  ASSERT_GE(m.lightmapTexture, 0);
  EXPECT_EQ(r.textures[m.lightmapTexture].width, 8);
}

// glTF numbers TEXCOORD sets from 0 without gaps: a source primitive without TEXCOORD_0 shares the
// light-map UVs as set 0 (the validator's MESH_PRIMITIVE_INDEXED_SEMANTIC_CONTINUITY error otherwise);
// an emissiveFactor above 1 (invalid glTF the loader accepts) moves into KHR_materials_emissive_strength.
TEST(GltfExport, PrimitiveWithoutTexcoord0AndEmissiveAboveOneStayValid) {
  auto dir = irbake::testing::testFolder("export_texcoord_continuity");
  GltfDocument src = irbake::testing::meshDocument({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2});
  src.append("materials", {{"name", "lamp"}, {"emissiveFactor", {8.0, 4.0, 2.0}}});
  src.root["meshes"][0]["primitives"][0]["material"] = 0;
  irbake::testing::writeDocument(src, dir / "in.gltf");
  Scene loaded = loadScene(dir / "in.gltf");
  ASSERT_EQ(loaded.primitives.size(), 1u);
  loaded.primitives[0].uv1.assign(loaded.primitives[0].positions.size(), glm::vec2(0.5f));
  loaded.primitives[0].lightmap = {0, 8, 4};
  ExportOptions o;
  o.output = dir / "out" / "baked.gltf";
  std::vector<Lightmap> maps = ramps();
  maps.resize(1);
  exportGltf(loaded, maps, o);
  const json j = readJson(o.output);
  const json& at = j["meshes"][0]["primitives"][0]["attributes"];
  ASSERT_TRUE(at.contains("TEXCOORD_1"));
  EXPECT_EQ(at["TEXCOORD_0"], at["TEXCOORD_1"]);
  const json& m = j["materials"][0];
  EXPECT_EQ(m["emissiveFactor"], json::array({1.0, 0.5, 0.25}));
  EXPECT_DOUBLE_EQ(m["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"].get<double>(), 8.0);
  Scene r = loadScene(o.output);
  EXPECT_EQ(r.materials[r.primitives[0].material].emission(), glm::vec3(8.0f, 4.0f, 2.0f));
}

namespace {

// n unit quads in a row, each its own mesh ("quad<i>": POSITION, NORMAL, indices) on its own node, all
// with material 0.
GltfDocument separateQuads(int n) {
  GltfDocument doc;
  doc.append("materials", {{"name", "grey"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1.0}}}}});
  const std::vector<glm::vec3> normals(4, glm::vec3(0, 1, 0));
  json roots = json::array();
  for (int i = 0; i < n; ++i) {
    const float x = 2.0f * static_cast<float>(i);
    const std::vector<glm::vec3> pos = {{x, 0, 0}, {x + 1, 0, 0}, {x + 1, 0, -1}, {x, 0, -1}};
    json attributes = {{"POSITION", doc.addPositions(pos)}, {"NORMAL", doc.addVec3(normals)}};
    json prim = {{"attributes", attributes}, {"indices", doc.addIndices({0, 1, 2, 0, 2, 3})}, {"material", 0}};
    doc.append("meshes", {{"name", "quad" + std::to_string(i)}, {"primitives", json::array({prim})}});
    roots.push_back(doc.append("nodes", {{"mesh", i}}));
  }
  doc.root["scenes"] = json::array({{{"nodes", roots}}});
  doc.root["scene"] = 0;
  return doc;
}

// Quad i's light-map UVs: corner k of a cell that depends on i (so a mix-up between meshes shows).
glm::vec2 cellCorner(int i, int k) {
  const glm::vec2 corner[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const float cell = 1.0f / 128.0f;
  return cell * (glm::vec2(static_cast<float>(i % 128), static_cast<float>((i / 128) % 128)) + 0.1f + 0.8f * corner[k]);
}

}  // namespace

// A source of 10,000 separate meshes (the export once took time quadratic in their number): every
// mesh is written back with its TEXCOORD_1 (4 elements, the values given) and its page's MOZ_lightmap
// material, and the file reloads with all 10,000.
TEST(GltfExport, TenThousandSeparateMeshesEachGetTexcoord1AndTheirPageMaterial) {
  constexpr int kMeshes = 10000;
  auto dir = irbake::testing::testFolder("export_separate_meshes");
  std::filesystem::create_directories(dir / "in");
  irbake::testing::writeDocument(separateQuads(kMeshes), dir / "in" / "source.gltf");
  LoadOptions lo;
  lo.decodeImages = false;
  Scene loaded = loadScene(dir / "in" / "source.gltf", lo);
  ASSERT_EQ(loaded.primitives.size(), size_t(kMeshes));
  for (Primitive& p : loaded.primitives) {
    ASSERT_EQ(p.positions.size(), 4u);
    p.uv1.resize(4);
    for (int k = 0; k < 4; ++k) p.uv1[k] = cellCorner(p.gltfMesh, k);
    p.lightmap = {p.gltfMesh % 2, 8, 4};  // even meshes on page 0, odd on page 1
  }
  ExportOptions o;
  o.output = dir / "out" / "baked.gltf";
  exportGltf(loaded, ramps(), o);

  const json j = readJson(o.output);
  EXPECT_NE(std::find(j["extensionsUsed"].begin(), j["extensionsUsed"].end(), "MOZ_lightmap"), j["extensionsUsed"].end());
  // "grey" carries page 0 in place, its copy page 1: each with its page's texture and intensity.
  ASSERT_EQ(j["materials"].size(), 2u);
  ASSERT_EQ(j["meshes"].size(), size_t(kMeshes));
  ASSERT_EQ(j["nodes"].size(), size_t(kMeshes));
  int wrong = 0;
  for (int i = 0; i < kMeshes; ++i) {
    const json& mesh = j["meshes"][j["nodes"][i]["mesh"].get<int>()];
    const json& prims = mesh["primitives"];
    const json& prim = prims[0];
    const json& attributes = prim["attributes"];
    const json& moz = j["materials"][prim.value("material", -1)]["extensions"]["MOZ_lightmap"];
    const bool ok = mesh["name"] == "quad" + std::to_string(i) && prims.size() == 1 && attributes.contains("TEXCOORD_1") &&
                    j["accessors"][attributes["TEXCOORD_1"].get<int>()]["count"] == 4 &&
                    j["accessors"][attributes["TEXCOORD_1"].get<int>()]["type"] == "VEC2" &&
                    j["accessors"][attributes["POSITION"].get<int>()]["count"] == 4 && prim["extras"]["lightmap"]["page"] == i % 2 &&
                    moz["texCoord"] == 1 && std::abs(moz["intensity"].get<double>() - kPi * 2.5 * (i % 2 + 1)) < 1e-5;
    if (!ok && ++wrong <= 3) ADD_FAILURE() << "mesh " << i << ": " << mesh.dump();
  }
  EXPECT_EQ(wrong, 0);

  Scene r = loadScene(o.output);
  ASSERT_EQ(r.primitives.size(), size_t(kMeshes));
  ASSERT_EQ(r.lightmapExrPaths.size(), 2u);
  wrong = 0;
  for (const Primitive& p : r.primitives) {
    bool ok = p.gltfMesh >= 0 && p.uv1.size() == 4 && p.lightmap.page == p.gltfMesh % 2 &&
              r.materials[p.material].lightmapTexture >= 0 &&
              std::abs(r.materials[p.material].lightmapIntensity - 2.5f * (p.gltfMesh % 2 + 1)) < 1e-5f;
    for (int k = 0; ok && k < 4; ++k) ok = p.uv1[k] == cellCorner(p.gltfMesh, k) && p.positions[k] == loaded.primitives[p.gltfMesh].positions[k];
    if (!ok && ++wrong <= 3) ADD_FAILURE() << "reloaded primitive of mesh " << p.gltfMesh;
  }
  EXPECT_EQ(wrong, 0);
}

// glTF allows extras of any JSON type: a source whose root extras is a string (and whose node, mesh and material
// extras are a number, an array and a string) exports and reloads; the root value is kept as it was, without the
// EXR page list and sky that an object would carry. It was a raw JSON type error at the end of the bake.
TEST(GltfExport, NonObjectExtrasAreKept) {
  auto dir = irbake::testing::testFolder("export_extras");
  Scene src = twoQuadScene();
  for (auto& p : src.primitives) {
    p.uv1.clear();
    p.lightmap = {};
  }
  std::filesystem::create_directories(dir / "in");
  writeGltf(src, dir / "in" / "source.gltf");
  json source = readJson(dir / "in" / "source.gltf");
  source["nodes"][0]["extras"] = 42;
  source["meshes"][0]["extras"] = json::array({1, 2});
  source["materials"][0]["extras"] = "note";

  for (const json& root : {json("hello"), json::object({{"tag", "kept"}})}) {
    source["extras"] = root;
    std::ofstream(dir / "in" / "source.gltf") << source.dump();
    Scene loaded = loadScene(dir / "in" / "source.gltf");
    ASSERT_EQ(loaded.primitives.size(), 2u);
    for (int i = 0; i < 2; ++i) {
      loaded.primitives[i].uv1 = {{0.1f, 0.1f}, {0.9f, 0.1f}, {0.9f, 0.9f}, {0.1f, 0.9f}};
      loaded.primitives[i].lightmap = {i, 8, 4};
    }
    loaded.environment = Environment::uniform(glm::vec3(0.25f, 0.5f, 1.0f));  // the export records a sky
    ExportOptions o;
    o.output = dir / "out" / "baked.gltf";
    ASSERT_NO_THROW(exportGltf(loaded, ramps(), o)) << root.dump();
    const json j = readJson(o.output);
    EXPECT_EQ(j["nodes"][0]["extras"], 42);
    EXPECT_EQ(j["meshes"][0]["extras"], json::array({1, 2}));
    EXPECT_EQ(j["materials"][0]["extras"], "note");
    const Scene r = loadScene(o.output);
    ASSERT_EQ(r.primitives.size(), 2u);
    EXPECT_EQ(r.primitives[1].lightmap.page, 1);
    EXPECT_NEAR(r.materials[r.primitives[1].material].lightmapIntensity, 5.0f, 1e-5f);
    if (root.is_string()) {
      EXPECT_EQ(j["extras"], "hello");
      EXPECT_TRUE(r.lightmapExrPaths.empty());
      EXPECT_FALSE(r.environment.present());
    } else {
      EXPECT_EQ(j["extras"]["tag"], "kept");
      EXPECT_EQ(j["extras"]["lightmapPages"], json::array({"lightmap_0.exr", "lightmap_1.exr"}));
      EXPECT_EQ(r.lightmapExrPaths.size(), 2u);
      EXPECT_FLOAT_EQ(r.environment.uniformRadiance().z, 1.0f);
    }
  }
}
