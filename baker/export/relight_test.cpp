// irbake relight on a hand-made grouped bake: two layers (a, b) of two pages each with their EXR pages, PNGs and
// probe coefficients (layer a holding the probes' sun), written as a GLB with IRBAKE_lightmap_scenarios whose
// default scenario is a + b. The relit pages, PNGs and probes are checked against the weighted sums computed here.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "common/error.h"
#include "common/maths.h"
#include "common/output_guard.h"
#include "export/exr_io.h"
#include "export/gltf_compact.h"
#include "export/gltf_export.h"
#include "export/light_probes_export.h"
#include "export/map_encoding.h"
#include "export/relight.h"

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace irbake;

namespace {

fs::path scratchDir(const std::string& name) {
  fs::path dir = fs::current_path() / "test_scratch" / "relight" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// A page with a smooth ramp, a black corner and one hot texel, different per layer and page.
Lightmap layerPage(int page, int layer, int w = 23, int h = 17) {
  Lightmap m;
  m.page = page;
  m.width = w;
  m.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float s = 0.1f + 0.37f * layer + 0.05f * page;
      m.texels.push_back(glm::vec3(s * (x + 1) / w, s * (y + 0.5f) / h * (layer + 1), x < 3 && y < 3 ? 0.0f : s * 0.3f));
    }
  m.texels[5] = glm::vec3(40.0f + layer);  // one hot texel: the page's range (its 99.9th percentile at 391 texels)
  m.valid.assign(m.size(), 1);
  return m;
}

ShCoefficients probeSh(size_t probe, int layer) {
  ShCoefficients c{};
  for (int k = 0; k < kShCoefficients; ++k)
    c[k] = glm::vec3(0.01f * (probe + 1) + 0.3f * layer, 0.02f * k - 0.05f, 0.7f / (layer + 1 + k));
  return c;
}

int addVec3Accessor(GltfDocument& doc, const std::vector<glm::vec3>& v) {
  const int view = doc.addBufferView(v.data(), v.size() * sizeof(glm::vec3));
  return doc.append("accessors", {{"bufferView", view}, {"componentType", 5126}, {"count", v.size()}, {"type", "VEC3"}});
}

std::vector<glm::vec3> flat(const std::vector<ShCoefficients>& c) {
  std::vector<glm::vec3> out;
  for (const ShCoefficients& s : c) out.insert(out.end(), s.begin(), s.end());
  return out;
}

constexpr int kPages = 2;
constexpr size_t kProbes = 8;

struct GroupedBake {
  fs::path file;
  std::vector<Lightmap> pages[2];           // per layer, per page
  std::vector<ShCoefficients> probes[2];    // per layer
  glm::vec3 sunIrradiance{0.8f, 0.7f, 0.6f};  // layer a's sun
  ShCoefficients sunSh{};
};

void writePng(GltfDocument& doc, const Lightmap& page, double& intensity, int& texture) {
  const EncodedMap e = mapEncoding(MapEncodingKind::Png8).encode(page, {});
  texture = doc.addTexture(doc.addImage(e.bytes, "page"), 0);
  intensity = kPi * e.metadata.intensity;
}

// Writes the grouped bake into dir (scene.glb, its EXR pages beside it), its default scenario a + b.
GroupedBake writeGroupedBake(const fs::path& dir) {
  GroupedBake bake;
  bake.file = dir / "scene.glb";
  GltfDocument doc;
  doc.addSampler(WrapMode::ClampToEdge, WrapMode::ClampToEdge, true);
  json pages = json::array(), exrPages = json::array(), layers = json::array();
  std::vector<Lightmap> sums;
  for (int p = 0; p < kPages; ++p) {
    for (int l = 0; l < 2; ++l) bake.pages[l].push_back(layerPage(p, l));
    Lightmap sum = bake.pages[0][p];
    for (size_t i = 0; i < sum.size(); ++i) sum.texels[i] += bake.pages[1][p].texels[i];
    double intensity = 0.0;
    int texture = 0;
    writePng(doc, sum, intensity, texture);
    pages.push_back(texture);
    doc.append("materials", {{"name", std::to_string(p)},
                             {"extensions", {{"MOZ_lightmap", {{"index", texture}, {"texCoord", 1}, {"intensity", intensity}}}}}});
    const std::string exr = "lightmap_" + std::to_string(p) + ".exr";
    exrPages.push_back(exr);
    writeExr(sum, dir / exr);
    sums.push_back(sum);
  }
  LightProbeGrid grid;
  grid.spacing = 1.0f;
  grid.counts = glm::ivec3(2);
  for (size_t i = 0; i < kProbes; ++i) {
    for (int l = 0; l < 2; ++l) bake.probes[l].push_back(probeSh(i, l));
    ShCoefficients c{};
    for (int k = 0; k < kShCoefficients; ++k) c[k] = bake.probes[0][i][k] + bake.probes[1][i][k];
    grid.coefficients.push_back(c);
  }
  grid.offsets.assign(kProbes, glm::vec3(0.0f));
  grid.valid.assign(kProbes, 1);
  for (int k = 0; k < kShCoefficients; ++k) bake.sunSh[k] = glm::vec3(0.1f * k, 0.2f, -0.03f * k);
  grid.sun.subdivisions = 1;
  grid.sun.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  grid.sun.irradiance = bake.sunIrradiance;
  grid.sun.sh = bake.sunSh;
  grid.sun.visibility.assign(kProbes, 1.0f);
  addLightProbesExtension(doc, grid);
  for (int l = 0; l < 2; ++l) {
    const std::string name = l == 0 ? "a" : "b";
    json layer = {{"name", name}, {"lights", json::array({{{"sun", true}}})}, {"textures", json::array()},
                  {"intensity", json::array()}, {"exr", json::array()}};
    for (int p = 0; p < kPages; ++p) {
      double intensity = 0.0;
      int texture = 0;
      writePng(doc, bake.pages[l][p], intensity, texture);
      layer["textures"].push_back(texture);
      layer["intensity"].push_back(intensity);
      layer["exr"].push_back("lightmap_" + std::to_string(p) + "_" + name + ".exr");
      writeExr(bake.pages[l][p], dir / layer["exr"].back().get<std::string>());
    }
    layer["probes"] = addVec3Accessor(doc, flat(bake.probes[l]));
    if (l == 0) {
      const glm::vec3 e = bake.sunIrradiance;
      layer["sun"] = {{"irradiance", {e.x, e.y, e.z}},
                      {"sh", addVec3Accessor(doc, std::vector<glm::vec3>(bake.sunSh.begin(), bake.sunSh.end()))}};
    }
    layers.push_back(layer);
  }
  doc.root["extras"]["lightmapPages"] = exrPages;
  doc.root["extensions"][kLightScenariosExtension] = {
      {"pages", pages},
      {"layers", layers},
      {"scenarios", {{{"name", "default"}, {"weights", {{"a", {1, 1, 1}}, {"b", {1, 1, 1}}}}},
                     {{"name", "b"}, {"weights", {{"b", {1, 1, 1}}}}}}},
      {"default", 0}};
  doc.useExtension(kLightScenariosExtension);
  writeAllAtomically(doc.files(bake.file));
  return bake;
}

RelightSummary relight(const fs::path& in, const fs::path& out, std::vector<std::pair<std::string, glm::vec3>> weights,
                       const std::string& scenario = "") {
  RelightOptions o;
  o.input = in;
  o.output = out;
  o.weights = std::move(weights);
  o.scenario = scenario;
  Relight r(o);
  OutputGuard guard;
  guard.addInputs(r.inputs());
  guard.keepManifest(out.parent_path());
  return r.write(guard);
}

json jsonOfGlb(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  uint32_t length = 0;
  std::memcpy(&length, bytes.data() + 12, 4);
  return json::parse(std::string(bytes.data() + 20, length));
}

// The expected page Σ w_L ⊙ layer_L, in float as the test writes it (the products are exact for weights 0.5 and 2).
Lightmap expectedPage(const GroupedBake& bake, int p, glm::vec3 wa, glm::vec3 wb) {
  Lightmap m = bake.pages[0][p];
  for (size_t i = 0; i < m.size(); ++i) m.texels[i] = wa * bake.pages[0][p].texels[i] + wb * bake.pages[1][p].texels[i];
  return m;
}

void expectErrorWith(const std::function<void()>& f, ErrorCode code, const std::string& text) {
  try {
    f();
    FAIL() << "no error; expected one with '" << text << "'";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(Relight, DefaultWeightsReproduceTheDefaultPagesBitForBit) {
  const fs::path dir = scratchDir("default");
  const GroupedBake bake = writeGroupedBake(dir / "in");
  const RelightSummary s = relight(bake.file, dir / "out" / "scene.gltf", {});
  EXPECT_EQ(s.pages, kPages);
  EXPECT_EQ(s.probes, kProbes);
  for (int p = 0; p < kPages; ++p) {
    const std::string name = "lightmap_" + std::to_string(p) + ".exr";
    const Lightmap in = readExr(dir / "in" / name), out = readExr(dir / "out" / name);
    ASSERT_EQ(out.texels.size(), in.texels.size());
    for (size_t i = 0; i < in.size(); ++i) ASSERT_EQ(out.texels[i], in.texels[i]) << name << " texel " << i;
  }
  const LightProbeGrid a = readLightProbes(bake.file), b = readLightProbes(dir / "out" / "scene.gltf");
  for (size_t i = 0; i < kProbes; ++i)
    for (int k = 0; k < kShCoefficients; ++k) EXPECT_EQ(b.coefficients[i][k], a.coefficients[i][k]);
  EXPECT_EQ(b.sun.irradiance, a.sun.irradiance);
}

TEST(Relight, HalfAndTwoAreTheWeightedSumInPagesPngsAndProbes) {
  const fs::path dir = scratchDir("half_two");
  const GroupedBake bake = writeGroupedBake(dir / "in");
  const fs::path out = dir / "out" / "relit.glb";
  const RelightSummary s = relight(bake.file, out, {{"a", glm::vec3(0.5f)}, {"b", glm::vec3(2.0f)}});
  const json root = jsonOfGlb(out);
  const json& ext = root["extensions"][kLightScenariosExtension];
  EXPECT_EQ(ext["scenarios"][0]["weights"]["a"], json({0.5, 0.5, 0.5}));
  EXPECT_EQ(ext["scenarios"][0]["weights"]["b"], json({2.0, 2.0, 2.0}));
  EXPECT_EQ(ext["scenarios"][1]["weights"], json({{"b", {1, 1, 1}}}));  // other scenarios as they were
  const GltfDocument doc = documentFromSource(out);
  const MapEncoding& png = mapEncoding(MapEncodingKind::Png8);
  for (int p = 0; p < kPages; ++p) {
    const Lightmap expected = expectedPage(bake, p, glm::vec3(0.5f), glm::vec3(2.0f));
    const Lightmap exr = readExr(dir / "out" / ("lightmap_" + std::to_string(p) + ".exr"));
    for (size_t i = 0; i < expected.size(); ++i) ASSERT_EQ(exr.texels[i], expected.texels[i]) << "page " << p << " texel " << i;
    // The PNG × intensity: the sum within the 8-bit encoding's tolerance; its range is the hot texel's value.
    const json& moz = root["materials"][p]["extensions"]["MOZ_lightmap"];
    EXPECT_DOUBLE_EQ(moz["intensity"].get<double>(), s.intensity[p]);
    MapMetadata meta;
    meta.intensity = static_cast<float>(moz["intensity"].get<double>() / kPi);
    meta.srgb = true;
    const int image = root["textures"][moz["index"].get<int>()]["source"].get<int>();
    const json& view = root["bufferViews"][root["images"][image]["bufferView"].get<int>()];
    const uint8_t* bytes = doc.bin.data() + view.value("byteOffset", size_t(0));
    const Lightmap decoded = png.decode(bytes, view["byteLength"].get<size_t>(), meta, "page").map;
    EXPECT_FLOAT_EQ(meta.intensity, expected.texels[5].x);
    for (size_t i = 0; i < expected.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        const float want = expected.texels[i][c];
        ASSERT_NEAR(decoded.texels[i][c], want, png.tolerance(want, meta)) << "page " << p << " texel " << i;
      }
  }
  const LightProbeGrid g = readLightProbes(out);
  for (size_t i = 0; i < kProbes; ++i)
    for (int k = 0; k < kShCoefficients; ++k)
      EXPECT_EQ(g.coefficients[i][k], 0.5f * bake.probes[0][i][k] + 2.0f * bake.probes[1][i][k]);
  EXPECT_EQ(g.sun.irradiance, 0.5f * bake.sunIrradiance);
  for (int k = 0; k < kShCoefficients; ++k) EXPECT_EQ(g.sun.sh[k], 0.5f * bake.sunSh[k]);
  // The layers are carried over: their EXR pages copied byte for byte, their probes as they were.
  for (const char* name : {"lightmap_0_a.exr", "lightmap_1_b.exr"}) {
    std::ifstream x(dir / "in" / name, std::ios::binary), y(dir / "out" / name, std::ios::binary);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(x), {}), std::string(std::istreambuf_iterator<char>(y), {})) << name;
  }
  const LightmapScenarios read = readLightmapScenarios(root, out.string());
  const AccessorBytes probesB = readAccessor(doc, read.layers[1].probes, out.string());
  EXPECT_EQ(std::memcmp(probesB.bytes.data(), flat(bake.probes[1]).data(), probesB.bytes.size()), 0);
}

TEST(Relight, RgbWeightsOnAStoredScenario) {
  const fs::path dir = scratchDir("rgb");
  const GroupedBake bake = writeGroupedBake(dir / "in");
  const glm::vec3 wa(0.25f, 0.5f, 4.0f);
  relight(bake.file, dir / "out" / "scene.gltf", {parseLayerWeight("a=0.25,0.5,4")}, "b");
  for (int p = 0; p < kPages; ++p) {
    const Lightmap expected = expectedPage(bake, p, wa, glm::vec3(1.0f));
    const Lightmap exr = readExr(dir / "out" / ("lightmap_" + std::to_string(p) + ".exr"));
    for (size_t i = 0; i < expected.size(); ++i) ASSERT_EQ(exr.texels[i], expected.texels[i]) << "page " << p << " texel " << i;
  }
  EXPECT_EQ(readLightProbes(dir / "out" / "scene.gltf").sun.irradiance, wa * bake.sunIrradiance);
}

TEST(Relight, RefusesNamingTheFileAndTheProblem) {
  const fs::path dir = scratchDir("refusals");
  const GroupedBake bake = writeGroupedBake(dir / "in");
  const fs::path out = dir / "out" / "scene.gltf";
  expectErrorWith([&] { relight(bake.file, out, {{"c", glm::vec3(1.0f)}}); }, ErrorCode::Usage,
                  "--group 'c': no such light group (the file's layers: a, b)");
  expectErrorWith([&] { relight(bake.file, out, {}, "night"); }, ErrorCode::Usage, "--scenario 'night': no such scenario");
  for (const char* bad : {"a=-1", "a=nan", "a=1,2", "a=1,2,3,4", "a=", "=1", "a"})
    expectErrorWith([&] { parseLayerWeight(bad); }, ErrorCode::Usage, "--group");
  // A file without the extension.
  GltfDocument plain;
  writeAllAtomically(plain.files(dir / "plain.glb"));
  expectErrorWith([&] { relight(dir / "plain.glb", out, {}); }, ErrorCode::InvalidData, "plain.glb: has no IRBAKE_lightmap_scenarios");
  // A layer page that is missing, then one of another size.
  fs::rename(dir / "in" / "lightmap_1_b.exr", dir / "moved.exr");
  expectErrorWith([&] { relight(bake.file, out, {}); }, ErrorCode::Io, "lightmap_1_b.exr: no such file");
  writeExr(layerPage(1, 1, 22, 17), dir / "in" / "lightmap_1_b.exr");
  expectErrorWith([&] { relight(bake.file, out, {}); }, ErrorCode::InvalidData, "lightmap_1_b.exr: 22×17 texels, but");
  // Onto the bake itself.
  writeExr(layerPage(1, 1), dir / "in" / "lightmap_1_b.exr");
  expectErrorWith([&] { relight(bake.file, dir / "in" / "scene.glb", {}); }, ErrorCode::Usage, "is an input of this command");
  EXPECT_FALSE(fs::exists(out));
}
