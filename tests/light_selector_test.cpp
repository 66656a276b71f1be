// --light-mode's selectors address one set of lights each: a plain `#I` or `sun` that is also another light's
// glTF name is refused, naming both lights and the explicit form of each (index:I, name:TEXT, option:sun), and
// those explicit forms (name:* for a light named "*") set exactly the lights they name.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "irbake_process.h"
#include "testing/gltf_builder.h"

namespace fs = std::filesystem;
using irbake::testing::fileText;
using irbake::testing::IrbakeRun;

namespace {

// A floor under four point lights: KHR light 0 "lamp", 1 "#0", 2 "sun", 3 "*".
fs::path fourLightScene(const fs::path& dir) {
  irbake::GltfDocument doc =
      irbake::testing::meshDocument({{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}}, {0, 2, 1, 0, 3, 2});
  nlohmann::json lights = nlohmann::json::array();
  const std::vector<std::string> names = {"lamp", "#0", "sun", "*"};
  for (size_t i = 0; i < names.size(); ++i) {
    lights.push_back({{"type", "point"}, {"intensity", 2.0 + double(i)}, {"name", names[i]}});
    doc.root["nodes"].push_back({{"translation", {-0.6 + 0.4 * double(i), 1.0, 0.1 * double(i)}},
                                 {"extensions", {{"KHR_lights_punctual", {{"light", i}}}}}});
    doc.root["scenes"][0]["nodes"].push_back(doc.root["nodes"].size() - 1);
  }
  doc.root["extensions"]["KHR_lights_punctual"]["lights"] = lights;
  doc.root["extensionsUsed"] = {"KHR_lights_punctual"};
  irbake::testing::writeDocument(doc, dir / "lights.gltf");
  return dir / "lights.gltf";
}

IrbakeRun bake(const fs::path& dir, const fs::path& scene, const std::string& out, std::vector<std::string> extra) {
  std::vector<std::string> args{"bake", scene.string(), "-o", (dir / out).string(), "--texels-per-unit", "4",
                                "--vpls", "16", "--backend", "embree", "--probes", "off", "--quiet"};
  args.insert(args.end(), extra.begin(), extra.end());
  return irbake::testing::runIrbakeLogged(args, dir / (out + ".txt"));
}

// The mode the bake's plan gave each light, by the name messages use ("light-mode NAME #i").
std::string modeOf(const fs::path& out, const std::string& name, int i) {
  const nlohmann::json plan = nlohmann::json::parse(fileText(out / "report.json"))["plan"];
  const std::string key = "light-mode " + name + " #" + std::to_string(i);
  return plan.contains(key) ? plan[key]["value"].get<std::string>() : "(no " + key + ")";
}

}  // namespace

TEST(LightSelector, AmbiguousPlainSelectorsAreRefusedNamingBothLights) {
  const fs::path dir = irbake::testing::scratchFolder("light_selector", "ambiguous");
  const fs::path scene = fourLightScene(dir);
  const IrbakeRun index = bake(dir, scene, "index", {"--light-mode", "#0=indirect"});
  EXPECT_EQ(index.code, 2) << index.output;
  EXPECT_NE(index.output.find("'#0' is ambiguous: it addresses KHR light 0 ('lamp') and the light named '#0', "
                              "KHR light 1 ('#0'); write index:0 for the first, name:#0 for the second"),
            std::string::npos)
      << index.output;
  const IrbakeRun sun = bake(dir, scene, "sun", {"--sun", "0,-1,0,3", "--light-mode", "sun=indirect"});
  EXPECT_EQ(sun.code, 2) << sun.output;
  EXPECT_NE(sun.output.find("'sun' is ambiguous: it addresses the --sun light and the light named 'sun', KHR light 2 "
                            "('sun'); write option:sun for the first, name:sun for the second"),
            std::string::npos)
      << sun.output;
  for (const char* out : {"index", "sun"}) EXPECT_FALSE(fs::exists(dir / out / "report.json")) << out;
  // A name nothing answers to lists how each light is addressed.
  const IrbakeRun none = bake(dir, scene, "none", {"--light-mode", "lantern=indirect"});
  EXPECT_EQ(none.code, 2) << none.output;
  EXPECT_NE(none.output.find("(its punctual lights: lamp, name:#0, name:sun, name:*)"), std::string::npos) << none.output;
}

TEST(LightSelector, ExplicitFormsSetExactlyTheLightsTheyName) {
  const fs::path dir = irbake::testing::scratchFolder("light_selector", "explicit");
  const fs::path scene = fourLightScene(dir);
  const IrbakeRun star = bake(dir, scene, "star", {"--light-mode", "name:*=indirect"});
  ASSERT_EQ(star.code, 0) << star.output;
  EXPECT_EQ(modeOf(dir / "star", "*", 3), "indirect");
  for (const auto& [name, i] : std::vector<std::pair<std::string, int>>{{"lamp", 0}, {"#0", 1}, {"sun", 2}})
    EXPECT_EQ(modeOf(dir / "star", name, i), "baked") << name;

  const IrbakeRun each = bake(dir, scene, "each", {"--sun", "0,-1,0,3", "--light-mode", "index:0=indirect", "--light-mode",
                                                   "name:#0=shadowmask", "--light-mode", "name:sun=indirect",
                                                   "--light-mode", "option:sun=shadowmask"});
  ASSERT_EQ(each.code, 0) << each.output;
  EXPECT_EQ(modeOf(dir / "each", "lamp", 0), "indirect");
  EXPECT_EQ(modeOf(dir / "each", "#0", 1), "shadowmask");
  EXPECT_EQ(modeOf(dir / "each", "sun", 2), "indirect");
  EXPECT_EQ(modeOf(dir / "each", "*", 3), "baked");
  EXPECT_EQ(modeOf(dir / "each", "sun", 4), "shadowmask");  // --sun's light comes after the glTF's

  // Without a glTF light of that name, the plain forms are unambiguous: `#3` is KHR light 3 (named "*").
  const IrbakeRun plain = bake(dir, scene, "plain", {"--light-mode", "#3=indirect"});
  ASSERT_EQ(plain.code, 0) << plain.output;
  EXPECT_EQ(modeOf(dir / "plain", "*", 3), "indirect");
  EXPECT_EQ(modeOf(dir / "plain", "lamp", 0), "baked");
}
