// Accessor reading (strides, sparse), gathering (stride padding, min/max) and compaction (what is kept,
// what is dropped, every reference renumbered) on hand-made documents.
#include <cstring>

#include <gtest/gtest.h>

#include "common/error.h"
#include "export/gltf_compact.h"

using namespace irbake;
using json = nlohmann::json;

namespace {

// Four VEC2 unsigned shorts (x = 10 i, y = 10 i + 1) interleaved with 4 bytes of padding (stride 8).
int stridedUshortAccessor(GltfDocument& doc) {
  std::vector<uint16_t> data;
  for (uint16_t i = 0; i < 4; ++i) data.insert(data.end(), {uint16_t(10 * i), uint16_t(10 * i + 1), 0xFFFF, 0xFFFF});
  const int view = doc.addBufferView(data.data(), data.size() * 2, 34962);
  doc.root["bufferViews"][view]["byteStride"] = 8;
  return doc.append("accessors", {{"bufferView", view}, {"componentType", 5123}, {"count", 4}, {"type", "VEC2"}});
}

}  // namespace

TEST(GltfCompact, ReadsStridedAndSparseAccessors) {
  GltfDocument doc;
  const int strided = stridedUshortAccessor(doc);
  AccessorBytes a = readAccessor(doc, strided, "doc");
  ASSERT_EQ(a.elementSize, 4u);
  ASSERT_EQ(a.count, 4u);
  uint16_t v[2];
  std::memcpy(v, a.bytes.data() + 3 * 4, 4);
  EXPECT_EQ(v[0], 30);
  EXPECT_EQ(v[1], 31);

  // Sparse without a base view: zeros, with element 2 replaced by (7, 8, 9).
  const uint8_t index = 2;
  const float value[3] = {7, 8, 9};
  const int iv = doc.addBufferView(&index, 1), vv = doc.addBufferView(value, sizeof value);
  const int sparse = doc.append("accessors", {{"componentType", 5126}, {"count", 3}, {"type", "VEC3"},
                                              {"sparse", {{"count", 1}, {"indices", {{"bufferView", iv}, {"componentType", 5121}}},
                                                          {"values", {{"bufferView", vv}}}}}});
  a = readAccessor(doc, sparse, "doc");
  ASSERT_EQ(a.bytes.size(), 36u);
  float f[9];
  std::memcpy(f, a.bytes.data(), 36);
  EXPECT_EQ(f[0], 0.0f);
  EXPECT_EQ(f[5], 0.0f);
  EXPECT_EQ(f[6], 7.0f);
  EXPECT_EQ(f[8], 9.0f);

  // An accessor past its view is an error naming the document.
  doc.root["accessors"][strided]["count"] = 5;
  try {
    readAccessor(doc, strided, "broken.gltf");
    FAIL() << "expected InvalidData";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidData);
    EXPECT_NE(std::string(e.what()).find("broken.gltf"), std::string::npos);
  }
}

TEST(GltfCompact, GatherPadsTheStrideAndComputesMinMax) {
  GltfDocument doc;
  const uint8_t rgb[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};  // three VEC3 unsigned bytes
  const int view = doc.addBufferView(rgb, 9);
  const int acc = doc.append("accessors", {{"bufferView", view}, {"componentType", 5121}, {"normalized", true}, {"count", 3}, {"type", "VEC3"}});
  const AccessorBytes src = readAccessor(doc, acc, "doc");
  const int out = addGatheredAccessor(doc, src, {2, 0, 2, 1}, true);
  const json& a = doc.root["accessors"][out];
  EXPECT_EQ(a["count"], 4);
  EXPECT_EQ(a["normalized"], true);
  EXPECT_EQ(a["min"], json::array({1.0, 2.0, 3.0}));
  EXPECT_EQ(a["max"], json::array({7.0, 8.0, 9.0}));
  EXPECT_EQ(doc.root["bufferViews"][a["bufferView"].get<int>()]["byteStride"], 4);  // 3-byte elements on 4
  const AccessorBytes back = readAccessor(doc, out, "doc");
  EXPECT_EQ(back.bytes, (std::vector<uint8_t>{7, 8, 9, 1, 2, 3, 7, 8, 9, 4, 5, 6}));
}

