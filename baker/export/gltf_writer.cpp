#include "export/gltf_writer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>

#include <glm/gtc/quaternion.hpp>

#include "common/error.h"
#include "common/file_paths.h"
#include "lights/light_kind.h"
#include "scene/image_codec.h"

namespace irbake {

using json = nlohmann::json;

namespace {

constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr int kFloat = 5126, kUnsignedInt = 5125;

int glWrap(WrapMode m) {
  switch (m) {
    case WrapMode::Repeat: return 10497;
    case WrapMode::ClampToEdge: return 33071;
    case WrapMode::MirroredRepeat: return 33648;
  }
  return 10497;
}

json vec(const glm::vec3& v) { return json::array({v.x, v.y, v.z}); }

// Rotation taking the glTF light/camera axis −Z onto `dir` (unit).
glm::quat rotationFromMinusZ(const glm::vec3& dir) {
  const glm::vec3 from(0.0f, 0.0f, -1.0f);
  float c = glm::dot(from, dir);
  if (c < -0.999999f) return glm::quat(0.0f, 0.0f, 1.0f, 0.0f);  // opposite: half turn about +Y
  glm::vec3 axis = glm::cross(from, dir);
  glm::quat q(1.0f + c, axis.x, axis.y, axis.z);  // half-angle construction, normalised below
  return glm::normalize(q);
}

json rotationJson(const glm::quat& q) { return json::array({q.x, q.y, q.z, q.w}); }

// KHR_texture_transform on a texture reference, when the material has one.
void writeUvTransform(GltfDocument& doc, json& textureInfo, const UvTransform& t) {
  if (!t.present) return;
  textureInfo["extensions"]["KHR_texture_transform"] = {
      {"offset", {t.offset.x, t.offset.y}}, {"rotation", t.rotation}, {"scale", {t.scale.x, t.scale.y}}};
  doc.useExtension("KHR_texture_transform");
}

}  // namespace

GltfDocument::GltfDocument() {
  root = json::object();
  root["asset"] = {{"version", "2.0"}, {"generator", "irbake"}};
  root["buffers"] = json::array({json::object({{"byteLength", 0}})});
}

GltfDocument::GltfDocument(nlohmann::json j, std::vector<uint8_t> b) : root(std::move(j)), bin(std::move(b)) {
  if (!root.contains("buffers") || !root["buffers"].is_array() || root["buffers"].empty())
    root["buffers"] = json::array({json::object({{"byteLength", 0}})});
}

int GltfDocument::append(const char* key, nlohmann::json element) {
  if (!root.contains(key) || !root[key].is_array()) root[key] = json::array();
  root[key].push_back(std::move(element));
  return static_cast<int>(root[key].size()) - 1;
}

void GltfDocument::useExtension(const std::string& name) {
  if (!root.contains("extensionsUsed") || !root["extensionsUsed"].is_array()) root["extensionsUsed"] = json::array();
  for (const auto& e : root["extensionsUsed"])
    if (e == name) return;
  root["extensionsUsed"].push_back(name);
}

void unlistExtension(json& root, const std::string& name) {
  for (const char* list : {"extensionsUsed", "extensionsRequired"}) {
    if (!root.contains(list) || !root[list].is_array()) continue;
    json& names = root[list];
    names.erase(std::remove(names.begin(), names.end(), json(name)), names.end());
    if (names.empty()) root.erase(list);
  }
}

void removeRootExtension(json& root, const std::string& name) {
  if (root.contains("extensions") && root["extensions"].is_object() && root["extensions"].contains(name)) {
    root["extensions"].erase(name);
    if (root["extensions"].empty()) root.erase("extensions");
  }
  unlistExtension(root, name);
}

int GltfDocument::addBufferView(const void* data, size_t size, int target) {
  while (bin.size() % 4) bin.push_back(0);
  size_t offset = bin.size();
  bin.resize(offset + size);
  if (size) std::memcpy(bin.data() + offset, data, size);
  json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}};
  if (target) view["target"] = target;
  return append("bufferViews", std::move(view));
}

