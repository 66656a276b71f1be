// Per-object settings (extras.irbake.mode and lightmapScale on nodes, docs/guide.md "Per-object settings") through
// the whole bake: a black floor under a point light with a black plate between them, so the floor's map is the
// direct term alone, E/π = I cosθ / (π d²) where the plate lets the light through and 0 in its umbra.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "atlas/atlas.h"
#include "common/error.h"
#include "common/maths.h"
#include "pipeline/bake.h"
#include "scene/gltf_loader.h"
#include "testing/gltf_builder.h"

namespace fs = std::filesystem;
using namespace irbake;
using json = nlohmann::json;

namespace {

constexpr float kLightHeight = 2.0f, kIntensity = 4.0f;  // point light above the origin (W/sr)
constexpr float kFloorHalf = 1.0f, kPlateHalf = 0.3f, kPlateHeight = 1.0f;
// The plate's umbra on the floor: its half size × light height / (light height − plate height).
constexpr float kUmbraHalf = kPlateHalf * kLightHeight / (kLightHeight - kPlateHeight);

// A square of half size h at height y facing +y, as a mesh of its own.
int addSquare(GltfDocument& doc, float h, float y) {
  const std::vector<glm::vec3> p = {{-h, y, -h}, {h, y, -h}, {h, y, h}, {-h, y, h}};
  json prim = {{"attributes", {{"POSITION", doc.addPositions(p)}, {"NORMAL", doc.addVec3(std::vector<glm::vec3>(4, {0, 1, 0}))}}},
               {"indices", doc.addIndices({0, 2, 1, 0, 3, 2})},
               {"material", 0}};
  return doc.append("meshes", {{"primitives", json::array({prim})}});
}

// Floor (node 0), plate (node 1, with `plateIrbake` as its extras.irbake unless null), the light (node 2).
fs::path floorAndPlate(const std::string& name, const json& plateIrbake) {
  GltfDocument doc;
  doc.append("materials", {{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}}, {"doubleSided", true}});
  doc.append("nodes", {{"name", "floor"}, {"mesh", addSquare(doc, kFloorHalf, 0.0f)}});
  json plate = {{"name", "plate"}, {"mesh", addSquare(doc, kPlateHalf, kPlateHeight)}};
  if (!plateIrbake.is_null()) plate["extras"]["irbake"] = plateIrbake;
  doc.append("nodes", plate);
  doc.root["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", kIntensity}}});
  doc.append("nodes", {{"translation", {0, kLightHeight, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  doc.root["scenes"] = json::array({{{"nodes", {0, 1, 2}}}});
  doc.root["scene"] = 0;
  doc.useExtension("KHR_lights_punctual");
  const fs::path file = irbake::testing::testFolder("object_modes_" + name) / "scene.gltf";
  irbake::testing::writeDocument(doc, file);
  return file;
}

BakeOptions smallBake(bool probes) {
  BakeOptions o;
  o.backend = BackendKind::Embree;
  o.atlas.texelsPerUnit = 16.0;
  o.walk.paths = 256;
  o.walk.seed = 3;
  o.probes.enabled = probes;
  return o;
}

// The primitives of a node in a baked scene.
std::vector<const Primitive*> primitivesOf(const Scene& s, int node) {
  std::vector<const Primitive*> out;
  for (const Primitive& p : s.primitives)
    if (p.node == node) out.push_back(&p);
  return out;
}

// World position of each texel centre a primitive's uv1 triangles cover, with the texel's index on its page.
struct TexelOnSurface {
  size_t index;
  glm::vec3 position;
};
std::vector<TexelOnSurface> texelCentres(const Primitive& p) {
  std::vector<TexelOnSurface> out;
  const int w = p.lightmap.width, h = p.lightmap.height;
  for (size_t t = 0; t < p.triangleCount(); ++t) {
    glm::vec2 uv[3];
    glm::vec3 q[3];
    for (int k = 0; k < 3; ++k) {
      uv[k] = p.uv1[p.indices[3 * t + k]] * glm::vec2(w, h);
      q[k] = p.positions[p.indices[3 * t + k]];
    }
    const glm::vec2 lo = glm::min(uv[0], glm::min(uv[1], uv[2])), hi = glm::max(uv[0], glm::max(uv[1], uv[2]));
    const float area = (uv[1].x - uv[0].x) * (uv[2].y - uv[0].y) - (uv[2].x - uv[0].x) * (uv[1].y - uv[0].y);
    for (int y = std::max(0, int(lo.y)); y <= std::min(h - 1, int(hi.y)); ++y)
      for (int x = std::max(0, int(lo.x)); x <= std::min(w - 1, int(hi.x)); ++x) {
        const glm::vec2 c(x + 0.5f, y + 0.5f);
        const float b1 = ((c.x - uv[0].x) * (uv[2].y - uv[0].y) - (uv[2].x - uv[0].x) * (c.y - uv[0].y)) / area;
        const float b2 = ((uv[1].x - uv[0].x) * (c.y - uv[0].y) - (c.x - uv[0].x) * (uv[1].y - uv[0].y)) / area;
        if (b1 < 0 || b2 < 0 || b1 + b2 > 1) continue;
        out.push_back({size_t(y) * w + x, (1 - b1 - b2) * q[0] + b1 * q[1] + b2 * q[2]});
      }
  }
  return out;
}

// Unoccluded direct light of the point light at a floor point, as the map stores it: I cosθ / d² / π.
float closedForm(const glm::vec3& x) {
  const float d2 = x.x * x.x + x.z * x.z + kLightHeight * kLightHeight;
  return kIntensity * (kLightHeight / std::sqrt(d2)) / d2 / float(kPi);
}

// The floor's texels away from its border: the largest relative difference from the closed form outside the
// umbra's neighbourhood (everywhere when `umbraExpected` is false), and the largest value inside the umbra.
struct FloorFigures {
  double litError = 0.0, umbraMax = 0.0, umbraClosedForm = 0.0;
  size_t lit = 0, umbra = 0;
};
FloorFigures floorFigures(const BakeResult& r, bool plateCasts) {
  FloorFigures f;
  const float texel = 1.0f / 16.0f;
  for (const Primitive* p : primitivesOf(r.scene, 0)) {
    const Lightmap& map = r.maps.at(size_t(p->lightmap.page));
    for (const TexelOnSurface& t : texelCentres(*p)) {
      const glm::vec3 x = t.position;
      const float edge = std::max(std::abs(x.x), std::abs(x.z));
      if (edge > kFloorHalf - 2 * texel || !map.valid[t.index]) continue;
      const float value = (map.texels[t.index].x + map.texels[t.index].y + map.texels[t.index].z) / 3.0f;
      const bool nearShadowEdge = std::abs(edge - kUmbraHalf) < 2 * texel;
      if (plateCasts && edge < kUmbraHalf - 2 * texel) {
        f.umbraMax = std::max(f.umbraMax, double(value));
        f.umbraClosedForm = std::max(f.umbraClosedForm, double(closedForm(x)));
        ++f.umbra;
      } else if (!plateCasts || !nearShadowEdge) {
        f.litError = std::max(f.litError, std::abs(double(value) / closedForm(x) - 1.0));
        ++f.lit;
      }
    }
  }
  return f;
}

// The bake's outputs written as `irbake bake` writes them; the exported glTF's path.
fs::path exportBake(const BakeResult& r, const std::string& name) {
  OutputOptions out;
  out.outDir = irbake::testing::testFolder("object_modes_out_" + name);
  writeBakeOutputs(r, out);
  return out.outDir / "scene.gltf";
}

json readJson(const fs::path& file) {
  std::ifstream in(file);
  return json::parse(in);
}

// The exported primitive of node `node` (its mesh's first primitive).
const json& exportedPrimitive(const json& doc, int node) {
  return doc["meshes"][doc["nodes"][node]["mesh"].get<int>()]["primitives"][0];
}

}  // namespace

// Baked (the default): the plate gets texels and its umbra is dark; `off`: the floor is the unoccluded closed form
// everywhere and the plate keeps no map; `shadow-only`: the umbra stays, the plate gets no texels, no TEXCOORD_1 and
// no MOZ_lightmap in the export.
TEST(ObjectModes, OffShadowOnlyAndBakedPlatesOnTheFloorsClosedForm) {
  struct Case {
    const char* name;
    json irbake;
    bool casts, texels;
  };
  const Case cases[] = {{"baked", nullptr, true, true},
                        {"off", {{"mode", "off"}}, false, false},
                        {"shadow_only", {{"mode", "shadow-only"}}, true, false}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const BakeResult r = bake(loadScene(floorAndPlate(c.name, c.irbake)), smallBake(false));
    const FloorFigures f = floorFigures(r, c.casts);
    RecordProperty(std::string(c.name) + "LitRelativeError", std::to_string(f.litError));
    RecordProperty(std::string(c.name) + "UmbraMax", std::to_string(f.umbraMax));
    std::printf("%s: %zu lit texels, worst relative error %.2e; %zu umbra texels, max %.2e (closed form up to %.3f)\n",
                c.name, f.lit, f.litError, f.umbra, f.umbraMax, f.umbraClosedForm);
    EXPECT_GT(f.lit, c.casts ? 150u : 600u);
    EXPECT_LT(f.litError, 0.002);  // point light, exact direct term: only the texel's own spread of E
    if (c.casts) {
      EXPECT_GT(f.umbra, 200u);
      EXPECT_LT(f.umbraMax, 0.002 * f.umbraClosedForm);  // black scene: nothing bounces into the umbra
    }
    const std::vector<const Primitive*> plate = primitivesOf(r.scene, 1);
    ASSERT_EQ(plate.size(), 1u);  // kept in the result's scene for the export, whatever its mode
    EXPECT_EQ(plate[0]->lightmap.page >= 0, c.texels);
    EXPECT_EQ(!plate[0]->uv1.empty(), c.texels);
    const json doc = readJson(exportBake(r, c.name));
    const json& prim = exportedPrimitive(doc, 1);
    EXPECT_EQ(prim["attributes"].contains("TEXCOORD_1"), c.texels) << prim.dump();
    const json& material = doc["materials"][prim["material"].get<int>()];
    EXPECT_EQ(material.contains("extensions") && material["extensions"].contains("MOZ_lightmap"), c.texels);
    EXPECT_TRUE(exportedPrimitive(doc, 0)["attributes"].contains("TEXCOORD_1"));
    EXPECT_FALSE(prim.contains("extras") && prim["extras"].contains("lightProbes"));
  }
}

// `probes`: in the bake as shadow-only (umbra, no texels), and its exported primitive says the clients light it
// from the probes, which the export carries.
TEST(ObjectModes, ProbeLitPlateCastsGetsNoTexelsAndIsMarkedForTheClients) {
  const BakeResult r = bake(loadScene(floorAndPlate("probes", {{"mode", "probes"}})), smallBake(true));
  const FloorFigures f = floorFigures(r, true);
  EXPECT_LT(f.litError, 0.002);
  EXPECT_GT(f.umbra, 200u);
  EXPECT_LT(f.umbraMax, 0.002 * f.umbraClosedForm);
  EXPECT_GT(r.probes.size(), 0u);
  const std::vector<const Primitive*> plate = primitivesOf(r.scene, 1);
  ASSERT_EQ(plate.size(), 1u);
  EXPECT_EQ(plate[0]->lightmap.page, -1);
  const fs::path exported = exportBake(r, "probes");
  const json doc = readJson(exported);
  const json& prim = exportedPrimitive(doc, 1);
  EXPECT_FALSE(prim["attributes"].contains("TEXCOORD_1"));
  EXPECT_EQ(prim["extras"]["lightProbes"], true);
  EXPECT_TRUE(doc["extensions"].contains("IRBAKE_light_probes"));
  // Read back as the viewer reads it: the primitive is probe-lit.
  LoadOptions viewer;
  viewer.shadingMaps = true;
  const Scene back = loadScene(exported, viewer);
  const auto probeLit = std::count_if(back.primitives.begin(), back.primitives.end(),
                                      [](const Primitive& p) { return p.mode == ObjectMode::Probes; });
  EXPECT_EQ(probeLit, 1);
}

// Every object off: nothing to bake, said plainly.
TEST(ObjectModes, EveryObjectOffIsRefused) {
  GltfDocument doc = irbake::testing::meshDocument({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2});
  doc.root["nodes"][0]["extras"]["irbake"]["mode"] = "off";
  const fs::path file = irbake::testing::testFolder("object_modes_all_off") / "scene.gltf";
  irbake::testing::writeDocument(doc, file);
  try {
    bake(loadScene(file), smallBake(false));
    ADD_FAILURE() << "baked a scene whose every object is off";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::EmptyScene);
    EXPECT_NE(std::string(e.what()).find("every object's extras.irbake.mode is \"off\""), std::string::npos) << e.what();
  }
}

// lightmapScale 2 on one of two equal squares: its texels are 4× the other's (texel area × scale²), within the
// packing's rounding.
TEST(ObjectModes, LightmapScaleTwoGivesFourTimesTheTexels) {
  GltfDocument doc;
  doc.append("materials", {{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}}}});
  const int mesh = addSquare(doc, 0.5f, 0.0f);
  doc.append("nodes", {{"name", "plain"}, {"mesh", mesh}, {"translation", {-2, 0, 0}}});
  doc.append("nodes", {{"name", "scaled"}, {"mesh", mesh}, {"translation", {2, 0, 0}},
                       {"extras", {{"irbake", {{"lightmapScale", 2.0}}}}}});
  doc.root["scenes"] = json::array({{{"nodes", {0, 1}}}});
  doc.root["scene"] = 0;
  const fs::path file = irbake::testing::testFolder("object_modes_scale") / "scene.gltf";
  irbake::testing::writeDocument(doc, file);
  for (double density : {16.0, 40.0}) {
    Scene s = loadScene(file);
    AtlasOptions o;
    o.texelsPerUnit = density;
    buildAtlas(s, o);
    size_t texels[2] = {0, 0};
    for (const Primitive& p : s.primitives) texels[p.node] += texelCentres(p).size();
    const double expected = density * density;  // a 1 m² square at the density, scale 1
    std::printf("%.0f texels per metre: %zu texels at scale 1, %zu at scale 2\n", density, texels[0], texels[1]);
    EXPECT_NEAR(double(texels[0]), expected, 0.1 * expected) << density;
    EXPECT_NEAR(double(texels[1]) / double(texels[0]), 4.0, 0.4) << density;
  }
}
