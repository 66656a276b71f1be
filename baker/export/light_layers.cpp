#include "export/light_layers.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace irbake {

namespace {

using json = nlohmann::json;
constexpr int kFloat = 5126;

int addFloatAccessor(GltfDocument& doc, const void* data, size_t count, const char* type, size_t components) {
  const int view = doc.addBufferView(data, count * components * sizeof(float));
  return doc.append("accessors", {{"bufferView", view}, {"componentType", kFloat}, {"count", count}, {"type", type}});
}

// Per page (in map order): the texture the materials' MOZ_lightmap names, read from the primitives'
// extras.lightmap.page and their material; -1 where no material names one.
std::vector<int> mozLightmapTextures(const json& root, size_t pages) {
  std::vector<int> textures(pages, -1);
  if (!root.contains("meshes") || !root.contains("materials")) return textures;
  for (const json& mesh : root["meshes"])
    for (const json& prim : mesh.value("primitives", json::array())) {
      if (!prim.contains("material") || !prim.contains("extras") || !prim["extras"].contains("lightmap")) continue;
      const int page = prim["extras"]["lightmap"].value("page", -1);
      const json& material = root["materials"][prim["material"].get<size_t>()];
      if (page < 0 || page >= static_cast<int>(pages) || !material.contains("extensions") ||
          !material["extensions"].contains("MOZ_lightmap"))
        continue;
      textures[static_cast<size_t>(page)] = material["extensions"]["MOZ_lightmap"].value("index", -1);
    }
  return textures;
}

}  // namespace

bool validLayerName(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

bool otherPageName(const std::string& name) {
  return name == "shadowmask" || name == "l1x" || name == "l1y" || name == "l1z";
}

CombinedLayers combineLayers(const std::vector<LightLayer>& layers, const std::vector<glm::vec3>& weights) {
  if (layers.empty() || weights.size() != layers.size())
    throw Error(ErrorCode::InvalidData, "", "combining light layers: " + std::to_string(weights.size()) + " weights for " +
                                                std::to_string(layers.size()) + " layers");
  CombinedLayers out;
  const LightLayer& first = layers.front();
  for (const Lightmap& m : first.maps) {
    Lightmap sum = m;
    std::fill(sum.texels.begin(), sum.texels.end(), glm::vec3(0.0f));
    std::fill(sum.valid.begin(), sum.valid.end(), uint8_t(0));
    out.maps.push_back(std::move(sum));
  }
  out.probes.assign(first.probes.size(), ShCoefficients{});
  for (size_t l = 0; l < layers.size(); ++l) {
    const LightLayer& layer = layers[l];
    const glm::vec3 w = weights[l];
    if (!(std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z)) || w.x < 0.0f || w.y < 0.0f || w.z < 0.0f)
      throw Error(ErrorCode::InvalidData, "", "light layer '" + layer.name + "': a weight must be finite and ≥ 0");
    if (layer.maps.size() != out.maps.size() || layer.probes.size() != out.probes.size())
      throw Error(ErrorCode::InvalidData, "", "light layer '" + layer.name + "' has " + std::to_string(layer.maps.size()) +
                                                  " pages and " + std::to_string(layer.probes.size()) + " probes, layer '" +
                                                  first.name + "' " + std::to_string(out.maps.size()) + " and " +
                                                  std::to_string(out.probes.size()));
    for (size_t p = 0; p < out.maps.size(); ++p) {
      Lightmap& sum = out.maps[p];
      const Lightmap& m = layer.maps[p];
      if (m.width != sum.width || m.height != sum.height || m.texels.size() != sum.texels.size())
        throw Error(ErrorCode::InvalidData, "", "light layer '" + layer.name + "': page " + std::to_string(m.page) +
                                                    " is " + std::to_string(m.width) + "x" + std::to_string(m.height) +
                                                    ", not " + std::to_string(sum.width) + "x" + std::to_string(sum.height));
      for (size_t t = 0; t < sum.texels.size(); ++t) sum.texels[t] += w * m.texels[t];
      for (size_t t = 0; t < sum.valid.size() && t < m.valid.size(); ++t) sum.valid[t] |= m.valid[t];
    }
    for (size_t i = 0; i < out.probes.size(); ++i)
      for (int k = 0; k < kShCoefficients; ++k) out.probes[i][k] += w * layer.probes[i][k];
  }
  return out;
}

