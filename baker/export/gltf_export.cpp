// glTF/GLB export with light maps. Two sources of the document:
//  - the scene came from a glTF (Scene::sourcePath): the source document is written back with only the
//    light-map data added. Nodes, names, transforms, cameras, lights, materials and unknown extensions
//    stay as they were; each baked mesh primitive is rewritten in its local space over the vertex set
//    the atlas made (every source attribute and morph target gathered through Primitive::sourceVertex,
//    TEXCOORD_1 added, one glTF primitive per light-map page). A mesh used by several nodes keeps its
//    index for the first node; every further node gets a copy of the mesh with its own light-map
//    region; each EXT_mesh_gpu_instancing instance becomes a child node of its own the same way (the
//    extension cannot carry a light map per instance). Materials get MOZ_lightmap in place (a copy per further
//    page); specular-glossiness materials become metal-rough (spec_gloss_conversion.h). Whatever nothing references
//    any more (the replaced accessors, their views) is dropped and buffer 0 rebuilt (gltf_compact.h).
//  - a generated scene: written by our writer from a copy whose materials carry the light maps.
// A .glb embeds every image; a .gltf gets its .bin and the images as files beside it. Every file is
// written to a temp name and renamed only when all succeeded (common/atomic_file.h).
#include "export/gltf_export.h"
#include "common/maths.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <set>

#include <glm/gtc/type_ptr.hpp>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/file_paths.h"
#include "common/log.h"
#include "export/gltf_compact.h"
#include "export/directional_export.h"
#include "export/light_layers.h"
#include "export/light_probes_export.h"
#include "export/map_encoding.h"
#include "export/spec_gloss_conversion.h"
#include "export/gltf_writer.h"
#include "scene/gltf_decompress.h"
#include "scene/gltf_source.h"
#include "scene/image_codec.h"
#include "scene/moz_lightmap_units.h"

namespace irbake {

using json = nlohmann::json;

namespace {

void checkMaps(const std::vector<Lightmap>& maps, const std::string& file) {
  for (const auto& m : maps) {
    if (m.width <= 0 || m.height <= 0 || m.texels.size() != m.size())
      throw Error(ErrorCode::InvalidData, file, "light map page " + std::to_string(m.page) + " has no texels or a size mismatch");
    for (const auto& t : m.texels)
      if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z))
        throw Error(ErrorCode::NumericError, file, "light map page " + std::to_string(m.page) + " holds NaN/Inf");
  }
}

std::vector<uint8_t> readWholeFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Bytes behind a buffer or image URI of the source (data URI or file beside it; URIs were checked).
std::vector<uint8_t> uriBytes(const GltfSource& src, const std::string& uri) {
  if (uri.rfind("data:", 0) == 0) return decodeDataUri(uri);
  return readWholeFile(src.folder / decodeUriEscapes(uri));
}

std::string mimeFor(const std::vector<uint8_t>& bytes, const std::string& fallback) {
  switch (sniffImageFormat(bytes.data(), bytes.size())) {
    case ImageFormat::Png: return "image/png";
    case ImageFormat::Jpeg: return "image/jpeg";
    case ImageFormat::Webp: return "image/webp";
    default: return fallback.empty() ? "application/octet-stream" : fallback;
  }
}

// Reads `length` bytes of a buffer file straight into bin[offset, offset + length): a big .bin is
// never held twice (a whole-file vector read by stream iterators grew by doubling, 2× at its peak).
// False when the file is missing or shorter.
bool readFileInto(const std::filesystem::path& path, std::vector<uint8_t>& bin, size_t offset, size_t length) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  bin.resize(offset + length);
  return length == 0 || static_cast<bool>(in.read(reinterpret_cast<char*>(bin.data() + offset), static_cast<std::streamsize>(length)));
}

}  // namespace

