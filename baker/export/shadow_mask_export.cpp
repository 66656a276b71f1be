#include "export/shadow_mask_export.h"

#include <cmath>
#include <map>

#include "common/error.h"
#include "export/map_encoding.h"

namespace irbake {

namespace {

// The page a MOZ_lightmap texture shows, from its image's name (lightmap_<page>); -1 when none.
int pageOfTexture(const GltfDocument& doc, int texture) {
  const nlohmann::json& root = doc.root;
  if (!root.contains("textures") || texture < 0 || texture >= int(root["textures"].size())) return -1;
  const int image = root["textures"][texture].value("source", -1);
  if (!root.contains("images") || image < 0 || image >= int(root["images"].size())) return -1;
  const std::string name = root["images"][image].value("name", std::string());
  if (name.rfind("lightmap_", 0) != 0 || name.size() == 9 || name.find_first_not_of("0123456789", 9) != std::string::npos)
    return -1;
  return std::stoi(name.substr(9));
}

nlohmann::json lightJson(const ShadowMaskLight& l, const Scene* scene) {
  nlohmann::json j = {{"name", l.name}, {"channel", l.channel}};
  if (const int index = documentLightIndex(scene, *l.light); index >= 0) {
    j["light"] = index;  // index into KHR_lights_punctual.lights
  } else {  // --sun: not in the document, so described here for the runtime to shade it
    const glm::vec3 d = l.light->direction, e = l.light->color * l.light->intensity;
    j["directional"] = {{"direction", {d.x, d.y, d.z}}, {"irradiance", {e.x, e.y, e.z}}};
  }
  return j;
}

}  // namespace

int documentLightIndex(const Scene* scene, const Light& l) {
  if (l.gltfLight >= 0) return l.gltfLight;
  if (!scene || (!scene->sourcePath.empty() && std::filesystem::exists(scene->sourcePath))) return -1;
  for (size_t i = 0; i < scene->lights.size(); ++i)
    if (&scene->lights[i] == &l) return static_cast<int>(i);
  return -1;
}

ShadowMaskPage shadowMaskPage(const ShadowMaskExport& mask, size_t i) {
  const Lightmap& rgb = (*mask.rgb)[i];
  const Lightmap* alpha = mask.alpha && i < mask.alpha->size() ? &(*mask.alpha)[i] : nullptr;
  ShadowMaskPage p;
  p.rgb.page = p.alpha.page = rgb.page;
  p.rgb.width = p.alpha.width = rgb.width;
  p.rgb.height = p.alpha.height = rgb.height;
  p.rgb.texels.resize(rgb.texels.size());
  p.alpha.texels.resize(rgb.texels.size());
  for (size_t k = 0; k < rgb.texels.size(); ++k) {
    const glm::vec4 v = glm::clamp(glm::vec4(rgb.texels[k], alpha ? alpha->texels[k].x : 1.0f), 0.0f, 1.0f);
    p.rgb.texels[k] = glm::vec3(v);
    p.alpha.texels[k] = glm::vec3(v.a);
  }
  return p;
}

namespace {

// The mask's encoding (png8 or exr): linear, values in [0, 1] as they are, four channels.
MapEncodeOptions shadowMaskEncoding(const ShadowMaskPage& page, const std::string& name) {
  MapEncodeOptions o;
  o.srgb = false;
  o.range = MapRange::Unit;
  o.alpha = &page.alpha;
  o.name = name;
  return o;
}

}  // namespace

std::string shadowMaskPageUri(const std::string& prefix, int page) {
  return prefix + "_" + std::to_string(page) + "_shadowmask.exr";
}

void writeShadowMaskExr(const ShadowMaskExport& mask, size_t i, const std::filesystem::path& file,
                        const std::filesystem::path& finalPath) {
  const ShadowMaskPage page = shadowMaskPage(mask, i);
  for (size_t k = 0; k < page.rgb.texels.size(); ++k) {
    const glm::vec4 v(page.rgb.texels[k], page.alpha.texels[k].x);
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z) || !std::isfinite(v.w))
      throw Error(ErrorCode::NumericError, finalPath.string(), "shadow-mask page holds NaN/Inf");
  }
  mapEncoding(MapEncodingKind::Exr).writeFile(page.rgb, shadowMaskEncoding(page, finalPath.string()), file, finalPath);
}

