// The probes' sun level (IRBAKE_light_probes.sun, docs/export.md) as a user runs it, on a scene with a closed
// form: a black floor (y = 0) and a black roof over x < 0 at y = 2, facing down, under a sun travelling straight
// down with E = π (map value 1), no sky. Nothing bounces, so a point reads the sun alone, which the clients shade
// as an exact clamped cosine: v · max(0, n·up), facing up 1 where it sees the sun, 0 where the roof hides it (L2
// alone: 17/16 facing it, 3/32 at 90° from it). The grid's probes stand at
// x = −2.3, −0.3, 0.7, 1.7 (1 m apart), so the roof's shadow edge x = 0 crosses the cell [−0.3, 0.7] 0.3 of a
// spacing from its probe: the probes' blend smears it over the cell, the sun level's lattice (every 0.25 m)
// holds it to one lattice step.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "irbake_process.h"

namespace fs = std::filesystem;
using namespace irbake::testing;
using json = nlohmann::json;

namespace {

// The floor and the roof as a glTF of two quads (positions, normals, indices), both black.
void writeRoofScene(const fs::path& gltf, bool roof = true) {
  const std::vector<float> p = {-4, 0, -4, 4, 0, -4, 4, 0, 4, -4, 0, 4,     // floor, facing +Y
                                -4, 2, -4, 0, 2, -4, 0, 2, 4, -4, 2, 4};    // roof over x < 0, facing −Y
  const std::vector<float> nrm = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1, 0};
  const std::vector<uint16_t> idx = {0, 2, 1, 0, 3, 2, 0, 1, 2, 0, 2, 3};
  std::string bin(reinterpret_cast<const char*>(p.data()), p.size() * 4);
  bin.append(reinterpret_cast<const char*>(nrm.data()), nrm.size() * 4);
  bin.append(reinterpret_cast<const char*>(idx.data()), idx.size() * 2);
  std::ofstream(gltf.parent_path() / "roof.bin", std::ios::binary) << bin;
  auto mesh = [](const char* name, int position, int normal, int indices) {
    json primitive = {{"attributes", {{"POSITION", position}, {"NORMAL", normal}}}, {"indices", indices}, {"material", 0}};
    return json{{"name", name}, {"primitives", json::array({primitive})}};
  };
  json doc = {{"asset", {{"version", "2.0"}}},
              {"scene", 0},
              {"scenes", {{{"nodes", roof ? json{0, 1} : json{0}}}}},
              {"nodes", {{{"mesh", 0}}, {{"mesh", 1}}}},
              {"materials", {{{"name", "black"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 0}}}}}},
              {"buffers", {{{"uri", "roof.bin"}, {"byteLength", bin.size()}}}},
              {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
                               {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 48}},
                               {{"buffer", 0}, {"byteOffset", 96}, {"byteLength", 48}},
                               {{"buffer", 0}, {"byteOffset", 144}, {"byteLength", 48}},
                               {{"buffer", 0}, {"byteOffset", 192}, {"byteLength", 24}}}},
              {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}, {"min", {-4, 0, -4}}, {"max", {4, 0, 4}}},
                             {{"bufferView", 1}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}, {"min", {-4, 2, -4}}, {"max", {0, 2, 4}}},
                             {{"bufferView", 2}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
                             {{"bufferView", 3}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
                             {{"bufferView", 4}, {"byteOffset", 0}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}},
                             {{"bufferView", 4}, {"byteOffset", 12}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}}}},
              {"meshes", {mesh("floor", 0, 2, 4), mesh("roof", 1, 3, 5)}}};
  std::ofstream(gltf) << doc.dump();
}

// `irbake probe` at `at` with `normal` (empty: the mean over normals): the red channel (the scene is grey).
double valueAt(const fs::path& dir, const fs::path& gltf, const std::string& at, const std::string& normal) {
  std::vector<std::string> args = {"probe", gltf.string(), "--at", at};
  if (!normal.empty()) args.insert(args.end(), {"--normal", normal});
  const IrbakeRun r = runIrbakeIn(dir, args);
  EXPECT_EQ(r.code, 0) << r.output;
  return r.code == 0 ? json::parse(r.output)["value"][0].get<double>() : -1.0;
}

double upAt(const fs::path& dir, const fs::path& gltf, const std::string& at) { return valueAt(dir, gltf, at, "0,1,0"); }

}  // namespace

