// Light groups (pipeline/light_groups.h) through the whole bake: the layers' sum against one bake of every source,
// a one-light layer against its closed form, the exported IRBAKE_lightmap_scenarios read from docs/export.md's
// text alone, and the refusals.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "common/error.h"
#include "common/maths.h"
#include "export/exr_io.h"
#include "pipeline/bake.h"
#include "pipeline/light_groups.h"
#include "scene/image_codec.h"
#include "stages/error_estimate/error_estimate.h"
#include "testing/gltf_builder.h"
#include "testing/scenes.h"

namespace fs = std::filesystem;
using namespace irbake;
using json = nlohmann::json;

namespace {

Light namedPoint(const std::string& name, glm::vec3 position, float intensity) {
  Light l = irbake::testing::pointLight(position, intensity);
  l.name = name;
  return l;
}

// A closed grey room, 2 × 1.5 × 2 m, with two point lights ("left", "right") and a small emissive panel
// ("neon") 10 cm under the ceiling, facing down: three sources whose light bounces.
Scene room() {
  Scene s;
  const int grey = irbake::testing::addMaterial(s, glm::vec3(0.6f));
  const int neon = irbake::testing::addMaterial(s, glm::vec3(0.5f), glm::vec3(3.0f, 1.5f, 0.5f));
  s.materials[static_cast<size_t>(neon)].name = "neon";
  irbake::testing::addBox(s, grey, {-1.0f, 0.0f, -1.0f}, {1.0f, 1.5f, 1.0f}, true);
  irbake::testing::addQuad(s, neon, {0.5f, 1.4f, 0.5f}, {-0.3f, 0.0f, 0.0f}, {0.0f, 0.0f, -0.3f});  // facing down
  s.lights = {namedPoint("left", {-0.5f, 1.0f, 0.0f}, 2.0f), namedPoint("right", {0.5f, 0.8f, -0.3f}, 1.0f)};
  return s;
}

BakeOptions roomBake() {
  BakeOptions o;
  o.backend = BackendKind::Embree;
  o.atlas.texelsPerUnit = 12.0;
  o.walk.paths = 2048;
  o.walk.seed = 5;
  o.errorEstimate.enabled = true;
  o.probes.enabled = true;
  return o;
}

LightGroupRequest request(const std::string& name, std::vector<std::string> sources) {
  return LightGroupRequest{name, std::move(sources)};
}

// The binned relative RMS difference of two bakes of the same pages (4×4 bins, as the estimate's): with two
// "replicates" a and b the estimate's noise is RMS(a − b)/2 per bin.
double binnedRelativeDifference(const std::vector<Lightmap>& a, const std::vector<Lightmap>& b) {
  const BinnedError e = replicateError({a, b}, &b, 4);
  return 2.0 * e.noiseRms / e.signalRms;
}

double sRgbToLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

json readJson(const fs::path& file) {
  std::ifstream in(file);
  return json::parse(in);
}

// An image of the document by texture index, its codes as read (no colour conversion: the reader applies the
// specification's sRGB decode itself).
Texture textureImage(const json& doc, const fs::path& folder, int texture) {
  const std::string uri = doc["images"][doc["textures"][texture]["source"].get<int>()]["uri"].get<std::string>();
  std::ifstream in(folder / uri, std::ios::binary);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return decodeImageToTexture(bytes.data(), bytes.size(), false, uri);
}

// Half a code of the sRGB decode at code value c (in [0, 1]), linear: the quantisation a texel's value carries.
double halfCode(double c) {
  const double step = 0.5 / 255.0;
  return 0.5 * (sRgbToLinear(std::min(1.0, c + step)) - sRgbToLinear(std::max(0.0, c - step)));
}

}  // namespace

