// The portable GLB: base colour × map (+ emission) × exposure as sRGB 8-bit texels on the atlas UVs, unlit
// materials, only ratified extensions, the texture scale against a finer albedo texture, clipping.
#include <cstring>
#include <fstream>

#include <gtest/gtest.h>

#include "common/error.h"
#include "export/gltf_compact.h"
#include "export/portable_export.h"
#include "scene/gltf_source.h"
#include "scene/image_codec.h"
#include "testing/gltf_builder.h"

using namespace irbake;
using json = nlohmann::json;

namespace {

// A unit quad with base colour 0.5 on page 0 (8×8 texels), its uv1 covering [0.25, 0.75]², uv0 over [0, 1]².
Scene quadScene() {
  Scene s;
  Material m;
  m.name = "grey";
  m.baseColorFactor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  s.materials.push_back(m);
  Primitive p;
  p.name = "quad";
  p.positions = {{0, 0, 0}, {1, 0, 0}, {1, 0, -1}, {0, 0, -1}};
  p.normals.assign(4, glm::vec3(0, 1, 0));
  p.uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  p.uv1 = {{0.25f, 0.25f}, {0.75f, 0.25f}, {0.75f, 0.75f}, {0.25f, 0.75f}};
  p.indices = {0, 1, 2, 0, 2, 3};
  p.lightmap = {0, 8, 8};
  s.primitives.push_back(p);
  Camera c;
  c.name = "view";
  s.cameras.push_back(c);
  Light l;  // baked into the map: the portable file must not light the scene again
  l.type = LightType::Point;
  s.lights.push_back(l);
  return s;
}

Lightmap constantMap(float value, int size = 8) {
  Lightmap m;
  m.width = m.height = size;
  m.texels.assign(m.size(), glm::vec3(value));
  m.valid.assign(m.size(), 1);
  return m;
}

// A w×h checker of 0.2 / 0.8 (linear).
Texture checker(int w, int h) {
  Texture t;
  t.name = "checker";
  t.width = w;
  t.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) t.texels.push_back(glm::vec4(glm::vec3((x + y) % 2 ? 0.8f : 0.2f), 1.0f));
  return t;
}

int srgbCode(float linear) { return static_cast<int>(std::lround(linearToSrgb(linear) * 255.0f)); }

struct ReadBack {
  json root;
  GltfDocument doc;
  Texture image;  // image 0, its 8-bit codes / 255 (not decoded with the sRGB curve)
};

ReadBack readPortable(const std::filesystem::path& path) {
  GltfSource src = readGltfSource(path);
  std::vector<uint8_t> bin(src.bytes.begin() + static_cast<std::ptrdiff_t>(src.binOffset),
                           src.bytes.begin() + static_cast<std::ptrdiff_t>(src.binOffset + src.binSize));
  ReadBack r{src.json, GltfDocument(src.json, bin), {}};
  const json& view = r.root["bufferViews"][r.root["images"][0]["bufferView"].get<int>()];
  const size_t offset = view.value("byteOffset", size_t(0)), length = view["byteLength"].get<size_t>();
  r.image = decodeImageToTexture(bin.data() + offset, length, false, "portable");
  return r;
}

int code(const Texture& t, int x, int y, int channel) {
  return static_cast<int>(std::lround(t.texels[static_cast<size_t>(y) * t.width + x][channel] * 255.0f));
}

}  // namespace

