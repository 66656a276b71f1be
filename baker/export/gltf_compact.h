// Byte-level work on a GltfDocument whose data all sits in buffer 0: reading an accessor whatever
// its component type, stride or sparse storage; gathering its elements into a new accessor (the
// export's vertex sets grow where the atlas split vertices); and compaction, which drops every mesh,
// accessor, buffer view and image nothing references and rebuilds buffer 0 from what remains.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "export/gltf_writer.h"

namespace irbake {

// An accessor's elements, tightly packed (sparse substitutions applied).
struct AccessorBytes {
  int componentType = 0;      // GL enum (5120..5126)
  std::string type;           // "SCALAR", "VEC2", ...
  bool normalized = false;
  size_t elementSize = 0;     // bytes per element
  size_t count = 0;
  std::vector<uint8_t> bytes; // count × elementSize
};

// Reads accessor `index` of `doc`. Throws Error(InvalidData, file) when it points outside its data.
AccessorBytes readAccessor(const GltfDocument& doc, int index, const std::string& file);

// A new accessor holding elements `source[at[i]]` (same component type, type, normalized). Vertex
// attributes get a buffer view with a stride padded to 4 bytes, as glTF requires; min/max are written
// when `withMinMax` (POSITION needs them). Returns the accessor index.
int addGatheredAccessor(GltfDocument& doc, const AccessorBytes& source, const std::vector<uint32_t>& at, bool withMinMax);

// Removes meshes no node uses, accessors no mesh/skin/animation/instancing uses, textures no material
// uses and samplers no texture uses (only when no root extension but lights could name a texture),
// images no texture uses and buffer views nothing uses, renumbering every reference; buffer 0 is
// rebuilt from the kept views only (each 4-byte aligned).
void compactDocument(GltfDocument& doc);
// Only the last step of compactDocument: drops the buffer views nothing references (an accessor, an image, a
// primitive extension) and rebuilds buffer 0 from the kept ones; every accessor is kept, wherever it is named.
void compactBufferViews(GltfDocument& doc);

// Key of an image's original URI while the document is being built (never written).
inline constexpr const char* kSourceUriKey = "__irbakeSourceUri";

// Moves every image stored in a buffer view out to its own file beside the glTF (named after its
// source URI, else its name, else its index; made unique against `takenNames`), setting its uri. Returns the files (name
// relative to the glTF's folder, bytes). Run compactDocument afterwards to drop the freed views.
std::vector<std::pair<std::string, std::vector<uint8_t>>> externalizeImages(GltfDocument& doc, const std::vector<std::string>& takenNames);

}  // namespace irbake
