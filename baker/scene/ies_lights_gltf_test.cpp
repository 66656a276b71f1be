// EXT_lights_ies through the loader: profiles from a bufferView, a data URI and a file beside the glTF, the
// node's frame, multiplier and colour; refusals naming the extension, the light, the bufferView or file and the
// profile's line; and the export's round trip (the profile written back as a data URI).
#include <fstream>

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include "common/base64.h"
#include "common/error.h"
#include "export/gltf_writer.h"
#include "scene/gltf_loader.h"
#include "testing/gltf_builder.h"
#include "testing/ies_profiles.h"

namespace irbake {
namespace {

using json = nlohmann::json;

constexpr char kMime[] = "application/x-ies-lm-63";

std::string dataUri(const std::string& text) {
  return std::string("data:") + kMime + ";base64," + base64Encode(text);
}

// A lit triangle and three EXT_lights_ies nodes: profile 0 in a bufferView, 1 a data URI, 2 the file lamp.ies.
// Node 1 is turned 90° about +X (its −Z, the nadir, towards +Y), with multiplier 2 and colour (1, 0.5, 2).
GltfDocument iesDocument(const std::string& viewText, const std::string& uriText) {
  GltfDocument doc = testing::meshDocument({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2});
  const int view = doc.addBufferView(viewText.data(), viewText.size());
  doc.root["extensions"]["EXT_lights_ies"]["lights"] =
      json::array({{{"bufferView", view}, {"mimeType", kMime}, {"name", "down"}}, {{"uri", dataUri(uriText)}},
                   {{"uri", "lamp.ies"}}});
  const glm::quat turn = glm::angleAxis(glm::radians(90.0f), glm::vec3(1, 0, 0));
  doc.append("nodes", {{"translation", {1, 2, 3}},
                       {"rotation", {turn.x, turn.y, turn.z, turn.w}},
                       {"extensions", {{"EXT_lights_ies", {{"light", 0}, {"multiplier", 2}, {"color", {1, 0.5, 2}}}}}}});
  doc.append("nodes", {{"translation", {0, 0, 4}}, {"extensions", {{"EXT_lights_ies", {{"light", 1}}}}}});
  doc.append("nodes", {{"translation", {0, 1, 4}}, {"extensions", {{"EXT_lights_ies", {{"light", 2}}}}}});
  doc.root["scenes"][0]["nodes"] = {0, 1, 2, 3};
  doc.useExtension("EXT_lights_ies");
  doc.root["extensionsRequired"] = {"EXT_lights_ies"};
  return doc;
}

std::filesystem::path writeWithLamp(const GltfDocument& doc, const std::string& folder, const std::string& lamp) {
  const auto dir = testing::testFolder(folder);
  std::ofstream(dir / "lamp.ies", std::ios::binary) << lamp;
  const auto file = dir / (folder + ".gltf");
  testing::writeDocument(doc, file);
  return file;
}

TEST(IesLightsGltf, ProfilesFromABufferViewADataUriAndAFileLightTheirNodes) {
  const std::string cosine = testing::cosineIesProfile(10.0);
  const auto file = writeWithLamp(iesDocument(cosine, testing::cosineIesProfile(20.0)), "ies_loader_ok",
                                  testing::cosineIesProfile(30.0));
  const Scene scene = loadScene(file);
  ASSERT_EQ(scene.lights.size(), 3u);
  const Light& turned = scene.lights[0];
  EXPECT_EQ(turned.type, LightType::Ies);
  EXPECT_EQ(turned.name, "down");
  EXPECT_NEAR(glm::length(turned.position - glm::vec3(1, 2, 3)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(turned.direction - glm::vec3(0, 1, 0)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(turned.profileAxisX - glm::vec3(1, 0, 0)), 0.0f, 1e-6f);
  EXPECT_EQ(turned.intensity, 2.0f);
  EXPECT_EQ(turned.color, glm::vec3(1.0f, 0.5f, 1.0f));  // clamped to [0, 1], as the specification says
  EXPECT_DOUBLE_EQ(turned.profile->maxCandela, 15.0);
  EXPECT_DOUBLE_EQ(scene.lights[1].profile->maxCandela, 30.0);
  EXPECT_DOUBLE_EQ(scene.lights[2].profile->maxCandela, 45.0);
  EXPECT_EQ(scene.lights[1].direction, glm::vec3(0, 0, -1));
  EXPECT_EQ(scene.lights[1].intensity, 1.0f);
  EXPECT_EQ(scene.lights[1].color, glm::vec3(1.0f));
}

// Each refusal: Error(InvalidData) naming the glTF file, and every one of `parts`.
void expectRefused(const GltfDocument& doc, const std::string& folder, const std::string& lamp,
                   const std::vector<std::string>& parts) {
  const auto file = writeWithLamp(doc, folder, lamp);
  try {
    loadScene(file);
    ADD_FAILURE() << folder << ": loaded, expected a refusal";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidData) << e.what();
    const std::string what = e.what();
    EXPECT_NE(what.find(file.string()), std::string::npos) << what;
    for (const auto& p : parts) EXPECT_NE(what.find(p), std::string::npos) << "'" << p << "' not in: " << what;
  }
}

TEST(IesLightsGltf, MalformedProfilesAndReferencesAreRefusedByName) {
  const std::string good = testing::cosineIesProfile(10.0);
  std::string noTilt = good;
  noTilt.replace(noTilt.find("TILT=NONE"), 9, "[MORE] x");
  std::string shortCandela = good.substr(0, good.rfind('\n', good.size() - 2) + 1);  // its last line cut
  expectRefused(iesDocument(noTilt, good), "ies_loader_view", good,
                {"EXT_lights_ies light 0", "bufferView", "IES profile, line", "no TILT= line"});
  expectRefused(iesDocument(good, good), "ies_loader_file", shortCandela,
                {"EXT_lights_ies light 2", "lamp.ies", "IES profile, line", "the file ends before candela value"});
  GltfDocument noMime = iesDocument(good, good);
  noMime.root["extensions"]["EXT_lights_ies"]["lights"][0].erase("mimeType");
  expectRefused(noMime, "ies_loader_mime", good, {"EXT_lights_ies light 0", "mimeType \"application/x-ies-lm-63\""});
  GltfDocument outOfRange = iesDocument(good, good);
  outOfRange.root["nodes"][1]["extensions"]["EXT_lights_ies"]["light"] = 7;
  expectRefused(outOfRange, "ies_loader_index", good, {"EXT_lights_ies light 7", "no such light"});
  GltfDocument badMultiplier = iesDocument(good, good);
  badMultiplier.root["nodes"][1]["extensions"]["EXT_lights_ies"]["multiplier"] = -1;
  expectRefused(badMultiplier, "ies_loader_multiplier", good, {"node 1: EXT_lights_ies", "multiplier -1"});
  GltfDocument escape = iesDocument(good, good);
  escape.root["extensions"]["EXT_lights_ies"]["lights"][2]["uri"] = "../lamp.ies";
  expectRefused(escape, "ies_loader_escape", good, {"EXT_lights_ies light 2", "leaves the scene's folder"});
}

// The export writes each IES light back as EXT_lights_ies (its profile as a data URI, its node's rotation
// carrying the nadir and the horizontal axis); read again, it is the same light.
TEST(IesLightsGltf, ExportKeepsTheLightAndItsProfile) {
  const auto file = writeWithLamp(iesDocument(testing::cosineIesProfile(10.0), testing::cosineIesProfile(20.0)),
                                  "ies_export_in", testing::cosineIesProfile(30.0));
  const Scene scene = loadScene(file);
  const auto out = testing::testFolder("ies_export_out") / "out.gltf";
  testing::writeDocument(gltfFromScene(scene), out);
  const Scene back = loadScene(out);
  ASSERT_EQ(back.lights.size(), scene.lights.size());
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light &a = scene.lights[i], &b = back.lights[i];
    EXPECT_EQ(b.type, LightType::Ies);
    EXPECT_NEAR(glm::length(a.position - b.position), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(a.direction - b.direction), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(a.profileAxisX - b.profileAxisX), 0.0f, 1e-6f);
    EXPECT_EQ(a.intensity, b.intensity);
    EXPECT_EQ(a.color, b.color);
    EXPECT_EQ(a.profile->text, b.profile->text);
  }
}

}  // namespace
}  // namespace irbake
