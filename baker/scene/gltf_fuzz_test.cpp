// Corrupted inputs never crash the loader: every mutation either loads or throws irbake::Error
// (the command turns that into one line and an exit code). Deterministic seeds, a few hundred cases.
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "common/error.h"
#include "scene/gltf_loader.h"
#include "scene/image_codec.h"
#include "testing/compressed_gltf.h"
#include "testing/gltf_builder.h"

using namespace irbake;
using json = nlohmann::json;

namespace {

// A small but feature-rich document: hierarchy, texture, light, camera, strip primitive.
GltfDocument richDocument() {
  GltfDocument doc = irbake::testing::meshDocument({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {0, 1, 2, 2, 1, 3});
  auto& prim = doc.root["meshes"][0]["primitives"][0];
  prim["attributes"]["TEXCOORD_0"] = doc.addVec2({{0, 0}, {1, 0}, {0, 1}, {1, 1}});
  prim["material"] = 0;
  Texture t;
  t.width = t.height = 2;
  t.texels.assign(4, glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));
  int tex = doc.addTexture(doc.addImage(encodePng(t, true), "t"), -1);
  doc.append("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", tex}}}}}, {"emissiveFactor", {1, 1, 1}}});
  doc.root["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "spot"}, {"intensity", 2}, {"spot", {{"outerConeAngle", 0.5}}}}});
  doc.append("cameras", {{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.1}}}});
  doc.root["nodes"][0]["children"] = {1, 2};
  doc.root["nodes"].push_back({{"camera", 0}, {"translation", {0, 0, 3}}});
  doc.root["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}, {"scale", {1, -1, 1}}, {"mesh", 0}});
  return doc;
}

// Loads and classifies: 0 loaded, 1 irbake::Error. Anything else fails the test.
int loadOrError(const std::filesystem::path& file, const std::string& label) {
  try {
    loadScene(file);
    return 0;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << label << ": " << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << label << ": not one line: " << e.what();
    return 1;
  } catch (const std::exception& e) {
    ADD_FAILURE() << label << ": escaped as a non-irbake exception: " << e.what();
  }
  return 2;
}

}  // namespace

TEST(GltfFuzz, RandomByteCorruptionOfGlbNeverCrashes) {
  auto dir = irbake::testing::testFolder("fuzz_bytes");
  irbake::testing::writeDocument(richDocument(), dir / "good.glb");
  std::ifstream in(dir / "good.glb", std::ios::binary);
  std::vector<char> good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(loadOrError(dir / "good.glb", "original"), 0);
  std::mt19937 rng(1234);
  int errors = 0;
  const int cases = 300;
  for (int c = 0; c < cases; ++c) {
    std::vector<char> bad = good;
    int flips = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < flips; ++k) bad[rng() % bad.size()] = static_cast<char>(rng() & 0xFF);
    if (rng() % 8 == 0) bad.resize(rng() % bad.size());  // truncation
    std::filesystem::path file = dir / ("case" + std::to_string(c) + ".glb");
    std::ofstream(file, std::ios::binary).write(bad.data(), static_cast<std::streamsize>(bad.size()));
    errors += loadOrError(file, "case " + std::to_string(c)) == 1;
  }
  // Most single-byte hits land in vertex data and still load; a fair share must be caught.
  EXPECT_GT(errors, cases / 20);
}

// The meshopt and Draco files: corrupted streams and JSON reach the decoders, which refuse or decode them.
TEST(GltfFuzz, RandomByteCorruptionOfCompressedGlbNeverCrashes) {
  const std::vector<glm::vec3> grid = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}};
  const std::vector<uint32_t> indices = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4};
  auto dir = irbake::testing::testFolder("fuzz_compressed");
  std::mt19937 rng(4321);
  for (const auto& [name, parts] : {std::pair{"meshopt", irbake::testing::meshoptParts(grid, indices)},
                                    std::pair{"draco", irbake::testing::dracoParts(grid, indices)}}) {
    const std::vector<uint8_t> good = irbake::testing::glbBytes(parts);
    std::ofstream(dir / "good.glb", std::ios::binary).write(reinterpret_cast<const char*>(good.data()), static_cast<std::streamsize>(good.size()));
    ASSERT_EQ(loadOrError(dir / "good.glb", name), 0);
    int errors = 0;
    const int cases = 200;
    for (int c = 0; c < cases; ++c) {
      std::vector<uint8_t> bad = good;
      // Half the hits in the BIN chunk (the compressed streams), half anywhere.
      const size_t bin = good.size() - parts.bin.size();
      for (int k = 0, flips = 1 + static_cast<int>(rng() % 4); k < flips; ++k)
        bad[k % 2 ? rng() % bad.size() : bin + rng() % parts.bin.size()] = static_cast<uint8_t>(rng() & 0xFF);
      const std::filesystem::path file = dir / (std::string(name) + std::to_string(c) + ".glb");
      std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(bad.data()), static_cast<std::streamsize>(bad.size()));
      errors += loadOrError(file, std::string(name) + " case " + std::to_string(c)) == 1;
    }
    EXPECT_GT(errors, cases / 20) << name;
  }
}