// (gltf_export.h) Reserved pages it does not use are never touched, so cost no memory.
GltfDocument documentFromSource(const std::filesystem::path& sourcePath, size_t extraBytes) {
  GltfSource src = decompressGltf(readGltfSource(sourcePath));
  json root = std::move(src.json);
  std::vector<uint8_t> bin;
  std::vector<size_t> offsets;
  if (root.contains("buffers")) {
    size_t total = extraBytes;
    for (const json& b : root["buffers"]) total += b.value("byteLength", size_t(0)) + 16;
    bin.reserve(total);
    for (size_t i = 0; i < root["buffers"].size(); ++i) {
      const json& b = root["buffers"][i];
      const size_t length = b.value("byteLength", size_t(0));
      while (bin.size() % 16) bin.push_back(0);  // keeps every accessor's alignment
      const size_t offset = bin.size();
      offsets.push_back(offset);
      bool complete = false;
      if (b.contains("uri") && b["uri"].get<std::string>().rfind("data:", 0) != 0) {
        complete = readFileInto(src.folder / decodeUriEscapes(b["uri"].get<std::string>()), bin, offset, length);
      } else {
        const uint8_t* data = nullptr;
        size_t size = 0;
        std::vector<uint8_t> decoded;
        if (b.contains("uri")) {
          decoded = decodeDataUri(b["uri"].get<std::string>());
          data = decoded.data();
          size = decoded.size();
        } else if (src.binary && i == 0) {
          data = src.bytes.data() + src.binOffset;
          size = src.binSize;
        }
        complete = size >= length;
        if (complete) bin.insert(bin.end(), data, data + length);
      }
      if (!complete)
        throw Error(ErrorCode::Io, sourcePath.string(), "cannot re-read buffer " + std::to_string(i) + " of the source scene");
    }
  }
  std::vector<uint8_t>().swap(src.bytes);  // a GLB's whole file: its BIN chunk is in bin now
  if (root.contains("bufferViews"))
    for (auto& v : root["bufferViews"]) {
      size_t b = v.value("buffer", 0);
      if (b >= offsets.size()) throw Error(ErrorCode::InvalidData, sourcePath.string(), "buffer view references a missing buffer");
      v["byteOffset"] = v.value("byteOffset", size_t(0)) + offsets[b];
      v["buffer"] = 0;
    }
  root["buffers"] = json::array({json::object({{"byteLength", bin.size()}})});
  GltfDocument doc(std::move(root), std::move(bin));
  if (doc.root.contains("images"))
    for (auto& image : doc.root["images"]) {
      if (!image.contains("uri")) continue;
      std::vector<uint8_t> bytes = uriBytes(src, image["uri"].get<std::string>());
      if (bytes.empty()) continue;  // unreadable (the loader warned): leave the reference as it was
      std::string mime = mimeFor(bytes, image.value("mimeType", std::string()));
      int view = doc.addBufferView(bytes.data(), bytes.size());
      image[kSourceUriKey] = image["uri"];  // a folder output writes it back under this name
      image.erase("uri");
      image["bufferView"] = view;
      image["mimeType"] = mime;
    }
  return doc;
}

