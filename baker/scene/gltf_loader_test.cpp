// Loader tests on hand-made glTF files: transforms, winding, primitive modes, normals, materials,
// textures, lights, cameras, extensions (compressed geometry too), and the DamagedHelmet counts (skipped without ../shared).
#include <algorithm>
#include <cmath>
#include <fstream>

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include "common/error.h"
#include "common/maths.h"
#include "export/exr_io.h"
#include "lights/light_kind.h"
#include "scene/environment.h"
#include "scene/gltf_decompress.h"
#include "scene/gltf_loader.h"
#include "imageio/image_io.h"
#include "scene/image_codec.h"
#include "testing/compressed_gltf.h"
#include "testing/gltf_builder.h"

using namespace irbake;
using irbake::testing::meshDocument;
using irbake::testing::testFolder;
using irbake::testing::writeDocument;
using json = nlohmann::json;

namespace {

const std::vector<glm::vec3> kTriangle = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};  // CCW seen from +Z

glm::vec3 faceNormal(const Primitive& p, size_t t) {
  const glm::vec3 &a = p.positions[p.indices[3 * t]], &b = p.positions[p.indices[3 * t + 1]], &c = p.positions[p.indices[3 * t + 2]];
  return glm::normalize(glm::cross(b - a, c - a));
}

void expectNear(const glm::vec3& a, const glm::vec3& b, float tol = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// Writes doc as <folder>/<name>.gltf and expects the load to throw `code` with a message naming the file
// and holding every one of `parts`.
void expectRefused(const GltfDocument& doc, const std::string& folder, const std::vector<std::string>& parts,
                   ErrorCode code = ErrorCode::InvalidData) {
  const auto file = testFolder(folder) / (folder + ".gltf");
  writeDocument(doc, file);
  try {
    loadScene(file);
    ADD_FAILURE() << folder << ": loaded, expected a refusal";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    const std::string what = e.what();
    EXPECT_NE(what.find(file.string()), std::string::npos) << what;
    for (const auto& p : parts) EXPECT_NE(what.find(p), std::string::npos) << "'" << p << "' not in: " << what;
  }
}

Scene loadDocument(const GltfDocument& doc, const std::string& folder) {
  const auto file = testFolder(folder) / (folder + ".gltf");
  writeDocument(doc, file);
  return loadScene(file);
}

// The triangle with one material (0) and one light (0) of the given JSON on node 1.
GltfDocument litDocument(const json& light, const json& material) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  doc.root["meshes"][0]["primitives"][0]["material"] = 0;
  doc.append("materials", material);
  doc.root["extensions"]["KHR_lights_punctual"]["lights"] = json::array({light});
  doc.root["nodes"].push_back({{"translation", {0, 0, 2}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  doc.root["scenes"][0]["nodes"] = {0, 1};
  return doc;
}

// The triangle on a node with a uniform scale.
GltfDocument scaledDocument(double scale) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  doc.root["nodes"][0]["scale"] = {scale, scale, scale};
  return doc;
}

}  // namespace

TEST(GltfLoader, NodeHierarchyTrsLandsInWorldSpace) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}});
  // Parent: translate (1,2,3). Child (holds the mesh): rotate +90° about Y, scale 2.
  glm::quat q = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0));
  doc.root["nodes"] = json::array({{{"translation", {1, 2, 3}}, {"children", {1}}},
                                   {{"mesh", 0}, {"rotation", {q.x, q.y, q.z, q.w}}, {"scale", {2, 2, 2}}}});
  auto dir = testFolder("loader_hierarchy");
  writeDocument(doc, dir / "h.gltf");
  Scene s = loadScene(dir / "h.gltf");
  ASSERT_EQ(s.primitives.size(), 1u);
  const Primitive& p = s.primitives[0];
  // R_y(90°) maps (1,0,0) → (0,0,−1) and (0,0,1) → (1,0,0).
  expectNear(p.positions[0], {1, 2, 3});
  expectNear(p.positions[1], {1, 2, 1});
  expectNear(p.positions[2], {1, 4, 3});
  expectNear(p.normals[0], {1, 0, 0});
  expectNear(faceNormal(p, 0), {1, 0, 0});
  EXPECT_EQ(p.node, 1);
  EXPECT_NEAR(p.nodeToWorld[3].x, 1.0f, 1e-6f);
}

TEST(GltfLoader, MirroredTransformFlipsWindingAndKeepsNormalsOutward) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}});
  doc.root["nodes"][0]["scale"] = {-1, 1, 1};
  // A second instance with a non-uniform scale tests the inverse-transpose on normals.
  doc.root["nodes"].push_back({{"mesh", 0}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -3, 0, 5, 0, 0, 1}}});
  doc.root["scenes"][0]["nodes"] = {0, 1};
  auto dir = testFolder("loader_mirror");
  writeDocument(doc, dir / "m.gltf");
  Scene s = loadScene(dir / "m.gltf");
  ASSERT_EQ(s.primitives.size(), 2u);
  const Primitive& mirrored = s.primitives[0];
  expectNear(mirrored.positions[1], {-1, 0, 0});
  // Mirroring in x keeps the normal (0,0,1) but reverses the visual winding: the loader swaps corners
  // so the geometric normal still agrees with the shading normal.
  expectNear(mirrored.normals[0], {0, 0, 1});
  expectNear(faceNormal(mirrored, 0), {0, 0, 1});
  EXPECT_EQ(mirrored.indices[1], 2u);
  const Primitive& flippedZ = s.primitives[1];
  expectNear(flippedZ.positions[0], {5, 0, 0});
  expectNear(flippedZ.normals[0], {0, 0, -1});
  expectNear(faceNormal(flippedZ, 0), {0, 0, -1});
}

TEST(GltfLoader, StripsAndFansAreTriangulatedWithConsistentWinding) {
  // Four vertices in the z = 0 plane, strip order; then the same as a fan.
  std::vector<glm::vec3> quad = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  GltfDocument doc = meshDocument(quad, {});
  doc.root["meshes"][0]["primitives"][0]["mode"] = 5;  // TRIANGLE_STRIP
  json fan = doc.root["meshes"][0]["primitives"][0];
  fan["mode"] = 6;  // TRIANGLE_FAN over 0,1,3,2 (same square)
  fan["indices"] = doc.addIndices({0, 1, 3, 2});
  doc.root["meshes"][0]["primitives"].push_back(fan);
  auto dir = testFolder("loader_strip");
  writeDocument(doc, dir / "s.gltf");
  Scene s = loadScene(dir / "s.gltf");
  ASSERT_EQ(s.primitives.size(), 2u);
  for (const auto& p : s.primitives) {
    ASSERT_EQ(p.triangleCount(), 2u);
    for (size_t t = 0; t < 2; ++t) expectNear(faceNormal(p, t), {0, 0, 1});
  }
  EXPECT_EQ(s.stats.normalsComputed, 2u);
}

// Without NORMAL, glTF requires flat normals: a unit cube of 8 shared vertices becomes 24 (one per corner
// and face orientation; the two triangles of a face still share theirs), every normal is exactly its
// face's, and sourceVertex leads back to the accessor vertex.
TEST(GltfLoader, MissingNormalsAreFlatAndSplitSharedCorners) {
  std::vector<glm::vec3> corners;
  for (int i = 0; i < 8; ++i) corners.push_back(glm::vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1));
  // Six faces, counter-clockwise seen from outside (corner bits: x = 1, y = 2, z = 4).
  const std::vector<uint32_t> faces[6] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<uint32_t> indices;
  for (const auto& f : faces) indices.insert(indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
  auto dir = testFolder("loader_flat");
  writeDocument(meshDocument(corners, indices), dir / "cube.gltf");
  Scene s = loadScene(dir / "cube.gltf");
  ASSERT_EQ(s.primitives.size(), 1u);
  const Primitive& p = s.primitives[0];
  EXPECT_EQ(s.stats.normalsComputed, 1u);
  EXPECT_EQ(p.triangleCount(), 12u);
  EXPECT_EQ(p.positions.size(), 24u);
  ASSERT_EQ(p.sourceVertex.size(), p.positions.size());
  for (size_t v = 0; v < p.positions.size(); ++v) EXPECT_EQ(p.positions[v], corners[p.sourceVertex[v]]) << v;
  for (size_t t = 0; t < p.triangleCount(); ++t) {
    const glm::vec3 f = faceNormal(p, t);
    EXPECT_NEAR(std::abs(f.x) + std::abs(f.y) + std::abs(f.z), 1.0f, 1e-6f);  // axis-aligned
    const glm::vec3 centre = (p.positions[p.indices[3 * t]] + p.positions[p.indices[3 * t + 1]] +
                              p.positions[p.indices[3 * t + 2]]) / 3.0f;
    EXPECT_GT(glm::dot(f, centre - glm::vec3(0.5f)), 0.0f) << t;  // outward
    for (int k = 0; k < 3; ++k) EXPECT_EQ(p.normals[p.indices[3 * t + k]], f) << t;
  }
}