TEST(GltfFuzz, JsonValueReplacementNeverCrashes) {
  auto dir = irbake::testing::testFolder("fuzz_json");
  irbake::testing::writeDocument(richDocument(), dir / "good.gltf");
  ASSERT_EQ(loadOrError(dir / "good.gltf", "original"), 0);
  json good = json::parse(std::ifstream(dir / "good.gltf"));
  // Every leaf path of the document, replaced by hostile values one at a time.
  std::vector<json::json_pointer> leaves;
  json flat = good.flatten();
  for (auto it = flat.begin(); it != flat.end(); ++it) leaves.emplace_back(it.key());
  const std::vector<json> hostile = {json(-1), json(4294967295u), json(1e300), json("x"), json(nullptr), json::array(), json(0.5)};
  int cases = 0, errors = 0;
  for (const auto& leaf : leaves) {
    if (leaf.to_string().find("/uri") != std::string::npos) continue;  // URIs are covered by their own tests
    for (const auto& h : hostile) {
      json bad = good;
      bad[leaf] = h;
      std::filesystem::path file = dir / "case.gltf";
      std::ofstream(file, std::ios::trunc) << bad.dump();
      errors += loadOrError(file, leaf.to_string() + " = " + h.dump()) == 1;
      ++cases;
    }
  }
  EXPECT_GT(cases, 200);
  EXPECT_GT(errors, cases / 10);
}

// Regression cases found by the libFuzzer harness (tests/fuzz). Each is the smallest document that
// shows the fault; the fuzzer's own reproducer came from our Cornell-box sample.

// 1. A number too large for a double (0.140000000596E4645): nlohmann::json throws out_of_range (406),
//    not parse_error, and it escaped loadScene as a bare std::exception with no file name.
TEST(GltfFuzzRegression, NumberOverflowIsAParseErrorNamingTheFile) {
  auto dir = irbake::testing::testFolder("fuzz_regression_number");
  GltfDocument doc = richDocument();
  doc.root["cameras"][0]["perspective"]["yfov"] = "OVERFLOW_HERE";
  irbake::testing::writeDocument(doc, dir / "marked.gltf");
  std::ifstream in(dir / "marked.gltf");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string marker = "\"OVERFLOW_HERE\"";
  ASSERT_NE(text.find(marker), std::string::npos);
  text.replace(text.find(marker), marker.size(), "0.140000000596E4645");
  std::ofstream(dir / "overflow.gltf") << text;
  for (int fromMemory = 0; fromMemory < 2; ++fromMemory) {
    try {
      if (fromMemory)
        loadSceneFromBytes(std::vector<uint8_t>(text.begin(), text.end()), dir / "overflow.gltf");
      else
        loadScene(dir / "overflow.gltf");
      ADD_FAILURE() << "a number out of double range loaded";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Parse);
      EXPECT_EQ(e.file(), (dir / "overflow.gltf").string());
      EXPECT_NE(std::string(e.what()).find("malformed JSON: number overflow"), std::string::npos) << e.what();
    }
  }
}

// 2. A buffer view whose byteOffset is 1e39: the out-of-bounds message cast the double to an integer
//    (undefined behaviour; UBSan: "outside the range of representable values"). The message now gives
//    such a number as written.
TEST(GltfFuzzRegression, HugeBufferViewOffsetIsReportedAsWritten) {
  auto dir = irbake::testing::testFolder("fuzz_regression_offset");
  GltfDocument doc = richDocument();
  doc.root["bufferViews"][0]["byteOffset"] = 1e39;
  irbake::testing::writeDocument(doc, dir / "offset.gltf");
  try {
    loadScene(dir / "offset.gltf");
    ADD_FAILURE() << "a buffer view at byte 1e39 loaded";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidData);
    EXPECT_NE(std::string(e.what()).find("buffer view 0 is out of bounds: bytes 1e+39..1e+39 of buffer 0"), std::string::npos)
        << e.what();
  }
}