TEST(GltfCompact, DropsWhatNothingUsesAndRenumbersTheRest) {
  GltfDocument doc;
  const int unusedA = doc.addVec3({{9, 9, 9}});                 // accessor 0: nothing uses it
  const int pos = doc.addPositions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});  // accessor 1
  const int ibm = doc.addVec2({{1, 2}});                          // accessor 2: a skin's (type faked, only referenced)
  const int times = doc.addVec2({{0, 1}});                        // accessor 3: an animation's
  const int target = doc.addVec3({{0, 0, 1}, {0, 0, 1}, {0, 0, 1}});  // accessor 4: a morph target's
  const uint8_t png[8] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  const int unusedImage = doc.addImage(std::vector<uint8_t>(png, png + 8), "orphan");
  const int usedImage = doc.addImage(std::vector<uint8_t>(png, png + 8), "used");
  doc.addTexture(unusedImage, doc.addSampler(WrapMode::Repeat, WrapMode::Repeat, false));  // texture 0: no material
  const int tex = doc.addTexture(usedImage, doc.addSampler(WrapMode::ClampToEdge, WrapMode::ClampToEdge, true));
  doc.append("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", tex}}}}}});
  doc.append("meshes", {{"name", "orphan"}, {"primitives", json::array({{{"attributes", {{"POSITION", unusedA}}}}})}});
  doc.append("meshes", {{"name", "used"},
                        {"primitives", json::array({{{"attributes", {{"POSITION", pos}}}, {"material", 0},
                                                     {"targets", json::array({{{"POSITION", target}}})}}})}});
  doc.append("nodes", {{"mesh", 1}, {"skin", 0}});
  doc.append("skins", {{"inverseBindMatrices", ibm}, {"joints", {0}}});
  doc.append("animations", {{"samplers", json::array({{{"input", times}, {"output", times}}})},
                            {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}}})}});
  const size_t binBefore = doc.bin.size();

  compactDocument(doc);
  const json& j = doc.root;
  ASSERT_EQ(j["meshes"].size(), 1u);
  EXPECT_EQ(j["meshes"][0]["name"], "used");
  EXPECT_EQ(j["nodes"][0]["mesh"], 0);
  ASSERT_EQ(j["accessors"].size(), 4u);  // 1..4 → 0..3
  EXPECT_EQ(j["meshes"][0]["primitives"][0]["attributes"]["POSITION"], 0);
  EXPECT_EQ(j["meshes"][0]["primitives"][0]["targets"][0]["POSITION"], 3);
  EXPECT_EQ(j["skins"][0]["inverseBindMatrices"], 1);
  EXPECT_EQ(j["animations"][0]["samplers"][0]["input"], 2);
  ASSERT_EQ(j["textures"].size(), 1u);
  EXPECT_EQ(j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"], 0);
  EXPECT_EQ(j["textures"][0]["source"], 0);
  EXPECT_EQ(j["textures"][0]["sampler"], 0);
  EXPECT_EQ(j["samplers"].size(), 1u);
  EXPECT_EQ(j["samplers"][0]["wrapS"], 33071);
  ASSERT_EQ(j["images"].size(), 1u);
  EXPECT_EQ(j["images"][0]["name"], "used");
  // Views: 4 accessors + 1 image; the buffer shrank by the dropped accessor and image.
  ASSERT_EQ(j["bufferViews"].size(), 5u);
  EXPECT_EQ(doc.bin.size(), binBefore - 12 - 8);
  // Data follows its view: the positions still read back.
  const AccessorBytes p = readAccessor(doc, 0, "doc");
  float xyz[9];
  std::memcpy(xyz, p.bytes.data(), 36);
  EXPECT_EQ(xyz[3], 1.0f);
  EXPECT_EQ(xyz[7], 1.0f);
}

TEST(GltfCompact, ExternalizedImagesGetUniqueNamesWhateverTheirCase) {
  // Five images from "tex.png" files in different folders, one named "Tex" (no source URI), one with
  // neither: against the taken "TEX_2.png" (another case) the suffixes go 1, 3, 4, 5, 6.
  GltfDocument doc;
  const uint8_t png[8] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  for (int i = 0; i < 5; ++i) {
    const int image = doc.addImage(std::vector<uint8_t>(png, png + 8), "");
    doc.root["images"][image][kSourceUriKey] = "folder" + std::to_string(i) + "/tex.png";
  }
  doc.addImage(std::vector<uint8_t>(png, png + 8), "Tex");
  doc.addImage(std::vector<uint8_t>(png, png + 8), "");
  const auto files = externalizeImages(doc, {"baked.gltf", "TEX_2.png"});
  std::vector<std::string> names;
  for (const auto& [name, bytes] : files) {
    names.push_back(name);
    EXPECT_EQ(bytes, std::vector<uint8_t>(png, png + 8)) << name;
  }
  EXPECT_EQ(names, (std::vector<std::string>{"tex.png", "tex_1.png", "tex_3.png", "tex_4.png", "tex_5.png", "Tex_6.png", "image6.png"}));
  for (size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(doc.root["images"][i]["uri"], names[i]);
    EXPECT_FALSE(doc.root["images"][i].contains("bufferView"));
    EXPECT_FALSE(doc.root["images"][i].contains(kSourceUriKey));
  }
}