TEST(PortableExport, BaseColourTimesMapIsAnSrgbTexelOnTheAtlasUvsUnlit) {
  auto dir = irbake::testing::testFolder("portable_quad");
  Scene s = quadScene();
  const std::vector<Lightmap> maps = {constantMap(0.4f)};
  json summary;
  writeAllAtomically({portableGlbFile(s, maps, dir / "portable.glb", {}, &summary)});
  ReadBack r = readPortable(dir / "portable.glb");

  // 0.5 × 0.4 = 0.2 → sRGB 0.4845 → code 124, on every texel (covered or filled by the dilation).
  ASSERT_EQ(srgbCode(0.2f), 124);
  ASSERT_EQ(r.image.width, 8);
  ASSERT_EQ(r.image.height, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      for (int ch = 0; ch < 3; ++ch) ASSERT_EQ(code(r.image, x, y, ch), 124) << x << "," << y;
      ASSERT_EQ(code(r.image, x, y, 3), 255);
    }
  EXPECT_EQ(r.root["extensionsUsed"], json::array({"KHR_materials_unlit"}));
  EXPECT_FALSE(r.root.contains("extensionsRequired"));
  ASSERT_EQ(r.root["materials"].size(), 1u);
  const json& mat = r.root["materials"][0];
  EXPECT_TRUE(mat["extensions"].contains("KHR_materials_unlit"));
  EXPECT_FALSE(mat["extensions"].contains("MOZ_lightmap"));
  EXPECT_EQ(mat["pbrMetallicRoughness"]["baseColorFactor"], json::array({1.0, 1.0, 1.0, 1.0}));
  EXPECT_EQ(mat["pbrMetallicRoughness"]["baseColorTexture"].value("texCoord", 0), 0);
  // The texture's sampler: linear, no mip maps (they would mix charts), clamped.
  const json& sampler = r.root["samplers"][r.root["textures"][0]["sampler"].get<int>()];
  EXPECT_EQ(sampler["minFilter"], 9729);
  EXPECT_EQ(sampler["wrapS"], 33071);
  // TEXCOORD_0 is the atlas UV; no TEXCOORD_1, no lights, the camera kept.
  const json& attributes = r.root["meshes"][0]["primitives"][0]["attributes"];
  EXPECT_FALSE(attributes.contains("TEXCOORD_1"));
  AccessorBytes uv = readAccessor(r.doc, attributes["TEXCOORD_0"].get<int>(), "portable");
  ASSERT_EQ(uv.count, 4u);
  std::vector<glm::vec2> uvs(4);
  std::memcpy(uvs.data(), uv.bytes.data(), sizeof(glm::vec2) * 4);
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(uvs[i], s.primitives[0].uv1[i]);
  EXPECT_FALSE(r.root.contains("extensions"));
  EXPECT_EQ(r.root["cameras"].size(), 1u);
  EXPECT_EQ(summary["pages"][0]["scale"], 1);
  EXPECT_EQ(summary["pages"][0]["clippedFraction"], 0.0);
}

TEST(PortableExport, ExposureScalesAndValuesAboveOneClip) {
  Scene s = quadScene();
  const Lightmap map = constantMap(0.4f);
  PortableOptions o;
  o.exposure = 4.0;  // 0.8 → sRGB 0.906 → 231
  PortablePage stats;
  Texture t = bakePortableTexture(s, map, 1, o, &stats);
  EXPECT_NEAR(t.texels[4 * 8 + 4].x, 0.8f, 1e-6f);
  EXPECT_EQ(srgbCode(t.texels[4 * 8 + 4].x), 231);
  EXPECT_EQ(stats.clippedFraction, 0.0);
  o.exposure = 8.0;  // 1.6: shown as 1, every covered texel counted
  t = bakePortableTexture(s, map, 1, o, &stats);
  EXPECT_EQ(t.texels[4 * 8 + 4].x, 1.0f);
  EXPECT_EQ(stats.clippedFraction, 1.0);
  o.exposure = 0.0;
  EXPECT_THROW(buildPortable(s, {map}, o), Error);
}

TEST(PortableExport, EmissionAddsToTheShownColour) {
  Scene s = quadScene();
  s.materials[0].emissiveFactor = glm::vec3(0.1f, 0.0f, 0.3f);
  Texture t = bakePortableTexture(s, constantMap(0.4f), 1, {});
  EXPECT_NEAR(t.texels[4 * 8 + 4].x, 0.3f, 1e-6f);
  EXPECT_NEAR(t.texels[4 * 8 + 4].y, 0.2f, 1e-6f);
  EXPECT_NEAR(t.texels[4 * 8 + 4].z, 0.5f, 1e-6f);
}

