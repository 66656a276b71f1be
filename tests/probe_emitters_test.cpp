// The probes' exact emitters (IRBAKE_light_probes.emitters, docs/export.md) as a user runs them, on a scene with
// a closed form: a black floor (y = 0) under a square emitter of half-side 0.25 m at y = 1, facing down, Le =
// (1, 0.5, 0.25), no sky. Nothing bounces and the square is an exact emitter, so the probes' SH is 0 and `irbake
// probe --normal n` reads the square's own E(n)/π = (Le/π) ∫ max(0, n·ω) dω over it (v = 1: nothing hides it),
// here against a midpoint quadrature, normals across the horizon included; without --normal, Le Ω/(4π).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
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

constexpr double kPi = 3.14159265358979323846;
constexpr double kA = 0.25, kH = 1.0;
const glm::dvec3 kLe(1.0, 0.5, 0.25);

// The floor (4 × 4 m, black) and the emitter (black, emissive) as a glTF of two quads.
void writeEmitterScene(const fs::path& gltf) {
  const float a = static_cast<float>(kA), h = static_cast<float>(kH);
  const std::vector<float> p = {-2, 0, -2, 2, 0, -2, 2, 0, 2, -2, 0, 2,     // floor, facing +Y
                                -a, h, -a, a, h, -a, a, h, a, -a, h, a};    // emitter, facing −Y
  const std::vector<float> nrm = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1, 0};
  const std::vector<uint16_t> idx = {0, 2, 1, 0, 3, 2, 0, 1, 2, 0, 2, 3};
  std::string bin(reinterpret_cast<const char*>(p.data()), p.size() * 4);
  bin.append(reinterpret_cast<const char*>(nrm.data()), nrm.size() * 4);
  bin.append(reinterpret_cast<const char*>(idx.data()), idx.size() * 2);
  std::ofstream(gltf.parent_path() / "emitter.bin", std::ios::binary) << bin;
  auto mesh = [](const char* name, int position, int normal, int indices, int material) {
    json primitive = {{"attributes", {{"POSITION", position}, {"NORMAL", normal}}}, {"indices", indices}, {"material", material}};
    return json{{"name", name}, {"primitives", json::array({primitive})}};
  };
  const json black = {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 0}};
  json doc = {{"asset", {{"version", "2.0"}}},
              {"scene", 0},
              {"scenes", {{{"nodes", {0, 1}}}}},
              {"nodes", {{{"mesh", 0}}, {{"mesh", 1}}}},
              {"materials", {{{"name", "floor"}, {"pbrMetallicRoughness", black}},
                             {{"name", "light"}, {"pbrMetallicRoughness", black}, {"emissiveFactor", {kLe.x, kLe.y, kLe.z}}}}},
              {"buffers", {{{"uri", "emitter.bin"}, {"byteLength", bin.size()}}}},
              {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
                               {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 48}},
                               {{"buffer", 0}, {"byteOffset", 96}, {"byteLength", 48}},
                               {{"buffer", 0}, {"byteOffset", 144}, {"byteLength", 48}},
                               {{"buffer", 0}, {"byteOffset", 192}, {"byteLength", 24}}}},
              {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}, {"min", {-2, 0, -2}}, {"max", {2, 0, 2}}},
                             {{"bufferView", 1}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}, {"min", {-a, h, -a}}, {"max", {a, h, a}}},
                             {{"bufferView", 2}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
                             {{"bufferView", 3}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
                             {{"bufferView", 4}, {"byteOffset", 0}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}},
                             {{"bufferView", 4}, {"byteOffset", 12}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}}}},
              {"meshes", {mesh("floor", 0, 2, 4, 0), mesh("light", 1, 3, 5, 1)}}};
  std::ofstream(gltf) << doc.dump();
}

// ∫ max(0, n·ω) dω over the square from p (midpoint rule, 600² cells): E/Le.
double squareIrradiance(const glm::dvec3& p, const glm::dvec3& n) {
  const int cells = 600;
  const double step = 2 * kA / cells;
  double sum = 0.0;
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j) {
      const glm::dvec3 d = glm::dvec3(-kA + (i + 0.5) * step, kH, -kA + (j + 0.5) * step) - p;
      const double r2 = glm::dot(d, d), r = std::sqrt(r2);
      sum += std::max(0.0, glm::dot(n, d) / r) * (d.y / r) / r2 * step * step;
    }
  return sum;
}

}  // namespace