TEST(ProbeSunLevel, HoldsTheRoofsShadowEdgeWithinOneLatticeStep) {
  const fs::path dir = scratchFolder("probe_sun_level", "roof");
  writeRoofScene(dir / "roof.gltf");
  const IrbakeRun bake = runIrbakeIn(dir, {"bake", (dir / "roof.gltf").string(), "-o", (dir / "out").string(), "--sun",
                                         "0,-1,0,3.14159265", "--probes", "1", "--probe-box=-2.8,0,-1,2.2,2,1", "--quiet"});
  ASSERT_EQ(bake.code, 0) << bake.output;
  const fs::path gltf = dir / "out" / "scene.gltf";
  const json doc = json::parse(fileText(gltf));
  const json& ext = doc["extensions"]["IRBAKE_light_probes"];
  ASSERT_EQ(ext["counts"], json({5, 2, 2}));
  ASSERT_TRUE(ext.contains("sun")) << ext.dump();
  EXPECT_EQ(ext["sun"]["subdivisions"], 4);
  // Refined: the cell the edge crosses, and the one before it, whose lattice is all shaded but whose blend
  // reaches the shaded probe at x = −0.3, which the visibility fit leaves at up to 0.16 (above the tolerance 0.1).
  // Not the lit cells beyond (lattice and blend 1).
  EXPECT_EQ(json::parse(fileText(dir / "out" / "report.json"))["probes"]["sunCells"], 2);
  EXPECT_EQ(ext["sun"]["irradiance"], json({1.0f, 1.0f, 1.0f}));  // map value: E/π facing the sun
  const double full = 1.0;
  // Lit side, 0.3 m from the edge (lattice points x = 0.2 and 0.45 both lit): the whole sun. Shadow side, 0.1 m
  // from it (x = −0.3 and −0.05 both shaded): none. Float rounding only.
  for (const char* at : {"0.3,1,0", "0.3,0.6,0.4", "0.6,1.4,-0.3"}) EXPECT_NEAR(upAt(dir, gltf, at), full, 2e-3) << at;
  for (const char* at : {"-0.1,1,0", "-0.25,0.6,0.4"}) EXPECT_NEAR(upAt(dir, gltf, at), 0.0, 2e-3) << at;
  // Outside the refined cell nothing changes: the probes alone, which see the sun fully or not at all there.
  EXPECT_NEAR(upAt(dir, gltf, "1.2,1,0"), full, 2e-3);
  EXPECT_NEAR(upAt(dir, gltf, "-1.5,1,0"), 0.0, 2e-3);
  // Other normals at the lit point: the clamped cosine, max(0, n·up) (60° from the sun, 90°, facing away).
  EXPECT_NEAR(valueAt(dir, gltf, "0.3,1,0", "0.8660254,0.5,0"), 0.5, 2e-3);
  EXPECT_NEAR(valueAt(dir, gltf, "0.3,1,0", "1,0,0"), 0.0, 2e-3);
  EXPECT_NEAR(valueAt(dir, gltf, "0.3,1,0", "0,-1,0"), 0.0, 2e-3);

  // A client that ignores `sun` reads the grid as before: the lit point gets part of the sun only.
  json old = doc;
  old["extensions"]["IRBAKE_light_probes"].erase("sun");
  std::ofstream(dir / "out" / "old.gltf") << old.dump();
  const double coarse = upAt(dir, dir / "out" / "old.gltf", "0.3,1,0");
  EXPECT_GT(coarse, 0.1 * 17.0 / 16.0);
  EXPECT_LT(coarse, 0.9 * 17.0 / 16.0);

  // Damaged sun levels are refused naming the field (exit 5).
  const std::string bin = fileText(dir / "out" / "scene.bin");
  auto refused = [&](const std::string& name, json d, const std::string& bytes, const std::string& message) {
    const fs::path f = dir / "out" / (name + ".gltf");
    d["buffers"][0]["uri"] = name + ".bin";
    std::ofstream(f) << d.dump();
    std::ofstream(dir / "out" / (name + ".bin"), std::ios::binary) << bytes;
    const IrbakeRun r = runIrbakeIn(dir, {"probe", f.string(), "--at", "0.3,1,0"});
    EXPECT_EQ(r.code, 5) << name << ": " << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << name << ": " << r.output;
  };
  auto at = [&](const char* field) {  // byte offset of the accessor's first element
    const json& a = doc["accessors"][ext["sun"][field].get<int>()];
    return doc["bufferViews"][a["bufferView"].get<int>()].value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0));
  };
  std::string b = bin;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(b.data() + at("sh"), &nan, 4);
  refused("sun_nan", doc, b, "IRBAKE_light_probes.sun.sh: a non-finite coefficient");
  json shortVisibility = doc;  // 20 probes, 4 a word
  shortVisibility["accessors"][ext["sun"]["visibility"].get<int>()]["count"] = 4;
  refused("sun_visibility", shortVisibility, bin, "IRBAKE_light_probes.sun.visibility: 4 elements, the grid needs 5");
  b = bin;
  const uint32_t outside = 4;  // probe (4, 0, 0): the last along x, no cell's base
  std::memcpy(b.data() + at("cells"), &outside, 4);
  refused("sun_cell", doc, b, "IRBAKE_light_probes.sun.cells: 4 is not a cell of the grid");
  json shortFine = doc;
  shortFine["accessors"][ext["sun"]["fine"].get<int>()]["count"] = 3;
  refused("sun_fine", shortFine, bin, "IRBAKE_light_probes.sun.fine: 3 elements, the grid needs 8");
  json badS = doc;
  badS["extensions"]["IRBAKE_light_probes"]["sun"]["subdivisions"] = 0;
  refused("sun_s", badS, bin, "IRBAKE_light_probes.sun.subdivisions");
  json negative = doc;
  negative["extensions"]["IRBAKE_light_probes"]["sun"]["irradiance"] = {1.0, -0.5, 1.0};
  refused("sun_negative", negative, bin, "IRBAKE_light_probes.sun.irradiance: negative");
  json noIrradiance = doc;
  noIrradiance["extensions"]["IRBAKE_light_probes"]["sun"].erase("irradiance");
  refused("sun_no_irradiance", noIrradiance, bin, "IRBAKE_light_probes.sun.irradiance: needs 3 numbers");
  json huge = doc;  // 1e39 does not fit a float: infinite once read
  huge["extensions"]["IRBAKE_light_probes"]["sun"]["irradiance"] = {1.0, 1e39, 1.0};
  refused("sun_infinite", huge, bin, "IRBAKE_light_probes.sun.irradiance: not finite");
  json onlyCells = doc;  // `cells` without `fine`
  onlyCells["extensions"]["IRBAKE_light_probes"]["sun"].erase("fine");
  refused("sun_no_fine", onlyCells, bin, "IRBAKE_light_probes.sun.fine: no accessor index");
}