TEST(GltfLoader, PointsAndLinesAreSkippedWithAWarning) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  json lines = doc.root["meshes"][0]["primitives"][0];
  lines["mode"] = 1;
  doc.root["meshes"][0]["primitives"].push_back(lines);
  auto dir = testFolder("loader_lines");
  writeDocument(doc, dir / "l.gltf");
  Scene s = loadScene(dir / "l.gltf");
  EXPECT_EQ(s.primitives.size(), 1u);
  EXPECT_EQ(s.stats.primitivesSkipped, 1u);
  ASSERT_FALSE(s.stats.warnings.empty());
  EXPECT_NE(s.stats.warnings[0].find("points or lines"), std::string::npos);
}

// A provided NORMAL with a zero vector (a broken exporter) gets the area-weighted adjacent face normals
// for that vertex; the others keep theirs.
TEST(GltfLoader, ZeroNormalsInAProvidedAttributeAreAreaWeighted) {
  // Vertex 0 is shared by a unit right triangle in z = 0 (area 0.5) and a 2×2 one in x = 0 (area 2).
  std::vector<glm::vec3> pos = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 2, 0}, {0, 0, 2}};
  GltfDocument doc = meshDocument(pos, {0, 1, 2, 0, 3, 4}, {{0, 0, 0}, {0, 0, 1}, {0, 0, 1}, {1, 0, 0}, {1, 0, 0}});
  auto dir = testFolder("loader_normals");
  writeDocument(doc, dir / "n.gltf");
  Scene s = loadScene(dir / "n.gltf");
  const Primitive& p = s.primitives[0];
  // Face normals: (0,0,1) × 0.5 and (1,0,0) × 2 → normalise (2, 0, 0.5).
  expectNear(p.normals[0], glm::normalize(glm::vec3(2.0f, 0.0f, 0.5f)));
  expectNear(p.normals[1], {0, 0, 1});
  expectNear(p.normals[3], {1, 0, 0});
}

TEST(GltfLoader, DegenerateTrianglesAreDroppedAndCounted) {
  std::vector<glm::vec3> pos = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}};
  // valid, repeated index, collinear (0,1,3), valid
  GltfDocument doc = meshDocument(pos, {0, 1, 2, 0, 0, 1, 0, 1, 3, 1, 2, 0});
  auto dir = testFolder("loader_degenerate");
  writeDocument(doc, dir / "d.gltf");
  Scene s = loadScene(dir / "d.gltf");
  EXPECT_EQ(s.stats.trianglesKept, 2u);
  EXPECT_EQ(s.stats.trianglesDropped, 2u);
  EXPECT_EQ(s.triangleCount(), 2u);
  // Never silently: the count is a warning.
  ASSERT_EQ(s.stats.warnings.size(), 1u);
  EXPECT_EQ(s.stats.warnings[0], "2 degenerate triangles (zero area or a repeated corner) dropped");
}

// KHR_materials_pbrSpecularGlossiness without a metal-rough fallback: the diffuse factor and texture are the albedo;
// a malformed diffuse factor is refused naming the material and the extension. With a fallback, the fallback.
TEST(GltfLoader, SpecularGlossinessDiffuseIsTheAlbedo) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  doc.root["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = doc.addVec2({{0, 0}, {1, 0}, {0, 1}});
  doc.root["meshes"][0]["primitives"][0]["material"] = 0;
  Texture t;
  t.width = t.height = 1;
  t.texels = {glm::vec4(1.0f)};
  const int fallback = doc.addTexture(doc.addImage(encodePng(t, false), "fallback"), -1);
  const int diffuse = doc.addTexture(doc.addImage(encodePng(t, false), "diffuse"), -1);
  doc.append("materials", {{"name", "old"},
                           {"extensions", {{"KHR_materials_pbrSpecularGlossiness",
                                            {{"diffuseFactor", {0.25, 0.5, 0.75, 1}}, {"diffuseTexture", {{"index", diffuse}, {"texCoord", 0}}},
                                             {"specularFactor", {0.04, 0.04, 0.04}}, {"glossinessFactor", 0.3}}}}}});
  doc.useExtension("KHR_materials_pbrSpecularGlossiness");
  doc.root["extensionsRequired"] = json::array({"KHR_materials_pbrSpecularGlossiness"});
  auto dir = testFolder("loader_spec_gloss");
  writeDocument(doc, dir / "t.gltf");
  Scene s = loadScene(dir / "t.gltf");
  ASSERT_EQ(s.materials.size(), 1u);
  expectNear(glm::vec3(s.materials[0].baseColorFactor), {0.25f, 0.5f, 0.75f});
  ASSERT_GE(s.materials[0].baseColorTexture, 0);
  EXPECT_EQ(s.textures[s.materials[0].baseColorTexture].gltfImage, doc.root["textures"][diffuse]["source"].get<int>());
  doc.root["materials"][0]["pbrMetallicRoughness"] = {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}, {"baseColorTexture", {{"index", fallback}}}};
  writeDocument(doc, dir / "fallback.gltf");
  Scene withFallback = loadScene(dir / "fallback.gltf");
  expectNear(glm::vec3(withFallback.materials[0].baseColorFactor), {0.5f, 0.5f, 0.5f});
  EXPECT_EQ(withFallback.textures[withFallback.materials[0].baseColorTexture].gltfImage,
            doc.root["textures"][fallback]["source"].get<int>());
  doc.root["materials"][0].erase("pbrMetallicRoughness");
  doc.root["materials"][0]["extensions"]["KHR_materials_pbrSpecularGlossiness"]["diffuseFactor"] = {0.25, 0.5};
  writeDocument(doc, dir / "bad.gltf");
  try {
    loadScene(dir / "bad.gltf");
    ADD_FAILURE() << "a 2-number diffuseFactor loaded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("material 0 ('old'): KHR_materials_pbrSpecularGlossiness diffuseFactor [0.25,0.5] must be 4"),
              std::string::npos) << e.what();
  }
}

TEST(GltfLoader, MaterialsTexturesAndEmissiveStrength) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  doc.root["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = doc.addVec2({{0, 0}, {1, 0}, {0, 1}});
  doc.root["meshes"][0]["primitives"][0]["material"] = 0;
  // 2×1 texture: sRGB 188 (linear 0.5029) and sRGB 255, written as PNG bytes.
  Texture t;
  t.width = 2;
  t.height = 1;
  t.texels = {glm::vec4(188 / 255.0f, 188 / 255.0f, 188 / 255.0f, 1.0f), glm::vec4(1.0f)};
  int image = doc.addImage(encodePng(t, false), "tex");
  int tex = doc.addTexture(image, doc.addSampler(WrapMode::ClampToEdge, WrapMode::MirroredRepeat, false));
  doc.append("materials", {{"name", "m"},
                           {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 1, 1, 1}}, {"baseColorTexture", {{"index", tex}}}}},
                           {"emissiveFactor", {1, 0.5, 0.25}},
                           {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 8}}}}},
                           {"alphaMode", "MASK"},
                           {"alphaCutoff", 0.25},
                           {"doubleSided", true}});
  auto dir = testFolder("loader_material");
  writeDocument(doc, dir / "t.gltf");
  Scene s = loadScene(dir / "t.gltf");
  ASSERT_EQ(s.materials.size(), 1u);
  const Material& m = s.materials[0];
  EXPECT_EQ(m.name, "m");
  expectNear(m.emission(), {8, 4, 2});
  EXPECT_EQ(m.alphaMode, AlphaMode::Mask);
  EXPECT_FLOAT_EQ(m.alphaCutoff, 0.25f);
  EXPECT_TRUE(m.doubleSided);
  ASSERT_EQ(m.baseColorTexture, 0);
  const Texture& tx = s.textures[0];
  ASSERT_EQ(tx.width, 2);
  EXPECT_EQ(tx.wrapS, WrapMode::ClampToEdge);
  EXPECT_EQ(tx.wrapT, WrapMode::MirroredRepeat);
  // sRGB decode: ((188/255 + 0.055)/1.055)^2.4 = 0.50289.
  EXPECT_NEAR(tx.texels[0].r, 0.50289f, 1e-4f);
  EXPECT_NEAR(tx.texels[1].g, 1.0f, 1e-6f);
  // baseColorAt multiplies the factor: at vertex 0 (uv (0,0), clamped to texel 0's centre region).
  glm::vec4 c = s.baseColorAt(s.primitives[0], 0, glm::vec2(0.0f));
  EXPECT_NEAR(c.r, 0.5f * 0.50289f, 1e-4f);
  EXPECT_NEAR(c.g, 0.50289f, 1e-4f);
}