// Two groups ("lamps": both point lights; "rest": the panel, by '*') against one bake of all three sources, same
// seed and options. Each bake's own estimate (replicates of its walk) gives its error; the groups' are independent
// of the together bake's, so the difference's expected RMS is sqrt(e_sum² + e_together²). The clamp is each bake's
// own (derived from its own VPLs), the compensation gathers back what it cut: what stays of that nonlinearity
// shows in the same difference, so the bound 3 × the combined estimate covers noise (≈ 1×) and the clamp's residue.
TEST(LightGroups, SumOfLayersMatchesOneBakeOfEveryLightWithinTheEstimatedError) {
  BakeOptions together = roomBake();
  const BakeResult all = bake(room(), together);
  BakeOptions grouped = roomBake();
  grouped.lightGroups = {request("lamps", {"left", "right"}), request("rest", {"*"})};
  const BakeResult sum = bakeLightGroups(room(), grouped);
  ASSERT_EQ(sum.layers.size(), 2u);
  EXPECT_EQ(sum.layers[0].name, "lamps");
  EXPECT_EQ(sum.layers[1].lights, json::array({{{"material", -1}, {"name", "neon"}}}));
  ASSERT_EQ(sum.maps.size(), all.maps.size());
  const double eAll = all.report["estimatedError"]["relative"].get<double>();
  const double eSum = sum.report["estimatedError"]["relative"].get<double>();
  const double difference = binnedRelativeDifference(sum.maps, all.maps);
  const double expected = std::hypot(eAll, eSum);
  std::printf("together: estimated error %.3f%%; groups' sum: %.3f%% (lamps %.3f%%, rest %.3f%%); binned difference "
              "%.3f%% = %.2f x the combined estimate %.3f%%\n",
              100 * eAll, 100 * eSum, 100 * sum.report["lightGroups"][0]["estimatedError"]["relative"].get<double>(),
              100 * sum.report["lightGroups"][1]["estimatedError"]["relative"].get<double>(), 100 * difference,
              difference / expected, 100 * expected);
  RecordProperty("differenceOverEstimate", std::to_string(difference / expected));
  std::printf("bake seconds: together %.2f, groups %.2f (%s %.2f + %s %.2f)\n",
              all.report["timings"]["seconds"]["bake"].get<double>(), sum.report["timings"]["seconds"]["bake"].get<double>(),
              sum.layers[0].name.c_str(), sum.report["lightGroups"][0]["timings"]["seconds"]["bake"].get<double>(),
              sum.layers[1].name.c_str(), sum.report["lightGroups"][1]["timings"]["seconds"]["bake"].get<double>());
  EXPECT_GT(eAll, 0.0);
  EXPECT_GT(eSum, 0.0);
  EXPECT_LT(difference, 3.0 * expected);
  // The sum is the layers' texel by texel.
  for (size_t p = 0; p < sum.maps.size(); ++p)
    for (size_t t = 0; t < sum.maps[p].texels.size(); t += 97) {
      const glm::vec3 layers = sum.layers[0].maps[p].texels[t] + sum.layers[1].maps[p].texels[t];
      EXPECT_NEAR(sum.maps[p].texels[t].x, layers.x, 1e-6f * std::max(1.0f, layers.x));
    }
  // Probes: the same per-group split.
  ASSERT_GT(sum.probes.size(), 0u);
  ASSERT_EQ(sum.layers[0].probes.size(), sum.probes.size());
  for (size_t i = 0; i < sum.probes.size(); ++i) {
    const glm::vec3 c = sum.layers[0].probes[i][0] + sum.layers[1].probes[i][0];
    EXPECT_NEAR(sum.probes.coefficients[i][0].x, c.x, 1e-6f * std::max(1.0f, c.x));
  }
}

// A black floor under two point lights, each its own group, direct light only (nothing bounces off black): the
// layer of one light is I cosθ / (π d²) of that light alone at every texel centre.
TEST(LightGroups, OnePointLightsLayerIsItsClosedForm) {
  Scene s;
  const int black = irbake::testing::addMaterial(s, glm::vec3(0.0f));
  irbake::testing::addQuad(s, black, {-1.0f, 0.0f, 1.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -2.0f});
  const glm::vec3 a(-0.3f, 1.0f, 0.2f);
  s.lights = {namedPoint("a", a, 3.0f), namedPoint("b", {0.6f, 0.7f, -0.4f}, 5.0f)};
  BakeOptions o;
  o.backend = BackendKind::Embree;
  o.atlas.texelsPerUnit = 16.0;
  o.walk.paths = 256;
  o.lightGroups = {request("one", {"a"}), request("two", {"b"})};
  const BakeResult r = bakeLightGroups(std::move(s), o);
  ASSERT_EQ(r.layers.size(), 2u);
  const Primitive& floor = r.scene.primitives.at(0);
  const Lightmap& layer = r.layers[0].maps.at(static_cast<size_t>(floor.lightmap.page));
  double worst = 0.0;
  size_t texels = 0;
  const int w = floor.lightmap.width, h = floor.lightmap.height;
  for (size_t t = 0; t < floor.triangleCount(); ++t) {
    glm::vec2 uv[3];
    glm::vec3 q[3];
    for (int k = 0; k < 3; ++k) {
      uv[k] = floor.uv1[floor.indices[3 * t + k]] * glm::vec2(w, h);
      q[k] = floor.positions[floor.indices[3 * t + k]];
    }
    const float area = (uv[1].x - uv[0].x) * (uv[2].y - uv[0].y) - (uv[2].x - uv[0].x) * (uv[1].y - uv[0].y);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const glm::vec2 c(x + 0.5f, y + 0.5f);
        const float b1 = ((c.x - uv[0].x) * (uv[2].y - uv[0].y) - (uv[2].x - uv[0].x) * (c.y - uv[0].y)) / area;
        const float b2 = ((uv[1].x - uv[0].x) * (c.y - uv[0].y) - (c.x - uv[0].x) * (uv[1].y - uv[0].y)) / area;
        const glm::vec3 p = (1 - b1 - b2) * q[0] + b1 * q[1] + b2 * q[2];
        const size_t i = static_cast<size_t>(y) * w + x;
        if (b1 < 0 || b2 < 0 || b1 + b2 > 1 || !layer.valid[i] || std::max(std::abs(p.x), std::abs(p.z)) > 1.0f - 2.0f / 16.0f)
          continue;
        const glm::vec3 d = a - p;
        const float d2 = glm::dot(d, d);
        const double closed = 3.0 * (d.y / std::sqrt(d2)) / d2 / kPi;
        worst = std::max(worst, std::abs(layer.texels[i].y / closed - 1.0));
        ++texels;
      }
  }
  std::printf("layer 'one': %zu texels, worst relative difference from the closed form %.2e\n", texels, worst);
  EXPECT_GT(texels, 500u);
  EXPECT_LT(worst, 0.002);  // the texel's own spread of E over its supersamples
}

