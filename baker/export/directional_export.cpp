#include "export/directional_export.h"

#include <map>

namespace irbake {

MapEncodeOptions directionalEncoding(const std::string& name) {
  MapEncodeOptions o;
  o.srgb = false;
  o.range = MapRange::SignedMax;
  o.name = name;
  return o;
}

std::string directionalPageUri(const std::string& prefix, int page, int axis) {
  static const char* kAxis[3] = {"x", "y", "z"};
  return prefix + "_" + std::to_string(page) + "_l1" + kAxis[axis] + ".exr";
}

void addDirectionalExtension(GltfDocument& doc, const std::array<std::vector<Lightmap>, 3>& l1,
                             const std::string& exrPrefix) {
  using nlohmann::json;
  if (l1[0].empty() || !doc.root.contains("materials")) return;
  // Page of each MOZ_lightmap texture, from its image's name (lightmap_<page>).
  auto pageOfTexture = [&](int texture) -> int {
    if (!doc.root.contains("textures") || texture < 0 || texture >= int(doc.root["textures"].size())) return -1;
    const int image = doc.root["textures"][texture].value("source", -1);
    if (!doc.root.contains("images") || image < 0 || image >= int(doc.root["images"].size())) return -1;
    const std::string name = doc.root["images"][image].value("name", std::string());
    if (name.rfind("lightmap_", 0) != 0) return -1;
    try {
      return std::stoi(name.substr(9));
    } catch (...) {
      return -1;
    }
  };
  std::map<int, json> extensionOfPage;
  auto extensionFor = [&](int page) -> const json* {
    auto it = extensionOfPage.find(page);
    if (it != extensionOfPage.end()) return &it->second;
    size_t index = l1[0].size();
    for (size_t i = 0; i < l1[0].size(); ++i)
      if (l1[0][i].page == page) index = i;
    if (index == l1[0].size()) return nullptr;
    json ext = {{"l1", json::array()}};
    for (int k = 0; k < 3; ++k) {
      const std::string name = "lightmap_" + std::to_string(page) + "_l1" + "xyz"[k];
      const MapEncoding& png8 = mapEncoding(MapEncodingKind::Png8);
      const EncodedMap encoded = png8.encode(l1[k][index], directionalEncoding(name));
      const int image = doc.addImage(encoded.bytes, name, png8.mimeType());
      const int texture = doc.addTexture(image, doc.addSampler(WrapMode::ClampToEdge, WrapMode::ClampToEdge, true));
      ext["l1"].push_back({{"index", texture}, {"texCoord", 1}, {"scale", encoded.metadata.intensity}});
    }
    if (!exrPrefix.empty()) {
      ext["exr"] = json::array();
      for (int k = 0; k < 3; ++k) ext["exr"].push_back(directionalPageUri(exrPrefix, page, k));
    }
    return &(extensionOfPage[page] = std::move(ext));
  };
  bool used = false;
  for (auto& mat : doc.root["materials"]) {
    if (!mat.contains("extensions") || !mat["extensions"].contains("MOZ_lightmap")) continue;
    const int page = pageOfTexture(mat["extensions"]["MOZ_lightmap"].value("index", -1));
    const json* ext = page >= 0 ? extensionFor(page) : nullptr;
    if (!ext) continue;
    mat["extensions"][kDirectionalExtension] = *ext;
    used = true;
  }
  if (used) doc.useExtension(kDirectionalExtension);
}

}  // namespace irbake