TEST(GltfLoader, PunctualLightsTakeNodeTransforms) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  doc.root["extensions"]["KHR_lights_punctual"]["lights"] = json::array(
      {{{"type", "point"}, {"intensity", 10}, {"color", {1, 0.5, 0.25}}, {"range", 4}},
       {{"type", "spot"}, {"intensity", 3}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.6}}}},
       {{"type", "directional"}, {"intensity", 2}}});
  // Rotating −Z by −90° about X gives −Y: a light pointing straight down.
  glm::quat down = glm::angleAxis(glm::radians(-90.0f), glm::vec3(1, 0, 0));
  doc.root["nodes"].push_back({{"translation", {1, 2, 3}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  doc.root["nodes"].push_back({{"translation", {0, 5, 0}}, {"rotation", {down.x, down.y, down.z, down.w}},
                               {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  doc.root["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
  doc.root["scenes"][0]["nodes"] = {0, 1, 2, 3};
  auto dir = testFolder("loader_lights");
  writeDocument(doc, dir / "l.gltf");
  Scene s = loadScene(dir / "l.gltf");
  ASSERT_EQ(s.lights.size(), 3u);
  EXPECT_EQ(s.lights[0].type, LightType::Point);
  expectNear(s.lights[0].position, {1, 2, 3});
  expectNear(s.lights[0].color, {1, 0.5f, 0.25f});
  EXPECT_FLOAT_EQ(s.lights[0].range, 4.0f);
  // Point power = 4π I colour.
  EXPECT_NEAR(lightKind(s.lights[0]).power(s.lights[0]).x, 4.0 * M_PI * 10.0, 1e-3);
  EXPECT_EQ(s.lights[1].type, LightType::Spot);
  expectNear(s.lights[1].direction, {0, -1, 0});
  EXPECT_FLOAT_EQ(s.lights[1].outerConeAngle, 0.6f);
  EXPECT_EQ(s.lights[2].type, LightType::Directional);
  expectNear(s.lights[2].direction, {0, 0, -1});
}

TEST(GltfLoader, PerspectiveCameraFromNode) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  doc.append("cameras", {{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.05}, {"aspectRatio", 1.5}}}});
  glm::quat half = glm::angleAxis(glm::radians(180.0f), glm::vec3(0, 1, 0));
  doc.root["nodes"].push_back({{"camera", 0}, {"translation", {0, 1, -4}}, {"rotation", {half.x, half.y, half.z, half.w}}});
  doc.root["scenes"][0]["nodes"] = {0, 1};
  auto dir = testFolder("loader_camera");
  writeDocument(doc, dir / "c.gltf");
  Scene s = loadScene(dir / "c.gltf");
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_FLOAT_EQ(s.cameras[0].yfov, 0.7f);
  EXPECT_FLOAT_EQ(s.cameras[0].aspectRatio, 1.5f);
  expectNear(glm::vec3(s.cameras[0].cameraToWorld[3]), {0, 1, -4});
  expectNear(-glm::vec3(s.cameras[0].cameraToWorld[2]), {0, 0, 1});  // looks down −Z locally → +Z
}

// extras.irbake.mode on a light (mixed lighting): read per light, the KHR index kept; absent: no mode given.
TEST(GltfLoader, ReadsEachLightsBakeModeFromExtras) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  doc.root["extensions"]["KHR_lights_punctual"]["lights"] = json::array(
      {{{"type", "point"}, {"name", "plain"}},
       {{"type", "point"}, {"name", "masked"}, {"extras", {{"irbake", {{"mode", "shadowmask"}}}, {"other", 1}}}},
       {{"type", "directional"}, {"extras", {{"irbake", {{"mode", "indirect"}}}}}}});
  for (int i = 0; i < 3; ++i)
    doc.root["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", i}}}}}});
  doc.root["scenes"][0]["nodes"] = {0, 1, 2, 3};
  auto dir = testFolder("loader_light_modes");
  writeDocument(doc, dir / "l.gltf");
  const Scene s = loadScene(dir / "l.gltf");
  ASSERT_EQ(s.lights.size(), 3u);
  EXPECT_FALSE(s.lights[0].hasExtrasMode);
  EXPECT_TRUE(s.lights[1].hasExtrasMode);
  EXPECT_EQ(s.lights[1].extrasMode, LightMode::ShadowMask);
  EXPECT_EQ(s.lights[2].extrasMode, LightMode::Indirect);
  EXPECT_EQ(s.lights[2].gltfLight, 2);
  // A mode that is not a string or not one of the three stops the load naming the light (exit 2, as --light-mode).
  for (const json& bad : {json("bright"), json(3), json::object()}) {
    doc.root["extensions"]["KHR_lights_punctual"]["lights"][1]["extras"]["irbake"]["mode"] = bad;
    writeDocument(doc, dir / "bad.gltf");
    try {
      loadScene(dir / "bad.gltf");
      ADD_FAILURE() << "accepted mode " << bad.dump();
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Usage);
      EXPECT_NE(std::string(e.what()).find("light 1 ('masked'): extras.irbake.mode must be"), std::string::npos) << e.what();
    }
  }
}

// Per-object settings (extras.irbake on nodes and meshes): a node's setting holds for its descendants until a nearer
// node sets its own, each key on its own; the node chain wins over the mesh's extras; absent everywhere: baked, 1.
TEST(GltfLoader, ObjectSettingsFromNodeAndMeshExtras) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  doc.root["meshes"][0]["extras"]["irbake"] = {{"mode", "shadow-only"}, {"lightmapScale", 0.5}};
  doc.root["meshes"].push_back(doc.root["meshes"][0]);
  doc.root["meshes"][1].erase("extras");
  doc.root["nodes"] = json::array(
      {{{"name", "group"}, {"children", {1, 2}}, {"extras", {{"irbake", {{"mode", "probes"}, {"lightmapScale", 2}}}}}},
       {{"name", "inherits"}, {"mesh", 0}},
       {{"name", "overrides"}, {"mesh", 0}, {"extras", {{"irbake", {{"mode", "baked"}, {"note", 1}}}}}},
       {{"name", "mesh setting"}, {"mesh", 0}},
       {{"name", "off"}, {"mesh", 1}, {"extras", {{"irbake", {{"mode", "off"}, {"lightmapScale", 4}, {"note", 2}}}}}},
       {{"name", "plain"}, {"mesh", 1}, {"extras", "not an object"}}});
  doc.root["scenes"][0]["nodes"] = {0, 3, 4, 5};
  const Scene s = loadDocument(doc, "loader_object_settings");
  ASSERT_EQ(s.primitives.size(), 5u);
  const std::vector<std::pair<ObjectMode, float>> expected = {{ObjectMode::Probes, 2.0f}, {ObjectMode::Baked, 2.0f},
                                                              {ObjectMode::ShadowOnly, 0.5f}, {ObjectMode::Off, 4.0f},
                                                              {ObjectMode::Baked, 1.0f}};
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(s.primitives[i].mode, expected[i].first) << i;
    EXPECT_EQ(s.primitives[i].lightmapScale, expected[i].second) << i;
  }
  // An unknown key is named once, at the first object that has it.
  const auto unknown = std::count_if(s.stats.warnings.begin(), s.stats.warnings.end(), [](const std::string& w) {
    return w.find("extras.irbake has unknown key(s) \"note\"") != std::string::npos;
  });
  EXPECT_EQ(unknown, 1);
  EXPECT_TRUE(std::any_of(s.stats.warnings.begin(), s.stats.warnings.end(),
                          [](const std::string& w) { return w.find("node 2 ('overrides')") != std::string::npos; }));
}

// A bad mode or texel scale stops the load naming the file, the node or mesh, the key and the value.
TEST(GltfLoader, BadObjectSettingsAreRefusedNamingTheObject) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  doc.root["nodes"][0]["name"] = "crate";
  doc.root["meshes"][0]["name"] = "box";
  const std::vector<std::pair<json, std::string>> badScales = {
      {json(0), "0"}, {json(-1.5), "-1.5"}, {json(65), "65"}, {json(0.01), "0.01"}, {json("2"), "\"2\""},
      {json(nullptr), "null"}, {json::array({2}), "[2]"}};
  int i = 0;
  for (const auto& [value, shown] : badScales) {
    doc.root["nodes"][0]["extras"]["irbake"] = {{"lightmapScale", value}};
    expectRefused(doc, "loader_bad_scale_" + std::to_string(i++),
                  {"node 0 ('crate')", "extras.irbake.lightmapScale must be a number from 1/64 to 64", "(got " + shown + ")"});
  }
  for (const json& mode : {json("shadow"), json(3), json("Baked")}) {
    doc.root["nodes"][0]["extras"]["irbake"] = {{"mode", mode}};
    expectRefused(doc, "loader_bad_mode_" + std::to_string(i++),
                  {"node 0 ('crate')", "extras.irbake.mode must be \"baked\", \"shadow-only\", \"probes\" or \"off\"",
                   "(got " + mode.dump() + ")"});
  }
  doc.root["nodes"][0]["extras"]["irbake"] = 5;
  expectRefused(doc, "loader_bad_irbake", {"node 0 ('crate')", "extras.irbake must be an object (got 5)"});
  doc.root["nodes"][0].erase("extras");
  doc.root["meshes"][0]["extras"]["irbake"] = {{"lightmapScale", 100}};
  expectRefused(doc, "loader_bad_mesh_scale", {"mesh 0 ('box')", "lightmapScale", "(got 100)"});
  // The range's ends are settings, not errors.
  for (double edge : {1.0 / 64.0, 64.0}) {
    doc.root["meshes"][0]["extras"]["irbake"] = {{"lightmapScale", edge}};
    EXPECT_EQ(loadDocument(doc, "loader_scale_edge").primitives.at(0).lightmapScale, float(edge));
  }
}