int GltfDocument::addPositions(const std::vector<glm::vec3>& v) {
  int a = addVec3(v);
  glm::vec3 lo(0.0f), hi(0.0f);
  if (!v.empty()) {
    lo = hi = v[0];
    for (const auto& p : v) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  }
  root["accessors"][a]["min"] = vec(lo);
  root["accessors"][a]["max"] = vec(hi);
  return a;
}

int GltfDocument::addVec3(const std::vector<glm::vec3>& v) {
  int view = addBufferView(v.data(), v.size() * sizeof(glm::vec3), kArrayBuffer);
  return append("accessors", {{"bufferView", view}, {"componentType", kFloat}, {"count", v.size()}, {"type", "VEC3"}});
}

int GltfDocument::addVec2(const std::vector<glm::vec2>& v) {
  int view = addBufferView(v.data(), v.size() * sizeof(glm::vec2), kArrayBuffer);
  return append("accessors", {{"bufferView", view}, {"componentType", kFloat}, {"count", v.size()}, {"type", "VEC2"}});
}

int GltfDocument::addIndices(const std::vector<uint32_t>& v) {
  int view = addBufferView(v.data(), v.size() * sizeof(uint32_t), kElementArrayBuffer);
  return append("accessors", {{"bufferView", view}, {"componentType", kUnsignedInt}, {"count", v.size()}, {"type", "SCALAR"}});
}

int GltfDocument::addImage(const std::vector<uint8_t>& bytes, const std::string& name, const std::string& mimeType) {
  int view = addBufferView(bytes.data(), bytes.size());
  json image = {{"bufferView", view}, {"mimeType", mimeType}};
  if (!name.empty()) image["name"] = name;
  return append("images", std::move(image));
}

int GltfDocument::addSampler(WrapMode s, WrapMode t, bool linearNoMips) {
  json sampler = {{"wrapS", glWrap(s)}, {"wrapT", glWrap(t)}};
  if (linearNoMips) {
    sampler["magFilter"] = 9729;  // LINEAR
    sampler["minFilter"] = 9729;  // light maps are smooth; mip-mapping across charts would bleed
  }
  if (root.contains("samplers"))
    for (size_t i = 0; i < root["samplers"].size(); ++i)
      if (root["samplers"][i] == sampler) return static_cast<int>(i);
  return append("samplers", std::move(sampler));
}

int GltfDocument::addTexture(int image, int sampler) {
  json tex = {{"source", image}};
  if (sampler >= 0) tex["sampler"] = sampler;
  return append("textures", std::move(tex));
}

std::vector<PendingFile> GltfDocument::files(const std::filesystem::path& path) const {
  std::vector<PendingFile> out;
  nlohmann::json doc = root;
  auto& buffer0 = doc["buffers"][0];
  buffer0["byteLength"] = bin.size();
  buffer0.erase("uri");
  if (bin.empty() && doc["buffers"].size() == 1) doc.erase("buffers");
  const std::string finalName = path.string();
  if (hasExtension(path, ".glb")) {
    auto text = std::make_shared<std::string>(doc.dump());
    out.push_back({path, [text, this, finalName](const std::filesystem::path& temp) {
                     std::string jsonChunk = *text;
                     while (jsonChunk.size() % 4) jsonChunk.push_back(' ');
                     size_t binPadded = (bin.size() + 3) / 4 * 4;
                     uint64_t total = 12 + 8 + jsonChunk.size() + (bin.empty() ? 0 : 8 + binPadded);
                     if (total > 0xFFFFFFFFull) throw Error(ErrorCode::Io, finalName, "GLB would exceed 4 GiB");
                     std::vector<uint8_t> glb;
                     glb.reserve(total);
                     auto u32 = [&](uint32_t v) {
                       uint8_t b[4];
                       std::memcpy(b, &v, 4);
                       glb.insert(glb.end(), b, b + 4);
                     };
                     glb.insert(glb.end(), {'g', 'l', 'T', 'F'});
                     u32(2);
                     u32(static_cast<uint32_t>(total));
                     u32(static_cast<uint32_t>(jsonChunk.size()));
                     u32(0x4E4F534Au);  // JSON
                     glb.insert(glb.end(), jsonChunk.begin(), jsonChunk.end());
                     if (!bin.empty()) {
                       u32(static_cast<uint32_t>(binPadded));
                       u32(0x004E4942u);  // BIN
                       glb.insert(glb.end(), bin.begin(), bin.end());
                       glb.resize(total, 0);
                     }
                     writeBytes(temp, glb.data(), glb.size(), finalName);
                   }});
    return out;
  }
  std::filesystem::path binPath = path;
  binPath.replace_extension(".bin");
  if (!bin.empty()) doc["buffers"][0]["uri"] = binPath.filename().string();
  auto text = std::make_shared<std::string>(doc.dump(1));
  out.push_back({path, [text, finalName](const std::filesystem::path& temp) { writeBytes(temp, text->data(), text->size(), finalName); }});
  if (!bin.empty()) {
    std::string binName = binPath.string();
    out.push_back({binPath, [this, binName](const std::filesystem::path& temp) { writeBytes(temp, bin.data(), bin.size(), binName); }});
  }
  return out;
}