TEST(ProbeEmitters, ProbeReadsLambertsPolygonUnderASquareEmitter) {
  const fs::path dir = scratchFolder("probe_emitters", "square");
  writeEmitterScene(dir / "emitter.gltf");
  const IrbakeRun bake = runIrbakeIn(dir, {"bake", (dir / "emitter.gltf").string(), "-o", (dir / "out").string(),
                                         "--probes", "0.5", "--quiet"});
  ASSERT_EQ(bake.code, 0) << bake.output;
  const fs::path gltf = dir / "out" / "scene.gltf";
  const json doc = json::parse(fileText(gltf));
  const json& ext = doc["extensions"]["IRBAKE_light_probes"];
  ASSERT_TRUE(ext.contains("emitters")) << ext.dump();
  ASSERT_EQ(ext["emitters"].size(), 1u);
  EXPECT_NEAR(ext["emitters"][0]["radiance"][0].get<double>(), kLe.x / kPi, 1e-6);
  const json report = json::parse(fileText(dir / "out" / "report.json"));
  EXPECT_EQ(report["probes"]["exactEmitters"], 1);
  EXPECT_EQ(report["probes"]["exactEmitterTriangles"], 2);
  auto value = [&](const std::string& at, const std::string& normal) {
    std::vector<std::string> args = {"probe", gltf.string(), "--at", at};
    if (!normal.empty()) args.insert(args.end(), {"--normal", normal});
    const IrbakeRun r = runIrbakeIn(dir, args);
    EXPECT_EQ(r.code, 0) << r.output;
    return r.code == 0 ? json::parse(r.output)["value"].get<std::vector<double>>() : std::vector<double>{-1, -1, -1};
  };
  // Facing up, across the horizon (the square straddles the tangent plane), sideways, and facing away.
  const std::vector<glm::dvec3> points = {{0.1, 0.5, -0.2}, {0.6, 0.9, 0.3}, {-0.05, 0.7, 0.0}};
  const std::vector<glm::dvec3> normals = {{0, 1, 0}, {1, 0, 0}, glm::normalize(glm::dvec3(1, 0.2, 0)),
                                           glm::normalize(glm::dvec3(-0.3, 0.5, 0.8)), glm::normalize(glm::dvec3(0.2, -0.3, 1)),
                                           {0, -1, 0}};
  int straddling = 0;
  for (const glm::dvec3& p : points)
    for (const glm::dvec3& n : normals) {
      char at[64], normal[64];
      std::snprintf(at, sizeof at, "%.9g,%.9g,%.9g", p.x, p.y, p.z);
      std::snprintf(normal, sizeof normal, "%.9g,%.9g,%.9g", n.x, n.y, n.z);
      const double E = squareIrradiance(p, n);
      bool above = false, below = false;
      for (double x : {-kA, kA})
        for (double z : {-kA, kA}) (glm::dot(glm::dvec3(x, kH, z) - p, n) > 0.0 ? above : below) = true;
      straddling += above && below;
      const std::vector<double> v = value(at, normal);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(v[c], kLe[c] / kPi * E, 2e-4 * std::max(kLe[c] / kPi * E, 1e-2)) << at << " normal " << normal << " channel " << c;
    }
  EXPECT_GE(straddling, 4);
  // The mean over normals under the centre: Le Ω/(4π), Ω = 4 asin(a²/(a² + h²)) at height h.
  const double h = kH - 0.5, omega = 4.0 * std::asin(kA * kA / (kA * kA + h * h));
  EXPECT_NEAR(value("0,0.5,0", "")[0], kLe.x * omega / (4.0 * kPi), 1e-5);

  // A bad `emitters` entry is refused naming the field (exit 5).
  auto refused = [&](const char* name, auto mutate, const std::string& message) {
    json bad = doc;
    mutate(bad["extensions"]["IRBAKE_light_probes"]["emitters"][0], bad);
    std::ofstream(dir / "out" / name) << bad.dump();
    const IrbakeRun r = runIrbakeIn(dir, {"probe", (dir / "out" / name).string(), "--at", "0,0.5,0"});
    EXPECT_EQ(r.code, 5) << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
  };
  refused("bad_positions.gltf", [&](json& e, json&) { e["positions"] = ext["valid"]; },
          "IRBAKE_light_probes.emitters[0].positions: accessor of componentType 5126 SCALAR, expected 5126 VEC3");
  refused("bad_radiance.gltf", [](json& e, json&) { e["radiance"] = {1, 1e39, 1}; },
          "IRBAKE_light_probes.emitters[0].radiance: not finite");
  refused("bad_visibility.gltf", [](json& e, json& d) {
    json copy = d["accessors"][e["visibility"].get<int>()];
    copy["count"] = copy["count"].get<int>() - 1;
    d["accessors"].push_back(copy);
    e["visibility"] = d["accessors"].size() - 1;
  }, "IRBAKE_light_probes.emitters[0].visibility: 31 elements, the grid needs 32");
}