TEST(GltfLoader, ReadsMozLightmapPrimitiveRecordsAndPageList) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  auto& prim = doc.root["meshes"][0]["primitives"][0];
  prim["attributes"]["TEXCOORD_1"] = doc.addVec2({{0.1f, 0.1f}, {0.9f, 0.1f}, {0.1f, 0.9f}});
  prim["extras"]["lightmap"] = {{"page", 2}, {"width", 256}, {"height", 128}};
  prim["material"] = 0;
  Texture t;
  t.width = t.height = 1;
  t.texels = {glm::vec4(0.5f, 0.25f, 1.0f, 1.0f)};
  int tex = doc.addTexture(doc.addImage(encodePng(t, false), "lm"), -1);
  doc.append("materials", {{"extensions", {{"MOZ_lightmap", {{"index", tex}, {"texCoord", 1}, {"intensity", 3.5}}}}}});
  doc.root["extras"]["lightmapPages"] = {"pages/lightmap_0.exr"};
  auto dir = testFolder("loader_moz");
  writeDocument(doc, dir / "m.gltf");
  Scene s = loadScene(dir / "m.gltf");
  const Primitive& p = s.primitives[0];
  EXPECT_EQ(p.lightmap.page, 2);
  EXPECT_EQ(p.lightmap.width, 256);
  EXPECT_EQ(p.lightmap.height, 128);
  ASSERT_EQ(p.uv1.size(), 3u);
  EXPECT_FLOAT_EQ(p.uv1[1].x, 0.9f);
  const Material& m = s.materials[0];
  ASSERT_GE(m.lightmapTexture, 0);
  EXPECT_FLOAT_EQ(m.lightmapIntensity, 3.5f);
  // Light-map PNGs are linear: 128/255 stays 0.50196, not sRGB-decoded.
  EXPECT_NEAR(s.textures[m.lightmapTexture].texels[0].r, 128.0f / 255.0f, 1e-5f);
  ASSERT_EQ(s.lightmapExrPaths.size(), 1u);
  EXPECT_EQ(std::filesystem::path(s.lightmapExrPaths[0]), dir / "pages/lightmap_0.exr");
}

// MOZ_lightmap's units: a file marked extras.irbake.mozLightmap = "irradiance" has intensity × texel = E, read
// as the map value E/π (intensity / π); an older irbake's (generator "irbake…", no marker) is E/π already;
// another marker value is not the marker. Another tool's file, or one naming no generator, is read per the
// specification whether or not it has the marker.
TEST(GltfLoader, MozLightmapIsReadPerSpecUnlessAnOlderIrbakeWroteIt) {
  auto intensityOf = [](const json& extras, const char* name, const json& generator = "irbake") {
    GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
    if (generator.is_null())
      doc.root["asset"].erase("generator");
    else
      doc.root["asset"]["generator"] = generator;
    auto& prim = doc.root["meshes"][0]["primitives"][0];
    prim["attributes"]["TEXCOORD_1"] = doc.addVec2({{0.1f, 0.1f}, {0.9f, 0.1f}, {0.1f, 0.9f}});
    prim["material"] = 0;
    Texture t;
    t.width = t.height = 1;
    t.texels = {glm::vec4(0.5f, 0.25f, 1.0f, 1.0f)};
    const int tex = doc.addTexture(doc.addImage(encodePng(t, true), "lm"), -1);
    json moz = {{"index", tex}, {"texCoord", 1}, {"intensity", 3.5}};
    if (!extras.is_null()) moz["extras"] = extras;
    doc.append("materials", {{"extensions", {{"MOZ_lightmap", moz}}}});
    auto dir = testFolder(name);
    writeDocument(doc, dir / "m.gltf");
    return loadScene(dir / "m.gltf").materials[0].lightmapIntensity;
  };
  const json marker = {{"colorSpace", "srgb"}, {"irbake", {{"mozLightmap", "irradiance"}}}};
  const float spec = static_cast<float>(3.5 / kPi);
  EXPECT_FLOAT_EQ(intensityOf(marker, "loader_moz_marked"), spec);
  EXPECT_FLOAT_EQ(intensityOf({{"colorSpace", "srgb"}}, "loader_moz_unmarked"), 3.5f);
  EXPECT_FLOAT_EQ(intensityOf(json(), "loader_moz_no_extras"), 3.5f);
  EXPECT_FLOAT_EQ(intensityOf({{"irbake", {{"mozLightmap", "radiance"}}}}, "loader_moz_other"), 3.5f);
  EXPECT_FLOAT_EQ(intensityOf({{"irbake", "irradiance"}}, "loader_moz_not_object"), 3.5f);
  EXPECT_FLOAT_EQ(intensityOf({{"colorSpace", "srgb"}}, "loader_moz_irbake_from", "irbake (from Blender)"), 3.5f);
  // Other tools' files carry no marker and follow the specification.
  EXPECT_FLOAT_EQ(intensityOf(json(), "loader_moz_other_tool", "Khronos glTF Blender I/O"), spec);
  EXPECT_FLOAT_EQ(intensityOf(json(), "loader_moz_other_tool_prefix", "THREE.GLTFExporter irbake"), spec);
  EXPECT_FLOAT_EQ(intensityOf(json(), "loader_moz_no_generator", json()), spec);
  EXPECT_FLOAT_EQ(intensityOf(marker, "loader_moz_other_tool_marked", "glTF-Transform"), spec);
}

// The viewer's maps (LoadOptions::shadingMaps): TANGENT to world space (w flipped by a mirroring node),
// normalTexture (linear, texCoord, scale) and IRBAKE_lightmap_directional (three linear PNGs, scales, EXR paths
// beside the glTF). A bake's load (the default options) reads none of them.
TEST(GltfLoader, ShadingMapsTangentsNormalTextureAndDirectionalExtension) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}});
  auto& prim = doc.root["meshes"][0]["primitives"][0];
  prim["attributes"]["TEXCOORD_0"] = doc.addVec2({{0, 0}, {1, 0}, {0, 1}});
  const std::vector<glm::vec4> tangents(3, glm::vec4(2, 0, 0, 1));  // unnormalised on purpose
  doc.append("accessors", {{"bufferView", doc.addBufferView(tangents.data(), tangents.size() * sizeof(glm::vec4), 34962)},
                           {"componentType", 5126}, {"count", 3}, {"type", "VEC4"}});
  prim["attributes"]["TANGENT"] = doc.root["accessors"].size() - 1;
  prim["material"] = 0;
  Texture t;
  t.width = t.height = 1;
  t.texels = {glm::vec4(128 / 255.0f, 64 / 255.0f, 1.0f, 1.0f)};
  auto texture = [&](const char* name) { return doc.addTexture(doc.addImage(encodePng(t, false), name), -1); };
  const int normal = texture("normal");
  json l1 = json::array();
  for (int k = 0; k < 3; ++k) l1.push_back({{"index", texture("l1")}, {"texCoord", 1}, {"scale", 0.25 * (k + 1)}});
  doc.append("materials", {{"normalTexture", {{"index", normal}, {"texCoord", 0}, {"scale", 0.5}}},
                           {"extensions", {{"IRBAKE_lightmap_directional",
                                            {{"l1", l1}, {"exr", {"a_l1x.exr", "a_l1y.exr", "a%20l1z.exr"}}}}}}});
  doc.root["nodes"][0]["scale"] = {-1, 1, 1};  // mirrored: w flips, xyz follows the node
  auto dir = testFolder("loader_shading_maps");
  writeDocument(doc, dir / "s.gltf");
  LoadOptions viewer;
  viewer.shadingMaps = true;
  const Scene s = loadScene(dir / "s.gltf", viewer);
  const Primitive& p = s.primitives[0];
  ASSERT_EQ(p.tangents.size(), 3u);
  expectNear(glm::vec3(p.tangents[0]), {-1, 0, 0});
  EXPECT_EQ(p.tangents[0].w, -1.0f);
  const Material& m = s.materials[0];
  ASSERT_GE(m.normalTexture, 0);
  EXPECT_EQ(m.normalTexCoord, 0);
  EXPECT_FLOAT_EQ(m.normalScale, 0.5f);
  EXPECT_NEAR(s.textures[m.normalTexture].texels[0].g, 64.0f / 255.0f, 1e-6f);  // linear, not sRGB-decoded
  ASSERT_TRUE(m.hasDirectionalTextures());
  for (int k = 0; k < 3; ++k) {
    EXPECT_FLOAT_EQ(m.directionalScales[k], 0.25f * (k + 1));
    EXPECT_NEAR(s.textures[m.directionalTextures[k]].texels[0].r, 128.0f / 255.0f, 1e-6f);
  }
  EXPECT_EQ(std::filesystem::path(m.directionalExrPaths[0]), dir / "a_l1x.exr");
  EXPECT_EQ(std::filesystem::path(m.directionalExrPaths[2]), dir / "a l1z.exr");

  const Scene bake = loadScene(dir / "s.gltf");
  EXPECT_TRUE(bake.primitives[0].tangents.empty());
  EXPECT_EQ(bake.materials[0].normalTexture, -1);
  EXPECT_FALSE(bake.materials[0].hasDirectionalTextures());
  EXPECT_TRUE(bake.textures.empty());
}

