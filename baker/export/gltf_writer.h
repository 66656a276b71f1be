// Our glTF writer: a Scene (world space) → .gltf (+ .bin beside it) or .glb, chosen by extension.
// Also the document builder the lightmap export reuses (JSON + one binary buffer).
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "scene/scene.h"

namespace irbake {

// A glTF document under construction: JSON plus buffer 0, to which every new view is appended.
class GltfDocument {
 public:
  GltfDocument();  // an empty glTF 2.0 asset with buffer 0 reserved
  // Starts from an existing document whose buffer 0 already holds `bin` (other buffers merged in).
  GltfDocument(nlohmann::json root, std::vector<uint8_t> bin);

  nlohmann::json root;       // the document (buffers[0].byteLength/uri are set when written)
  std::vector<uint8_t> bin;  // contents of buffer 0

  // Appends bytes as a buffer view (4-byte aligned); target 0 = none (images).
  int addBufferView(const void* data, size_t size, int target = 0);
  int addPositions(const std::vector<glm::vec3>& v);  // VEC3 float with min/max
  int addVec3(const std::vector<glm::vec3>& v);
  int addVec2(const std::vector<glm::vec2>& v);
  int addIndices(const std::vector<uint32_t>& v);     // UNSIGNED_INT scalar
  // An encoded image in buffer 0 (a PNG unless mimeType says otherwise).
  int addImage(const std::vector<uint8_t>& bytes, const std::string& name, const std::string& mimeType = "image/png");
  int addSampler(WrapMode s, WrapMode t, bool linearNoMips);
  int addTexture(int image, int sampler);
  int append(const char* arrayKey, nlohmann::json element);  // returns the new element's index
  void useExtension(const std::string& name);

  // The files making up the document at `path`: .glb → one; .gltf → JSON and <stem>.bin. For
  // writeAllAtomically (so a glTF and its companions appear together or not at all).
  std::vector<PendingFile> files(const std::filesystem::path& path) const;
};

// Takes `name` out of the root's extensionsUsed and extensionsRequired (a list left empty goes): the inverse of
// useExtension, for an extension the export no longer uses.
void unlistExtension(nlohmann::json& root, const std::string& name);
// Removes the root object's extension `name` (an "extensions" left empty goes) and unlists it; the objects it
// referred to are left to compaction.
void removeRootExtension(nlohmann::json& root, const std::string& name);

struct GltfWriteOptions {
  std::vector<std::string> lightmapPages;  // relative URIs of float EXR pages, written to root extras
};

// Writes `size` bytes to `path` (a temp of a set); messages name `finalName`. Throws Error(Io).
void writeBytes(const std::filesystem::path& path, const void* data, size_t size, const std::string& finalName);
// A file of the set that writes `bytes` (an image, a copy of an input's file) under finalPath.
PendingFile pendingBytes(const std::filesystem::path& finalPath, std::vector<uint8_t> bytes);

// Scene → document: one mesh and one identity node per primitive (positions are world space),
// materials (emission > 1 via KHR_materials_emissive_strength), textures as PNG (colour textures
// sRGB-encoded, MOZ_lightmap textures linear), MOZ_lightmap, TEXCOORD_1 and extras.lightmap where
// set, KHR_lights_punctual lights (node rotation maps −Z onto the light direction), cameras.
GltfDocument gltfFromScene(const Scene& scene, const GltfWriteOptions& options = {});

// Writes the scene atomically. Throws Error(Io) naming the file.
void writeGltf(const Scene& scene, const std::filesystem::path& path, const GltfWriteOptions& options = {});

// Material JSON for a Scene material (textures added to doc through the cache: key texture×srgb).
nlohmann::json materialJson(const Scene& scene, const Material& m, GltfDocument& doc, std::map<std::pair<int, bool>, int>& textureCache);

// A primitive as a new mesh (POSITION, NORMAL, TEXCOORD_0/1 when present, indices, extras.lightmap
// when lightmapped) using document material `material` (-1: none). Returns the mesh index.
int addPrimitiveMesh(GltfDocument& doc, const Primitive& prim, int material);

}  // namespace irbake