// The sun level without a shadow: the black floor alone under a sun from 60° above the horizon (E = π, map value
// 1 facing it), no sky. No cell is refined, yet the `sun` object is written (without `cells` and `fine`) and
// `irbake probe --normal n` reads the exact max(0, n·l) for normals toward the sun, across it and away from it,
// where L2 alone rings by up to 3/32 of it. The mean over normals stays the L0 term: 1/4.
TEST(ProbeSunLevel, SunWithoutShadowIsAnExactClampedCosine) {
  const fs::path dir = scratchFolder("probe_sun_level", "open");
  writeRoofScene(dir / "floor.gltf", false);
  const glm::vec3 l = glm::normalize(glm::vec3(0.5f, 0.8660254f, 0.0f));  // toward the sun
  const IrbakeRun bake = runIrbakeIn(dir, {"bake", (dir / "floor.gltf").string(), "-o", (dir / "out").string(), "--sun",
                                         "-0.5,-0.8660254,0,3.14159265", "--probes", "1", "--probe-box=-2,0.5,-1,2,2,1", "--quiet"});
  ASSERT_EQ(bake.code, 0) << bake.output;
  const fs::path gltf = dir / "out" / "scene.gltf";
  const json ext = json::parse(fileText(gltf))["extensions"]["IRBAKE_light_probes"];
  ASSERT_TRUE(ext.contains("sun")) << ext.dump();
  EXPECT_FALSE(ext["sun"].contains("cells"));
  EXPECT_FALSE(ext["sun"].contains("fine"));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(ext["sun"]["irradiance"][c].get<double>(), 1.0, 1e-6);
  const float s = std::sqrt(0.5f);
  for (const glm::vec3 n : {l, glm::vec3(0, 1, 0), glm::vec3(s, 0, s), glm::vec3(-l.y, l.x, 0.0f), glm::vec3(0, 0, 1), -l,
                            glm::vec3(0, -1, 0)}) {
    const std::string normal = std::to_string(n.x) + "," + std::to_string(n.y) + "," + std::to_string(n.z);
    for (const char* at : {"0.3,1.2,0.1", "-1.1,0.7,-0.4"})
      EXPECT_NEAR(valueAt(dir, gltf, at, normal), std::max(0.0f, glm::dot(n, l)), 2e-3) << at << " normal " << normal;
  }
  EXPECT_NEAR(valueAt(dir, gltf, "0.3,1.2,0.1", ""), 0.25, 2e-3);
}
