// `irbake bake --probes` and `irbake probe` as a user runs them: the probes of real bakes against closed forms,
// the extension's presence and absence, and every refusal of a damaged file.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "irbake_process.h"

namespace fs = std::filesystem;
using namespace irbake::testing;
using json = nlohmann::json;

namespace {

// `irbake probe` → its JSON value (asserting exit 0).
std::vector<double> probeValue(const fs::path& dir, const fs::path& gltf, const std::string& at, const std::string& normal = "") {
  std::vector<std::string> args = {"probe", gltf.string(), "--at", at};
  if (!normal.empty()) args.insert(args.end(), {"--normal", normal});
  const IrbakeRun r = runIrbakeIn(dir, args);
  EXPECT_EQ(r.code, 0) << r.output;
  if (r.code != 0) return {0, 0, 0};
  return json::parse(r.output)["value"].get<std::vector<double>>();
}

json readJson(const fs::path& p) { return json::parse(fileText(p)); }

}  // namespace

TEST(ProbesCommand, FurnaceProbesReadLeOverOneMinusRho) {
  // Every direction brings Le/(1 − ρ) = 2. Tolerance: the map's mean is within 1% of 2 (BakePipeline's furnace
  // test), and 3σ of 16384 independent rays is 3 · 1.28 · 2 / 128 = 0.06 (constant radiance: no L2 truncation).
  const fs::path dir = scratchFolder("probes_command", "furnace");
  const fs::path samples = sampleScenes("probes_command");
  const IrbakeRun bake = runIrbakeIn(dir, {"bake", (samples / "furnace.gltf").string(), "-o", (dir / "out").string(),
                                      "--probes", "0.5", "--probe-rays", "16384", "--quiet"});
  ASSERT_EQ(bake.code, 0) << bake.output;
  const json report = readJson(dir / "out" / "report.json");
  EXPECT_EQ(report["probes"]["count"], 64);  // 2 m / 0.5 m per axis
  EXPECT_EQ(report["probes"]["valid"], 64);
  EXPECT_EQ(report["plan"]["probe-spacing"]["automatic"], false);
  EXPECT_GT(report["timings"]["seconds"]["probes"].get<double>(), 0.0);
  const fs::path gltf = dir / "out" / "scene.gltf";
  const json doc = readJson(gltf);
  EXPECT_NE(std::find(doc["extensionsUsed"].begin(), doc["extensionsUsed"].end(), "IRBAKE_light_probes"), doc["extensionsUsed"].end());
  EXPECT_FALSE(doc.contains("extensionsRequired") &&
               std::find(doc["extensionsRequired"].begin(), doc["extensionsRequired"].end(), "IRBAKE_light_probes") !=
                   doc["extensionsRequired"].end());
  for (const auto& [at, normal] : std::vector<std::pair<std::string, std::string>>{
           {"0,0,0", ""}, {"0.3,-0.4,0.1", "0,1,0"}, {"-0.6,0.5,0.7", "1,-1,0.5"}, {"0.9,0.9,-0.9", "0,0,-1"}}) {
    const std::vector<double> v = probeValue(dir, gltf, at, normal);
    for (double c : v) EXPECT_NEAR(c, 2.0, 0.08) << at << " normal " << normal;
  }
}

TEST(ProbesCommand, NoLightOnTheDarkSideOfTheThinWall) {
  // makeThinWall: the room x > 0 gets nothing (its map stays below 1e-3 of the lit side's). Points on the dark
  // side, in cells whose corners straddle the wall too, read the dark room's probes only.
  const fs::path dir = scratchFolder("probes_command", "thin_wall");
  const fs::path samples = sampleScenes("probes_command");
  const IrbakeRun bake = runIrbakeIn(dir, {"bake", (samples / "thin_wall.gltf").string(), "-o", (dir / "out").string(),
                                      "--probes", "0.3", "--quiet"});
  ASSERT_EQ(bake.code, 0) << bake.output;
  const fs::path gltf = dir / "out" / "scene.gltf";
  double lit = 0.0;
  for (const char* at : {"-1.5,1,0", "-0.5,0.5,0.5", "-0.05,1.5,-0.5"}) lit += probeValue(dir, gltf, at)[0] / 3.0;
  EXPECT_GT(lit, 0.1);
  for (const char* at : {"0.02,1,0", "0.1,0.3,0.6", "0.14,1.8,-0.8", "0.5,1,0", "1.5,0.2,0.9"})
    for (const char* normal : {"", "-1,0,0", "0,1,0"}) {
      const std::vector<double> v = probeValue(dir, gltf, at, normal);
      for (double c : v) EXPECT_LT(c, 1e-3 * lit) << at << " normal " << normal;
    }
}

