// First pass over a glTF file, before tinygltf touches anything: reads the bytes, tells JSON from
// GLB, parses the JSON, and checks what tinygltf would otherwise read blindly (URIs that escape
// the scene folder, missing or short buffers, absurd declared sizes). Every failure is an
// irbake::Error naming the file with a one-line message.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace irbake {

struct GltfSource {
  std::filesystem::path path;       // the file as given
  std::filesystem::path folder;     // its folder: every relative URI resolves here
  bool binary = false;              // GLB container
  std::vector<uint8_t> bytes;       // the whole file
  size_t jsonOffset = 0, jsonSize = 0;  // the JSON text inside bytes (the whole file for .gltf)
  size_t binOffset = 0, binSize = 0;    // the GLB BIN chunk (binSize 0: none)
  nlohmann::json json;              // the parsed document
  // Compression extensions decoded into this document (scene/gltf_decompress.h): none for a file as read.
  std::vector<std::string> decodedExtensions;
};

// Reads and checks `path`. Throws Error(Io | Parse | InvalidData, path, ...).
GltfSource readGltfSource(const std::filesystem::path& path);
// The same checks on bytes already in memory (the fuzz harness): `path` names them in messages and
// its folder resolves relative URIs, exactly as if the bytes had been read from `path`.
GltfSource gltfSourceFromBytes(std::vector<uint8_t> bytes, const std::filesystem::path& path);

// The bytes of a base64 data URI (empty when it is not one).
std::vector<uint8_t> decodeDataUri(const std::string& uri);
// True when buffer `index` of `json` is an EXT_meshopt_compression placeholder: no URI (and not the GLB
// BIN chunk), tagged as fallback or read only through views that carry compressed data of their own.
bool isMeshoptPlaceholder(const nlohmann::json& json, size_t index);

// Decodes %XX escapes of a URI (glTF URIs are RFC 3986 references).
std::string decodeUriEscapes(const std::string& uri);
// True when a (decoded) relative URI stays inside the scene folder: not absolute, no scheme, no "..".
bool uriStaysInFolder(const std::string& decodedUri);

}  // namespace irbake
