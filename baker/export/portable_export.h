// The portable bake: a GLB that any glTF viewer shows with the baked light, in core glTF plus the ratified
// KHR_materials_unlit only (no MOZ_lightmap). What irview shades per pixel, base colour × light map + emission,
// is baked per light-map page into one sRGB 8-bit base-colour texture read through the atlas UVs (the portable
// file's TEXCOORD_0), and every material is unlit. docs/export.md ("Portable export") has the encoding.
#pragma once
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "lightmap/lightmap.h"
#include "common/atomic_file.h"
#include "export/gltf_writer.h"
#include "scene/scene.h"

namespace irbake {

struct PortableOptions {
  double exposure = 1.0;  // multiplies the shown value before the sRGB encode (1: as irview shows it at 0 EV)
  int maxScale = 4;       // a page's texture has at most this many texels per light-map texel, per axis
  int maxSize = 8192;     // and is at most this many texels wide or high
};

// One page's baked texture.
struct PortablePage {
  int page = 0;
  int width = 0, height = 0;     // texture size in texels
  int scale = 1;                 // texture texels per light-map texel, per axis
  double clippedFraction = 0.0;  // covered texels with a channel above 1 after the exposure (shown as 1)
};

struct PortableBake {
  GltfDocument document;          // the portable glTF (write it with document.files(path))
  std::vector<PortablePage> pages;
};

// Texture texels per light-map texel on `page` (per axis): the base-colour textures' density over the page,
// the page-area-weighted mean over its textured triangles of sqrt(albedo texels / map texels), rounded up;
// 1 where no triangle is textured; capped by maxScale and maxSize.
int portableScale(const Scene& scene, int page, int pageWidth, int pageHeight, const PortableOptions& options = {});

// The shown colour of one page at `scale` × its resolution: per texel centre inside a triangle,
// exposure × (base colour × map + emission), clipped to [0, 1] (linear; alpha: the base colour's alpha);
// the rest filled from covered neighbours (post/dilate) so filtering at a chart's border never reads black.
Texture bakePortableTexture(const Scene& scene, const Lightmap& map, int scale, const PortableOptions& options = {},
                            PortablePage* stats = nullptr);

// The portable document of a bake (`scene` after the atlas, `maps` its pages): world-space meshes (one node
// each, as our writer writes them), the cameras, no lights, unlit materials. Primitives without a page keep
// their base colour (factor and texture) unlit, without emission.
PortableBake buildPortable(const Scene& scene, const std::vector<Lightmap>& maps, const PortableOptions& options = {});

// The portable GLB at `path` as one file of an all-or-nothing set (the document is built now); `summary`,
// when given, receives {"file", "exposure", "pages": [{page, width, height, scale, clippedFraction}]} for the
// report. Throws Error(Usage, path) unless path names a .glb.
PendingFile portableGlbFile(const Scene& scene, const std::vector<Lightmap>& maps, const std::filesystem::path& path,
                            const PortableOptions& options = {}, nlohmann::json* summary = nullptr);

}  // namespace irbake