// The export read from docs/export.md's section alone: root extension, each layer's PNG × intensity summed against
// the default MOZ_lightmap value within 8-bit quantisation, the layers' EXR pages summed against lightmap_<p>.exr.
TEST(LightGroups, ExportedLayersSumToTheDefaultMaps) {
  BakeOptions o = roomBake();
  o.walk.paths = 256;
  o.errorEstimate.enabled = false;
  o.lightGroups = {request("left", {"left"}), request("others", {"right", "emissive"})};
  const BakeResult r = bakeLightGroups(room(), o);
  OutputOptions out;
  out.outDir = irbake::testing::testFolder("light_groups_export");
  writeBakeOutputs(r, out);
  const fs::path folder = out.outDir;
  const json doc = readJson(folder / "scene.gltf");
  ASSERT_TRUE(doc["extensions"].contains("IRBAKE_lightmap_scenarios"));
  EXPECT_NE(std::find(doc["extensionsUsed"].begin(), doc["extensionsUsed"].end(), "IRBAKE_lightmap_scenarios"),
            doc["extensionsUsed"].end());
  EXPECT_FALSE(doc.contains("extensionsRequired"));
  const json& ext = doc["extensions"]["IRBAKE_lightmap_scenarios"];
  const json& layers = ext["layers"];
  ASSERT_EQ(layers.size(), 2u);
  EXPECT_EQ(ext["default"], 0);
  EXPECT_EQ(ext["scenarios"][0]["name"], "default");
  EXPECT_EQ(ext["scenarios"][0]["weights"]["left"], json::array({1, 1, 1}));
  EXPECT_EQ(ext["scenarios"][1]["weights"], json({{"left", {1, 1, 1}}}));
  EXPECT_EQ(layers[1]["lights"].size(), 2u);
  const size_t pages = ext["pages"].size();
  ASSERT_EQ(pages, r.maps.size());
  ASSERT_TRUE(doc["extensions"].contains("IRBAKE_light_probes") || !r.probes.size());
  double worstExcess = 0.0, meanDifference = 0.0;
  size_t compared = 0;
  for (size_t p = 0; p < pages; ++p) {
    // The default map: the texture the materials' MOZ_lightmap names, with its intensity.
    double intensity = 0.0;
    for (const json& m : doc["materials"])
      if (m.contains("extensions") && m["extensions"].contains("MOZ_lightmap") &&
          m["extensions"]["MOZ_lightmap"]["index"] == ext["pages"][p])
        intensity = m["extensions"]["MOZ_lightmap"]["intensity"].get<double>();
    ASSERT_GT(intensity, 0.0);
    const Texture whole = textureImage(doc, folder, ext["pages"][p].get<int>());
    std::vector<Texture> parts;
    for (const json& layer : layers) parts.push_back(textureImage(doc, folder, layer["textures"][p].get<int>()));
    for (size_t t = 0; t < whole.texels.size(); ++t)
      for (int c = 0; c < 3; ++c) {
        const double code = whole.texels[t][c];
        double sum = 0.0, tolerance = intensity * halfCode(code);
        bool clipped = code >= 1.0;
        for (size_t l = 0; l < parts.size(); ++l) {
          const double k = layers[l]["intensity"][p].get<double>(), v = parts[l].texels[t][c];
          sum += k * sRgbToLinear(v);
          tolerance += k * halfCode(v);
          clipped = clipped || v >= 1.0;
        }
        if (clipped) continue;  // above a PNG's range (its 99.9th percentile): the EXR pages hold it
        const double whole_ = intensity * sRgbToLinear(code);
        worstExcess = std::max(worstExcess, std::abs(sum - whole_) / (tolerance + 1e-7));
        meanDifference += std::abs(sum - whole_);
        ++compared;
      }
    // The float pages: lightmap_<p>.exr against the layers' exr[p].
    const Lightmap exr = readExr(folder / ("lightmap_" + std::to_string(p) + ".exr"));
    std::vector<Lightmap> layerExr;
    for (const json& layer : layers) layerExr.push_back(readExr(folder / layer["exr"][p].get<std::string>()));
    for (size_t t = 0; t < exr.texels.size(); ++t) {
      glm::vec3 s(0.0f);
      for (const Lightmap& m : layerExr) s += m.texels[t];
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(s[c], exr.texels[t][c], 1e-6f * std::max(1.0f, std::abs(s[c]))) << "page " << p << " texel " << t;
    }
  }
  std::printf("%zu channels: layers' PNG sum vs the default PNG, worst |difference| / quantisation bound %.3f, mean |difference| %.3g\n",
              compared, worstExcess, meanDifference / std::max<size_t>(1, compared));
  EXPECT_GT(compared, 1000u);
  EXPECT_LE(worstExcess, 1.0);
  if (r.probes.size() > 0) {
    EXPECT_TRUE(layers[0].contains("probes"));
    const json& accessor = doc["accessors"][layers[0]["probes"].get<int>()];
    EXPECT_EQ(accessor["count"].get<size_t>(), 9 * r.probes.size());
    EXPECT_EQ(accessor["type"], "VEC3");
  }
}

