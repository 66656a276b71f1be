// glTF/GLB export with light maps. Two sources of the document:
//  - the scene came from a glTF (Scene::sourcePath): its JSON is kept (materials, textures, cameras,
//    lights, unknown extensions), its buffers merged into one and its images embedded, and every
//    baked primitive is added as a new world-space mesh on an identity root node (the atlas split
//    vertices, so the source accessors no longer fit); the source nodes lose their mesh.
//  - a generated scene: written by our writer from a copy whose materials carry the light maps.
// Materials are duplicated per page (MOZ_lightmap names one texture). Every file is written to a
// temp name and renamed only when all succeeded (common/atomic_file.h).
#include "export/gltf_export.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include "common/atomic_file.h"
#include "common/error.h"
#include "export/exr_io.h"
#include "export/gltf_writer.h"
#include "scene/gltf_source.h"
#include "scene/image_codec.h"

namespace irbake {

using json = nlohmann::json;

namespace {

// One baked page as the 8-bit linear PNG of MOZ_lightmap: value = PNG × intensity, intensity = the
// page's largest texel value so the PNG spans the full 0..255 range.
struct PngPage {
  Texture texture;
  float intensity = 1.0f;
};

PngPage pngPage(const Lightmap& map) {
  PngPage p;
  float peak = 0.0f;
  for (const auto& t : map.texels) peak = std::max(peak, std::max(t.x, std::max(t.y, t.z)));
  p.intensity = peak > 0.0f ? peak : 1.0f;
  p.texture.name = "lightmap_" + std::to_string(map.page);
  p.texture.width = map.width;
  p.texture.height = map.height;
  p.texture.wrapS = p.texture.wrapT = WrapMode::ClampToEdge;
  p.texture.texels.resize(map.texels.size());
  for (size_t i = 0; i < map.texels.size(); ++i) p.texture.texels[i] = glm::vec4(glm::max(map.texels[i], glm::vec3(0.0f)) / p.intensity, 1.0f);
  return p;
}

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

std::vector<uint8_t> decodeDataUri(const std::string& uri) {
  size_t comma = uri.find(',');
  if (comma == std::string::npos || uri.find(";base64") == std::string::npos) return {};
  // Plain RFC 4648 base64 (the only data URI encoding glTF allows).
  std::vector<uint8_t> out;
  uint32_t acc = 0;
  int bits = 0;
  for (size_t i = comma + 1; i < uri.size(); ++i) {
    char c = uri[i];
    int v = c >= 'A' && c <= 'Z' ? c - 'A' : c >= 'a' && c <= 'z' ? c - 'a' + 26 : c >= '0' && c <= '9' ? c - '0' + 52
          : c == '+' ? 62 : c == '/' ? 63 : -1;
    if (v < 0) continue;  // padding and whitespace
    acc = (acc << 6) | static_cast<uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<uint8_t>((acc >> bits) & 0xFF));
    }
  }
  return out;
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
    default: return fallback.empty() ? "application/octet-stream" : fallback;
  }
}

// The source document with all buffers merged into buffer 0 and every image embedded.
GltfDocument documentFromSource(const std::filesystem::path& sourcePath) {
  GltfSource src = readGltfSource(sourcePath);
  json root = src.json;
  std::vector<uint8_t> bin;
  std::vector<size_t> offsets;
  if (root.contains("buffers")) {
    for (size_t i = 0; i < root["buffers"].size(); ++i) {
      const json& b = root["buffers"][i];
      std::vector<uint8_t> data;
      if (b.contains("uri")) data = uriBytes(src, b["uri"].get<std::string>());
      else if (src.binary && i == 0) data.assign(src.bytes.begin() + src.binOffset, src.bytes.begin() + src.binOffset + src.binSize);
      size_t length = b.value("byteLength", size_t(0));
      if (data.size() < length)
        throw Error(ErrorCode::Io, sourcePath.string(), "cannot re-read buffer " + std::to_string(i) + " of the source scene");
      data.resize(length);
      while (bin.size() % 16) bin.push_back(0);  // keeps every accessor's alignment
      offsets.push_back(bin.size());
      bin.insert(bin.end(), data.begin(), data.end());
    }
  }
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
      image.erase("uri");
      image["bufferView"] = view;
      image["mimeType"] = mime;
    }
  return doc;
}

std::string pageUri(const ExportOptions& options, int page) { return options.exrPrefix + "_" + std::to_string(page) + ".exr"; }

}  // namespace

