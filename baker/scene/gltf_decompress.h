// The decode step every reader of a glTF shares (the loader, the export's copy of the document, irview):
// a file that uses EXT_meshopt_compression or KHR_draco_mesh_compression becomes a plain glTF in memory,
// one GLB buffer holding every buffer view, decoded where compressed, so that the rest reads it as any
// other file. KHR_mesh_quantization needs no step: its accessor types are read as they are.
#pragma once
#include <string>
#include <vector>

#include "scene/gltf_source.h"

namespace irbake {

inline constexpr const char* kMeshoptCompression = "EXT_meshopt_compression";
inline constexpr const char* kDracoCompression = "KHR_draco_mesh_compression";

// `source` as it is when it uses neither extension; else a GLB in memory with the same path and folder
// (image URIs resolve as before) whose JSON no longer names them, and decodedExtensions listing them.
// Broken data is refused with Error(InvalidData, file, ...) naming the extension and the buffer view,
// mesh, primitive or accessor.
GltfSource decompressGltf(GltfSource source);

// The warning for an extension the input used and the output no longer does, and how to get it back.
std::string decodedExtensionWarning(const std::string& extension);

}  // namespace irbake