namespace {

// The encoding of the MOZ_lightmap image (the float pages beside it are MapEncodingKind::Exr).
constexpr MapEncodingKind kLightmapImageEncoding = MapEncodingKind::Png8;

std::string pageUri(const ExportOptions& options, int page) { return options.exrPrefix + "_" + std::to_string(page) + ".exr"; }

// The light-map record of one output primitive (extras.lightmap), kept beside the source extras.
// source: the scene primitive it is a part of, [node, mesh, primitive, GPU instance] of the source document (a
// later bake onto this atlas matches its primitives by it, docs/export.md "irbakeAtlas").
void setLightmapRecord(json& prim, const Primitive& part) {
  const LightmapRef& ref = part.lightmap;
  if (ref.page < 0) return;
  if (!prim.contains("extras") || !prim["extras"].is_object()) prim["extras"] = json::object();
  prim["extras"]["lightmap"] = {{"page", ref.page}, {"width", ref.width}, {"height", ref.height},
                                {"source", {part.node, part.gltfMesh, part.gltfPrimitive, part.instance}}};
}

// A probe-lit object (extras.irbake.mode "probes"): its primitives say so, for the clients (docs/export.md,
// "Probe-lit objects"); a source primitive's extras of another type are left alone.
void setProbeLitRecord(json& prim, const Primitive& part) {
  if (part.mode != ObjectMode::Probes) return;
  if (!prim.contains("extras")) prim["extras"] = json::object();
  if (prim["extras"].is_object()) prim["extras"]["lightProbes"] = true;
}

// MOZ_lightmap of one page as its specification defines it: the texture, TEXCOORD_1 written explicitly, and
// the intensity that makes intensity × sRGBToLinear(texel) the irradiance E (mozLightmapIntensity); the extras say
// the PNG is sRGB-encoded and carry the units marker that tells these files from an older irbake's (scene/moz_lightmap_units.h, docs/export.md).
json mozLightmap(int texture, const EncodedMap& image) {
  json moz = {{"index", texture}, {"texCoord", 1}, {"intensity", mozLightmapIntensity(image)}};
  if (image.metadata.srgb) moz["extras"]["colorSpace"] = "srgb";
  moz["extras"][kMozLightmapMarkerKey] = mozLightmapMarker();
  return moz;
}

// A material that carries MOZ_lightmap drops its occlusionTexture: the bake's own occlusion is in the map,
// and the specification applies occlusionTexture to the light map, which would darken it twice.
void dropOcclusionUnderLightmap(json& material) { material.erase("occlusionTexture"); }

// True when a material's texture (core or extension) reads TEXCOORD_1.
bool readsTexcoord1(const json& j) {
  if (j.is_object()) {
    if (j.contains("texCoord") && j["texCoord"] == 1) return true;
    for (const auto& [k, v] : j.items())
      if (v.is_structured() && readsTexcoord1(v)) return true;
  } else if (j.is_array()) {
    for (const auto& v : j)
      if (readsTexcoord1(v)) return true;
  }
  return false;
}

// About what SourceExport appends to buffer 0: per vertex the gathered source attributes (96 bytes
// covers position, normal, tangent, two UV sets and a colour) and TEXCOORD_1, per corner an index,
// and the light-map PNGs. Only a reservation: more just grows the buffer.
size_t appendedBytes(const Scene& scene, const std::vector<EncodedMap>& images) {
  size_t bytes = 0;
  for (const Primitive& p : scene.primitives) bytes += p.positions.size() * (96 + 8) + p.indices.size() * 4 + 64;
  for (const EncodedMap& image : images) bytes += image.bytes.size() + 4;
  return bytes;
}

// The source document with only the light-map data added (see the file comment).
class SourceExport {
 public:
  SourceExport(const Scene& scene, const std::vector<Lightmap>& maps, const std::vector<EncodedMap>& images, const std::string& file)
      : scene_(scene), images_(images), file_(file), doc_(documentFromSource(scene.sourcePath, appendedBytes(scene, images))) {
    for (size_t i = 0; i < maps.size(); ++i) imageOfPage_[maps[i].page] = i;
    sourceMaterials_ = doc_.root.value("materials", json::array());
    sourceMeshes_ = doc_.root.value("meshes", json::array());
  }

  GltfDocument run() {
    // Scene primitives grouped per (node, GPU instance) and source primitive, in scene order; the atlas
    // may have split one source primitive into one part per page.
    using Instance = std::pair<int, int>;  // (node, EXT_mesh_gpu_instancing instance or -1)
    std::map<Instance, std::map<int, std::vector<const Primitive*>>> partsOf;
    std::vector<Instance> order;
    for (const auto& p : scene_.primitives) {
      if (p.node < 0 || p.gltfMesh < 0 || p.gltfPrimitive < 0) continue;
      const Instance key(p.node, p.instance);
      if (!partsOf.count(key)) order.push_back(key);
      partsOf[key][p.gltfPrimitive].push_back(&p);
    }
    std::set<int> meshesTaken;  // source meshes already rewritten for their first instance
    for (const Instance& key : order) {
      const auto& parts = partsOf[key];
      const Primitive& any = *parts.begin()->second.front();
      const int node = key.first, mesh = any.gltfMesh;
      if (node >= static_cast<int>(doc_.root["nodes"].size()) || mesh >= static_cast<int>(sourceMeshes_.size())) continue;
      json rewritten = rewriteMesh(mesh, parts);
      // Instancing rule: the first node keeps the mesh index; every further instance gets its own
      // copy of the mesh (its own light-map region, TEXCOORD_1 and split vertices).
      int index = mesh;
      if (meshesTaken.insert(mesh).second) doc_.root["meshes"][mesh] = std::move(rewritten);
      else index = doc_.append("meshes", std::move(rewritten));
      if (key.second >= 0) expandGpuInstance(node, key.second, index, any.instanceToNode);
      else if (index != mesh) doc_.root["nodes"][node]["mesh"] = index;
    }
    finishGpuInstancing();
    if (!images_.empty()) doc_.useExtension("MOZ_lightmap");
    repairEmissiveFactors();
    convertSpecularGlossiness(doc_, file_);  // before compaction: a replaced fallback texture may go unused
    compactDocument(doc_);
    const std::string generator = doc_.root["asset"].value("generator", std::string("unknown"));
    if (generator.rfind("irbake", 0) != 0) doc_.root["asset"]["generator"] = "irbake (from " + generator + ")";
    return std::move(doc_);
  }

