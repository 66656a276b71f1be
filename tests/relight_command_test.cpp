// `irbake relight` on a real bake with light groups (the Cornell box: a sun through its open front in one group, its
// emissive ceiling in the other): at the bake's own weights the default EXR pages and probes come back bit for bit;
// at day = 0.5, lamp = 2 they are 0.5·day + 2·lamp of the layers the bake wrote; the command's refusals.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "export/exr_io.h"
#include "export/light_probes_export.h"
#include "irbake_process.h"

namespace fs = std::filesystem;
using namespace irbake;
using namespace irbake::testing;
using json = nlohmann::json;

namespace {

// The grouped bake, one per test: ctest runs each test in a process of its own, in parallel, and a folder shared
// between them would be cleared by one while another reads it.
fs::path groupedBake(const std::string& test) {
  const fs::path dir = scratchFolder("relight_command", test + "_grouped");
  const fs::path samples = sampleScenes("relight_command");
  const IrbakeRun r = runIrbakeIn(dir, {"bake", (samples / "cornell_box.gltf").string(), "-o", (dir / "out").string(),
                                        "--vpls", "256", "--texels-per-unit", "40", "--sun", "0.2,-0.5,1,3", "--probes",
                                        "0.1", "--light-group", "day=sun", "--light-group", "lamp=emissive", "--quiet"});
  EXPECT_EQ(r.code, 0) << r.output;
  return dir / "out" / "scene.gltf";
}

}  // namespace

TEST(RelightCommand, TheBakesWeightsGiveItsPagesAndProbesBackBitForBit) {
  const fs::path in = groupedBake("same"), dir = scratchFolder("relight_command", "same");
  const IrbakeRun r = runIrbakeIn(dir, {"relight", in.string(), "-o", (dir / "out" / "scene.glb").string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const Lightmap a = readExr(in.parent_path() / "lightmap_0.exr"), b = readExr(dir / "out" / "lightmap_0.exr");
  ASSERT_EQ(a.texels.size(), b.texels.size());
  size_t lit = 0;
  for (size_t i = 0; i < a.texels.size(); ++i) {
    ASSERT_EQ(a.texels[i], b.texels[i]) << "texel " << i;
    lit += a.texels[i].x > 0.0f ? 1 : 0;
  }
  EXPECT_GT(lit, a.texels.size() / 4);
  const LightProbeGrid pa = readLightProbes(in), pb = readLightProbes(dir / "out" / "scene.glb");
  ASSERT_EQ(pa.coefficients.size(), pb.coefficients.size());
  for (size_t i = 0; i < pa.coefficients.size(); ++i)
    for (int k = 0; k < kShCoefficients; ++k) ASSERT_EQ(pa.coefficients[i][k], pb.coefficients[i][k]) << "probe " << i;
  EXPECT_EQ(pa.sun.irradiance, pb.sun.irradiance);
  EXPECT_GT(pa.sun.irradiance.x, 0.0f);
}

TEST(RelightCommand, HalfAndTwoAreTheLayersWeightedSum) {
  const fs::path in = groupedBake("half_two"), dir = scratchFolder("relight_command", "half_two");
  const IrbakeRun r = runIrbakeIn(dir, {"relight", in.string(), "--group", "day=0.5", "--group", "lamp=2", "-o",
                                        (dir / "out" / "scene.gltf").string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const fs::path folder = in.parent_path();
  const Lightmap day = readExr(folder / "lightmap_0_day.exr"), lamp = readExr(folder / "lightmap_0_lamp.exr");
  const Lightmap out = readExr(dir / "out" / "lightmap_0.exr");
  size_t both = 0;
  for (size_t i = 0; i < out.texels.size(); ++i) {
    ASSERT_EQ(out.texels[i], 0.5f * day.texels[i] + 2.0f * lamp.texels[i]) << "texel " << i;
    both += day.texels[i].x > 0.0f && lamp.texels[i].x > 0.0f ? 1 : 0;
  }
  EXPECT_GT(both, out.texels.size() / 10);  // both layers lit: the weights are tested, not one alone
  const json doc = json::parse(fileText(dir / "out" / "scene.gltf"));
  const json& weights = doc["extensions"]["IRBAKE_lightmap_scenarios"]["scenarios"][0]["weights"];
  EXPECT_EQ(weights["day"], json({0.5, 0.5, 0.5}));
  EXPECT_EQ(weights["lamp"], json({2.0, 2.0, 2.0}));
  EXPECT_EQ(readLightProbes(dir / "out" / "scene.gltf").sun.irradiance, 0.5f * readLightProbes(in).sun.irradiance);
}

TEST(RelightCommand, RefusesNamingTheFile) {
  const fs::path in = groupedBake("refusals"), dir = scratchFolder("relight_command", "refusals");
  const std::string out = (dir / "out" / "scene.gltf").string();
  struct Case {
    std::vector<std::string> args;
    int code;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"--group", "night=1"}, 2, "--group 'night': no such light group (the file's layers: day, lamp)"},
      {{"--group", "day=-1"}, 2, "--group 'day=-1': a weight must be a finite number from 0 to 1e20"},
      {{"--group", "day=1,2"}, 2, "W must be one finite number ≥ 0 or three (R,G,B)"},
      {{"--group", "day=nan"}, 2, "W must be one finite number"},
      {{"--group", "day=1", "--group", "day=2"}, 2, "--group 'day' given twice"},
      {{"--scenario", "dusk"}, 2, "--scenario 'dusk': no such scenario (the file has default, day, lamp)"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"relight", in.string(), "-o", out};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const IrbakeRun r = runIrbakeIn(dir, args);
    EXPECT_EQ(r.code, c.code) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
  }
  // Onto the bake's own folder: its pages are inputs.
  const IrbakeRun onto = runIrbakeIn(dir, {"relight", in.string(), "-o", (in.parent_path() / "relit.gltf").string()});
  EXPECT_EQ(onto.code, 2) << onto.output;
  EXPECT_NE(onto.output.find("is an input of this command"), std::string::npos) << onto.output;
  // A bake without groups.
  const IrbakeRun plain = runIrbakeIn(dir, {"relight", (sampleScenes("relight_command") / "cornell_box.gltf").string(), "-o", out});
  EXPECT_EQ(plain.code, 5) << plain.output;
  EXPECT_NE(plain.output.find("cornell_box.gltf: has no IRBAKE_lightmap_scenarios"), std::string::npos) << plain.output;
  EXPECT_FALSE(fs::exists(out));
}
