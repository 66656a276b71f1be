// glTF/GLB export of a baked scene: the input glTF with TEXCOORD_1, extras.lightmap page records and
// MOZ_lightmap materials (PNG × intensity inside the glTF, float EXR pages beside it).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "backend/lightmap.h"
#include "scene/scene.h"

namespace irbake {

struct ExportOptions {
  std::filesystem::path output;       // .gltf (JSON + .bin beside) or .glb (one file), chosen by extension
  bool writeExrPages = true;          // float EXR pages beside the glTF, listed in root extras
  std::string exrPrefix = "lightmap"; // EXR names: <prefix>_<page>.exr
};

// Writes `scene` (after the atlas: uv1 and primitive.lightmap set) with `maps` (one per page, may be
// empty: then only TEXCOORD_1 and extras.lightmap are added, as `irbake unwrap` does). Every file is
// written to a temp name and renamed only when all succeeded. Throws Error(Io) naming the file.
void exportGltf(const Scene& scene, const std::vector<Lightmap>& maps, const ExportOptions& options);

}  // namespace irbake