TEST(GltfLoader, ExrAndMissingImagesLoadWithWarnings) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  doc.root["meshes"][0]["primitives"][0]["material"] = 0;
  doc.append("images", {{"uri", "lightmap_0.exr"}});
  doc.append("images", {{"uri", "missing.png"}});
  doc.append("textures", {{"source", 0}});
  doc.append("textures", {{"source", 1}});
  doc.append("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 1}}}}}});
  auto dir = testFolder("loader_exr");
  std::ofstream(dir / "lightmap_0.exr") << "not really an exr";
  writeDocument(doc, dir / "e.gltf");
  Scene s = loadScene(dir / "e.gltf");
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].width, 0);  // missing: sampled as white
  EXPECT_FALSE(s.stats.warnings.empty());
  EXPECT_NEAR(s.baseColorAt(s.primitives[0], 0, glm::vec2(0.3f)).r, 1.0f, 1e-6f);
}

TEST(GltfLoader, GlbRoundTripThroughOurWriter) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  auto dir = testFolder("loader_glb");
  writeDocument(doc, dir / "t.glb");
  EXPECT_FALSE(std::filesystem::exists(dir / "t.bin"));
  Scene s = loadScene(dir / "t.glb");
  ASSERT_EQ(s.triangleCount(), 1u);
  expectNear(s.primitives[0].positions[2], {0, 1, 0});
}

TEST(GltfLoader, RequireLightNeedsALightOrAnEmitter) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  auto dir = testFolder("loader_nolight");
  writeDocument(doc, dir / "n.gltf");
  Scene s = loadScene(dir / "n.gltf");
  try {
    requireLight(s, dir / "n.gltf");
    FAIL() << "expected NoLight";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NoLight);
    EXPECT_NE(std::string(e.what()).find("--sun"), std::string::npos);
  }
  s.materials[s.primitives[0].material].emissiveFactor = glm::vec3(1.0f);
  EXPECT_NO_THROW(requireLight(s, dir / "n.gltf"));
}

TEST(GltfLoader, UriEscapeIsRefusedBeforeAnyRead) {
  auto dir = testFolder("loader_escape");
  std::filesystem::create_directories(dir / "scene");
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  writeDocument(doc, dir / "outside.gltf");  // writes outside.bin next to the scene folder
  json j = json::parse(std::ifstream(dir / "outside.gltf"));
  j["buffers"][0]["uri"] = "%2E%2E/outside.bin";  // "../" hidden behind escapes: still refused
  std::ofstream(dir / "scene" / "s.gltf") << j.dump();
  try {
    loadScene(dir / "scene" / "s.gltf");
    FAIL() << "expected InvalidData";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidData);
    EXPECT_NE(std::string(e.what()).find("escapes the scene folder"), std::string::npos);
  }
}

TEST(GltfLoader, DamagedHelmetCounts) {
  const char* src = std::getenv("IRBAKE_SOURCE_DIR");
  std::filesystem::path file = std::filesystem::path(src ? src : ".") / "../shared/scenes/damaged_helmet/DamagedHelmet.gltf";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "third-party scene not present: " << file;
  Scene s = loadScene(file);
  EXPECT_EQ(s.triangleCount(), 15452u);
  EXPECT_EQ(s.stats.trianglesDropped, 0u);
  ASSERT_EQ(s.materials.size(), 1u);
  // Base colour and emissive textures are the ones the baker uses (normal/metal/AO are not decoded).
  ASSERT_EQ(s.textures.size(), 2u);
  for (const auto& t : s.textures) {
    EXPECT_EQ(t.width, 2048);
    EXPECT_EQ(t.height, 2048);
  }
  EXPECT_TRUE(s.materials[0].isEmissive());
  EXPECT_GE(s.materials[0].emissiveTexture, 0);
}

TEST(GltfLoader, SharedChildLatticeIsCappedNotExpanded) {
  // 40 levels of two nodes, each the child of both nodes above: 2^40 paths, no cycle.
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  json nodes = json::array();
  for (int level = 0; level < 40; ++level)
    for (int k = 0; k < 2; ++k) {
      json n = {{"mesh", 0}};
      if (level + 1 < 40) n["children"] = {2 * (level + 1), 2 * (level + 1) + 1};
      nodes.push_back(n);
    }
  doc.root["nodes"] = nodes;
  doc.root["scenes"][0]["nodes"] = {0, 1};
  auto dir = testFolder("loader_lattice");
  writeDocument(doc, dir / "l.gltf");
  try {
    loadScene(dir / "l.gltf");
    FAIL() << "expected InvalidData";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidData);
    EXPECT_NE(std::string(e.what()).find("absurd size"), std::string::npos) << e.what();
  }
}

// Colours are checked per component: (−1, −1, −1) was accepted (only NaN/Inf were caught) and gave a negative map.
TEST(GltfLoader, NegativeOrNonFiniteColoursAreRefused) {
  const json light = {{"type", "point"}, {"intensity", 5}, {"color", {0.5, 1, 0.25}}};
  const json material = {{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}}}, {"emissiveFactor", {1, 0.5, 0}}};
  const Scene ok = loadDocument(litDocument(light, material), "loader_colours_ok");
  ASSERT_EQ(ok.lights.size(), 1u);
  expectNear(ok.lights[0].color, {0.5f, 1.0f, 0.25f});
  expectNear(ok.materials[0].emission(), {1.0f, 0.5f, 0.0f});

  json badLight = light;
  badLight["color"] = {-1, -1, -1};
  expectRefused(litDocument(badLight, material), "loader_light_negative", {"light 0", "negative or non-finite colour (-1, -1, -1)"});
  badLight["color"] = {1, -0.001, 1};
  expectRefused(litDocument(badLight, material), "loader_light_negative_one", {"light 0", "colour (1, -0.001, 1)"});
  badLight["color"] = {1, 1e39, 1};  // a double beyond float: Inf once read
  expectRefused(litDocument(badLight, material), "loader_light_inf", {"light 0", "non-finite colour"});

  json badBase = material;
  badBase["pbrMetallicRoughness"]["baseColorFactor"] = {-0.5, 0.5, 0.5, 1};
  expectRefused(litDocument(light, badBase), "loader_base_negative", {"material 0", "baseColorFactor (-0.5, 0.5, 0.5)"});
  badBase["pbrMetallicRoughness"]["baseColorFactor"] = {0.5, 0.5, 0.5, -1};
  expectRefused(litDocument(light, badBase), "loader_alpha_negative", {"material 0", "baseColorFactor", "alpha -1"});
  json badEmissive = material;
  badEmissive["emissiveFactor"] = {-1, -1, -1};
  badEmissive["name"] = "lamp";
  expectRefused(litDocument(light, badEmissive), "loader_emissive_negative", {"material 0 ('lamp')", "emissiveFactor (-1, -1, -1)"});
}

// A negative strength made the scene look unlit ("no light"): it is refused at load, naming the material.
TEST(GltfLoader, NegativeEmissiveStrengthIsRefused) {
  const json light = {{"type", "point"}, {"intensity", 5}};
  json material = {{"name", "glow"}, {"emissiveFactor", {1, 1, 1}},
                   {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 0}}}}}};
  const Scene zero = loadDocument(litDocument(light, material), "loader_strength_zero");
  EXPECT_FALSE(zero.materials[0].isEmissive());  // 0 is allowed: no emission
  material["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = -2;
  expectRefused(litDocument(light, material), "loader_strength_negative",
                {"material 0 ('glow')", "emissiveStrength must be ≥ 0", "-2"});
}

