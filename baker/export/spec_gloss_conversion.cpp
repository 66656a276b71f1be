#include "export/spec_gloss_conversion.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "common/log.h"
#include "scene/image_codec.h"

namespace irbake {

using json = nlohmann::json;

namespace {

// A reader of one material's specular-glossiness object whose complaints name the file, material and field.
struct SpecGlossReader {
  const json& sg;
  const std::string& file;
  std::string what;  // "material 3 ('floor')"

  [[noreturn]] void invalid(const std::string& field, const std::string& problem) const {
    const std::string name = std::string(kSpecularGlossinessExtension) + (field.empty() ? "" : "." + field);
    throw Error(ErrorCode::InvalidData, file, what + ": " + name + " " + problem);
  }
  // A factor of n finite numbers, or `fallback` when absent.
  json factor(const char* field, size_t n, json fallback) const {
    if (!sg.contains(field)) return fallback;
    const json& f = sg[field];
    if (!f.is_array() || f.size() != n) invalid(field, "must be " + std::to_string(n) + " numbers");
    for (const json& c : f)
      if (!c.is_number() || !std::isfinite(c.get<double>())) invalid(field, "must be finite numbers");
    return f;
  }
  double glossiness() const {
    if (!sg.contains("glossinessFactor")) return 1.0;
    const json& g = sg["glossinessFactor"];
    if (!g.is_number() || !(g.get<double>() >= 0.0 && g.get<double>() <= 1.0)) invalid("glossinessFactor", "must be a number in [0, 1]");
    return g.get<double>();
  }
  // A textureInfo naming a texture of the document, or null when absent.
  const json* texture(const char* field, const json& root) const {
    if (!sg.contains(field)) return nullptr;
    const json& t = sg[field];
    const size_t textures = root.contains("textures") && root["textures"].is_array() ? root["textures"].size() : 0;
    if (!t.is_object() || !t.contains("index") || !t["index"].is_number_integer() || t["index"].get<long long>() < 0 ||
        t["index"].get<size_t>() >= textures)
      invalid(field, "names no texture of the file");
    return &t;
  }
};

// The encoded bytes of texture `index`'s image (buffer 0 holds every image of the export).
std::vector<uint8_t> textureImageBytes(const GltfDocument& doc, int index, const SpecGlossReader& r) {
  const json& root = doc.root;
  const json& texture = root["textures"][index];
  const size_t images = root.contains("images") && root["images"].is_array() ? root["images"].size() : 0;
  if (!texture.contains("source") || !texture["source"].is_number_integer() || texture["source"].get<size_t>() >= images)
    r.invalid("specularGlossinessTexture", "names texture " + std::to_string(index) + ", which has no image");
  const json& image = root["images"][texture["source"].get<size_t>()];
  const size_t views = root.contains("bufferViews") ? root["bufferViews"].size() : 0;
  if (!image.contains("bufferView") || !image["bufferView"].is_number_integer() || image["bufferView"].get<size_t>() >= views)
    r.invalid("specularGlossinessTexture", "names an image whose bytes the file does not hold");
  const json& view = root["bufferViews"][image["bufferView"].get<size_t>()];
  const size_t offset = view.value("byteOffset", size_t(0)), length = view.value("byteLength", size_t(0));
  if (offset > doc.bin.size() || length > doc.bin.size() - offset)
    r.invalid("specularGlossinessTexture", "names an image beyond the end of its buffer");
  return std::vector<uint8_t>(doc.bin.begin() + static_cast<long>(offset), doc.bin.begin() + static_cast<long>(offset + length));
}

// A metallic-roughness texture from a specular-glossiness one: G = 1 − alpha × glossiness (8-bit codes,
// 255 − round(alpha code × glossiness)), R = B = 0, alpha 1; its own image, the source texture's sampler.
int roughnessTexture(GltfDocument& doc, int source, double glossiness, const SpecGlossReader& r) {
  const std::vector<uint8_t> bytes = textureImageBytes(doc, source, r);
  Texture t;
  try {
    t = decodeImageToTexture(bytes.data(), bytes.size(), false, "specularGlossinessTexture");
  } catch (const Error& e) {
    r.invalid("specularGlossinessTexture", std::string("has an image that cannot be decoded: ") + e.what());
  }
  for (glm::vec4& texel : t.texels) {
    const double alphaCode = std::round(std::clamp(static_cast<double>(texel.a), 0.0, 1.0) * 255.0);
    const double roughnessCode = 255.0 - std::round(alphaCode * glossiness);
    texel = glm::vec4(0.0f, static_cast<float>(roughnessCode / 255.0), 0.0f, 1.0f);
  }
  const json& image = doc.root["images"][doc.root["textures"][source]["source"].get<size_t>()];
  std::string stem = image.value("name", std::string("specular_glossiness_") + std::to_string(source));
  json texture = doc.root["textures"][source];
  texture["source"] = doc.addImage(encodePng(t, false), stem + "_roughness");
  return doc.append("textures", std::move(texture));
}


}  // namespace

int convertSpecularGlossiness(GltfDocument& doc, const std::string& file) {
  int converted = 0;
  if (doc.root.contains("materials") && doc.root["materials"].is_array()) {
    for (size_t i = 0; i < doc.root["materials"].size(); ++i) {
      json& mat = doc.root["materials"][i];
      if (!mat.is_object() || !mat.contains("extensions") || !mat["extensions"].is_object() ||
          !mat["extensions"].contains(kSpecularGlossinessExtension))
        continue;
      const json sg = mat["extensions"][kSpecularGlossinessExtension];
      const SpecGlossReader r{sg, file, "material " + std::to_string(i) + " ('" + mat.value("name", std::string()) + "')"};
      if (!sg.is_object()) r.invalid("", "must be an object");
      const double glossiness = r.glossiness();
      json pbr = json::object();
      // A metal-rough fallback's base colour is what the bake used (scene/gltf_loader.cpp) and may hold an
      // opacity the diffuse factor lacks: it is kept; the diffuse colour fills in only where it is absent.
      const json fallback = mat.contains("pbrMetallicRoughness") && mat["pbrMetallicRoughness"].is_object()
                                ? mat["pbrMetallicRoughness"]
                                : json();
      if (!fallback.is_null()) {
        for (const char* kept : {"baseColorFactor", "baseColorTexture"})
          if (fallback.contains(kept)) pbr[kept] = fallback[kept];
      } else {
        if (sg.contains("diffuseFactor")) pbr["baseColorFactor"] = r.factor("diffuseFactor", 4, json());
        if (const json* diffuse = r.texture("diffuseTexture", doc.root)) pbr["baseColorTexture"] = *diffuse;
      }
      pbr["metallicFactor"] = 0.0;
      json specular = {{"specularColorFactor", r.factor("specularFactor", 3, json::array({1.0, 1.0, 1.0}))}};
      if (const json* sgTexture = r.texture("specularGlossinessTexture", doc.root)) {
        pbr["roughnessFactor"] = 1.0;
        json info = *sgTexture;
        info["index"] = roughnessTexture(doc, (*sgTexture)["index"].get<int>(), glossiness, r);
        pbr["metallicRoughnessTexture"] = std::move(info);
        specular["specularColorTexture"] = *sgTexture;
      } else {
        pbr["roughnessFactor"] = 1.0 - glossiness;
      }
      mat["pbrMetallicRoughness"] = std::move(pbr);
      mat["extensions"].erase(kSpecularGlossinessExtension);
      mat["extensions"]["KHR_materials_specular"] = std::move(specular);
      mat["extensions"]["KHR_materials_ior"] = {{"ior", 1000.0}};
      ++converted;
    }
  }
  unlistExtension(doc.root, kSpecularGlossinessExtension);
  if (converted > 0) {
    doc.useExtension("KHR_materials_specular");
    doc.useExtension("KHR_materials_ior");
    log::info(file + ": " + std::to_string(converted) + " material(s) converted from " + kSpecularGlossinessExtension +
              " to metal-rough (docs/export.md)");
  }
  return converted;
}

}  // namespace irbake