TEST(ProbesCommand, OffWritesNoExtensionAndBadFilesAreRefused) {
  const fs::path dir = scratchFolder("probes_command", "refusals");
  const fs::path samples = sampleScenes("probes_command");
  const std::string scene = (samples / "point_over_plane.gltf").string();
  ASSERT_EQ(runIrbakeIn(dir, {"bake", scene, "-o", (dir / "off").string(), "--probes", "off", "--quiet"}).code, 0);
  const json offDoc = readJson(dir / "off" / "scene.gltf");
  EXPECT_FALSE(offDoc.contains("extensions") && offDoc["extensions"].contains("IRBAKE_light_probes"));
  EXPECT_FALSE(readJson(dir / "off" / "report.json").contains("probes"));
  IrbakeRun r = runIrbakeIn(dir, {"probe", (dir / "off" / "scene.gltf").string(), "--at", "0,1,0"});
  EXPECT_EQ(r.code, 5);
  EXPECT_NE(r.output.find("scene.gltf: no IRBAKE_light_probes extension"), std::string::npos) << r.output;

  ASSERT_EQ(runIrbakeIn(dir, {"bake", scene, "-o", (dir / "on").string(), "--probes", "2", "--probe-box",
                         "-5,0.25,-5,5,0.75,5", "--quiet"}).code, 0);
  const fs::path gltf = dir / "on" / "scene.gltf";
  // The probe at (0, 0.5, 0), 0.5 m under the light (I = 10 W/sr): facing up the light's peak I/(π h²) times the
  // L2 kernel at c = 1, 17/16; the lit plane below adds at most 3/32 of ∫ ρ M dω/π ≤ 3/32 · 2 · 0.5 · 10/π = 0.3.
  const std::vector<double> up = probeValue(dir, gltf, "0,0.5,0", "0,1,0");
  EXPECT_NEAR(up[0], 10.0 / (M_PI * 0.25) * 17.0 / 16.0, 0.3);
  // A bake of that export replaces its probes; with --probes off it drops them (no stale accessor indices).
  ASSERT_EQ(runIrbakeIn(dir, {"bake", gltf.string(), "-o", (dir / "again").string(), "--probes", "3", "--quiet"}).code, 0);
  EXPECT_EQ(readJson(dir / "again" / "scene.gltf")["extensions"]["IRBAKE_light_probes"]["spacing"], 3.0);
  EXPECT_EQ(runIrbakeIn(dir, {"probe", (dir / "again" / "scene.gltf").string(), "--at", "0,0.5,0"}).code, 0);
  ASSERT_EQ(runIrbakeIn(dir, {"bake", gltf.string(), "-o", (dir / "again_off").string(), "--probes", "off", "--quiet"}).code, 0);
  const json againOff = readJson(dir / "again_off" / "scene.gltf");
  EXPECT_FALSE(againOff.contains("extensions") && againOff["extensions"].contains("IRBAKE_light_probes"));
  EXPECT_EQ(std::count(againOff["extensionsUsed"].begin(), againOff["extensionsUsed"].end(), "IRBAKE_light_probes"), 0);
  // Damaged copies: each refused with exit 5, naming the file and the problem.
  const json good = readJson(gltf);
  const std::string bin = fileText(dir / "on" / "scene.bin");
  auto damaged = [&](const std::string& name, json doc, std::string bytes) {
    const fs::path d = dir / name;
    fs::create_directories(d);
    for (const auto& e : fs::directory_iterator(dir / "on"))
      if (e.path().extension() == ".png") fs::copy_file(e.path(), d / e.path().filename(), fs::copy_options::overwrite_existing);
    std::ofstream(d / "scene.gltf") << doc.dump();
    std::ofstream(d / "scene.bin", std::ios::binary) << bytes;
    return runIrbakeIn(d, {"probe", (d / "scene.gltf").string(), "--at", "0,0.5,0"});
  };
  json wrongCounts = good;
  wrongCounts["extensions"]["IRBAKE_light_probes"]["counts"][0] = good["extensions"]["IRBAKE_light_probes"]["counts"][0].get<int>() + 1;
  r = damaged("counts", wrongCounts, bin);
  EXPECT_EQ(r.code, 5);
  EXPECT_NE(r.output.find("IRBAKE_light_probes.coefficients:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the grid needs"), std::string::npos) << r.output;
  json shortAccessor = good;  // the view shorter than the accessor claims
  const int coefficients = good["extensions"]["IRBAKE_light_probes"]["coefficients"];
  const int view = good["accessors"][coefficients]["bufferView"];
  shortAccessor["bufferViews"][view]["byteLength"] = good["bufferViews"][view]["byteLength"].get<size_t>() - 12;
  r = damaged("short", shortAccessor, bin);
  EXPECT_EQ(r.code, 5);
  EXPECT_NE(r.output.find("scene.gltf"), std::string::npos) << r.output;
  std::string nanBin = bin;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nanBin.data() + good["bufferViews"][view].value("byteOffset", size_t(0)) + 4, &nan, sizeof(float));
  r = damaged("nan", good, nanBin);
  EXPECT_EQ(r.code, 5);
  EXPECT_NE(r.output.find("non-finite coefficient"), std::string::npos) << r.output;
  json badSpacing = good;
  badSpacing["extensions"]["IRBAKE_light_probes"]["spacing"] = -1;
  r = damaged("spacing", badSpacing, bin);
  EXPECT_EQ(r.code, 5);
  EXPECT_NE(r.output.find("IRBAKE_light_probes.spacing"), std::string::npos) << r.output;
  // Bad arguments: exit 2, nothing written.
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"bake", scene, "-o", (dir / "bad1").string(), "--probes", "-1"},
        {"bake", scene, "-o", (dir / "bad2").string(), "--probes", "often"},
        {"bake", scene, "-o", (dir / "bad3").string(), "--probes", "0.1", "--probe-box", "0,0,0,20,20,20"},  // 8M probes
        {"bake", scene, "-o", (dir / "bad4").string(), "--probe-box", "1,1,1,0,0,0"}}) {
    r = runIrbakeIn(dir, args);
    EXPECT_EQ(r.code, 2) << args.back() << ": " << r.output;
    EXPECT_FALSE(fs::exists(fs::path(args[3]) / "scene.gltf"));
  }
  r = runIrbakeIn(dir, {"probe", gltf.string(), "--at", "0,1,0", "--normal", "0,0,0"});
  EXPECT_EQ(r.code, 2) << r.output;
}