json materialJson(const Scene& scene, const Material& m, GltfDocument& doc, std::map<std::pair<int, bool>, int>& cache) {
  auto texture = [&](int sceneTexture, bool srgb) {
    auto key = std::make_pair(sceneTexture, srgb);
    auto it = cache.find(key);
    if (it != cache.end()) return it->second;
    const Texture& t = scene.textures.at(sceneTexture);
    int image = doc.addImage(encodePng(t, srgb), t.name);
    int index = doc.addTexture(image, doc.addSampler(t.wrapS, t.wrapT, !srgb));
    cache[key] = index;
    return index;
  };
  json mat = json::object();
  if (!m.name.empty()) mat["name"] = m.name;
  json pbr = {{"baseColorFactor", {m.baseColorFactor.r, m.baseColorFactor.g, m.baseColorFactor.b, m.baseColorFactor.a}},
              {"metallicFactor", 0.0},
              {"roughnessFactor", 1.0}};
  if (m.baseColorTexture >= 0 && !scene.textures.at(m.baseColorTexture).texels.empty()) {
    pbr["baseColorTexture"] = {{"index", texture(m.baseColorTexture, true)}};
    if (m.baseColorTexCoord) pbr["baseColorTexture"]["texCoord"] = m.baseColorTexCoord;
    writeUvTransform(doc, pbr["baseColorTexture"], m.baseColorUvTransform);
  }
  mat["pbrMetallicRoughness"] = pbr;
  // glTF keeps emissiveFactor in [0,1]: the scale above 1 moves into KHR_materials_emissive_strength.
  glm::vec3 e = m.emissiveFactor;
  float strength = m.emissiveStrength;
  float peak = std::max(e.x, std::max(e.y, e.z));
  if (peak > 1.0f) {
    e /= peak;
    strength *= peak;
  }
  if (peak > 0.0f) mat["emissiveFactor"] = vec(e);
  if (peak > 0.0f && strength != 1.0f) {
    mat["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", strength}};
    doc.useExtension("KHR_materials_emissive_strength");
  }
  if (m.emissiveTexture >= 0 && !scene.textures.at(m.emissiveTexture).texels.empty()) {
    mat["emissiveTexture"] = {{"index", texture(m.emissiveTexture, true)}};
    if (m.emissiveTexCoord) mat["emissiveTexture"]["texCoord"] = m.emissiveTexCoord;
    writeUvTransform(doc, mat["emissiveTexture"], m.emissiveUvTransform);
  }
  if (m.normalTexture >= 0 && !scene.textures.at(m.normalTexture).texels.empty()) {
    mat["normalTexture"] = {{"index", texture(m.normalTexture, false)}};
    if (m.normalTexCoord) mat["normalTexture"]["texCoord"] = m.normalTexCoord;
    if (m.normalScale != 1.0f) mat["normalTexture"]["scale"] = m.normalScale;
  }
  if (m.lightmapTexture >= 0 && !scene.textures.at(m.lightmapTexture).texels.empty()) {
    mat["extensions"]["MOZ_lightmap"] = {{"index", texture(m.lightmapTexture, false)}, {"texCoord", 1}, {"intensity", m.lightmapIntensity}};
    doc.useExtension("MOZ_lightmap");
  }
  if (m.alphaMode == AlphaMode::Mask) {
    mat["alphaMode"] = "MASK";
    mat["alphaCutoff"] = m.alphaCutoff;
  } else if (m.alphaMode == AlphaMode::Blend) {
    mat["alphaMode"] = "BLEND";
  }
  if (m.doubleSided) mat["doubleSided"] = true;
  return mat;
}