// KHR_lights_punctual: 0 ≤ innerConeAngle < outerConeAngle ≤ π/2.
TEST(GltfLoader, SpotConeAnglesOutsideTheSpecAreRefused) {
  auto spot = [](double inner, double outer) {
    return json{{"type", "spot"}, {"name", "beam"}, {"intensity", 3}, {"spot", {{"innerConeAngle", inner}, {"outerConeAngle", outer}}}};
  };
  const json material = json::object();
  const Scene ok = loadDocument(litDocument(spot(0.0, static_cast<float>(M_PI / 2)), material), "loader_spot_ok");
  EXPECT_FLOAT_EQ(ok.lights[0].outerConeAngle, static_cast<float>(M_PI / 2));  // π/2 written as a float is accepted
  const std::string rule = "0 ≤ innerConeAngle < outerConeAngle ≤ π/2";
  expectRefused(litDocument(spot(0.6, 0.3), material), "loader_spot_inverted", {"light 0 ('beam')", "inner 0.6, outer 0.3", rule});
  expectRefused(litDocument(spot(0.4, 0.4), material), "loader_spot_equal", {"light 0", rule});
  expectRefused(litDocument(spot(-0.1, 0.3), material), "loader_spot_negative", {"light 0", "inner -0.1", rule});
  expectRefused(litDocument(spot(0.2, 2.0), material), "loader_spot_wide", {"light 0", "outer 2", rule});
}

// glTF 2.0: a loader must refuse a file whose extensionsRequired it does not support.
TEST(GltfLoader, UnsupportedRequiredExtensionIsRefused) {
  GltfDocument doc = litDocument({{"type", "point"}, {"intensity", 5}},
                                 {{"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 2}}}}}});
  doc.root["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_emissive_strength"};
  doc.root["extensionsRequired"] = {"KHR_lights_punctual", "KHR_materials_emissive_strength"};
  EXPECT_EQ(loadDocument(doc, "loader_required_ok").lights.size(), 1u);
  for (const char* name : {"EXT_unknown_vendor_geometry", "KHR_texture_basisu"}) {
    doc.root["extensionsRequired"] = {"KHR_lights_punctual", name};
    expectRefused(doc, std::string("loader_required_") + name, {std::string("requires extension ") + name, "extensionsRequired"});
  }
}

// Quantised positions (KHR_mesh_quantization, normalised shorts) read like any accessor: that extension may be required.
TEST(GltfLoader, RequiredMeshQuantizationLoads) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  const int16_t q[12] = {0, 0, 0, 0, 32767, 0, 0, 0, 0, 16384, 0, 0};  // 3 × (x, y, z, pad): 4-byte aligned elements
  const int view = doc.addBufferView(q, sizeof q, 34962);
  doc.root["bufferViews"][view]["byteStride"] = 8;
  doc.append("accessors", {{"bufferView", view}, {"componentType", 5122}, {"normalized", true}, {"count", 3}, {"type", "VEC3"},
                           {"min", {0, 0, 0}}, {"max", {1, 0.5, 0}}});
  doc.root["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = doc.root["accessors"].size() - 1;
  doc.root["extensionsUsed"] = {"KHR_mesh_quantization"};
  doc.root["extensionsRequired"] = {"KHR_mesh_quantization"};
  const Scene s = loadDocument(doc, "loader_quantized");
  ASSERT_EQ(s.triangleCount(), 1u);
  expectNear(s.primitives[0].positions[1], {1, 0, 0});
  expectNear(s.primitives[0].positions[2], {0, 16384 / 32767.0f, 0});
}

// extras may be any JSON value (glTF 2.0): strings, numbers and arrays on the root, nodes, meshes and materials load.
TEST(GltfLoader, ExtrasOfAnyTypeLoad) {
  GltfDocument doc = litDocument({{"type", "point"}, {"intensity", 5}}, {{"extras", "material note"}});
  doc.root["extras"] = "hello";
  doc.root["nodes"][0]["extras"] = 42;
  doc.root["nodes"][1]["extras"] = json::array({1, "two", nullptr});
  doc.root["meshes"][0]["extras"] = json::array({1, 2});
  doc.root["meshes"][0]["primitives"][0]["extras"] = 3.5;
  const Scene s = loadDocument(doc, "loader_extras");
  EXPECT_EQ(s.triangleCount(), 1u);
  EXPECT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.primitives[0].lightmap.page, -1);
  EXPECT_TRUE(s.lightmapExrPaths.empty());
  EXPECT_FALSE(s.environment.present());
  for (const json& root : {json(7), json::array({"a"}), json(nullptr), json(true)}) {
    doc.root["extras"] = root;
    EXPECT_EQ(loadDocument(doc, "loader_extras_root").triangleCount(), 1u) << root.dump();
  }
}

// A 1×1 equirectangular map is a constant sky: loaded as uniform, its integral exactly 4π L.
TEST(GltfLoader, OnePixelEnvironmentIsUniform) {
  const auto dir = testFolder("loader_env_1x1");
  Lightmap px;
  px.width = px.height = 1;
  px.texels = {glm::vec3(0.5f, 1.0f, 2.0f)};
  px.valid = {1};
  writeExr(px, dir / "sky.exr");
  const Environment env = loadEnvironment(dir / "sky.exr", 3.0f, 45.0f);
  ASSERT_TRUE(env.present());
  EXPECT_TRUE(env.isUniform());
  expectNear(env.uniformRadiance(), {1.5f, 3.0f, 6.0f});
  expectNear(env.radiance(glm::normalize(glm::vec3(1, 2, 3))), {1.5f, 3.0f, 6.0f});
  EXPECT_NEAR(env.integral().z, 4.0 * M_PI * 6.0, 1e-9);
}

// Scale: refused outside 1e-4 … 1e9 m (extent) and beyond 1e9 m (any coordinate), never dropped silently.
TEST(GltfLoader, ScenesOutsideTheSupportedScaleAreRefused) {
  const std::string rescale = "rescale the scene (node scale)";
  expectRefused(scaledDocument(1e10), "loader_scale_1e10", {"node 0", "mesh 0", "coordinate of 1e10 m", "supported 1e9 m", rescale});
  expectRefused(scaledDocument(1e30), "loader_scale_1e30", {"node 0", "mesh 0", "coordinate of 1e30 m", rescale});
  expectRefused(scaledDocument(1e-8), "loader_scale_1e-8",
                {"scene extent 1e-8 m", "outside the supported 1e-4 … 1e9 m", rescale});
  expectRefused(meshDocument({{0, 0, 0}, {1e38f, 0, 0}, {0, 1e38f, 0}}, {0, 1, 2}), "loader_position_1e38",
                {"node 0", "mesh 0", "coordinate of 1e38 m", rescale});
  // A scale that overflows float on a large position: non-finite, refused naming node and mesh.
  GltfDocument overflow = meshDocument({{0, 0, 0}, {1e20f, 0, 0}, {0, 1, 0}}, {0, 1, 2});
  overflow.root["nodes"][0]["scale"] = {1e20, 1, 1};
  expectRefused(overflow, "loader_scale_overflow", {"node 0", "mesh 0", "NaN/Inf in world space"});
  // Every coordinate within 1e9 m, but 2e9 m wide.
  GltfDocument wide = meshDocument({{-1e9f, 0, 0}, {1e9f, 0, 0}, {0, 1e9f, 0}}, {0, 1, 2});
  expectRefused(wide, "loader_extent_2e9", {"scene extent 2e9 m", "outside the supported 1e-4 … 1e9 m"});
  // A point light beyond the range: its walk would start at an unusable coordinate.
  GltfDocument farLight = litDocument({{"type", "point"}, {"intensity", 5}}, json::object());
  farLight.root["nodes"][1]["translation"] = {0, 5e12, 0};
  expectRefused(farLight, "loader_light_far", {"light 0", "node 1", "coordinate of 5e12 m", rescale});
}

TEST(GltfLoader, ScenesInsideTheSupportedScaleLoad) {
  for (double scale : {1e-4, 1e-3, 1.0, 1e8, 1e9}) {
    const Scene s = loadDocument(scaledDocument(scale), "loader_scale_ok");
    ASSERT_EQ(s.triangleCount(), 1u) << scale;
    EXPECT_EQ(s.stats.trianglesDropped, 0u) << scale;
    EXPECT_FLOAT_EQ(s.primitives[0].positions[1].x, static_cast<float>(scale));
    EXPECT_FLOAT_EQ(s.primitives[0].positions[2].y, static_cast<float>(scale));
    EXPECT_TRUE(s.stats.warnings.empty()) << scale;
  }
  // Far from the origin for its size: loads, with a warning about float precision there.
  GltfDocument far = meshDocument(kTriangle, {0, 1, 2});
  far.root["nodes"][0]["translation"] = {1e5, 0, 0};
  const Scene s = loadDocument(far, "loader_far_from_origin");
  ASSERT_EQ(s.stats.warnings.size(), 1u);
  EXPECT_NE(s.stats.warnings[0].find("move it nearer the origin"), std::string::npos) << s.stats.warnings[0];
}

namespace {

// The triangle with every TEXCOORD_0 at `uv`, and material 0 whose base colour and emissive textures are a
// 2×1 image, black then white (sRGB 0 and 255: linear 0 and 1), clamped; `transform` on both references.
GltfDocument twoTexelDocument(glm::vec2 uv, const json& transform) {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  doc.root["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = doc.addVec2({uv, uv, uv});
  doc.root["meshes"][0]["primitives"][0]["material"] = 0;
  Texture t;
  t.width = 2;
  t.height = 1;
  t.texels = {glm::vec4(0, 0, 0, 1), glm::vec4(1.0f)};
  const int tex = doc.addTexture(doc.addImage(encodePng(t, true), "two"), doc.addSampler(WrapMode::ClampToEdge, WrapMode::ClampToEdge, false));
  json info = {{"index", tex}};
  if (!transform.is_null()) info["extensions"]["KHR_texture_transform"] = transform;
  doc.append("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", info}}}, {"emissiveTexture", info}, {"emissiveFactor", {1, 1, 1}}});
  doc.root["extensionsUsed"] = {"KHR_texture_transform"};
  doc.root["extensionsRequired"] = {"KHR_texture_transform"};
  return doc;
}

