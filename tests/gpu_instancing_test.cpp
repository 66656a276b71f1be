// EXT_mesh_gpu_instancing through `irbake bake`: each instance gets a light-map region of its own, the export
// writes each instance as a node of its own (the extension dropped, said in the log and the report), the maps
// are those of the same scene written as plain nodes, and irview opens the output.
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "export/exr_io.h"
#include "scene/gltf_loader.h"
#include "testing/gltf_builder.h"

namespace fs = std::filesystem;
using namespace irbake;
using json = nlohmann::json;

namespace {

// Runs a program with the arguments (each quoted); its exit code, and its output in *output.
int run(const std::string& exe, const std::vector<std::string>& args, const fs::path& log, std::string* output) {
  std::string cmd = "\"" + exe + "\"";
  for (const auto& a : args) cmd += " \"" + a + "\"";
  cmd += " > \"" + log.string() + "\" 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  *output = text.str();
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

struct Placement {
  glm::vec3 translation;
  float turnDegrees;  // about +y
  float scale;
};
// Four instances of a 0.8 m square facing up, under a point light 2 m above the origin.
const std::vector<Placement> kPlacements = {
    {{-1, 0, -1}, 0, 1}, {{1, 0, -1}, 90, 1}, {{-1, 0, 1}, 0, 1.5f}, {{1.2f, 0.3f, 1}, 30, 0.75f}};

// The square mesh instanced by EXT_mesh_gpu_instancing on node 0 (gpu) or on one plain node per placement.
GltfDocument squares(bool gpu) {
  const float h = 0.4f;
  GltfDocument doc = irbake::testing::meshDocument({{-h, 0, -h}, {h, 0, -h}, {h, 0, h}, {-h, 0, h}}, {0, 2, 1, 0, 3, 2},
                                           std::vector<glm::vec3>(4, glm::vec3(0, 1, 0)));
  doc.root["meshes"][0]["name"] = "square";
  std::vector<glm::vec3> t, s;
  std::vector<float> r;
  json nodes = json::array();
  for (const Placement& p : kPlacements) {
    const glm::quat q = glm::angleAxis(glm::radians(p.turnDegrees), glm::vec3(0, 1, 0));
    t.push_back(p.translation);
    s.push_back(glm::vec3(p.scale));
    r.insert(r.end(), {q.x, q.y, q.z, q.w});
    nodes.push_back({{"mesh", 0},
                     {"translation", {p.translation.x, p.translation.y, p.translation.z}},
                     {"rotation", {q.x, q.y, q.z, q.w}},
                     {"scale", {p.scale, p.scale, p.scale}}});
  }
  if (gpu) {
    const int view = doc.addBufferView(r.data(), r.size() * sizeof(float));
    const int rotation = doc.append("accessors", {{"bufferView", view}, {"componentType", 5126}, {"count", kPlacements.size()}, {"type", "VEC4"}});
    doc.root["nodes"][0]["name"] = "props";
    doc.root["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"] = {
        {"TRANSLATION", doc.addVec3(t)}, {"ROTATION", rotation}, {"SCALE", doc.addVec3(s)}};
    doc.root["extensionsUsed"] = {"EXT_mesh_gpu_instancing", "KHR_lights_punctual"};
  } else {
    doc.root["nodes"] = nodes;
    doc.root["extensionsUsed"] = {"KHR_lights_punctual"};
  }
  doc.root["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", 20}}});
  const int light = doc.append("nodes", {{"translation", {0, 2, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  json roots = json::array();
  for (int n = 0; n <= light; ++n) roots.push_back(n);
  doc.root["scenes"][0]["nodes"] = roots;
  return doc;
}

// The rectangle a primitive's TEXCOORD_1 covers, in texels of its page.
struct TexelRect {
  int page;
  glm::vec2 lo, hi;
};
TexelRect rectOf(const Primitive& p) {
  TexelRect r{p.lightmap.page, glm::vec2(1e30f), glm::vec2(-1e30f)};
  for (const glm::vec2& uv : p.uv1) {
    const glm::vec2 texel = uv * glm::vec2(p.lightmap.width, p.lightmap.height);
    r.lo = glm::min(r.lo, texel);
    r.hi = glm::max(r.hi, texel);
  }
  return r;
}

}  // namespace

// The same four squares baked as GPU instances and as plain nodes: each instance has its own rectangle of
// texels (no two overlap), the maps agree within 1e-5 (relative) at every texel, the output holds one node per
// instance at the instance's place and no EXT_mesh_gpu_instancing, and irview opens it.
TEST(GpuInstancing, EachInstanceHasItsOwnRegionAndTheMapsOfPlainNodes) {
  const fs::path dir = fs::current_path() / "test_scratch" / "gpu_instancing";
  fs::remove_all(dir);
  fs::create_directories(dir);
  irbake::testing::writeDocument(squares(true), dir / "instanced.gltf");
  irbake::testing::writeDocument(squares(false), dir / "plain.gltf");
  const std::vector<std::string> options = {"--backend", "embree", "--texels-per-unit", "16", "--vpls", "64", "--seed", "3", "--probes", "off"};
  std::string log;
  for (const char* name : {"instanced", "plain"}) {
    std::vector<std::string> args = {"bake", (dir / (std::string(name) + ".gltf")).string(), "-o", (dir / name).string()};
    args.insert(args.end(), options.begin(), options.end());
    ASSERT_EQ(run(IRBAKE_EXE, args, dir / (std::string(name) + "_log.txt"), &log), 0) << log;
    if (std::string(name) == "instanced") {
      EXPECT_NE(log.find("EXT_mesh_gpu_instancing"), std::string::npos) << log;
    }
  }
  const json report = json::parse(std::ifstream(dir / "instanced" / "report.json"));
  EXPECT_EQ(report["scene"]["gpuInstancing"]["instances"].get<int>(), 4) << report["scene"].dump();
  EXPECT_EQ(report["scene"]["gpuInstancing"]["nodes"].get<int>(), 1);

  // The output: node 0 lost its mesh and the extension, and has one child per instance, each with a mesh of its own.
  const json gltf = json::parse(std::ifstream(dir / "instanced" / "scene.gltf"));
  EXPECT_EQ(gltf.dump().find("EXT_mesh_gpu_instancing"), std::string::npos);
  EXPECT_FALSE(gltf["nodes"][0].contains("mesh"));
  ASSERT_EQ(gltf["nodes"][0]["children"].size(), kPlacements.size());
  std::vector<int> meshes;
  for (const auto& c : gltf["nodes"][0]["children"]) meshes.push_back(gltf["nodes"][c.get<int>()]["mesh"].get<int>());
  std::sort(meshes.begin(), meshes.end());
  EXPECT_EQ(std::unique(meshes.begin(), meshes.end()), meshes.end()) << "two instances share a mesh";

  const Scene input = loadScene(dir / "instanced.gltf", LoadOptions{false, true});
  const Scene out = loadScene(dir / "instanced" / "scene.gltf", LoadOptions{false, true});
  ASSERT_EQ(out.primitives.size(), kPlacements.size());
  std::vector<TexelRect> rects;
  for (size_t i = 0; i < out.primitives.size(); ++i) {
    const Primitive& p = out.primitives[i];
    EXPECT_EQ(p.instance, -1);
    ASSERT_EQ(p.uv1.size(), p.positions.size());
    // Each output node puts the square where its instance was: same corners (the vertex set may be split).
    for (const glm::vec3& v : p.positions) {
      float nearest = 1e30f;
      for (const glm::vec3& w : input.primitives[i].positions) nearest = std::min(nearest, glm::length(v - w));
      EXPECT_LT(nearest, 1e-5f) << "instance " << i;
    }
    rects.push_back(rectOf(p));
  }
  for (size_t a = 0; a < rects.size(); ++a)
    for (size_t b = a + 1; b < rects.size(); ++b) {
      if (rects[a].page != rects[b].page) continue;
      const bool apart = rects[a].hi.x <= rects[b].lo.x || rects[b].hi.x <= rects[a].lo.x || rects[a].hi.y <= rects[b].lo.y ||
                         rects[b].hi.y <= rects[a].lo.y;
      EXPECT_TRUE(apart) << "instances " << a << " and " << b << " overlap on page " << rects[a].page;
    }

  // The maps: page for page, texel for texel, those of the plain nodes.
  for (int page = 0; fs::exists(dir / "plain" / ("lightmap_" + std::to_string(page) + ".exr")); ++page) {
    const std::string name = "lightmap_" + std::to_string(page) + ".exr";
    ASSERT_TRUE(fs::exists(dir / "instanced" / name)) << name;
    const Lightmap a = readExr(dir / "instanced" / name), b = readExr(dir / "plain" / name);
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    double worst = 0.0, peak = 0.0;
    for (size_t i = 0; i < a.texels.size(); ++i) {
      worst = std::max(worst, double(glm::length(a.texels[i] - b.texels[i])));
      peak = std::max(peak, double(glm::length(b.texels[i])));
    }
    EXPECT_GT(peak, 0.0);
    EXPECT_LE(worst, 1e-5 * peak) << name;
  }

#ifdef IRVIEW_EXE
  ASSERT_EQ(run(IRVIEW_EXE, {(dir / "instanced" / "scene.gltf").string(), "--width", "32", "--height", "32", "--screenshot",
                             (dir / "instanced.png").string()},
                dir / "irview_log.txt", &log),
            0)
      << log;
  EXPECT_TRUE(fs::exists(dir / "instanced.png"));
#endif
}

// --atlas-from on an instanced scene: the export wrote each instance as a node with a mesh of its own, and its
// parts name their source (node, mesh, primitive, instance), so the second bake finds every instance's region
// and, with the same options, gives the same map.
TEST(GpuInstancing, AtlasFromFindsEveryInstancesRegion) {
  const fs::path dir = fs::current_path() / "test_scratch" / "gpu_instancing_atlas_from";
  fs::remove_all(dir);
  fs::create_directories(dir);
  irbake::testing::writeDocument(squares(true), dir / "instanced.gltf");
  const std::vector<std::string> common = {"bake", (dir / "instanced.gltf").string(), "--backend", "embree", "--vpls", "64",
                                           "--seed", "3", "--probes", "off", "--quiet"};
  std::vector<std::string> first = common, second = common;
  first.insert(first.end(), {"-o", (dir / "a").string(), "--texels-per-unit", "16"});
  second.insert(second.end(), {"-o", (dir / "b").string(), "--atlas-from", (dir / "a" / "scene.gltf").string()});
  std::string log;
  ASSERT_EQ(run(IRBAKE_EXE, first, dir / "a_log.txt", &log), 0) << log;
  ASSERT_EQ(run(IRBAKE_EXE, second, dir / "b_log.txt", &log), 0) << log;
  const Lightmap a = readExr(dir / "a" / "lightmap_0.exr"), b = readExr(dir / "b" / "lightmap_0.exr");
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  float peak = 0.0f, diff = 0.0f;
  for (size_t i = 0; i < a.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      peak = std::max(peak, a.texels[i][c]);
      diff = std::max(diff, std::abs(a.texels[i][c] - b.texels[i][c]));
    }
  EXPECT_GT(peak, 0.0f);
  EXPECT_LE(diff, 1e-6f * peak);
}