 private:
  json rewriteMesh(int mesh, const std::map<int, std::vector<const Primitive*>>& parts) {
    json out = sourceMeshes_[mesh];
    const json sourcePrims = out.value("primitives", json::array());
    json prims = json::array();
    for (int pi = 0; pi < static_cast<int>(sourcePrims.size()); ++pi) {
      auto it = parts.find(pi);
      if (it == parts.end()) {  // not baked (points, lines, all degenerate): kept as it was
        prims.push_back(sourcePrims[pi]);
        continue;
      }
      for (const Primitive* part : it->second) prims.push_back(rewritePrimitive(sourcePrims[pi], *part));
    }
    out["primitives"] = std::move(prims);
    return out;
  }

  // The source primitive over the part's vertex set: every source attribute (and morph target)
  // gathered through sourceVertex, TEXCOORD_1 = the atlas UVs, the part's triangles, its material.
  json rewritePrimitive(const json& source, const Primitive& part) {
    const size_t n = part.positions.size();
    std::vector<uint32_t> at = part.sourceVertex;
    if (at.empty()) {
      at.resize(n);
      for (size_t i = 0; i < n; ++i) at[i] = static_cast<uint32_t>(i);
    }
    if (at.size() != n) throw Error(ErrorCode::InvalidData, file_, "primitive " + part.name + " lost track of its source vertices");
    json prim = source;
    auto gather = [&](const json& attributes, bool isTarget) {
      json outAttrs = json::object();
      for (const auto& [name, index] : attributes.items()) {
        if (name == "TEXCOORD_1" && !isTarget) continue;  // replaced by the light-map UVs
        if (!index.is_number_integer()) continue;
        const AccessorBytes bytes = accessorBytes(index.get<int>());
        for (uint32_t v : at)
          if (v >= bytes.count)
            throw Error(ErrorCode::InvalidData, file_, "mesh " + std::to_string(part.gltfMesh) + " attribute " + name + " is shorter than POSITION");
        outAttrs[name] = addGatheredAccessor(doc_, bytes, at, name == "POSITION" || isTarget);
      }
      return outAttrs;
    };
    if (!warnedTexcoord1_ && source.contains("material") && source["material"].is_number_integer() &&
        source["material"].get<int>() < static_cast<int>(sourceMaterials_.size())) {
      json mat = sourceMaterials_[source["material"].get<int>()];
      if (mat.contains("extensions") && mat["extensions"].is_object()) mat["extensions"].erase("MOZ_lightmap");
      if (readsTexcoord1(mat)) {
        warnedTexcoord1_ = true;
        log::warn(file_ + ": a material reads textures with TEXCOORD_1, which the export replaces by the light-map UVs");
      }
    }
    prim["attributes"] = gather(source.value("attributes", json::object()), false);
    if (part.uv1.size() == n) {
      const int uv1 = doc_.addVec2(part.uv1);
      prim["attributes"]["TEXCOORD_1"] = uv1;
      // glTF numbers TEXCOORD sets from 0 without gaps: a primitive without TEXCOORD_0 shares the
      // light-map UVs as its set 0 (MOZ_lightmap keeps texCoord 1 for every primitive).
      if (!prim["attributes"].contains("TEXCOORD_0")) prim["attributes"]["TEXCOORD_0"] = uv1;
    }
    if (source.contains("targets") && source["targets"].is_array()) {
      json targets = json::array();
      for (const auto& t : source["targets"]) targets.push_back(gather(t, true));
      prim["targets"] = std::move(targets);
    }
    // The loader swapped two corners under a mirroring node (world space is counter-clockwise);
    // in the node's local space the source winding comes back.
    std::vector<uint32_t> indices = part.indices;
    if (glm::determinant(glm::mat3(part.nodeToWorld)) < 0.0f)
      for (size_t t = 0; t + 2 < indices.size(); t += 3) std::swap(indices[t + 1], indices[t + 2]);
    prim["indices"] = doc_.addIndices(indices);
    prim["mode"] = 4;  // strips and fans arrive as triangle lists
    const int material = outputMaterial(part);
    if (material >= 0) prim["material"] = material;
    else prim.erase("material");
    setLightmapRecord(prim, part);
    setProbeLitRecord(prim, part);
    return prim;
  }