// The quad covers 4×4 map texels. A 64×64 albedo texture over it is 16 albedo texels per map texel: the
// scale is capped at 4 (and at 2 by a size limit of 16 texels); a 6×6 one (1.5 per map texel) gives 2;
// a 4×4 one (1) gives 1.
TEST(PortableExport, TextureScaleFollowsAFinerAlbedoTexture) {
  Scene s = quadScene();
  s.materials[0].baseColorTexture = 0;
  s.textures.push_back(checker(64, 64));
  EXPECT_EQ(portableScale(s, 0, 8, 8), 4);
  PortableOptions small;
  small.maxSize = 16;
  EXPECT_EQ(portableScale(s, 0, 8, 8, small), 2);
  s.textures[0] = checker(6, 6);
  EXPECT_EQ(portableScale(s, 0, 8, 8), 2);
  s.textures[0] = checker(4, 4);
  EXPECT_EQ(portableScale(s, 0, 8, 8), 1);
  s.materials[0].baseColorTexture = -1;
  EXPECT_EQ(portableScale(s, 0, 8, 8), 1);

  // At scale 4 the 32×32 texture samples the 4×4 checker at its own texel centres: the quad spans texels
  // 8..23, so texel (9, 9) reads the checker at (−0.125, −0.125) texels (0.2 weighted 0.78125 with the
  // wrapped 0.8 neighbours: 0.33125) and texel (13, 9) at (0.875, −0.125) (0.66875); times the map 0.5.
  s.materials[0].baseColorTexture = 0;
  s.materials[0].baseColorFactor = glm::vec4(1.0f);
  Texture t = bakePortableTexture(s, constantMap(0.5f), 4, {});
  ASSERT_EQ(t.width, 32);
  EXPECT_NEAR(t.texels[9 * 32 + 9].x, 0.165625f, 1e-5f);
  EXPECT_NEAR(t.texels[9 * 32 + 13].x, 0.334375f, 1e-5f);
}

TEST(PortableExport, PrimitiveWithoutPageKeepsItsBaseColourAndNamesAGlbOnly) {
  auto dir = irbake::testing::testFolder("portable_unpaged");
  Scene s = quadScene();
  Primitive extra = s.primitives[0];
  extra.lightmap = {};
  extra.uv1.clear();
  for (auto& p : extra.positions) p.y += 1.0f;
  Material red;
  red.name = "red";
  red.baseColorFactor = glm::vec4(0.9f, 0.1f, 0.1f, 1.0f);
  red.emissiveFactor = glm::vec3(1.0f);
  extra.material = 1;
  s.materials.push_back(red);
  s.primitives.push_back(extra);
  writeAllAtomically({portableGlbFile(s, {constantMap(0.4f)}, dir / "two.glb")});
  json j = readPortable(dir / "two.glb").root;
  ASSERT_EQ(j["materials"].size(), 2u);
  const json& m = j["materials"][j["meshes"][1]["primitives"][0]["material"].get<int>()];
  EXPECT_NEAR(m["pbrMetallicRoughness"]["baseColorFactor"][0].get<double>(), 0.9, 1e-6);
  EXPECT_FALSE(m["pbrMetallicRoughness"].contains("baseColorTexture"));
  EXPECT_FALSE(m.contains("emissiveFactor"));
  EXPECT_TRUE(m["extensions"].contains("KHR_materials_unlit"));
  EXPECT_EQ(j["extensionsUsed"], json::array({"KHR_materials_unlit"}));

  try {
    portableGlbFile(s, {constantMap(0.4f)}, dir / "portable.gltf");
    FAIL() << "a .gltf name was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Usage);
    EXPECT_NE(std::string(e.what()).find("portable.gltf"), std::string::npos);
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "portable.gltf"));
}