TEST(ProbesCommand, ProbeBoxesAndBudgetsRefusedBeforeAnyWork) {
  const fs::path dir = scratchFolder("probes_command", "box_refusals");
  const fs::path samples = sampleScenes("probes_command");
  const std::string plane = (samples / "point_over_plane.gltf").string();  // a 10 × 10 m plane at y = 0
  const std::string furnace = (samples / "furnace.gltf").string();         // a 2 m box
  auto refused = [&](const std::string& name, const std::string& scene, std::vector<std::string> options,
                     const std::string& expected) {
    std::vector<std::string> args = {"bake", scene, "-o", (dir / name).string(), "--quiet"};
    args.insert(args.end(), options.begin(), options.end());
    const IrbakeRun r = runIrbakeIn(dir, args);
    EXPECT_EQ(r.code, 2) << name << ": " << r.output;  // Usage, not Embree's SIGABRT (134) nor a bake
    EXPECT_NE(r.output.find(expected), std::string::npos) << name << ": " << r.output;
    EXPECT_FALSE(fs::exists(dir / name / "scene.gltf")) << name;
    return r.output;
  };
  // Coordinates beyond the scene's supported 1e9 m: the probes' rays would start where Embree aborts.
  refused("huge", plane, {"--probe-box=-1e30,-1e30,-1e30,1e30,1e30,1e30"}, "--probe-box needs coordinates within");
  refused("past_float", plane, {"--probe-box=-1,-1,-1,1e300,1,1"}, "--probe-box needs coordinates within");
  // A box more than the scene's size (10 m) from its bounds, and boxes without a size on an axis.
  refused("far", plane, {"--probe-box=100,100,100,101,101,101"}, "does not come within the scene's size (10 m)");
  refused("point", plane, {"--probe-box=0,0.5,0,0,0.5,0"}, "--probe-box needs a size on every axis");
  refused("flat", plane, {"--probe-box=-1,0.5,-1,1,0.5,1"}, "--probe-box needs a size on every axis");
  // 2e9 m per axis at 0.01 m: (2e11)³ = 8e33 probes, quoted as such rather than a wrapped 64-bit integer.
  const std::string many = refused("many", plane, {"--probes", "0.01", "--probe-box=-1e9,-1e9,-1e9,1e9,1e9,1e9"}, "gives ");
  const size_t at = many.find("gives ") + 6;
  EXPECT_NEAR(std::strtod(many.c_str() + at, nullptr) / 8e33, 1.0, 1e-3) << many;
  // The budget: 64 probes (2 m at 0.5 m) over a budget of 63 are refused, naming the count and the option that
  // raises it; a budget of 64 bakes them.
  refused("budget63", furnace, {"--probes", "0.5", "--probe-budget", "63"},
          "gives 64 probes, about 0.0625 times the automatic grid's 1024, over the probe budget of 63: raise it with "
          "--probe-budget 64");
  ASSERT_EQ(runIrbakeIn(dir, {"bake", furnace, "-o", (dir / "budget64").string(), "--probes", "0.5", "--probe-budget",
                              "64", "--quiet"}).code, 0);
  EXPECT_EQ(readJson(dir / "budget64" / "report.json")["probes"]["count"], 64);
  // The default budget, 16384: 0.05 m over the 2 m box asks for 40³ = 64000 (about 100 s of probes).
  refused("default_budget", furnace, {"--probes", "0.05"}, "gives 64000 probes, about 62.5 times the automatic grid's "
                                                           "1024, over the probe budget of 16384: raise it with --probe-budget 64000");
}

