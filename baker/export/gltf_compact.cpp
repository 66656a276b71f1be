#include "export/gltf_compact.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <set>

#include "common/error.h"
#include "scene/gltf_component_types.h"
#include "scene/gltf_source.h"
#include "scene/image_codec.h"

namespace irbake {

using json = nlohmann::json;

namespace {

constexpr int kArrayBuffer = 34962;

double componentValue(const uint8_t* p, int componentType) {
  switch (componentType) {
    case 5120: return static_cast<double>(*reinterpret_cast<const int8_t*>(p));
    case 5121: return static_cast<double>(*p);
    case 5122: { int16_t v; std::memcpy(&v, p, 2); return v; }
    case 5123: { uint16_t v; std::memcpy(&v, p, 2); return v; }
    case 5125: { uint32_t v; std::memcpy(&v, p, 4); return v; }
    case 5126: { float v; std::memcpy(&v, p, 4); return v; }
    default: return 0.0;
  }
}

// root[key], or an empty array when absent, by reference: json::value() returns a copy, so each read
// would cost the whole array and the export would grow with the square of the mesh count.
const json& arrayOrEmpty(const json& root, const char* key) {
  static const json empty = json::array();
  const auto it = root.find(key);
  return it != root.end() ? *it : empty;
}

// Bytes [offset, offset + size) of buffer view `view` (all views live in buffer 0 here).
const uint8_t* viewBytes(const GltfDocument& doc, int view, size_t& length, size_t& stride, const std::string& file) {
  const json& views = arrayOrEmpty(doc.root, "bufferViews");
  if (view < 0 || view >= static_cast<int>(views.size())) throw Error(ErrorCode::InvalidData, file, "accessor names a missing buffer view");
  const json& v = views[view];
  const size_t offset = v.value("byteOffset", size_t(0));
  length = v.value("byteLength", size_t(0));
  stride = v.value("byteStride", size_t(0));
  if (offset + length > doc.bin.size()) throw Error(ErrorCode::InvalidData, file, "buffer view " + std::to_string(view) + " runs past its buffer");
  return doc.bin.data() + offset;
}

// Visits every accessor reference of the document: mesh primitives (attributes, indices, morph
// targets), skins, animation samplers and EXT_mesh_gpu_instancing.
template <class F>
void forEachAccessorRef(json& root, F&& f) {
  auto visitAttributes = [&](json& attrs) {
    if (!attrs.is_object()) return;
    for (auto& [name, a] : attrs.items())
      if (a.is_number_integer()) f(a);
  };
  if (root.contains("meshes"))
    for (auto& mesh : root["meshes"]) {
      if (!mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
      for (auto& prim : mesh["primitives"]) {
        if (prim.contains("attributes")) visitAttributes(prim["attributes"]);
        if (prim.contains("indices") && prim["indices"].is_number_integer()) f(prim["indices"]);
        if (prim.contains("targets") && prim["targets"].is_array())
          for (auto& t : prim["targets"]) visitAttributes(t);
      }
    }
  if (root.contains("skins"))
    for (auto& skin : root["skins"])
      if (skin.contains("inverseBindMatrices")) f(skin["inverseBindMatrices"]);
  if (root.contains("animations"))
    for (auto& anim : root["animations"])
      if (anim.contains("samplers"))
        for (auto& s : anim["samplers"]) {
          if (s.contains("input")) f(s["input"]);
          if (s.contains("output")) f(s["output"]);
        }
  if (root.contains("nodes"))
    for (auto& node : root["nodes"])
      if (node.contains("extensions") && node["extensions"].contains("EXT_mesh_gpu_instancing"))
        visitAttributes(node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]);
}

// Buffer view references: accessors (and their sparse parts), images, and any "bufferView" inside a
// primitive extension (KHR_draco_mesh_compression and the like).
template <class F>
void forEachViewRef(json& root, F&& f) {
  if (root.contains("accessors"))
    for (auto& a : root["accessors"]) {
      if (a.contains("bufferView")) f(a["bufferView"]);
      if (a.contains("sparse")) {
        auto& s = a["sparse"];
        if (s.contains("indices") && s["indices"].contains("bufferView")) f(s["indices"]["bufferView"]);
        if (s.contains("values") && s["values"].contains("bufferView")) f(s["values"]["bufferView"]);
      }
    }
  if (root.contains("images"))
    for (auto& i : root["images"])
      if (i.contains("bufferView")) f(i["bufferView"]);
  if (root.contains("meshes"))
    for (auto& mesh : root["meshes"])
      if (mesh.contains("primitives"))
        for (auto& prim : mesh["primitives"])
          if (prim.contains("extensions") && prim["extensions"].is_object())
            for (auto& [name, ext] : prim["extensions"].items())
              if (ext.is_object() && ext.contains("bufferView")) f(ext["bufferView"]);
}

// Texture references: every textureInfo in a material (any object with an integer "index", core and
// extension alike: baseColorTexture, normalTexture, MOZ_lightmap, KHR_materials_* ...).
template <class F>
void forEachTextureInfo(json& j, F&& f) {
  if (j.is_object()) {
    if (j.contains("index") && j["index"].is_number_integer()) f(j["index"]);
    for (auto& [k, v] : j.items())
      if (v.is_structured()) forEachTextureInfo(v, f);
  } else if (j.is_array()) {
    for (auto& v : j) forEachTextureInfo(v, f);
  }
}
template <class F>
void forEachTextureRef(json& root, F&& f) {
  if (root.contains("materials")) forEachTextureInfo(root["materials"], f);
}

// Textures may be collected only when materials are the only place that can name them: no root extension
// other than lights (KHR_lights_punctual, EXT_lights_ies; an unknown one, e.g. image-based lighting, might
// use a texture).
bool texturesOnlyInMaterials(const json& root) {
  if (!root.contains("extensions") || !root["extensions"].is_object()) return true;
  for (const auto& [name, ext] : root["extensions"].items())
    if (name != "KHR_lights_punctual" && name != "EXT_lights_ies") return false;
  return true;
}

template <class F>
void forEachSamplerRef(json& root, F&& f) {
  if (root.contains("textures"))
    for (auto& t : root["textures"])
      if (t.contains("sampler")) f(t["sampler"]);
}

// Image references: textures' source and any "source" in a texture extension (KHR_texture_basisu,
// EXT_texture_webp, ...).
template <class F>
void forEachImageRef(json& root, F&& f) {
  if (!root.contains("textures")) return;
  for (auto& t : root["textures"]) {
    if (t.contains("source")) f(t["source"]);
    if (t.contains("extensions") && t["extensions"].is_object())
      for (auto& [name, ext] : t["extensions"].items())
        if (ext.is_object() && ext.contains("source")) f(ext["source"]);
  }
}

// Keeps the elements of root[key] whose index is in `used`, renumbering the references through `visit`.
template <class Visit>
void keepUsed(json& root, const char* key, const std::vector<bool>& used, Visit&& visit) {
  if (!root.contains(key)) return;
  std::vector<int> newIndex(used.size(), -1);
  json kept = json::array();
  for (size_t i = 0; i < used.size(); ++i)
    if (used[i]) {
      newIndex[i] = static_cast<int>(kept.size());
      kept.push_back(std::move(root[key][i]));
    }
  root[key] = std::move(kept);
  visit(root, [&](json& ref) {
    int i = ref.get<int>();
    if (i >= 0 && i < static_cast<int>(newIndex.size()) && newIndex[i] >= 0) ref = newIndex[i];
  });
  if (root[key].empty()) root.erase(key);
}

template <class Visit>
std::vector<bool> usedBy(json& root, const char* key, Visit&& visit) {
  std::vector<bool> used(root.contains(key) ? root[key].size() : 0, false);
  visit(root, [&](json& ref) {
    if (!ref.is_number_integer()) return;
    int i = ref.get<int>();
    if (i >= 0 && i < static_cast<int>(used.size())) used[i] = true;
  });
  return used;
}

std::string safeFileName(std::string name) {
  for (auto& c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) c = '_';
  return name;
}

}  // namespace

AccessorBytes readAccessor(const GltfDocument& doc, int index, const std::string& file) {
  const json& accessors = arrayOrEmpty(doc.root, "accessors");
  if (index < 0 || index >= static_cast<int>(accessors.size())) throw Error(ErrorCode::InvalidData, file, "missing accessor " + std::to_string(index));
  const json& a = accessors[index];
  const std::string what = "accessor " + std::to_string(index);
  AccessorBytes out;
  out.componentType = a.value("componentType", 0);
  out.type = a.value("type", std::string());
  out.normalized = a.value("normalized", false);
  out.count = a.value("count", size_t(0));
  out.elementSize = gltfComponentSize(out.componentType) * gltfComponentCount(out.type);
  if (out.elementSize == 0) throw Error(ErrorCode::InvalidData, file, what + " has an unknown component type or type");
  out.bytes.assign(out.count * out.elementSize, 0);  // no view: zeros (glTF), sparse may fill in
  if (a.contains("bufferView")) {
    size_t length = 0, stride = 0;
    const uint8_t* base = viewBytes(doc, a["bufferView"].get<int>(), length, stride, file);
    const size_t offset = a.value("byteOffset", size_t(0));
    if (stride == 0) stride = out.elementSize;
    if (out.count > 0 && offset + (out.count - 1) * stride + out.elementSize > length)
      throw Error(ErrorCode::InvalidData, file, what + " runs past its buffer view");
    for (size_t i = 0; i < out.count; ++i) std::memcpy(out.bytes.data() + i * out.elementSize, base + offset + i * stride, out.elementSize);
  }
  if (a.contains("sparse")) {
    const json& s = a["sparse"];
    const size_t n = s.value("count", size_t(0));
    const json& si = s["indices"];
    const json& sv = s["values"];
    size_t li = 0, lv = 0, stride = 0;
    const uint8_t* ib = viewBytes(doc, si.value("bufferView", -1), li, stride, file) + si.value("byteOffset", size_t(0));
    const uint8_t* vb = viewBytes(doc, sv.value("bufferView", -1), lv, stride, file) + sv.value("byteOffset", size_t(0));
    const int indexType = si.value("componentType", 5125);
    const size_t isz = gltfComponentSize(indexType);
    if (isz == 0 || n * isz + si.value("byteOffset", size_t(0)) > li || n * out.elementSize + sv.value("byteOffset", size_t(0)) > lv)
      throw Error(ErrorCode::InvalidData, file, what + " has sparse data past its buffer view");
    for (size_t k = 0; k < n; ++k) {
      const size_t target = static_cast<size_t>(componentValue(ib + k * isz, indexType));
      if (target >= out.count) throw Error(ErrorCode::InvalidData, file, what + " has a sparse index out of range");
      std::memcpy(out.bytes.data() + target * out.elementSize, vb + k * out.elementSize, out.elementSize);
    }
  }
  return out;
}

int addGatheredAccessor(GltfDocument& doc, const AccessorBytes& src, const std::vector<uint32_t>& at, bool withMinMax) {
  const size_t stride = (src.elementSize + 3) / 4 * 4;
  std::vector<uint8_t> packed(at.size() * stride, 0);
  for (size_t i = 0; i < at.size(); ++i) std::memcpy(packed.data() + i * stride, src.bytes.data() + size_t(at[i]) * src.elementSize, src.elementSize);
  const int view = doc.addBufferView(packed.data(), packed.size(), kArrayBuffer);
  if (stride != src.elementSize) doc.root["bufferViews"][view]["byteStride"] = stride;
  json a = {{"bufferView", view}, {"componentType", src.componentType}, {"count", at.size()}, {"type", src.type}};
  if (src.normalized) a["normalized"] = true;
  if (withMinMax && !at.empty()) {
    const size_t n = gltfComponentCount(src.type), cs = gltfComponentSize(src.componentType);
    std::vector<double> lo(n, 1e300), hi(n, -1e300);
    for (size_t i = 0; i < at.size(); ++i)
      for (size_t c = 0; c < n; ++c) {
        double v = componentValue(packed.data() + i * stride + c * cs, src.componentType);
        lo[c] = std::min(lo[c], v);
        hi[c] = std::max(hi[c], v);
      }
    if (src.componentType == 5126) {  // the exact float values, as the validator compares them
      for (size_t c = 0; c < n; ++c) {
        lo[c] = static_cast<float>(lo[c]);
        hi[c] = static_cast<float>(hi[c]);
      }
    }
    a["min"] = lo;
    a["max"] = hi;
  }
  return doc.append("accessors", std::move(a));
}

void compactDocument(GltfDocument& doc) {
  json& root = doc.root;
  auto nodeMeshRefs = [](json& r, auto&& f) {
    if (r.contains("nodes"))
      for (auto& n : r["nodes"])
        if (n.contains("mesh")) f(n["mesh"]);
  };
  keepUsed(root, "meshes", usedBy(root, "meshes", nodeMeshRefs), nodeMeshRefs);
  auto accessorRefs = [](json& r, auto&& f) { forEachAccessorRef(r, f); };
  keepUsed(root, "accessors", usedBy(root, "accessors", accessorRefs), accessorRefs);
  if (texturesOnlyInMaterials(root)) {
    auto textureRefs = [](json& r, auto&& f) { forEachTextureRef(r, f); };
    keepUsed(root, "textures", usedBy(root, "textures", textureRefs), textureRefs);
    auto samplerRefs = [](json& r, auto&& f) { forEachSamplerRef(r, f); };
    keepUsed(root, "samplers", usedBy(root, "samplers", samplerRefs), samplerRefs);
  }
  auto imageRefs = [](json& r, auto&& f) { forEachImageRef(r, f); };
  keepUsed(root, "images", usedBy(root, "images", imageRefs), imageRefs);
  compactBufferViews(doc);
}

void compactBufferViews(GltfDocument& doc) {
  json& root = doc.root;
  // Buffer views: keep the used ones, their bytes packed in view order (4-byte aligned) into buffer 0.
  auto viewRefs = [](json& r, auto&& f) { forEachViewRef(r, f); };
  std::vector<bool> usedViews = usedBy(root, "bufferViews", viewRefs);
  struct Move {
    size_t from, to, length;
    bool inside;  // the source range lies inside buffer 0 (else the view reads as zeros)
  };
  std::vector<Move> moves;
  size_t size = 0;
  bool inPlace = true;  // every view moves towards the front: compact within buffer 0 itself
  if (root.contains("bufferViews"))
    for (size_t i = 0; i < usedViews.size(); ++i) {
      if (!usedViews[i]) continue;
      json& v = root["bufferViews"][i];
      const size_t offset = v.value("byteOffset", size_t(0)), length = v.value("byteLength", size_t(0));
      size = (size + 3) / 4 * 4;
      const bool inside = offset + length <= doc.bin.size();
      moves.push_back({offset, size, length, inside});
      if ((inside && size > offset) || size + length > doc.bin.size()) inPlace = false;
      v["byteOffset"] = size;
      v["buffer"] = 0;
      if (v["byteOffset"] == 0) v.erase("byteOffset");
      size += length;
    }
  keepUsed(root, "bufferViews", usedViews, viewRefs);
  // Writes for views before k end at or before moves[k].to ≤ moves[k].from, so packing in view order
  // never overwrites bytes a later view still has to read. In place, buffer 0 is not held twice (the
  // source's buffers plus the new geometry are the export's peak).
  std::vector<uint8_t> fresh;
  if (!inPlace) fresh.resize(size);
  uint8_t* out = inPlace ? doc.bin.data() : fresh.data();
  size_t end = 0;
  for (const Move& m : moves) {
    std::fill(out + end, out + m.to, uint8_t(0));  // alignment padding
    if (m.inside) std::memmove(out + m.to, doc.bin.data() + m.from, m.length);
    else std::fill(out + m.to, out + m.to + m.length, uint8_t(0));
    end = m.to + m.length;
  }
  if (inPlace) doc.bin.resize(size);
  else doc.bin = std::move(fresh);
}

std::vector<std::pair<std::string, std::vector<uint8_t>>> externalizeImages(GltfDocument& doc, const std::vector<std::string>& taken) {
  std::vector<std::pair<std::string, std::vector<uint8_t>>> files;
  if (!doc.root.contains("images")) return files;
  // Names compare case-insensitively (names differing only in case collide on case-insensitive file
  // systems); sets keep the check cheap when a scene has thousands of images.
  auto lower = [](std::string n) {
    for (auto& c : n) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return n;
  };
  std::set<std::string> takenLower;
  for (const auto& t : taken) takenLower.insert(lower(t));
  auto isTaken = [&](const std::string& n) { return takenLower.count(lower(n)) > 0; };
  // First suffix still worth trying per stem and extension: names are only ever added, so the first free
  // suffix never goes down, and many images sharing one stem do not retry every earlier suffix.
  std::map<std::string, int> nextSuffix;
  for (size_t i = 0; i < doc.root["images"].size(); ++i) {
    json& image = doc.root["images"][i];
    if (!image.contains("bufferView")) continue;
    size_t length = 0, stride = 0;
    const uint8_t* bytes = viewBytes(doc, image["bufferView"].get<int>(), length, stride, "image " + std::to_string(i));
    std::vector<uint8_t> data(bytes, bytes + length);
    const ImageFormat format = sniffImageFormat(data.data(), data.size());
    const std::string ext = format == ImageFormat::Png ? ".png" : format == ImageFormat::Jpeg ? ".jpg" : format == ImageFormat::Webp ? ".webp" : ".bin";
    std::string stem;
    if (image.contains(kSourceUriKey) && image[kSourceUriKey].is_string()) {
      const std::string uri = image[kSourceUriKey].get<std::string>();
      if (uri.rfind("data:", 0) != 0) stem = safeFileName(std::filesystem::path(decodeUriEscapes(uri)).stem().string());
      image.erase(kSourceUriKey);
    }
    if (stem.empty()) stem = safeFileName(image.value("name", std::string()));
    if (stem.size() > 4 && (stem.substr(stem.size() - 4) == ".png" || stem.substr(stem.size() - 4) == ".jpg")) stem.resize(stem.size() - 4);
    if (stem.empty() || stem[0] == '.') stem = "image" + std::to_string(i);
    std::string name = stem + ext;
    if (isTaken(name)) {
      int& k = nextSuffix.try_emplace(lower(stem) + '/' + ext, 1).first->second;
      for (name = stem + "_" + std::to_string(k) + ext; isTaken(name); name = stem + "_" + std::to_string(++k) + ext) {}
    }
    takenLower.insert(lower(name));
    image.erase("bufferView");
    image["uri"] = name;
    files.emplace_back(name, std::move(data));
  }
  return files;
}

}  // namespace irbake