namespace {

// The image of texture `texture` in the written document, decoded with the sRGB curve (linear values).
Texture imageOfTexture(const ReadBack& r, int texture) {
  const int image = r.root["textures"][texture]["source"].get<int>();
  const json& view = r.root["bufferViews"][r.root["images"][image]["bufferView"].get<int>()];
  const size_t offset = view.value("byteOffset", size_t(0)), length = view["byteLength"].get<size_t>();
  return decodeImageToTexture(r.doc.bin.data() + offset, length, true, "tile");
}

}  // namespace

// A white quad over a whole 64×64 page whose map ramps from 0 to 10: the shown values go far above 1. The
// range is the 99.9th percentile of the texels (nearest rank 4092 of 4096: (4092 − 0.5) / 4096 × 10), so the
// written texture, decoded and times the range, gives back every texel but the 4 above it (0.098%) within
// one 8-bit sRGB code, and the file says the range.
TEST(PortableExport, RangeKeepsTheClippedTexelsUnderOnePerMille) {
  auto dir = irbake::testing::testFolder("portable_range");
  Scene s = quadScene();
  s.materials[0].baseColorFactor = glm::vec4(1.0f);
  s.primitives[0].uv1 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  s.primitives[0].lightmap = {0, 64, 64};
  Lightmap map = constantMap(0.0f, 64);
  for (size_t i = 0; i < map.size(); ++i) {
    const size_t rank = (i * 2654435761u) % map.size();  // a permutation of the ramp over the page
    map.texels[i] = glm::vec3(10.0f * (static_cast<float>(rank) + 0.5f) / static_cast<float>(map.size()));
  }
  json summary;
  writeAllAtomically({portableGlbFile(s, {map}, dir / "range.glb", {}, &summary)});
  const double range = summary["range"].get<double>();
  EXPECT_NEAR(range, 10.0 * (4091 + 0.5) / 4096, 1e-5);
  ReadBack r = readPortable(dir / "range.glb");
  EXPECT_NEAR(r.root["asset"]["extras"]["irbakePortable"]["range"].get<double>(), range, 1e-12);
  const Texture t = imageOfTexture(r, 0);
  ASSERT_EQ(t.width, 64);
  size_t clipped = 0;
  for (size_t i = 0; i < map.size(); ++i) {
    const double value = map.texels[i].x, back = t.texels[i].x * range;
    // One code at the top of the range is its widest step in linear terms: 1 − srgbToLinear(254.5/255).
    const double code = range * (1.0 - srgbToLinear(254.5f / 255.0f));
    if (value > range + 1e-6) {
      ++clipped;
      EXPECT_NEAR(back, range, code);
    } else {
      ASSERT_NEAR(back, value, code) << i;
    }
  }
  EXPECT_EQ(clipped, 4u);
  EXPECT_LE(static_cast<double>(clipped) / map.size(), 0.001);
  EXPECT_NEAR(summary["pages"][0]["clippedFraction"].get<double>(), 4.0 / 4096, 1e-12);
  EXPECT_NEAR(summary["pages"][0]["litClippedFraction"].get<double>(), 4.0 / 4096, 1e-12);

  // A dim bake is not brightened: the range is at least 1.
  for (glm::vec3& v : map.texels) v *= 0.05f;
  writeAllAtomically({portableGlbFile(s, {map}, dir / "dim.glb", {}, &summary)});
  EXPECT_EQ(summary["range"].get<double>(), 1.0);
  EXPECT_EQ(summary["pages"][0]["clippedFraction"].get<double>(), 0.0);
}

// An emitter's face is a lamp: it may clip (white, as irview shows it) and does not set the range.
TEST(PortableExport, EmittersDoNotSetTheRange) {
  Scene s = quadScene();
  Primitive lamp = s.primitives[0];
  lamp.uv1 = {{0.0f, 0.0f}, {0.2f, 0.0f}, {0.2f, 0.2f}, {0.0f, 0.2f}};
  lamp.material = 1;
  Material bright;
  bright.emissiveFactor = glm::vec3(1.0f);
  bright.emissiveStrength = 50.0f;
  s.materials.push_back(bright);
  s.primitives.push_back(lamp);
  const PortableBake bake = buildPortable(s, {constantMap(0.4f)});
  EXPECT_EQ(bake.range, 1.0);
  EXPECT_GT(bake.pages[0].clippedFraction, 0.0);
  EXPECT_EQ(bake.pages[0].litClippedFraction, 0.0);
}