void exportGltf(const Scene& scene, const std::vector<Lightmap>& maps, const ExportOptions& options) {
  const std::string file = options.output.string();
  if (options.output.empty()) throw Error(ErrorCode::Usage, "", "export needs an output path");
  checkMaps(maps, file);
  std::map<int, size_t> mapOfPage;  // page → index in maps
  for (size_t i = 0; i < maps.size(); ++i) mapOfPage[maps[i].page] = i;
  std::vector<PngPage> pngs;
  for (const auto& m : maps) pngs.push_back(pngPage(m));
  std::vector<std::string> pageUris;
  if (options.writeExrPages)
    for (const auto& m : maps) pageUris.push_back(pageUri(options, m.page));

  // (scene material, page) → material of the written document; page −1: no light map.
  auto pageWithMap = [&](const Primitive& p) { return mapOfPage.count(p.lightmap.page) ? p.lightmap.page : -1; };

  GltfDocument doc;
  const bool fromSource = !scene.sourcePath.empty() && std::filesystem::exists(scene.sourcePath);
  if (fromSource) {
    doc = documentFromSource(scene.sourcePath);
    std::map<int, int> pageTexture;  // page → document texture
    auto lightmapTexture = [&](int page) {
      auto it = pageTexture.find(page);
      if (it != pageTexture.end()) return it->second;
      const PngPage& png = pngs[mapOfPage.at(page)];
      int image = doc.addPngImage(encodePng(png.texture, false), png.texture.name);
      int tex = doc.addTexture(image, doc.addSampler(WrapMode::ClampToEdge, WrapMode::ClampToEdge, true));
      pageTexture[page] = tex;
      return tex;
    };
    const json sourceMaterials = doc.root.value("materials", json::array());
    std::map<std::pair<int, int>, int> materialFor;
    std::set<int> bakedNodes;
    json newRoots = json::array();
    for (const auto& prim : scene.primitives) {
      const Material& m = scene.materials.at(prim.material);
      int page = pageWithMap(prim);
      auto key = std::make_pair(prim.material, page);
      if (!materialFor.count(key)) {
        json mat = (m.gltfMaterial >= 0 && m.gltfMaterial < static_cast<int>(sourceMaterials.size())) ? sourceMaterials[m.gltfMaterial]
                                                                                                      : json::object({{"name", m.name}});
        if (page >= 0) {
          mat["extensions"]["MOZ_lightmap"] = {{"index", lightmapTexture(page)}, {"texCoord", 1}, {"intensity", pngs[mapOfPage.at(page)].intensity}};
          if (mat.contains("name")) mat["name"] = mat["name"].get<std::string>() + "_lightmap" + std::to_string(page);
          doc.useExtension("MOZ_lightmap");
        }
        materialFor[key] = doc.append("materials", std::move(mat));
      }
      int mesh = addPrimitiveMesh(doc, prim, materialFor[key]);
      newRoots.push_back(doc.append("nodes", {{"mesh", mesh}, {"name", prim.name}}));
      if (prim.node >= 0) bakedNodes.insert(prim.node);
    }
    for (int n : bakedNodes)
      if (doc.root.contains("nodes") && n < static_cast<int>(doc.root["nodes"].size())) doc.root["nodes"][n].erase("mesh");
    if (!doc.root.contains("scenes") || doc.root["scenes"].empty()) {
      doc.root["scenes"] = json::array({json::object({{"nodes", json::array()}})});
      doc.root["scene"] = 0;
    }
    int sceneIndex = doc.root.value("scene", 0);
    auto& rootNodes = doc.root["scenes"][sceneIndex]["nodes"];
    if (!rootNodes.is_array()) rootNodes = json::array();
    for (const auto& n : newRoots) rootNodes.push_back(n);
    if (!pageUris.empty()) doc.root["extras"]["lightmapPages"] = pageUris;
    // The document changed under the generator's name.
    doc.root["asset"]["generator"] = "irbake (from " + doc.root["asset"].value("generator", std::string("unknown")) + ")";
  } else {
    // Generated scene: materials duplicated per page with the page's PNG as MOZ_lightmap texture.
    Scene copy = scene;
    copy.materials.clear();
    std::map<std::pair<int, int>, int> materialFor;
    std::map<int, int> pageTexture;
    for (auto& prim : copy.primitives) {
      int page = pageWithMap(prim);
      auto key = std::make_pair(prim.material, page);
      if (!materialFor.count(key)) {
        Material m = scene.materials.at(prim.material);
        if (page >= 0) {
          if (!pageTexture.count(page)) {
            pageTexture[page] = static_cast<int>(copy.textures.size());
            copy.textures.push_back(pngs[mapOfPage.at(page)].texture);
          }
          m.lightmapTexture = pageTexture[page];
          m.lightmapIntensity = pngs[mapOfPage.at(page)].intensity;
          m.name += "_lightmap" + std::to_string(page);
        } else {
          m.lightmapTexture = -1;
        }
        materialFor[key] = static_cast<int>(copy.materials.size());
        copy.materials.push_back(m);
      }
      prim.material = materialFor[key];
    }
    GltfWriteOptions wo;
    wo.lightmapPages = pageUris;
    doc = gltfFromScene(copy, wo);
  }

  std::vector<PendingFile> files = doc.files(options.output);
  if (options.writeExrPages) {
    const std::filesystem::path folder = options.output.parent_path();
    for (size_t i = 0; i < maps.size(); ++i) {
      const Lightmap* map = &maps[i];
      files.push_back({folder / pageUris[i], [map](const std::filesystem::path& temp) { writeExr(*map, temp); }});
    }
  }
  writeAllAtomically(files);
}

}  // namespace irbake