  // EXT_mesh_gpu_instancing: each instance is written as a child node of the instanced node, with the
  // instance's transform and a mesh of its own (the light map is per instance, which the extension cannot
  // carry); the node keeps everything else and loses its mesh and the extension.
  void expandGpuInstance(int node, int instance, int mesh, const glm::mat4& instanceToNode) {
    json child = json::object();
    const std::string name = doc_.root["nodes"][node].value("name", std::string("node") + std::to_string(node));
    child["name"] = name + "_instance" + std::to_string(instance);
    child["mesh"] = mesh;
    if (instanceToNode != glm::mat4(1.0f)) {
      json matrix = json::array();
      for (int i = 0; i < 16; ++i) matrix.push_back(glm::value_ptr(instanceToNode)[i]);  // both column-major
      child["matrix"] = std::move(matrix);
    }
    const int index = doc_.append("nodes", std::move(child));
    json& parent = doc_.root["nodes"][node];
    if (!parent.contains("children") || !parent["children"].is_array()) parent["children"] = json::array();
    parent["children"].push_back(index);
    parent.erase("mesh");
    if (parent.contains("extensions") && parent["extensions"].is_object()) {
      parent["extensions"].erase("EXT_mesh_gpu_instancing");
      if (parent["extensions"].empty()) parent.erase("extensions");
    }
    expandedNodes_.insert(node);
    ++expandedInstances_;
  }

  // Once no node carries EXT_mesh_gpu_instancing any more, the document no longer uses or requires it.
  void finishGpuInstancing() {
    if (expandedNodes_.empty()) return;
    for (const json& n : doc_.root["nodes"])
      if (n.contains("extensions") && n["extensions"].is_object() && n["extensions"].contains("EXT_mesh_gpu_instancing")) return;
    unlistExtension(doc_.root, "EXT_mesh_gpu_instancing");
    log::warn(file_ + ": EXT_mesh_gpu_instancing: " + std::to_string(expandedNodes_.size()) + " instanced node(s) written as " +
              std::to_string(expandedInstances_) + " nodes, one per instance, each with its own light-map region; the extension is dropped");
  }

  // glTF keeps emissiveFactor in [0, 1]; a source above that (the loader took it as factor × strength)
  // is written as factor / peak with KHR_materials_emissive_strength × peak: the same emission, valid.
  void repairEmissiveFactors() {
    if (!doc_.root.contains("materials")) return;
    for (auto& mat : doc_.root["materials"]) {
      if (!mat.contains("emissiveFactor") || !mat["emissiveFactor"].is_array() || mat["emissiveFactor"].size() != 3) continue;
      double peak = 0.0;
      for (const auto& c : mat["emissiveFactor"])
        if (c.is_number()) peak = std::max(peak, c.get<double>());
      if (!(peak > 1.0)) continue;
      for (auto& c : mat["emissiveFactor"])
        if (c.is_number()) c = c.get<double>() / peak;
      if (!mat.contains("extensions") || !mat["extensions"].is_object()) mat["extensions"] = json::object();
      json& ext = mat["extensions"]["KHR_materials_emissive_strength"];
      const double strength = ext.is_object() && ext.contains("emissiveStrength") ? ext["emissiveStrength"].get<double>() : 1.0;
      ext = {{"emissiveStrength", strength * peak}};
      doc_.useExtension("KHR_materials_emissive_strength");
      if (!warnedEmissive_) {
        warnedEmissive_ = true;
        log::warn(file_ + ": emissiveFactor above 1 written as KHR_materials_emissive_strength (glTF keeps the factor in [0, 1])");
      }
    }
  }

  const AccessorBytes& accessorBytes(int index) {
    auto it = accessorCache_.find(index);
    if (it != accessorCache_.end()) return it->second;
    return accessorCache_.emplace(index, readAccessor(doc_, index, file_)).first->second;
  }

  int pageWithMap(const Primitive& p) const { return imageOfPage_.count(p.lightmap.page) ? p.lightmap.page : -1; }