// The triangle on node 0 (translated by (10, 0, 0)) instanced three times by EXT_mesh_gpu_instancing:
// translations (0,0,0), (1,0,0), (0,2,0); rotations identity, 90° about z, identity; scales 1, 1, 2.
GltfDocument instancedDocument() {
  GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
  doc.root["nodes"][0]["translation"] = {10, 0, 0};
  const int t = doc.addVec3({{0, 0, 0}, {1, 0, 0}, {0, 2, 0}});
  const float h = std::sqrt(0.5f);
  const std::vector<float> q = {0, 0, 0, 1, 0, 0, h, h, 0, 0, 0, 1};
  const int view = doc.addBufferView(q.data(), q.size() * sizeof(float));
  const int r = doc.append("accessors", {{"bufferView", view}, {"componentType", 5126}, {"count", 3}, {"type", "VEC4"}});
  const int sc = doc.addVec3({{1, 1, 1}, {1, 1, 1}, {2, 2, 2}});
  doc.root["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"] = {{"TRANSLATION", t}, {"ROTATION", r}, {"SCALE", sc}};
  doc.root["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
  doc.root["extensionsRequired"] = {"EXT_mesh_gpu_instancing"};
  return doc;
}

// Two triangles of a unit square in z = 0, CCW seen from +Z.
const std::vector<glm::vec3> kSquare = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
const std::vector<uint32_t> kSquareIndices = {0, 1, 2, 0, 2, 3};

std::filesystem::path writeGlb(const irbake::testing::GlbParts& parts, const std::string& folder) {
  const auto file = testFolder(folder) / (folder + ".glb");
  const std::vector<uint8_t> bytes = irbake::testing::glbBytes(parts);
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return file;
}

void expectGlbRefused(const irbake::testing::GlbParts& parts, const std::string& folder, const std::vector<std::string>& parts_) {
  const auto file = writeGlb(parts, folder);
  try {
    loadScene(file);
    ADD_FAILURE() << folder << ": loaded, expected a refusal";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidData) << e.what();
    const std::string what = e.what();
    EXPECT_NE(what.find(file.string()), std::string::npos) << what;
    for (const auto& p : parts_) EXPECT_NE(what.find(p), std::string::npos) << "'" << p << "' not in: " << what;
  }
}

// The square's two triangles: area 1 in total, every normal +Z, every corner one of the square's.
void expectSquare(const Scene& scene) {
  ASSERT_EQ(scene.primitives.size(), 1u);
  const Primitive& p = scene.primitives[0];
  ASSERT_EQ(p.indices.size(), 6u);
  double area = 0.0;
  for (size_t t = 0; t < 2; ++t) {
    const glm::vec3 &a = p.positions[p.indices[3 * t]], &b = p.positions[p.indices[3 * t + 1]], &c = p.positions[p.indices[3 * t + 2]];
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
    expectNear(faceNormal(p, t), {0, 0, 1});
  }
  EXPECT_NEAR(area, 1.0, 1e-6);
  for (const glm::vec3& v : p.positions)
    EXPECT_TRUE(std::any_of(kSquare.begin(), kSquare.end(), [&](const glm::vec3& s) { return glm::length(s - v) < 1e-6f; }));
}

bool warned(const Scene& scene, const std::string& part) {
  return std::any_of(scene.stats.warnings.begin(), scene.stats.warnings.end(),
                     [&](const std::string& w) { return w.find(part) != std::string::npos; });
}

}  // namespace

// KHR_texture_transform, closed form on a 2-texel image (texel centres at u = 1/4 and 3/4): UV (1/8, 1/2)
// clamps to the black texel; scale 2 takes it to 1/4, the black centre; an offset of half a texel (1/4) on
// top lands on 1/2, halfway: bilinear 0.5. A rotation of π/2 maps (u, v) to (v, −u): UV (0.3, 0.75) reads
// the white texel (the opposite turn would read u = −0.75, clamped black). texCoord overrides the set.
TEST(GltfLoader, TextureTransformOnBaseColourAndEmissiveHasItsClosedForm) {
  auto at = [](const Scene& s) {
    return std::make_pair(s.baseColorAt(s.primitives[0], 0, glm::vec2(0.3f)).r, s.emissionAt(s.primitives[0], 0, glm::vec2(0.3f)).r);
  };
  const Scene plain = loadDocument(twoTexelDocument({0.125f, 0.5f}, nullptr), "loader_uvt_plain");
  EXPECT_NEAR(at(plain).first, 0.0f, 1e-6f);
  const Scene scaled = loadDocument(twoTexelDocument({0.125f, 0.5f}, {{"scale", {2, 1}}}), "loader_uvt_scale");
  EXPECT_NEAR(at(scaled).first, 0.0f, 1e-6f);
  const Scene both = loadDocument(twoTexelDocument({0.125f, 0.5f}, {{"offset", {0.25, 0}}, {"scale", {2, 1}}}), "loader_uvt_both");
  EXPECT_NEAR(at(both).first, 0.5f, 1e-5f);
  EXPECT_NEAR(at(both).second, 0.5f, 1e-5f);
  const Material& m = both.materials[0];
  EXPECT_TRUE(m.baseColorUvTransform.present);
  const glm::vec3 viaMatrix = m.baseColorUvTransform.matrix() * glm::vec3(0.125f, 0.5f, 1.0f);
  EXPECT_NEAR(viaMatrix.x, 0.5f, 1e-6f);
  const Scene turned = loadDocument(twoTexelDocument({0.3f, 0.75f}, {{"rotation", kPi / 2}}), "loader_uvt_rotation");
  EXPECT_NEAR(at(turned).first, 1.0f, 1e-5f);
  EXPECT_NEAR(at(turned).second, 1.0f, 1e-5f);
  const Scene set1 = loadDocument(twoTexelDocument({0.125f, 0.5f}, {{"texCoord", 1}}), "loader_uvt_texcoord");
  EXPECT_EQ(set1.materials[0].baseColorTexCoord, 1);
  EXPECT_EQ(set1.materials[0].emissiveTexCoord, 1);
}

TEST(GltfLoader, BrokenTextureTransformIsRefusedNamingTheExtension) {
  expectRefused(twoTexelDocument({0, 0}, {{"offset", {1}}}), "loader_uvt_bad_offset", {"KHR_texture_transform offset", "baseColorTexture", "material 0"});
  expectRefused(twoTexelDocument({0, 0}, {{"rotation", "left"}}), "loader_uvt_bad_rotation", {"KHR_texture_transform rotation"});
  expectRefused(twoTexelDocument({0, 0}, {{"texCoord", -1}}), "loader_uvt_bad_texcoord", {"KHR_texture_transform texCoord"});
}

// irview's normal map does not apply the transform: a load for the viewer warns, naming the extension.
TEST(GltfLoader, TextureTransformOnANormalMapWarnsTheViewer) {
  GltfDocument doc = twoTexelDocument({0, 0}, nullptr);
  doc.root["materials"][0]["normalTexture"] = {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"scale", {2, 2}}}}}}};
  const auto file = testFolder("loader_uvt_normal") / "n.gltf";
  writeDocument(doc, file);
  LoadOptions viewer;
  viewer.shadingMaps = true;
  const Scene s = loadScene(file, viewer);
  const auto& w = s.stats.warnings;
  EXPECT_EQ(std::count_if(w.begin(), w.end(), [](const std::string& x) { return x.find("KHR_texture_transform") != std::string::npos; }), 1);
}

