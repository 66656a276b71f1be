// irbake bake --atlas-from BAKED.gltf (atlas/atlas_from_bake.h): lighting scenarios on one atlas. A second bake
// with another light keeps the first bake's TEXCOORD_1 byte for byte and its pages; with the same light it gives
// the same map as the first; a moved vertex is refused naming the mesh, a changed light colour is accepted.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "export/exr_io.h"
#include "irbake_process.h"

namespace irbake {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using testing::fileText;
using testing::runIrbakeIn;

// A quick bake of the Cornell box: preview quality, one seed.
std::vector<std::string> bakeArgs(const fs::path& scene, const fs::path& out, const std::vector<std::string>& more) {
  std::vector<std::string> args{"bake", scene.string(), "-o", out.string(), "--quality", "preview", "--seed", "3", "--quiet"};
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

// Each exported primitive's TEXCOORD_1 bytes, in document order (the bake writes float VEC2, tightly packed).
std::vector<std::string> texcoord1Bytes(const fs::path& gltf) {
  const json j = json::parse(fileText(gltf));
  const std::string bin = fileText(gltf.parent_path() / j["buffers"][0]["uri"].get<std::string>());
  std::vector<std::string> out;
  for (const json& mesh : j["meshes"])
    for (const json& prim : mesh["primitives"]) {
      if (!prim["attributes"].contains("TEXCOORD_1")) continue;
      const json& a = j["accessors"][prim["attributes"]["TEXCOORD_1"].get<int>()];
      const json& view = j["bufferViews"][a["bufferView"].get<int>()];
      const size_t at = view.value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0));
      out.push_back(bin.substr(at, a["count"].get<size_t>() * 8));
    }
  return out;
}

json atlasRecord(const fs::path& gltf) { return json::parse(fileText(gltf))["extras"]["irbakeAtlas"]; }

// The largest texel difference of two pages over the larger page's peak (any channel).
double relativeMaxDifference(const Lightmap& a, const Lightmap& b) {
  double peak = 0.0, diff = 0.0;
  for (size_t i = 0; i < a.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      peak = std::max({peak, double(a.texels[i][c]), double(b.texels[i][c])});
      diff = std::max(diff, std::abs(double(a.texels[i][c]) - double(b.texels[i][c])));
    }
  return peak > 0.0 ? diff / peak : diff;
}

// The Cornell box's glTF and .bin copied into dir (the scene a test then edits).
fs::path copiedCornell(const fs::path& samples, const fs::path& dir) {
  fs::copy_file(samples / "cornell_box.gltf", dir / "cornell_box.gltf");
  fs::copy_file(samples / "cornell_box.bin", dir / "cornell_box.bin");
  return dir / "cornell_box.gltf";
}

TEST(AtlasFrom, AnotherLightKeepsTheAtlasAndTheSameLightGivesTheSameMap) {
  const fs::path samples = testing::sampleScenes("atlas_from");
  const fs::path dir = testing::scratchFolder("atlas_from", "scenarios");
  const fs::path scene = samples / "cornell_box.gltf";
  const std::vector<std::string> sunA{"--sun", "0.3,-1,0.2,5"}, sunB{"--sun", "-0.4,-1,-0.3,8"};
  ASSERT_EQ(runIrbakeIn(dir, bakeArgs(scene, dir / "a", sunA)).code, 0);
  std::vector<std::string> withB = sunB, withA = sunA;
  for (auto* v : {&withB, &withA}) v->insert(v->end(), {"--atlas-from", (dir / "a" / "scene.gltf").string()});
  const auto b = runIrbakeIn(dir, bakeArgs(scene, dir / "b", withB));
  ASSERT_EQ(b.code, 0) << b.output;
  ASSERT_EQ(runIrbakeIn(dir, bakeArgs(scene, dir / "a_again", withA)).code, 0);

  const auto uvA = texcoord1Bytes(dir / "a" / "scene.gltf");
  ASSERT_EQ(uvA.size(), 8u);  // the Cornell box's eight meshes, one page
  EXPECT_EQ(texcoord1Bytes(dir / "b" / "scene.gltf"), uvA);
  EXPECT_EQ(texcoord1Bytes(dir / "a_again" / "scene.gltf"), uvA);
  EXPECT_EQ(atlasRecord(dir / "b" / "scene.gltf")["pages"], atlasRecord(dir / "a" / "scene.gltf")["pages"]);
  EXPECT_EQ(atlasRecord(dir / "b" / "scene.gltf")["geometryHash"], atlasRecord(dir / "a" / "scene.gltf")["geometryHash"]);

  const Lightmap mapA = readExr(dir / "a" / "lightmap_0.exr");
  const Lightmap mapB = readExr(dir / "b" / "lightmap_0.exr");
  const Lightmap mapAgain = readExr(dir / "a_again" / "lightmap_0.exr");
  ASSERT_EQ(mapB.width, mapA.width);
  ASSERT_EQ(mapB.height, mapA.height);
  // Another sun (direction and irradiance) moves its patch on the floor: far more than the bake's noise.
  EXPECT_GT(relativeMaxDifference(mapA, mapB), 0.1);
  // The same lights and seed on the same atlas: the same scene reaches every stage, so the same map.
  ASSERT_EQ(mapAgain.width, mapA.width);
  EXPECT_LE(relativeMaxDifference(mapA, mapAgain), 1e-6);
}