  // Material of a part: its source material with MOZ_lightmap for the part's page. The first page a
  // source material meets is written into it in place (same index, same name); further pages get a
  // copy named <name>_lightmap<page>.
  int outputMaterial(const Primitive& part) {
    const Material& m = scene_.materials.at(part.material);
    const int source = (m.gltfMaterial >= 0 && m.gltfMaterial < static_cast<int>(sourceMaterials_.size())) ? m.gltfMaterial : -1;
    const int page = pageWithMap(part);
    auto key = std::make_pair(source, page);
    auto it = materialFor_.find(key);
    if (it != materialFor_.end()) return it->second;
    if (source < 0 && page < 0) return materialFor_[key] = -1;
    json mat = source >= 0 ? sourceMaterials_[source] : json::object({{"name", "default"}});
    if (page >= 0) {
      if (!mat.contains("extensions") || !mat["extensions"].is_object()) mat["extensions"] = json::object();
      mat["extensions"]["MOZ_lightmap"] = mozLightmap(lightmapTexture(page), images_[imageOfPage_.at(page)]);
      dropOcclusionUnderLightmap(mat);
    }
    int index;
    if (source >= 0 && sourceMaterialsTaken_.insert(source).second) {
      index = source;
      doc_.root["materials"][source] = std::move(mat);
    } else {
      if (page >= 0 && mat.contains("name")) mat["name"] = mat["name"].get<std::string>() + "_lightmap" + std::to_string(page);
      index = doc_.append("materials", std::move(mat));
    }
    return materialFor_[key] = index;
  }

  int lightmapTexture(int page) {
    auto it = pageTexture_.find(page);
    if (it != pageTexture_.end()) return it->second;
    const EncodedMap& encoded = images_[imageOfPage_.at(page)];
    const int image = doc_.addImage(encoded.bytes, encoded.stored.name, mapEncoding(kLightmapImageEncoding).mimeType());
    const int tex = doc_.addTexture(image, doc_.addSampler(WrapMode::ClampToEdge, WrapMode::ClampToEdge, true));
    return pageTexture_[page] = tex;
  }

  const Scene& scene_;
  const std::vector<EncodedMap>& images_;
  const std::string file_;
  GltfDocument doc_;
  json sourceMaterials_, sourceMeshes_;
  std::map<int, size_t> imageOfPage_;
  std::map<int, AccessorBytes> accessorCache_;
  std::map<std::pair<int, int>, int> materialFor_;
  std::set<int> sourceMaterialsTaken_;
  std::map<int, int> pageTexture_;
  bool warnedTexcoord1_ = false;
  bool warnedEmissive_ = false;
  std::set<int> expandedNodes_;   // nodes whose EXT_mesh_gpu_instancing became child nodes
  size_t expandedInstances_ = 0;
};

// Generated scene (no source document): our writer from a copy whose materials carry the light maps.
GltfDocument documentFromScene(const Scene& scene, const std::vector<Lightmap>& maps, const std::vector<EncodedMap>& images,
                               const std::vector<std::string>& pageUris) {
  std::map<int, size_t> imageOfPage;
  for (size_t i = 0; i < maps.size(); ++i) imageOfPage[maps[i].page] = i;
  Scene copy = scene;
  copy.materials.clear();
  std::map<std::pair<int, int>, int> materialFor;
  std::map<int, int> pageTexture;
  for (auto& prim : copy.primitives) {
    const int page = imageOfPage.count(prim.lightmap.page) ? prim.lightmap.page : -1;
    auto key = std::make_pair(prim.material, page);
    if (!materialFor.count(key)) {
      Material m = scene.materials.at(prim.material);
      m.lightmapTexture = -1;
      if (page >= 0) {
        if (!pageTexture.count(page)) {
          pageTexture[page] = static_cast<int>(copy.textures.size());
          copy.textures.push_back(images[imageOfPage.at(page)].stored);
        }
        m.lightmapTexture = pageTexture[page];
        m.lightmapIntensity = images[imageOfPage.at(page)].metadata.intensity;
        m.name += "_lightmap" + std::to_string(page);
      }
      materialFor[key] = static_cast<int>(copy.materials.size());
      copy.materials.push_back(m);
    }
    prim.material = materialFor[key];
  }
  GltfWriteOptions wo;
  wo.lightmapPages = pageUris;
  GltfDocument doc = gltfFromScene(copy, wo);
  // gltfFromScene encodes light-map textures linearly: put the sRGB-encoded PNGs and their marker in.
  // Each page's PNG goes into buffer 0 once (not once per material), at the last material on that page,
  // which fixes the order the pages' PNGs are packed in.
  if (doc.root.contains("materials")) {
    std::map<int, int> pageOfTexture;
    for (const auto& [page, t] : pageTexture) pageOfTexture[t] = page;
    std::map<int, size_t> lastMaterialOfTexture;
    for (size_t i = 0; i < copy.materials.size(); ++i)
      if (copy.materials[i].lightmapTexture >= 0) lastMaterialOfTexture[copy.materials[i].lightmapTexture] = i;
    for (size_t i = 0; i < copy.materials.size(); ++i) {
      const Material& m = copy.materials[i];
      if (m.lightmapTexture < 0) continue;
      json& moz = doc.root["materials"][i]["extensions"]["MOZ_lightmap"];
      const int tex = moz["index"].get<int>();
      const EncodedMap& encoded = images[imageOfPage.at(pageOfTexture.at(m.lightmapTexture))];
      if (lastMaterialOfTexture.at(m.lightmapTexture) == i) {
        const int image = doc.root["textures"][tex]["source"].get<int>();
        doc.root["images"][image]["bufferView"] = doc.addBufferView(encoded.bytes.data(), encoded.bytes.size());
      }
      moz = mozLightmap(tex, encoded);
    }
  }
  compactDocument(doc);
  return doc;
}

}  // namespace

