// `irbake bake --only-group NAME --atlas-from BAKED.gltf` (pipeline/only_group.h) on the Cornell box with a sun
// through its open front and its emissive ceiling in group "day", a point light "bulb" inside in group "lamp": the
// carried layer comes back bit for bit and the maps are the layers' sum; a re-baked lamp at another seed, and a
// lamp of doubled intensity, agree with full bakes within the bakes' own estimated errors; the refusals.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "export/exr_io.h"
#include "export/light_probes_export.h"
#include "irbake_process.h"
#include "stages/error_estimate/error_estimate.h"

namespace fs = std::filesystem;
using namespace irbake;
using namespace irbake::testing;
using json = nlohmann::json;

namespace {

// The Cornell box with a point light "bulb" of `intensity` candela in the middle of its front half.
fs::path bulbScene(const fs::path& dir, double intensity) {
  json doc = json::parse(fileText(sampleScenes("only_group") / "cornell_box.gltf"));
  const std::string bin = doc["buffers"][0]["uri"].get<std::string>();
  fs::copy_file(sampleScenes("only_group") / bin, dir / bin, fs::copy_options::overwrite_existing);
  doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", intensity}, {"name", "bulb"}}};
  doc["extensionsUsed"].push_back("KHR_lights_punctual");
  doc["nodes"].push_back({{"name", "bulb"}, {"translation", {0.28, 0.3, 0.2}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
  const fs::path file = dir / ("bulb_" + std::to_string(intensity) + ".gltf");
  std::ofstream(file) << doc.dump();
  return file;
}

const std::vector<std::string> kGroups = {"--vpls", "256", "--sun", "0.2,-0.5,1,3", "--probes", "0.1", "--light-group",
                                          "day=sun,emissive", "--light-group", "lamp=bulb", "--estimate-error", "--quiet"};

// irbake bake SCENE -o dir/out with the groups, `more` after them; the output's scene.gltf.
fs::path bakeGroups(const fs::path& dir, const fs::path& scene, const std::string& out, std::vector<std::string> more) {
  std::vector<std::string> args = {"bake", scene.string(), "-o", (dir / out).string()};
  args.insert(args.end(), kGroups.begin(), kGroups.end());
  args.insert(args.end(), more.begin(), more.end());
  const IrbakeRun r = runIrbakeIn(dir, args);
  EXPECT_EQ(r.code, 0) << r.output;
  return dir / out / "scene.gltf";
}

// A full grouped bake's atlas density (an --only-group bake keeps it).
const std::vector<std::string> kFullBake = {"--texels-per-unit", "25"};

std::vector<Lightmap> page(const fs::path& gltf, const std::string& name) { return {readExr(gltf.parent_path() / name)}; }

json report(const fs::path& gltf) { return json::parse(fileText(gltf.parent_path() / "report.json")); }

// The layer's own estimated error (relative) in a grouped bake's report.
double layerError(const json& r, const std::string& layer) {
  for (const json& g : r["lightGroups"])
    if (g["name"] == layer) return g["estimatedError"]["relative"].get<double>();
  ADD_FAILURE() << "no layer " << layer;
  return 0.0;
}

// The binned relative RMS difference of two bakes of the same pages (4×4 bins, as the estimate's; two
// "replicates" a and b: the estimate's noise is RMS(a − b)/2 per bin).
double binnedRelativeDifference(const std::vector<Lightmap>& a, const std::vector<Lightmap>& b) {
  const BinnedError e = replicateError({a, b}, &b, 4);
  return 2.0 * e.noiseRms / e.signalRms;
}

std::vector<Lightmap> scaled(std::vector<Lightmap> maps, float k) {
  for (Lightmap& m : maps)
    for (glm::vec3& t : m.texels) t *= k;
  return maps;
}

}  // namespace

// Same seed: the lamp re-baked alone is the full bake's lamp layer bit for bit (one group's bake depends on its
// sources, the atlas and the settled options only), the carried day layer is copied, and the default pages and
// probes are day + lamp exactly, so the whole result equals the full bake's.
TEST(OnlyGroupCommand, CarriesTheOtherLayerBitForBitAndSumsTheLayers) {
  const fs::path dir = scratchFolder("only_group", "carry");
  const fs::path scene = bulbScene(dir, 0.3);
  const fs::path full = bakeGroups(dir, scene, "full", kFullBake);
  const fs::path only = bakeGroups(dir, scene, "only", {"--only-group", "lamp", "--atlas-from", full.string()});
  EXPECT_EQ(fileText(full.parent_path() / "lightmap_0_day.exr"), fileText(only.parent_path() / "lightmap_0_day.exr"));
  EXPECT_EQ(fileText(full.parent_path() / "lightmap_0_lamp.exr"), fileText(only.parent_path() / "lightmap_0_lamp.exr"));
  const Lightmap day = readExr(only.parent_path() / "lightmap_0_day.exr"), lamp = readExr(only.parent_path() / "lightmap_0_lamp.exr");
  const Lightmap sum = readExr(only.parent_path() / "lightmap_0.exr");
  size_t both = 0;
  for (size_t i = 0; i < sum.texels.size(); ++i) {
    ASSERT_EQ(sum.texels[i], day.texels[i] + lamp.texels[i]) << "texel " << i;
    both += day.texels[i].x > 0.0f && lamp.texels[i].x > 0.0f ? 1 : 0;
  }
  EXPECT_GT(both, sum.texels.size() / 4);
  const LightProbeGrid a = readLightProbes(full), b = readLightProbes(only);
  ASSERT_EQ(a.coefficients.size(), b.coefficients.size());
  for (size_t i = 0; i < a.coefficients.size(); ++i)
    for (int k = 0; k < kShCoefficients; ++k) ASSERT_EQ(a.coefficients[i][k], b.coefficients[i][k]) << "probe " << i;
  EXPECT_EQ(a.sun.irradiance, b.sun.irradiance);  // the carried day layer holds the sun
  EXPECT_GT(a.sun.irradiance.x, 0.0f);
  const json r = report(only);
  EXPECT_EQ(r["onlyGroup"]["rebaked"], "lamp");
  EXPECT_EQ(r["onlyGroup"]["carried"], json::array({"day"}));
  EXPECT_EQ(r["lightGroups"][0]["carried"], true);
  EXPECT_EQ(r["lightGroups"][0]["estimatedError"], report(full)["lightGroups"][0]["estimatedError"]);
}

// Another seed: the re-baked lamp layer against the full bake's, within 3 × the two layers' estimates in
// quadrature (noise ≈ 1×, as LightGroups' sum test bounds it); the day layer still bit for bit.
TEST(OnlyGroupCommand, AnotherSeedsLampIsWithinTheEstimatedError) {
  const fs::path dir = scratchFolder("only_group", "seed");
  const fs::path scene = bulbScene(dir, 0.3);
  const fs::path full = bakeGroups(dir, scene, "full", kFullBake);
  const fs::path only = bakeGroups(dir, scene, "only", {"--only-group", "lamp", "--atlas-from", full.string(), "--seed", "7"});
  EXPECT_EQ(fileText(full.parent_path() / "lightmap_0_day.exr"), fileText(only.parent_path() / "lightmap_0_day.exr"));
  const double difference = binnedRelativeDifference(page(only, "lightmap_0_lamp.exr"), page(full, "lightmap_0_lamp.exr"));
  const double expected = std::hypot(layerError(report(full), "lamp"), layerError(report(only), "lamp"));
  std::printf("lamp at seed 7 vs seed 0: binned difference %.3f%% = %.2f x the combined estimate %.3f%%\n", 100 * difference,
              difference / expected, 100 * expected);
  EXPECT_GT(difference, 0.0);
  EXPECT_LT(difference, 3.0 * expected);
}

// The bulb at twice its intensity: the re-baked lamp layer is 2 × the old one, and the whole result a full grouped
// bake of the edited scene (at another seed), each within 3 × the bakes' estimates in quadrature.
TEST(OnlyGroupCommand, DoubledLampMatchesAFullBakeOfTheEditedScene) {
  const fs::path dir = scratchFolder("only_group", "doubled");
  const fs::path full = bakeGroups(dir, bulbScene(dir, 0.3), "full", kFullBake);
  const fs::path edited = bulbScene(dir, 0.6);
  const fs::path only = bakeGroups(dir, edited, "only", {"--only-group", "lamp", "--atlas-from", full.string(), "--seed", "3"});
  const fs::path again = bakeGroups(dir, edited, "again", {"--atlas-from", full.string(), "--seed", "11"});
  const double twice = binnedRelativeDifference(page(only, "lightmap_0_lamp.exr"), scaled(page(full, "lightmap_0_lamp.exr"), 2.0f));
  const double twiceExpected = std::hypot(layerError(report(full), "lamp"), layerError(report(only), "lamp"));
  const double whole = binnedRelativeDifference(page(only, "lightmap_0.exr"), page(again, "lightmap_0.exr"));
  const double wholeExpected = std::hypot(report(only)["estimatedError"]["relative"].get<double>(),
                                          report(again)["estimatedError"]["relative"].get<double>());
  std::printf("new lamp vs 2 x old: %.3f%% = %.2f x %.3f%%; only-group vs full bake of the edited scene: %.3f%% = %.2f x %.3f%%\n",
              100 * twice, twice / twiceExpected, 100 * twiceExpected, 100 * whole, whole / wholeExpected, 100 * wholeExpected);
  EXPECT_LT(twice, 3.0 * twiceExpected);
  EXPECT_LT(whole, 3.0 * wholeExpected);
  // Not the old lamp: the doubling is seen (the old layer is half the new one, far outside the estimate).
  EXPECT_GT(binnedRelativeDifference(page(only, "lightmap_0_lamp.exr"), page(full, "lightmap_0_lamp.exr")), 10.0 * twiceExpected);
}

TEST(OnlyGroupCommand, RefusesNamingTheFileAndWritesNothing) {
  const fs::path dir = scratchFolder("only_group", "refusals");
  const fs::path scene = bulbScene(dir, 0.3);
  const fs::path full = bakeGroups(dir, scene, "full", kFullBake);
  std::vector<std::string> plainArgs = {"bake", scene.string(), "-o", (dir / "plain").string(), "--vpls", "64", "--quiet"};
  ASSERT_EQ(runIrbakeIn(dir, plainArgs).code, 0);
  const std::string out = (dir / "out").string();
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<std::string> groups = {"--light-group", "day=sun,emissive", "--light-group", "lamp=bulb"};
  auto with = [](std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
  };
  const std::vector<Case> cases = {
      {with(groups, {"--only-group", "lamp"}),
       scene.string() + ": --only-group re-bakes one group on an earlier grouped bake: give --atlas-from"},
      {with(groups, {"--only-group", "night", "--atlas-from", full.string()}),
       scene.string() + ": --only-group 'night': no such light group (the scene's groups: day, lamp)"},
      {{"--light-group", "day=sun,emissive", "--light-group", "street=bulb", "--only-group", "street", "--atlas-from", full.string()},
       full.string() + ": --only-group: the scene's light group 'street' is no layer of this bake (its layers: day, lamp)"},
      {{"--light-group", "day=*", "--only-group", "day", "--atlas-from", full.string()},
       full.string() + ": --only-group: its layer 'lamp' is no light group of the scene (the scene's groups: day)"},
      {with(groups, {"--only-group", "lamp", "--atlas-from", (dir / "plain" / "scene.gltf").string()}),
       (dir / "plain" / "scene.gltf").string() + ": --only-group: has no IRBAKE_lightmap_scenarios"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"bake", scene.string(), "-o", out, "--vpls", "64", "--sun", "0.2,-0.5,1,3", "--probes", "0.1", "--quiet"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const IrbakeRun r = runIrbakeIn(dir, args);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out" / "scene.gltf"));
    EXPECT_FALSE(fs::exists(dir / "out" / "report.json"));
  }
  // A relit file (its default scenario weighs lamp 2): its maps are not its layers' sum at weight 1.
  ASSERT_EQ(runIrbakeIn(dir, {"relight", full.string(), "--group", "lamp=2", "-o", (dir / "relit" / "scene.gltf").string()}).code, 0);
  // The probes: none where the bake has them, and a grid other than the bake's (known only once baked).
  const std::vector<Case> late = {
      {{"--atlas-from", (dir / "relit" / "scene.gltf").string(), "--probes", "0.1"},
       (dir / "relit" / "scene.gltf").string() + ": --only-group: the default scenario weighs layer 'lamp' other than 1 (a relit file)"},
      {{"--atlas-from", full.string(), "--probes", "off"}, full.string() + ": --only-group: this bake has probes, do not turn them off"},
      {{"--atlas-from", full.string(), "--probes", "0.2"}, full.string() + ": --only-group: the probe grid came out as "},
  };
  for (const Case& c : late) {
    std::vector<std::string> args = with({"bake", scene.string(), "-o", out, "--vpls", "64", "--sun", "0.2,-0.5,1,3", "--quiet",
                                          "--only-group", "lamp"}, groups);
    args.insert(args.end(), c.args.begin(), c.args.end());
    const IrbakeRun r = runIrbakeIn(dir, args);
    EXPECT_EQ(r.code, c.args.back() == "0.2" ? 5 : 2) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out" / "scene.gltf"));
    EXPECT_FALSE(fs::exists(dir / "out" / "report.json"));
  }
  // Into the earlier bake's folder: its layers' pages are inputs.
  const IrbakeRun onto = runIrbakeIn(dir, {"bake", scene.string(), "-o", (full.parent_path() / "again.gltf").string(), "--light-group",
                                           "day=sun,emissive", "--light-group", "lamp=bulb", "--sun", "0.2,-0.5,1,3", "--only-group",
                                           "lamp", "--atlas-from", full.string(), "--quiet"});
  EXPECT_EQ(onto.code, 2) << onto.output;
  EXPECT_NE(onto.output.find("is an input of this command"), std::string::npos) << onto.output;
  EXPECT_FALSE(fs::exists(full.parent_path() / "again.gltf"));
}