int addPrimitiveMesh(GltfDocument& doc, const Primitive& prim, int material) {
  json attributes = {{"POSITION", doc.addPositions(prim.positions)}};
  if (prim.normals.size() == prim.positions.size()) attributes["NORMAL"] = doc.addVec3(prim.normals);
  if (prim.uv0.size() == prim.positions.size()) attributes["TEXCOORD_0"] = doc.addVec2(prim.uv0);
  if (prim.uv1.size() == prim.positions.size()) {
    attributes["TEXCOORD_1"] = doc.addVec2(prim.uv1);
    // TEXCOORD sets are numbered from 0 without gaps: without its own set 0 it shares the light-map UVs.
    if (!attributes.contains("TEXCOORD_0")) attributes["TEXCOORD_0"] = attributes["TEXCOORD_1"];
  }
  json p = {{"attributes", attributes}, {"indices", doc.addIndices(prim.indices)}, {"mode", 4}};
  if (material >= 0) p["material"] = material;
  if (prim.lightmap.page >= 0)
    p["extras"]["lightmap"] = {{"page", prim.lightmap.page}, {"width", prim.lightmap.width}, {"height", prim.lightmap.height}};
  if (prim.mode == ObjectMode::Probes) p["extras"]["lightProbes"] = true;  // a probe-lit object (docs/export.md)
  json mesh = {{"primitives", json::array({p})}};
  if (!prim.name.empty()) mesh["name"] = prim.name;
  return doc.append("meshes", std::move(mesh));
}

// EXT_lights_ies: the profile (the file as read, as a data URI) once in the root's lights, and a node placing it
// with its multiplier and colour, its rotation taking −Z to the profile's nadir and +X to its horizontal angle 0.
static int addIesLight(GltfDocument& doc, const Light& l, std::map<const IesProfile*, size_t>& profiles) {
  json& lights = doc.root["extensions"]["EXT_lights_ies"]["lights"];
  if (!lights.is_array()) lights = json::array();
  auto [it, added] = profiles.emplace(l.profile.get(), lights.size());
  if (added) {
    json profile = json::object();
    lightKind(l).describeGltf(l, profile);
    if (!l.name.empty()) profile["name"] = l.name;
    lights.push_back(std::move(profile));
  }
  json node = {{"extensions",
                {{"EXT_lights_ies", {{"light", it->second}, {"multiplier", l.intensity}, {"color", vec(l.color)}}}}}};
  if (!l.name.empty()) node["name"] = l.name;
  node["translation"] = vec(l.position);
  const glm::vec3 z = -glm::normalize(l.direction), x = glm::normalize(l.profileAxisX);
  node["rotation"] = rotationJson(glm::normalize(glm::quat_cast(glm::mat3(x, glm::cross(z, x), z))));
  doc.useExtension("EXT_lights_ies");
  return doc.append("nodes", std::move(node));
}