// EXT_mesh_gpu_instancing: world = node · T · R · S per instance. Vertex (1, 0, 0) of the triangle lands at
// (11, 0, 0), at (10 + 1 + 0, 1, 0) under the 90° turn, and at (10 + 2, 2, 0) scaled by 2 and moved up 2.
TEST(GltfLoader, GpuInstancesAreMeshInstancesOfTheirOwn) {
  const Scene s = loadDocument(instancedDocument(), "loader_gpu_instancing");
  ASSERT_EQ(s.primitives.size(), 3u);
  EXPECT_EQ(s.stats.gpuInstancedNodes, 1u);
  EXPECT_EQ(s.stats.gpuInstances, 3u);
  const glm::vec3 expected[3] = {{11, 0, 0}, {11, 1, 0}, {12, 2, 0}};
  for (int i = 0; i < 3; ++i) {
    const Primitive& p = s.primitives[i];
    EXPECT_EQ(p.node, 0);
    EXPECT_EQ(p.instance, i);
    expectNear(p.positions[1], expected[i]);
    expectNear(glm::vec3(p.nodeToWorld * glm::vec4(1, 0, 0, 1)), expected[i]);
    expectNear(glm::vec3(p.instanceToNode * glm::vec4(1, 0, 0, 1)), expected[i] - glm::vec3(10, 0, 0));
    expectNear(faceNormal(p, 0), {0, 0, 1});
  }
}

TEST(GltfLoader, BrokenGpuInstancingIsRefusedNamingExtensionNodeAndAccessor) {
  GltfDocument doc = instancedDocument();
  doc.root["nodes"][0]["name"] = "props";
  auto withAttribute = [&](const char* name, auto add, int& accessor) {
    GltfDocument d = doc;
    accessor = add(d);
    d.root["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"][name] = accessor;
    return d;
  };
  int a = -1;
  GltfDocument shortScale = withAttribute("SCALE", [](GltfDocument& d) { return d.addVec3({{1, 1, 1}, {1, 1, 1}}); }, a);
  expectRefused(shortScale, "loader_gpu_count", {"EXT_mesh_gpu_instancing", "node 0 ('props')", "accessor " + std::to_string(a), "SCALE"});
  GltfDocument flat = withAttribute("TRANSLATION", [](GltfDocument& d) { return d.addVec2({{0, 0}, {1, 0}, {2, 0}}); }, a);
  expectRefused(flat, "loader_gpu_type", {"EXT_mesh_gpu_instancing", "TRANSLATION", "accessor " + std::to_string(a), "components"});
  GltfDocument nan = withAttribute("TRANSLATION", [](GltfDocument& d) { return d.addVec3({{0, 0, 0}, {std::nanf(""), 0, 0}, {0, 0, 0}}); }, a);
  expectRefused(nan, "loader_gpu_nan", {"EXT_mesh_gpu_instancing", "TRANSLATION", "accessor " + std::to_string(a), "NaN"});
  GltfDocument missing = doc;
  missing.root["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["ROTATION"] = 99;
  expectRefused(missing, "loader_gpu_missing", {"EXT_mesh_gpu_instancing", "ROTATION", "accessor 99"});
}

// EXT_texture_webp: the WebP source is decoded (OpenImageIO reads WebP); an unreadable WebP falls back to
// the texture's core source, and without one it is refused naming the extension and the image.
TEST(GltfLoader, WebpTexturesAreDecodedWithTheirFallback) {
  const auto dir = testFolder("loader_webp");
  imageio::Pixels px;
  px.width = 2;
  px.height = 2;
  px.channels = 3;
  px.u8 = {255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0};
  imageio::api().writeFile((dir / "red.webp").string(), "webp", px, -1, "red.webp");
  std::ifstream in(dir / "red.webp", std::ios::binary);
  const std::vector<uint8_t> webp((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(webp.size(), 12u);
  Texture grey;
  grey.width = grey.height = 1;
  grey.texels = {glm::vec4(0.5f, 0.5f, 0.5f, 1.0f)};
  auto document = [&](const std::vector<uint8_t>& webpBytes, bool fallback) {
    GltfDocument doc = meshDocument(kTriangle, {0, 1, 2});
    doc.root["meshes"][0]["primitives"][0]["material"] = 0;
    const int w = doc.addImage(webpBytes, "red", "image/webp");
    const int png = doc.addImage(encodePng(grey, false), "grey");
    json texture = {{"extensions", {{"EXT_texture_webp", {{"source", w}}}}}};
    if (fallback) texture["source"] = png;
    doc.append("textures", texture);
    doc.append("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
    doc.root["extensionsUsed"] = {"EXT_texture_webp"};
    if (!fallback) doc.root["extensionsRequired"] = {"EXT_texture_webp"};
    return doc;
  };
  const Scene s = loadDocument(document(webp, false), "loader_webp_read");
  const glm::vec4 c = s.baseColorAt(s.primitives[0], 0, glm::vec2(0.3f));
  EXPECT_NEAR(c.r, 1.0f, 0.01f);
  EXPECT_NEAR(c.g, 0.0f, 0.01f);
  std::vector<uint8_t> broken(webp.begin(), webp.begin() + 16);
  const Scene f = loadDocument(document(broken, true), "loader_webp_fallback");
  // The fallback PNG holds byte 128, read as sRGB colour.
  EXPECT_NEAR(f.baseColorAt(f.primitives[0], 0, glm::vec2(0.3f)).g, srgbToLinear(128 / 255.0f), 1e-4f);
  expectRefused(document(broken, false), "loader_webp_refused", {"EXT_texture_webp", "image 0", "red"});
}

TEST(GltfLoader, MeshoptCompressedViewsAreDecodedAndTheFallbackBufferNeedsNoData) {
  const Scene scene = loadScene(writeGlb(irbake::testing::meshoptParts(kSquare, kSquareIndices), "meshopt_square"));
  expectSquare(scene);
  EXPECT_TRUE(warned(scene, "input used EXT_meshopt_compression"));
  EXPECT_EQ(scene.stats.decodedExtensions, std::vector<std::string>{"EXT_meshopt_compression"});
}

TEST(GltfLoader, DracoPrimitivesAreDecodedIntoTheirAccessors) {
  const Scene scene = loadScene(writeGlb(irbake::testing::dracoParts(kSquare, kSquareIndices), "draco_square"));
  expectSquare(scene);
  EXPECT_EQ(scene.stats.decodedExtensions, std::vector<std::string>{"KHR_draco_mesh_compression"});
}

TEST(GltfLoader, BrokenMeshoptViewsAreRefusedNamingTheExtensionAndView) {
  using irbake::testing::meshoptParts;
  auto parts = meshoptParts(kSquare, kSquareIndices);
  parts.json["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["mode"] = "QUADS";
  expectGlbRefused(parts, "meshopt_bad_mode", {"EXT_meshopt_compression", "buffer view 1", "mode QUADS"});
  parts = meshoptParts(kSquare, kSquareIndices);
  parts.json["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["byteStride"] = 6;
  expectGlbRefused(parts, "meshopt_bad_stride", {"EXT_meshopt_compression", "buffer view 1", "byteStride 6"});
  parts = meshoptParts(kSquare, kSquareIndices);
  parts.json["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["count"] = 5;
  expectGlbRefused(parts, "meshopt_bad_count", {"EXT_meshopt_compression", "buffer view 0", "count 5"});
  parts = meshoptParts(kSquare, kSquareIndices);
  parts.json["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["filter"] = "OCTAHEDRAL";
  expectGlbRefused(parts, "meshopt_bad_filter", {"EXT_meshopt_compression", "buffer view 1", "filter OCTAHEDRAL"});
  parts = meshoptParts(kSquare, kSquareIndices);
  parts.json["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["byteLength"] = 8;  // cut short
  expectGlbRefused(parts, "meshopt_truncated", {"EXT_meshopt_compression", "buffer view 1", "does not decode"});
  parts = meshoptParts(kSquare, kSquareIndices);
  parts.json["accessors"][0]["bufferView"] = 2;
  parts.json["bufferViews"].push_back({{"buffer", 1}, {"byteOffset", 0}, {"byteLength", 4}});  // plain view into the fallback
  expectGlbRefused(parts, "meshopt_plain_view_of_fallback", {"EXT_meshopt_compression", "buffer view 2", "fallback buffer"});
}

TEST(GltfLoader, BrokenDracoPrimitivesAreRefusedNamingTheExtensionAndAccessor) {
  using irbake::testing::dracoParts;
  auto parts = dracoParts(kSquare, kSquareIndices);
  std::fill(parts.bin.begin(), parts.bin.end(), uint8_t(0x5A));
  expectGlbRefused(parts, "draco_bad_stream", {"KHR_draco_mesh_compression", "mesh 0 primitive 0", "does not decode"});
  parts = dracoParts(kSquare, kSquareIndices);
  parts.json["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["POSITION"] = 7;
  expectGlbRefused(parts, "draco_missing_id", {"KHR_draco_mesh_compression", "accessor 1 (POSITION)", "id 7 is not in the stream"});
  parts = dracoParts(kSquare, kSquareIndices);
  parts.json["accessors"][1]["count"] = 99;
  expectGlbRefused(parts, "draco_bad_count", {"KHR_draco_mesh_compression", "accessor 1 (POSITION)", "count 99"});
  parts = dracoParts(kSquare, kSquareIndices);
  parts.json["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["NORMAL"] = 1;
  expectGlbRefused(parts, "draco_unmapped_attribute", {"KHR_draco_mesh_compression", "attribute NORMAL"});
}