TEST(ProbesCommand, HugePointsAndTamperedGridsAreRefused) {
  const fs::path dir = scratchFolder("probes_command", "tampered");
  const fs::path samples = sampleScenes("probes_command");
  ASSERT_EQ(runIrbakeIn(dir, {"bake", (samples / "point_over_plane.gltf").string(), "-o", (dir / "on").string(),
                              "--probes", "2", "--probe-box=-5,0.25,-5,5,0.75,5", "--quiet"}).code, 0);
  const fs::path gltf = dir / "on" / "scene.gltf";
  // --at beyond 1e9 m (1e300 is Inf in float): Usage, naming the option, where Embree aborted on the visibility rays.
  for (const char* point : {"1e30,0.5,0.5", "1e19,0.5,0.5", "0.5,-1e300,0.5"}) {
    const IrbakeRun r = runIrbakeIn(dir, {"probe", gltf.string(), "--at", point});
    EXPECT_EQ(r.code, 2) << point << ": " << r.output;
    EXPECT_NE(r.output.find("--at needs coordinates within the supported ±1e9 m"), std::string::npos) << r.output;
  }
  EXPECT_EQ(probeValue(dir, gltf, "1e9,0.5,0").size(), 3u);  // the limit itself is read (the edge probe)
  // Grids no bake writes: InvalidData (5), naming the file and the field.
  const json good = readJson(gltf);
  const std::string bin = fileText(dir / "on" / "scene.bin");
  auto tampered = [&](const std::string& name, const std::function<void(json&)>& edit, std::string bytes, const std::string& field) {
    const fs::path d = dir / name;
    fs::create_directories(d);
    for (const auto& e : fs::directory_iterator(dir / "on"))
      if (e.path().extension() == ".png") fs::copy_file(e.path(), d / e.path().filename(), fs::copy_options::overwrite_existing);
    json doc = good;
    edit(doc["extensions"]["IRBAKE_light_probes"]);
    std::ofstream(d / "scene.gltf") << doc.dump();
    std::ofstream(d / "scene.bin", std::ios::binary) << bytes;
    const IrbakeRun r = runIrbakeIn(d, {"probe", (d / "scene.gltf").string(), "--at", "0,0.5,0"});
    EXPECT_EQ(r.code, 5) << name << ": " << r.output;
    EXPECT_NE(r.output.find((d / "scene.gltf").string() + ": IRBAKE_light_probes." + field), std::string::npos)
        << name << ": " << r.output;
  };
  tampered("origin", [](json& e) { e["origin"] = {3e38, 0.5, 0}; }, bin, "origin: 3e+38 m is beyond the supported 1e9 m");
  tampered("spacing_huge", [](json& e) { e["spacing"] = 3e38; }, bin, "spacing: 3e+38 m is outside the 0.01 … 1e9 m");
  tampered("spacing_tiny", [](json& e) { e["spacing"] = 1e-30; }, bin, "spacing: 1e-30 m is outside the 0.01 … 1e9 m");
  // Every number finite and each within 1e9 m, but the grid's far corner at 9e8 + 4 · 1e8 = 1.3e9 m.
  tampered("extent", [](json& e) { e["origin"] = {9e8, 0.5, 0}; e["spacing"] = 1e8; }, bin,
           "counts: the grid reaches 1.3e+09 m");
  // A probe moved 1e30 m from its grid point (a bake moves one at most half a spacing).
  std::string far = bin;
  const int offsets = good["extensions"]["IRBAKE_light_probes"]["offsets"];
  const int view = good["accessors"][offsets]["bufferView"];
  const float huge = 1e30f;
  std::memcpy(far.data() + good["bufferViews"][view].value("byteOffset", size_t(0)) + good["accessors"][offsets].value("byteOffset", size_t(0)),
              &huge, sizeof(float));
  tampered("offset", [](json&) {}, far, "offsets: probe 0 is moved 1e+30 m from its grid point");
}
