// Mixed lighting through the whole bake: a light in indirect mode leaves exactly its direct light out of the
// map (same seed: baked = indirect + that light's direct term, shadow-edge refinement included, with the final
// gather and the clamp compensation reading every light's light one bounce away); a lone plane under an
// indirect light bakes to exactly 0; bad light names and extras values stop the command with exit 2 and no output.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "atlas/atlas.h"
#include "common/error.h"
#include "pipeline/bake.h"
#include "pipeline/light_modes.h"
#include "testing/scenes.h"
#include "testing/gltf_builder.h"

namespace irbake {
namespace {

using namespace testing;

// A floor, a box above it and two point lights ("a" over the box, "b" beside it).
Scene boxScene() {
  Scene s;
  const int white = addMaterial(s, glm::vec3(0.7f));
  addQuad(s, white, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0});
  addBox(s, white, {-0.2f, -0.2f, 0.4f}, {0.2f, 0.2f, 0.6f}, false);
  Light a = pointLight({0.1f, 0.05f, 1.5f}, 8.0f), b = pointLight({0.7f, -0.5f, 1.0f}, 4.0f);
  a.name = "a";
  b.name = "b";
  s.lights = {a, b};
  return s;
}

BakeOptions smallBake(BackendKind backend = BackendKind::Embree) {
  BakeOptions o;
  o.backend = backend;
  o.atlas.targetPageSize = o.atlas.maxPageSize = 64;
  o.walk.paths = 4000;
  o.finalGather = FinalGatherMode::On;
  return o;
}

// Both VPL evaluators: GL draws each light's shadow map in its own pass, Embree traces its rays.
TEST(MixedLighting, BakedEqualsIndirectPlusTheLightsDirectTerm) {
  for (const BackendKind backend : {BackendKind::Embree, BackendKind::Gl}) {
  const BakeResult baked = bake(boxScene(), smallBake(backend));
  BakeOptions indirect = smallBake(backend);
  indirect.lightModes = {{"b", LightMode::Indirect}};
  const BakeResult without = bake(boxScene(), indirect);
  // direct(b): the direct stage alone with a left out, so its edge texels are the same as the bakes' (found on
  // both lights' light) and the value is b's mean over them.
  BakeOptions direct = smallBake(backend);
  direct.eval.includeVpls = false;
  direct.eval.biasCompensation = false;
  direct.finalGather = FinalGatherMode::Off;
  direct.lightModes = {{"a", LightMode::Indirect}};
  const BakeResult directB = bake(boxScene(), direct);
  ASSERT_EQ(baked.maps.size(), without.maps.size());
  ASSERT_EQ(baked.maps.size(), directB.maps.size());
  size_t texels = 0, worstAt = 0;
  double worst = 0.0, bShare = 0.0, total = 0.0;
  for (size_t p = 0; p < baked.maps.size(); ++p)
    for (size_t t = 0; t < baked.maps[p].size(); ++t) {
      if (!baked.maps[p].valid[t]) continue;
      const glm::vec3 full = baked.maps[p].texels[t], sum = without.maps[p].texels[t] + directB.maps[p].texels[t];
      for (int c = 0; c < 3; ++c) {
        const double rel = std::abs(double(full[c]) - sum[c]) / std::max(1e-6, double(full[c]));
        if (rel > worst) worst = rel, worstAt = t;
      }
      bShare += directB.maps[p].texels[t].x;
      total += full.x;
      ++texels;
    }
  ASSERT_GT(texels, 1000u);
  EXPECT_LT(worst, 1e-4) << "texel " << worstAt;
  EXPECT_GT(bShare / total, 0.05);  // b's direct light is a real part of the map
  std::printf("[ figure ] %s: %zu texels: max |baked − (indirect + direct(b))| / baked = %.2e; direct(b) is %.1f%% of the map\n",
              toString(backend), texels, worst, 100.0 * bShare / total);
  }
}

TEST(MixedLighting, PlaneUnderAnIndirectLightBakesToZero) {
  for (const FinalGatherMode gather : {FinalGatherMode::Off, FinalGatherMode::On}) {
    Scene s;
    addQuad(s, addMaterial(s, glm::vec3(0.8f)), {-1, -1, 0}, {2, 0, 0}, {0, 2, 0});
    s.lights = {pointLight({0, 0, 1}, 10.0f)};
    s.lights[0].name = "lamp";
    BakeOptions o = smallBake();
    o.finalGather = gather;
    o.lightModes = {{"lamp", LightMode::Indirect}};
    const BakeResult r = bake(std::move(s), o);
    size_t valid = 0;
    for (const Lightmap& m : r.maps)
      for (size_t t = 0; t < m.size(); ++t) {
        EXPECT_EQ(m.texels[t], glm::vec3(0.0f)) << "texel " << t;
        valid += m.valid[t];
      }
    EXPECT_GT(valid, 100u);
  }
}

TEST(MixedLighting, BadNamesAreRefusedNamingTheLight) {
  Scene s = boxScene();
  s.materials.push_back(s.materials[0]);
  s.materials.back().name = "glow";
  s.materials.back().emissiveFactor = glm::vec3(1.0f);
  s.primitives[1].material = 1;
  auto refusal = [&](const std::string& name) -> std::string {
    try {
      resolveLightModes(s, {{name, LightMode::Indirect}});
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Usage);
      return e.what();
    }
    return "";
  };
  EXPECT_NE(refusal("lamp").find("no punctual light is named 'lamp' (its punctual lights: a, b)"), std::string::npos);
  EXPECT_NE(refusal("sky").find("'sky' is not a punctual light"), std::string::npos);
  EXPECT_NE(refusal("glow").find("'glow' is an emissive surface"), std::string::npos);
  // A name beats "*" whatever the order; the command line beats the file's extras.
  s.lights[1].hasExtrasMode = true;
  s.lights[1].extrasMode = LightMode::ShadowMask;
  const auto modes = resolveLightModes(s, {{"a", LightMode::Baked}, {"*", LightMode::Indirect}});
  EXPECT_EQ(modes[0].mode, LightMode::Baked);
  EXPECT_EQ(modes[1].mode, LightMode::Indirect);
  EXPECT_EQ(resolveLightModes(s, {})[1].mode, LightMode::ShadowMask);
}