bool namesGltfFile(const std::filesystem::path& output) {
  return hasExtension(output, ".glb") || hasExtension(output, ".gltf");
}

std::filesystem::path outputFolderOf(const std::filesystem::path& output) {
  if (!namesGltfFile(output)) return output;
  return folderOf(output);
}

void exportGltf(const Scene& scene, const std::vector<Lightmap>& maps, const ExportOptions& options) {
  const std::string file = options.output.string();
  if (options.output.empty()) throw Error(ErrorCode::Usage, "", "export needs an output path");
  checkMaps(maps, file);
  const MapEncoding& encoding = mapEncoding(kLightmapImageEncoding);
  std::vector<EncodedMap> images;
  for (const auto& m : maps) images.push_back(encoding.encode(m, options.lightmapEncoding));
  std::vector<std::string> pageUris;
  if (options.writeExrPages)
    for (const auto& m : maps) pageUris.push_back(pageUri(options, m.page));

  const bool fromSource = !scene.sourcePath.empty() && std::filesystem::exists(scene.sourcePath);
  GltfDocument doc = fromSource ? SourceExport(scene, maps, images, file).run() : documentFromScene(scene, maps, images, pageUris);
  removeLightScenariosExtension(doc.root);  // a source's layers go: this bake writes its own, or none
  // glTF allows extras of any type: a source's non-object root extras is kept as it is, without our records.
  const bool rootExtrasIsObject = !doc.root.contains("extras") || doc.root["extras"].is_object();
  if (!rootExtrasIsObject && ((fromSource && !pageUris.empty()) || scene.environment.present()))
    log::warn(file + ": the source's root extras is a " + std::string(doc.root["extras"].type_name()) +
              ", not an object: kept, so the export does not record its EXR pages or sky there");
  if (rootExtrasIsObject && fromSource && !pageUris.empty()) doc.root["extras"]["lightmapPages"] = pageUris;
  // The sky the bake used, for viewers (irview draws it behind the scene) and for a bake of this export.
  if (rootExtrasIsObject && scene.environment.present()) doc.root["extras"]["irbakeSky"] = skyJson(scene.environment);
  // The atlas, for a later bake onto it (--atlas-from); only where the parts name their source document's primitives.
  if (rootExtrasIsObject && fromSource && !options.atlasRecord.is_null()) doc.root["extras"]["irbakeAtlas"] = options.atlasRecord;
  const bool directional = options.directional && !(*options.directional)[0].empty();
  if (directional) {
    for (const auto& axis : *options.directional) checkMaps(axis, file);
    addDirectionalExtension(doc, *options.directional, options.writeExrPages ? options.exrPrefix : std::string());
    if (options.writeExrPages)
      for (const auto& m : maps)
        for (int k = 0; k < 3; ++k) pageUris.push_back(directionalPageUri(options.exrPrefix, m.page, k));
  }
  if (options.lightModes) recordLightModes(doc, scene, *options.lightModes);
  const bool masked = options.shadowMask && !options.shadowMask->empty();
  if (masked) {
    addShadowMaskExtension(doc, *options.shadowMask, options.writeExrPages ? options.exrPrefix : std::string());
    if (options.writeExrPages)
      for (const Lightmap& m : *options.shadowMask->rgb) pageUris.push_back(shadowMaskPageUri(options.exrPrefix, m.page));
  }

  const bool layered = options.layers && !options.layers->empty();
  if (layered) {
    addLightScenariosExtension(doc, *options.layers, options.lightmapEncoding, options.writeExrPages ? options.exrPrefix : std::string());
    if (options.writeExrPages)
      for (const LightLayer& layer : *options.layers)
        for (const Lightmap& m : layer.maps) pageUris.push_back(layerPageUri(options.exrPrefix, m.page, layer.name));
  }

  std::vector<PendingFile> files;
  const std::filesystem::path folder = options.output.parent_path();
  if (!hasExtension(options.output, ".glb")) {
    // A folder output: images as files beside the .gltf (a GLB keeps them embedded).
    std::vector<std::string> taken = {options.output.filename().string(), options.output.stem().string() + ".bin"};
    taken.insert(taken.end(), pageUris.begin(), pageUris.end());
    for (const auto& input : options.inputs)
      if (sameFile(folderOf(input), folderOf(options.output)))
        taken.push_back(input.filename().string());
    auto images = externalizeImages(doc, taken);
    compactDocument(doc);
    for (auto& [name, bytes] : images) files.push_back(pendingBytes(folder / name, std::move(bytes)));
  }
  if (doc.root.contains("images"))
    for (auto& image : doc.root["images"]) image.erase(kSourceUriKey);
  // After the last compaction, which knows nothing of the probes' accessors; a source's own probes go.
  removeLightProbesExtension(doc.root);
  if (options.probes && options.probes->size() > 0) addLightProbesExtension(doc, *options.probes);
  if (layered && options.probes) addLightScenarioProbes(doc, *options.layers, *options.probes);
  std::vector<PendingFile> docFiles = doc.files(options.output);
  files.insert(files.begin(), docFiles.begin(), docFiles.end());
  if (options.writeExrPages) {
    const MapEncoding* exr = &mapEncoding(MapEncodingKind::Exr);
    for (size_t i = 0; i < maps.size(); ++i) {
      const Lightmap* map = &maps[i];
      const std::filesystem::path finalPath = folder / pageUris[i];
      files.push_back({finalPath, [exr, map, finalPath](const std::filesystem::path& temp) { exr->writeFile(*map, {}, temp, finalPath); }});
    }
    if (directional)
      for (int k = 0; k < 3; ++k)
        for (const Lightmap& m : (*options.directional)[k]) {
          const Lightmap* map = &m;
          const std::filesystem::path finalPath = folder / directionalPageUri(options.exrPrefix, m.page, k);
          files.push_back({finalPath, [exr, map, finalPath](const std::filesystem::path& temp) { exr->writeFile(*map, {}, temp, finalPath); }});
        }
    for (size_t l = 0; layered && l < options.layers->size(); ++l)
      for (const Lightmap& m : (*options.layers)[l].maps) {
        const Lightmap* map = &m;
        const std::filesystem::path finalPath = folder / layerPageUri(options.exrPrefix, m.page, (*options.layers)[l].name);
        files.push_back({finalPath, [exr, map, finalPath](const std::filesystem::path& temp) { exr->writeFile(*map, {}, temp, finalPath); }});
      }
    for (size_t i = 0; masked && i < options.shadowMask->rgb->size(); ++i) {
      const ShadowMaskExport* mask = options.shadowMask;
      const std::filesystem::path finalPath = folder / shadowMaskPageUri(options.exrPrefix, (*mask->rgb)[i].page);
      files.push_back({finalPath, [mask, i, finalPath](const std::filesystem::path& temp) { writeShadowMaskExr(*mask, i, temp, finalPath); }});
    }
  }
  files.insert(files.end(), options.alsoWrite.begin(), options.alsoWrite.end());
  if (options.guard) {
    options.guard->write(files);
    return;
  }
  OutputGuard guard;
  guard.addInputs(options.inputs);
  guard.write(files);
}

nlohmann::json skyJson(const Environment& sky) {
  if (sky.isUniform()) {
    const glm::vec3 L = sky.uniformRadiance();
    return {{"radiance", {L.x, L.y, L.z}}};
  }
  const glm::dvec3 mean = sky.integral() / (4.0 * kPi);
  return {{"environment", sky.source()}, {"meanRadiance", {mean.x, mean.y, mean.z}}, {"rotation", sky.rotation()}};
}

}  // namespace irbake