TEST(AtlasFrom, APrimitiveSpreadOverSeveralPagesKeepsEveryPage) {
  const fs::path samples = testing::sampleScenes("atlas_from");
  const fs::path dir = testing::scratchFolder("atlas_from", "pages");
  const fs::path scene = samples / "cornell_box.gltf";
  // Small pages at a fine density: the blocks' charts land on several pages, one exported part per page.
  ASSERT_EQ(runIrbakeIn(dir, bakeArgs(scene, dir / "a", {"--page-size", "128", "--texels-per-unit", "300"})).code, 0);
  const json a = json::parse(fileText(dir / "a" / "scene.gltf"));
  std::map<json, int> partsOf;
  for (const json& mesh : a["meshes"])
    for (const json& prim : mesh["primitives"]) ++partsOf[prim["extras"]["lightmap"]["source"]];
  ASSERT_TRUE(std::any_of(partsOf.begin(), partsOf.end(), [](const auto& p) { return p.second > 1; }));
  const auto b = runIrbakeIn(dir, bakeArgs(scene, dir / "b", {"--atlas-from", (dir / "a" / "scene.gltf").string()}));
  ASSERT_EQ(b.code, 0) << b.output;
  EXPECT_EQ(texcoord1Bytes(dir / "b" / "scene.gltf"), texcoord1Bytes(dir / "a" / "scene.gltf"));
  const size_t pages = a["extras"]["irbakeAtlas"]["pages"].size();
  ASSERT_GT(pages, 1u);
  // irbake plan with --atlas-from predicts that atlas as it is, not an unwrap at the default density.
  const auto plan = runIrbakeIn(dir, {"plan", scene.string(), "--quality", "preview", "--json", "--atlas-from",
                                      (dir / "a" / "scene.gltf").string()});
  ASSERT_EQ(plan.code, 0) << plan.output;
  const json predicted = json::parse(plan.output.substr(plan.output.find('{')))["atlas"];
  double pageTexels = 0.0;
  for (const json& p : a["extras"]["irbakeAtlas"]["pages"]) pageTexels += p["width"].get<double>() * p["height"].get<double>();
  EXPECT_EQ(predicted["pages"].get<size_t>(), pages);
  EXPECT_EQ(predicted["pageTexels"].get<double>(), pageTexels);
  EXPECT_EQ(predicted["texelsPerMetre"].get<double>(), 300.0);
  for (size_t page = 0; page < pages; ++page) {
    const std::string name = "lightmap_" + std::to_string(page) + ".exr";
    EXPECT_LE(relativeMaxDifference(readExr(dir / "a" / name), readExr(dir / "b" / name)), 1e-6) << name;
  }
}

// Byte offset of vertex 0's x in the POSITION accessor of the mesh named `name`.
size_t firstPositionOffset(const json& j, const std::string& name) {
  for (const json& mesh : j["meshes"])
    if (mesh["name"] == name) {
      const json& a = j["accessors"][mesh["primitives"][0]["attributes"]["POSITION"].get<int>()];
      return j["bufferViews"][a["bufferView"].get<int>()].value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0));
    }
  return std::string::npos;
}