// Nine quads on a 64×64 page, 16×16 texels each, with a texture limit of 32: nine tiles (the 2×2 grid's
// middle quads straddle its cells, so a 3×3 grid), each at most 32 texels a side, each quad's material reading
// its own tile; every texel the quads cover reads, through the tile, what the whole-page texture has there.
TEST(PortableExport, LargePageIsTiledIntoTexturesUnderTheLimit) {
  auto dir = irbake::testing::testFolder("portable_tiles");
  Scene s = quadScene();
  const Primitive quad = s.primitives[0];
  s.primitives.clear();
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      Primitive p = quad;
      p.name = "quad" + std::to_string(j * 3 + i);
      const glm::vec2 lo(4 + 20 * i, 4 + 20 * j);
      p.uv1 = {lo / 64.0f, (lo + glm::vec2(16, 0)) / 64.0f, (lo + glm::vec2(16, 16)) / 64.0f, (lo + glm::vec2(0, 16)) / 64.0f};
      for (glm::vec3& v : p.positions) v += glm::vec3(1.5f * i, 0.0f, -1.5f * j);
      p.lightmap = {0, 64, 64};
      s.primitives.push_back(p);
    }
  Lightmap map = constantMap(0.0f, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) map.texels[static_cast<size_t>(y) * 64 + x] = glm::vec3(x / 64.0f, y / 64.0f, 0.5f);
  const Texture whole = bakePortableTexture(s, map, 1, {});
  PortableOptions o;
  o.maxTextureSize = 32;
  json summary;
  writeAllAtomically({portableGlbFile(s, {map}, dir / "tiles.glb", o, &summary)});
  ReadBack r = readPortable(dir / "tiles.glb");
  ASSERT_EQ(summary["pages"][0]["tiles"].size(), 9u);
  ASSERT_EQ(r.root["images"].size(), 9u);
  ASSERT_EQ(r.root["meshes"].size(), 9u);
  for (size_t m = 0; m < 9; ++m) {
    const json& prim = r.root["meshes"][m]["primitives"][0];
    const json& mat = r.root["materials"][prim["material"].get<int>()];
    const Texture tile = imageOfTexture(r, mat["pbrMetallicRoughness"]["baseColorTexture"]["index"].get<int>());
    EXPECT_LE(tile.width, 32);
    EXPECT_LE(tile.height, 32);
    AccessorBytes uvBytes = readAccessor(r.doc, prim["attributes"]["TEXCOORD_0"].get<int>(), "tiles");
    std::vector<glm::vec2> uv(uvBytes.count);
    std::memcpy(uv.data(), uvBytes.bytes.data(), sizeof(glm::vec2) * uv.size());
    // The quad's texels: its UVs map the tile's texel (u·w − ½, v·h − ½) onto the page's texel of the same centre.
    const glm::vec2 page0 = s.primitives[m].uv1[0] * 64.0f, tile0 = uv[0] * glm::vec2(tile.width, tile.height);
    const glm::vec2 page2 = s.primitives[m].uv1[2] * 64.0f, tile2 = uv[2] * glm::vec2(tile.width, tile.height);
    EXPECT_NEAR(glm::length((page2 - page0) - (tile2 - tile0)), 0.0f, 1e-3f);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        const int px = static_cast<int>(page0.x) + x, py = static_cast<int>(page0.y) + y;
        const int tx = static_cast<int>(std::lround(tile0.x)) + x, ty = static_cast<int>(std::lround(tile0.y)) + y;
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(srgbCode(tile.texels[static_cast<size_t>(ty) * tile.width + tx][c]),
                    srgbCode(whole.texels[static_cast<size_t>(py) * 64 + px][c]))
              << "quad " << m << " texel " << x << "," << y;
      }
  }
}