GltfDocument gltfFromScene(const Scene& scene, const GltfWriteOptions& options) {
  GltfDocument doc;
  std::map<std::pair<int, bool>, int> textureCache;
  std::vector<int> materialIndex(scene.materials.size(), -1);
  for (size_t i = 0; i < scene.materials.size(); ++i)
    materialIndex[i] = doc.append("materials", materialJson(scene, scene.materials[i], doc, textureCache));
  json roots = json::array();
  for (const auto& prim : scene.primitives) {
    int mesh = addPrimitiveMesh(doc, prim, prim.material >= 0 ? materialIndex.at(prim.material) : -1);
    json node = {{"mesh", mesh}};
    if (!prim.name.empty()) node["name"] = prim.name;
    roots.push_back(doc.append("nodes", std::move(node)));
  }
  std::map<const IesProfile*, size_t> iesProfiles;
  for (const auto& l : scene.lights) {
    if (l.type == LightType::Ies) {
      roots.push_back(addIesLight(doc, l, iesProfiles));
      continue;
    }
    json light = {{"color", vec(l.color)}, {"intensity", l.intensity}};
    if (!l.name.empty()) light["name"] = l.name;
    const LightKind& kind = lightKind(l.type);
    kind.describeGltf(l, light);
    if (l.range > 0.0f) light["range"] = l.range;
    if (!doc.root["extensions"]["KHR_lights_punctual"].contains("lights"))
      doc.root["extensions"]["KHR_lights_punctual"]["lights"] = json::array();
    auto& lights = doc.root["extensions"]["KHR_lights_punctual"]["lights"];
    lights.push_back(light);
    json node = {{"extensions", {{"KHR_lights_punctual", {{"light", lights.size() - 1}}}}}};
    if (!l.name.empty()) node["name"] = l.name;
    if (!kind.atInfinity()) node["translation"] = vec(l.position);
    if (kind.aimed()) node["rotation"] = rotationJson(rotationFromMinusZ(glm::normalize(l.direction)));
    roots.push_back(doc.append("nodes", std::move(node)));
    doc.useExtension("KHR_lights_punctual");
  }
  for (const auto& c : scene.cameras) {
    json persp = {{"yfov", c.yfov}, {"znear", c.znear}};
    if (c.aspectRatio > 0.0f) persp["aspectRatio"] = c.aspectRatio;
    if (c.zfar > 0.0f) persp["zfar"] = c.zfar;
    json cam = {{"type", "perspective"}, {"perspective", persp}};
    if (!c.name.empty()) cam["name"] = c.name;
    int ci = doc.append("cameras", std::move(cam));
    glm::mat3 r(c.cameraToWorld);
    for (int k = 0; k < 3; ++k) r[k] = glm::normalize(r[k]);
    json node = {{"camera", ci},
                 {"translation", vec(glm::vec3(c.cameraToWorld[3]))},
                 {"rotation", rotationJson(glm::normalize(glm::quat_cast(r)))}};
    if (!c.name.empty()) node["name"] = c.name;
    roots.push_back(doc.append("nodes", std::move(node)));
  }
  doc.root["scenes"] = json::array({{{"nodes", roots}}});
  doc.root["scene"] = 0;
  if (!options.lightmapPages.empty()) doc.root["extras"]["lightmapPages"] = options.lightmapPages;
  return doc;
}

void writeGltf(const Scene& scene, const std::filesystem::path& path, const GltfWriteOptions& options) {
  GltfDocument doc = gltfFromScene(scene, options);
  writeAllAtomically(doc.files(path));
}

void writeBytes(const std::filesystem::path& path, const void* data, size_t size, const std::string& finalName) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(ErrorCode::Io, finalName, "cannot open for writing");
  if (size) out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) throw Error(ErrorCode::Io, finalName, "write failed (disk full?)");
}

PendingFile pendingBytes(const std::filesystem::path& finalPath, std::vector<uint8_t> bytes) {
  auto data = std::make_shared<std::vector<uint8_t>>(std::move(bytes));
  const std::string finalName = finalPath.string();
  return {finalPath, [data, finalName](const std::filesystem::path& temp) { writeBytes(temp, data->data(), data->size(), finalName); }};
}

}  // namespace irbake