TEST(AtlasFrom, RefusesAMovedVertexNamingTheMeshAndAcceptsAChangedLightColour) {
  const fs::path samples = testing::sampleScenes("atlas_from");
  const fs::path dir = testing::scratchFolder("atlas_from", "geometry");
  ASSERT_EQ(runIrbakeIn(dir, bakeArgs(samples / "cornell_box.gltf", dir / "a", {})).code, 0);
  const std::string from = (dir / "a" / "scene.gltf").string();

  // The short block's first vertex 1 cm higher: the same vertex count, other positions.
  fs::create_directories(dir / "moved");
  const fs::path moved = copiedCornell(samples, dir / "moved");
  const json j = json::parse(fileText(moved));
  const size_t at = firstPositionOffset(j, "short_block");
  ASSERT_NE(at, std::string::npos);
  std::string bin = fileText(dir / "moved" / "cornell_box.bin");
  float y = 0.0f;
  std::memcpy(&y, &bin[at + 4], 4);
  y += 0.01f;
  std::memcpy(&bin[at + 4], &y, 4);
  std::ofstream(dir / "moved" / "cornell_box.bin", std::ios::binary) << bin;
  const auto refused = runIrbakeIn(dir, bakeArgs(moved, dir / "b_moved", {"--atlas-from", from}));
  EXPECT_NE(refused.code, 0);
  EXPECT_NE(refused.output.find("mesh \"short_block\""), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find("positions differ"), std::string::npos) << refused.output;
  EXPECT_FALSE(fs::exists(dir / "b_moved" / "scene.gltf"));

  // The ceiling light's emission (colour) changed: the geometry is the same, the bake goes on.
  fs::create_directories(dir / "colour");
  const fs::path colour = copiedCornell(samples, dir / "colour");
  json c = json::parse(fileText(colour));
  bool changed = false;
  for (json& m : c["materials"])
    if (m.contains("emissiveFactor")) m["emissiveFactor"] = json::array({1.0, 0.5, 0.25}), changed = true;
  ASSERT_TRUE(changed);
  std::ofstream(colour) << c.dump();
  const auto accepted = runIrbakeIn(dir, bakeArgs(colour, dir / "b_colour", {"--atlas-from", from}));
  ASSERT_EQ(accepted.code, 0) << accepted.output;
  EXPECT_EQ(texcoord1Bytes(dir / "b_colour" / "scene.gltf"), texcoord1Bytes(dir / "a" / "scene.gltf"));
}

TEST(AtlasFrom, RefusesAMissingFileAnotherGltfItsOwnFolderAndAnAtlasOption) {
  const fs::path samples = testing::sampleScenes("atlas_from");
  const fs::path dir = testing::scratchFolder("atlas_from", "refusals");
  const fs::path scene = samples / "cornell_box.gltf";
  ASSERT_EQ(runIrbakeIn(dir, bakeArgs(scene, dir / "a", {})).code, 0);
  const std::string from = (dir / "a" / "scene.gltf").string();
  struct Case {
    std::vector<std::string> more;
    fs::path out;
    std::string says;
  };
  const std::vector<Case> cases = {
      {{"--atlas-from", (dir / "none.gltf").string()}, dir / "b", "none.gltf: --atlas-from: no such file"},
      {{"--atlas-from", scene.string()}, dir / "b", "not an irbake bake"},
      {{"--atlas-from", from}, dir / "a", "is an input of this command"},
      {{"--atlas-from", from, "--texels-per-unit", "100"}, dir / "b", "--texels-per-unit would make an atlas of its own"},
  };
  for (const Case& k : cases) {
    const auto run = runIrbakeIn(dir, bakeArgs(scene, k.out, k.more));
    EXPECT_NE(run.code, 0) << k.says;
    EXPECT_NE(run.output.find(k.says), std::string::npos) << run.output;
  }
  EXPECT_FALSE(fs::exists(dir / "b" / "scene.gltf"));
}

}  // namespace
}  // namespace irbake