std::string layerPageUri(const std::string& prefix, int page, const std::string& layer) {
  return prefix + "_" + std::to_string(page) + "_" + layer + ".exr";
}

void addLightScenariosExtension(GltfDocument& doc, const std::vector<LightLayer>& layers, const MapEncodeOptions& encoding,
                                const std::string& exrPrefix) {
  if (layers.empty()) return;
  const size_t pages = layers.front().maps.size();
  const MapEncoding& png8 = mapEncoding(MapEncodingKind::Png8);  // the MOZ_lightmap image's encoding
  json ext;
  ext["pages"] = mozLightmapTextures(doc.root, pages);
  json layerList = json::array(), everyOne = json::object(), scenarios = json::array();
  for (const LightLayer& layer : layers) {
    json textures = json::array(), intensity = json::array(), exr = json::array();
    for (const Lightmap& m : layer.maps) {
      MapEncodeOptions o = encoding;
      o.name = "lightmap_" + std::to_string(m.page) + "_" + layer.name;
      const EncodedMap encoded = png8.encode(m, o);
      const int image = doc.addImage(encoded.bytes, encoded.stored.name, png8.mimeType());
      textures.push_back(doc.addTexture(image, doc.addSampler(WrapMode::ClampToEdge, WrapMode::ClampToEdge, true)));
      intensity.push_back(mozLightmapIntensity(encoded));  // as MOZ_lightmap's
      if (!exrPrefix.empty()) exr.push_back(layerPageUri(exrPrefix, m.page, layer.name));
    }
    json entry = {{"name", layer.name}, {"lights", layer.lights}, {"textures", textures}, {"intensity", intensity}};
    if (!exrPrefix.empty()) entry["exr"] = exr;
    layerList.push_back(std::move(entry));
    everyOne[layer.name] = {1, 1, 1};
  }
  scenarios.push_back({{"name", "default"}, {"weights", everyOne}});
  for (const LightLayer& layer : layers)
    if (layer.name != "default") scenarios.push_back({{"name", layer.name}, {"weights", {{layer.name, {1, 1, 1}}}}});
  ext["layers"] = std::move(layerList);
  ext["scenarios"] = std::move(scenarios);
  ext["default"] = 0;
  doc.root["extensions"][kLightScenariosExtension] = std::move(ext);
  doc.useExtension(kLightScenariosExtension);
}

void addLightScenarioProbes(GltfDocument& doc, const std::vector<LightLayer>& layers, const LightProbeGrid& grid) {
  if (!doc.root.contains("extensions") || !doc.root["extensions"].contains(kLightScenariosExtension)) return;
  json& list = doc.root["extensions"][kLightScenariosExtension]["layers"];
  for (size_t l = 0; l < layers.size() && l < list.size(); ++l) {
    const LightLayer& layer = layers[l];
    if (grid.size() == 0 || layer.probes.size() != grid.size()) continue;
    list[l]["probes"] = addFloatAccessor(doc, layer.probes.data(), layer.probes.size() * kShCoefficients, "VEC3", 3);
    if (layer.holdsSun && grid.sun.present()) {
      const glm::vec3 e = grid.sun.irradiance;
      list[l]["sun"] = {{"irradiance", {e.x, e.y, e.z}},
                        {"sh", addFloatAccessor(doc, grid.sun.sh.data(), kShCoefficients, "VEC3", 3)}};
    }
  }
}

void removeLightScenariosExtension(json& root) { removeRootExtension(root, kLightScenariosExtension); }

}  // namespace irbake
