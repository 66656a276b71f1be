// glTF/GLB export of a baked scene: the input glTF kept as it was, with TEXCOORD_1, extras.lightmap page
// records and MOZ_lightmap materials added (sRGB PNG × intensity, float EXR pages beside it); see
// docs/export.md for the convention a client follows.
#pragma once
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lightmap/lightmap.h"
#include "lightmap/probe_grid.h"
#include "common/atomic_file.h"
#include "common/output_guard.h"
#include "export/gltf_writer.h"
#include "export/light_layers.h"
#include "export/map_encoding.h"
#include "export/shadow_mask_export.h"
#include "scene/scene.h"

namespace irbake {

struct ExportOptions {
  std::filesystem::path output;       // .gltf (JSON + .bin beside) or .glb (one file), chosen by extension
  bool writeExrPages = true;          // float EXR pages beside the glTF, listed in root extras
  std::string exrPrefix = "lightmap"; // EXR names: <prefix>_<page>.exr
  MapEncodeOptions lightmapEncoding;  // the 8-bit MOZ_lightmap image's encoding (png8: sRGB, range at a percentile)
  std::vector<PendingFile> alsoWrite; // more files of the same all-or-nothing set (the bake's report)
  // Directional maps' L1 pages (x, y, z; export/directional_export.h), or null: no extension, no files.
  const std::array<std::vector<Lightmap>, 3>* directional = nullptr;
  // Irradiance probes (export/light_probes_export.h), or null (or empty): no IRBAKE_light_probes.
  const LightProbeGrid* probes = nullptr;
  // Shadow-mask pages and their lights (export/shadow_mask_export.h), or null: no extension, no files.
  const ShadowMaskExport* shadowMask = nullptr;
  // Light groups' layers (export/light_layers.h): IRBAKE_lightmap_scenarios, each layer's PNG per page and, with
  // writeExrPages, <prefix>_<page>_<layer>.exr; null (or empty): no extension. `maps` are their sum.
  const std::vector<LightLayer>* layers = nullptr;
  // Each scene light's settled mode (recordLightModes), or null: nothing recorded.
  const std::vector<LightMode>* lightModes = nullptr;
  // The atlas's record (atlas/atlas_from_bake.h: atlasRecordJson), written as the root extras "irbakeAtlas" of an
  // export of a source document, so a later bake can reuse the atlas (--atlas-from); null: not written.
  nlohmann::json atlasRecord;
  // Files never to overwrite (the scene's own): an image whose name one of them has takes another, and
  // any other output that would land on one is refused with Error(Usage).
  std::vector<std::filesystem::path> inputs;
  // The command's output guard, which writes the set (null: one that knows only `inputs`).
  const OutputGuard* guard = nullptr;
};


// True when a command's -o names a glTF file (.gltf / .glb, any case) rather than an output folder.
bool namesGltfFile(const std::filesystem::path& output);
// The folder a command writes into: -o's parent when it names a glTF file ("." when it has none), else -o.
std::filesystem::path outputFolderOf(const std::filesystem::path& output);

// Writes `scene` (after the atlas: uv1 and primitive.lightmap set) with `maps` (one per page, may be
// empty: then only TEXCOORD_1 and extras.lightmap are added, as `irbake unwrap` does). Every file is
// written to a temp name and renamed only when all succeeded. Throws Error(Io) naming the file.
void exportGltf(const Scene& scene, const std::vector<Lightmap>& maps, const ExportOptions& options);

// The document of a glTF/GLB file with all its buffers merged into buffer 0 and every image embedded;
// extraBytes: what the caller will append (reserved up front). Throws Error naming the file.
GltfDocument documentFromSource(const std::filesystem::path& sourcePath, size_t extraBytes = 0);

// The scene's sky as the export's root extras "irbakeSky": {"radiance": [r, g, b]} for a uniform sky,
// {"environment": file, "meanRadiance": [...], "rotation": radians} for a map (its file is not copied).
nlohmann::json skyJson(const Environment& sky);

}  // namespace irbake