void addShadowMaskExtension(GltfDocument& doc, const ShadowMaskExport& mask, const std::string& exrPrefix) {
  using nlohmann::json;
  if (mask.empty() || !doc.root.contains("materials")) return;
  std::map<int, json> extensionOfPage;
  auto extensionFor = [&](int page) -> const json* {
    auto it = extensionOfPage.find(page);
    if (it != extensionOfPage.end()) return &it->second;
    for (size_t i = 0; i < mask.rgb->size(); ++i) {
      if ((*mask.rgb)[i].page != page) continue;
      const std::string name = "lightmap_" + std::to_string(page) + "_shadowmask";
      // Linear 8-bit: a mask is a visibility in [0, 1], so steps of 1/255 are finer than the 1/64 of its
      // 8×8 edge rays and invisible on a light's direct term.
      const ShadowMaskPage maskPage = shadowMaskPage(mask, i);
      const MapEncoding& png8 = mapEncoding(MapEncodingKind::Png8);
      const EncodedMap encoded = png8.encode(maskPage.rgb, shadowMaskEncoding(maskPage, name));
      const int texture = doc.addTexture(doc.addImage(encoded.bytes, name, png8.mimeType()),
                                         doc.addSampler(WrapMode::ClampToEdge, WrapMode::ClampToEdge, true));
      json ext = {{"index", texture}, {"texCoord", 1}};
      if (!exrPrefix.empty()) ext["exr"] = shadowMaskPageUri(exrPrefix, page);
      return &(extensionOfPage[page] = std::move(ext));
    }
    return nullptr;
  };
  bool used = false;
  for (auto& mat : doc.root["materials"]) {
    if (!mat.contains("extensions") || !mat["extensions"].contains("MOZ_lightmap")) continue;
    const json* ext = extensionFor(pageOfTexture(doc, mat["extensions"]["MOZ_lightmap"].value("index", -1)));
    if (!ext) continue;
    mat["extensions"][kShadowMaskExtension] = *ext;
    used = true;
  }
  if (!used) return;
  json lights = json::array();
  for (const ShadowMaskLight& l : mask.lights) lights.push_back(lightJson(l, mask.scene));
  doc.root["extensions"][kShadowMaskExtension] = {{"lights", lights}};
  doc.useExtension(kShadowMaskExtension);
}

void recordLightModes(GltfDocument& doc, const Scene& scene, const std::vector<LightMode>& modes) {
  using nlohmann::json;
  if (modes.size() != scene.lights.size()) return;
  json* khr = nullptr;
  if (doc.root.contains("extensions") && doc.root["extensions"].contains("KHR_lights_punctual") &&
      doc.root["extensions"]["KHR_lights_punctual"].contains("lights") &&
      doc.root["extensions"]["KHR_lights_punctual"]["lights"].is_array())
    khr = &doc.root["extensions"]["KHR_lights_punctual"]["lights"];
  for (size_t i = 0; i < modes.size(); ++i) {
    const Light& l = scene.lights[i];
    const int index = documentLightIndex(&scene, l);
    if (index < 0) {  // the command line's sun: not in the document
      if (modes[i] == LightMode::Baked || (doc.root.contains("extras") && !doc.root["extras"].is_object())) continue;
      const glm::vec3 d = l.direction, e = l.color * l.intensity;
      doc.root["extras"]["irbakeSun"] = {{"mode", toString(modes[i])}, {"direction", {d.x, d.y, d.z}},
                                         {"irradiance", {e.x, e.y, e.z}}};
      continue;
    }
    if (!khr || index >= static_cast<int>(khr->size())) continue;
    json& light = (*khr)[static_cast<size_t>(index)];
    if (modes[i] == LightMode::Baked && !l.hasExtrasMode) continue;
    if (light.contains("extras") && !light["extras"].is_object()) continue;  // a source's own non-object extras stay
    light["extras"]["irbake"]["mode"] = toString(modes[i]);
  }
}

}  // namespace irbake
