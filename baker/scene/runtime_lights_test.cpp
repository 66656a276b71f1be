// The export's mixed-light records read back (docs/export.md, "Mixed lights"): the channel map, the light
// extras and the command line's sun; malformed records refused naming the entry.
#include "scene/runtime_lights.h"

#include <gtest/gtest.h>

#include "common/error.h"

namespace irbake {
namespace {

using nlohmann::json;

std::vector<Light> twoKhrLights() {
  Light a, b;
  a.gltfLight = 0;
  a.name = "lamp";
  b.gltfLight = 1;
  b.name = "fill";
  b.hasExtrasMode = true;
  b.extrasMode = LightMode::Indirect;
  return {a, b};
}

TEST(RuntimeLights, ChannelMapExtrasAndSunAreRead) {
  const json root = {
      {"extensions",
       {{"IRBAKE_shadowmask",
         {{"lights", {{{"name", "lamp"}, {"light", 0}, {"channel", 2}}}}}}}},
      {"extras", {{"irbakeSun", {{"mode", "indirect"}, {"direction", {0, -2, 0}}, {"irradiance", {5, 4, 3}}}}}}};
  const std::vector<RuntimeLight> r = readRuntimeLights(root, twoKhrLights(), 2, "f.gltf");
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0].light.name, "lamp");
  EXPECT_EQ(r[0].maskChannel, 2);
  EXPECT_EQ(r[0].mode, LightMode::ShadowMask);
  EXPECT_EQ(r[1].light.name, "fill");
  EXPECT_EQ(r[1].maskChannel, -1);
  EXPECT_EQ(r[2].light.type, LightType::Directional);
  EXPECT_FLOAT_EQ(r[2].light.direction.y, -1.0f);  // normalised
  EXPECT_FLOAT_EQ(r[2].light.color.x * r[2].light.intensity, 5.0f);
  EXPECT_TRUE(readRuntimeLights(json::object(), {Light{}}, 0, "f.gltf").empty());  // baked: nothing
}

TEST(RuntimeLights, MalformedRecordsAreRefusedNamingTheEntry) {
  const std::pair<json, std::string> cases[] = {
      {{{"extensions", {{"IRBAKE_shadowmask", {{"lights", 3}}}}}}, "\"lights\": an array"},
      {{{"extensions", {{"IRBAKE_shadowmask", {{"lights", {{{"light", 0}, {"channel", 4}}}}}}}}},
       "IRBAKE_shadowmask.lights[0]: channel must be an integer 0..3"},
      {{{"extensions", {{"IRBAKE_shadowmask", {{"lights", {{{"light", 9}, {"channel", 0}}}}}}}}},
       "light 9 is not a KHR_lights_punctual light of the file (it has 2)"},
      {{{"extensions", {{"IRBAKE_shadowmask", {{"lights", {{{"channel", 0}, {"directional", {{"direction", {0, 0, 0}}}}}}}}}}}},
       "needs a finite, non-zero \"direction\""},
      {{{"extras", {{"irbakeSun", {{"mode", "dim"}}}}}}, "extras.irbakeSun.mode must be"},
  };
  for (const auto& [root, message] : cases) {
    try {
      readRuntimeLights(root, twoKhrLights(), 2, "f.gltf");
      ADD_FAILURE() << "accepted " << root.dump();
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::InvalidData);
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("f.gltf"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace irbake