// Refused before anything is traced: the message names the group and the source.
TEST(LightGroups, RefusesDuplicatesBadNamesUnknownLightsAndSourcesInNoGroup) {
  const Scene s = room();
  auto refusal = [&](const std::vector<LightGroupRequest>& requests) -> std::string {
    try {
      resolveLightGroups(s, requests);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Usage);
      return e.what();
    }
    return "";
  };
  const std::string duplicate = refusal({request("a", {"left"}), request("b", {"left", "*"})});
  EXPECT_NE(duplicate.find("'left'"), std::string::npos) << duplicate;
  EXPECT_NE(duplicate.find("group 'a'"), std::string::npos) << duplicate;
  const std::string badName = refusal({request("day time", {"*"})});
  EXPECT_NE(badName.find("'day time'"), std::string::npos) << badName;
  const std::string pageName = refusal({request("shadowmask", {"*"})});
  EXPECT_NE(pageName.find("shadow-mask"), std::string::npos) << pageName;
  const std::string unknown = refusal({request("a", {"lamp7"}), request("b", {"*"})});
  EXPECT_NE(unknown.find("'lamp7'"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("left"), std::string::npos) << unknown;  // the sources it has
  const std::string unplaced = refusal({request("a", {"left"}), request("b", {"right"})});
  EXPECT_NE(unplaced.find("'neon'"), std::string::npos) << unplaced;
  EXPECT_NE(unplaced.find("'*'"), std::string::npos) << unplaced;
  const std::string empty = refusal({request("a", {"*"}), request("b", {"emissive"}), request("c", {"left", "right"}), request("d", {"*"})});
  EXPECT_NE(empty.find("'*'"), std::string::npos) << empty;
  EXPECT_EQ(resolveLightGroups(s, {request("a", {"left", "right"}), request("b", {"emissive:neon"})}).size(), 2u);
}

// The automatic probe spacing follows the lights (a directional light's shadows ask for a finer grid): a group with
// the sun and one without would place grids of their own, whose coefficients cannot be summed. The grid is settled
// once for the whole scene: every layer's probes are the ungrouped bake's grid, and they sum to the total's.
TEST(LightGroups, TheProbeGridIsTheWholeScenesWhenOnlyOneGroupHasTheSun) {
  Scene s;
  const int grey = irbake::testing::addMaterial(s, glm::vec3(0.5f));
  irbake::testing::addQuad(s, grey, {-2.0f, 0.0f, 2.0f}, {4.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -4.0f});  // floor, facing up
  irbake::testing::addBox(s, grey, {-0.5f, 0.0f, -0.5f}, {0.5f, 1.0f, 0.5f}, false);
  Light sun = irbake::testing::directionalLight(glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f)), 3.0f);
  sun.name = "daylight";
  s.lights = {sun, namedPoint("lamp", {1.2f, 1.5f, 0.0f}, 2.0f)};
  BakeOptions o = roomBake();
  o.walk.paths = 512;
  o.errorEstimate.enabled = false;
  const BakeResult all = bake(s, o);
  o.lightGroups = {request("day", {"daylight"}), request("night", {"lamp"})};
  const BakeResult sum = bakeLightGroups(s, o);
  ASSERT_GT(all.probes.size(), 0u);
  EXPECT_EQ(sum.probes.counts, all.probes.counts);
  ASSERT_EQ(sum.layers.size(), 2u);
  for (const auto& layer : sum.layers) EXPECT_EQ(layer.probes.size(), all.probes.size()) << layer.name;
}