int runIrbake(const std::string& args, std::string& output) {
  FILE* pipe = popen(("\"" + std::string(IRBAKE_EXE) + "\" " + args + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) output.append(buf.data(), n);
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(MixedLighting, CommandRefusesBadModesWithExit2AndNoOutput) {
  const std::filesystem::path dir = testFolder("mixed_lighting_cli");
  GltfDocument doc = meshDocument({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2});
  doc.root["extensions"]["KHR_lights_punctual"]["lights"] =
      nlohmann::json::array({{{"type", "point"}, {"intensity", 5}, {"name", "lamp"}, {"extras", {{"irbake", {{"mode", "dim"}}}}}}});
  doc.root["nodes"].push_back({{"translation", {0, 0, 1}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  doc.root["scenes"][0]["nodes"] = {0, 1};
  writeDocument(doc, dir / "bad_extras.gltf");
  doc.root["extensions"]["KHR_lights_punctual"]["lights"][0].erase("extras");
  writeDocument(doc, dir / "good.gltf");
  const std::string out = (dir / "out").string();
  const std::pair<std::string, std::string> cases[] = {
      {"bad_extras.gltf", "light 0 ('lamp'): extras.irbake.mode must be \"baked\", \"indirect\" or \"shadowmask\" (got \"dim\")"},
      {"good.gltf --light-mode lamp=dim", "--light-mode needs NAME=MODE"},
      {"good.gltf --light-mode lantern=indirect", "no punctual light is named 'lantern' (its punctual lights: lamp)"},
      {"good.gltf --light-mode sky=indirect", "'sky' is not a punctual light"},
      {"good.gltf --sun 0,-1,0,3 --light-mode sun=indirect --backend reference", "needs a VPL backend"},
      {"good.gltf --light-mode lamp=shadowmask --backend reference", "light 'lamp' in mode shadowmask (--light-mode lamp=shadowmask): needs a VPL backend"},
      {"good.gltf --light-mode lamp=indirect --directional", "light 'lamp' in mode indirect (--light-mode lamp=indirect): --directional bakes every light's direct term into its L1 pages"},
      {"good.gltf --sun 0,-1,0,3 --light-mode sun=shadowmask --directional", "light 'sun' in mode shadowmask"}};
  for (const auto& [args, message] : cases) {
    std::string output;
    EXPECT_EQ(runIrbake("bake " + (dir / args).string() + " -o " + out + " --quiet", output), 2) << args << ": " << output;
    EXPECT_NE(output.find(message), std::string::npos) << output;
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "report.json")) << args;
  }
}

// Five point lights over one triangle, all reaching it (a range, so the bake's cut of lights without one does not
// decide the overlap): four get channels, the dimmest bakes as indirect with a warning naming it, and the report
// and the export say so.
TEST(MixedLighting, FifthOverlappingMaskLightFallsBackWithAWarning) {
  const std::filesystem::path dir = testFolder("mixed_lighting_fallback");
  GltfDocument doc = meshDocument({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2});
  nlohmann::json lights = nlohmann::json::array();
  for (int i = 0; i < 5; ++i) {
    lights.push_back({{"type", "point"}, {"intensity", 10 - i}, {"range", 5.0}, {"name", "l" + std::to_string(i)}});
    doc.root["nodes"].push_back({{"translation", {0.1 * i, 0.2, 1}}, {"extensions", {{"KHR_lights_punctual", {{"light", i}}}}}});
    doc.root["scenes"][0]["nodes"].push_back(i + 1);
  }
  doc.root["extensions"]["KHR_lights_punctual"]["lights"] = lights;
  writeDocument(doc, dir / "five.gltf");
  std::string output;
  ASSERT_EQ(runIrbake("bake " + (dir / "five.gltf").string() + " -o " + (dir / "out").string() +
                          " --vpls 64 --light-mode '*=shadowmask'", output), 0) << output;
  EXPECT_NE(output.find("light 'l4' falls back from shadowmask to indirect"), std::string::npos) << output;
  const nlohmann::json report = nlohmann::json::parse(std::ifstream(dir / "out" / "report.json"));
  const nlohmann::json& assignment = report["shadowMask"]["assignment"];
  EXPECT_EQ(assignment["channels"], 4);
  EXPECT_EQ(assignment["fellBackToIndirect"], nlohmann::json::array({"l4"}));
  for (int i = 0; i < 4; ++i) EXPECT_EQ(assignment["lights"][i]["channel"], i) << assignment.dump();
  EXPECT_EQ(report["plan"]["light-mode l4 #4"]["value"], "indirect");
  const nlohmann::json gltf = nlohmann::json::parse(std::ifstream(dir / "out" / "scene.gltf"));
  EXPECT_EQ(gltf["extensions"]["IRBAKE_shadowmask"]["lights"].size(), 4u);
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "lightmap_0_shadowmask.exr"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "lightmap_0_shadowmask.png"));
}

}  // namespace
}  // namespace irbake
