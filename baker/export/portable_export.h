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
  double exposure = 1.0;        // multiplies the shown value before the range (1: as irview shows it at 0 EV)
  int maxScale = 4;             // a page's texture has at most this many texels per light-map texel, per axis
  int maxSize = 8192;           // and is at most this many texels wide or high (all its tiles together)
  int maxTextureSize = 4096;    // one texture (a tile of a page's texture) is at most this many texels a side
  double percentile = 99.9;     // the range: this percentile of the texels' largest shown channel (at least 1),
                                // over the texels without emission (a lamp's face may still clip)
};

// A texture's rectangle in its page's texture (texels at the page's scale).
struct PortableTile {
  int x = 0, y = 0, width = 0, height = 0;
};

// One page's baked texture, as one or more tiles.
struct PortablePage {
  int page = 0;
  int width = 0, height = 0;        // the page's texture size in texels (all tiles together)
  int scale = 1;                    // texture texels per light-map texel, per axis
  double clippedFraction = 0.0;     // covered texels with a channel above the range (shown as white)
  double litClippedFraction = 0.0;  // the same over the covered texels without emission
  std::vector<PortableTile> tiles;  // one texture each
};

struct PortableBake {
  GltfDocument document;  // the portable glTF (write it with document.files(path))
  std::vector<PortablePage> pages;
  double range = 1.0;     // every texture holds exposure × shown / range (at least 1: never brightened)
};

// Texture texels per light-map texel on `page` (per axis): the base-colour textures' density over the page,
// the page-area-weighted mean over its textured triangles of sqrt(albedo texels / map texels), rounded up;
// 1 where no triangle is textured; capped by maxScale and maxSize.
int portableScale(const Scene& scene, int page, int pageWidth, int pageHeight, const PortableOptions& options = {});

// How a page's texture (width × height texels) is cut into textures of at most maxSize texels a side: a grid
// of cells, each triangle in the cell of its UV box's centre, each tile the box of its triangles' boxes (with
// a 2-texel margin for filtering). One tile covering the whole texture where it fits.
struct PortableTiling {
  std::vector<PortableTile> tiles;
  std::vector<std::vector<int>> tileOfTriangle;  // per scene primitive (empty when not on the page), per triangle
};
// Empty tiles when no grid fits (a triangle wider than maxSize texels).
PortableTiling portableTiles(const Scene& scene, int page, int width, int height, int maxSize);

// The shown colour of one page at `scale` × its resolution, over `tile` (default: the whole texture): per
// texel centre inside a triangle, exposure × (base colour × map + emission) / range, clipped to [0, 1]
// (linear; alpha: the base colour's alpha); the rest filled from covered neighbours (post/dilate) so
// filtering at a chart's border never reads black. stats: clippedFraction over the tile's covered texels.
Texture bakePortableTexture(const Scene& scene, const Lightmap& map, int scale, const PortableOptions& options = {},
                            PortablePage* stats = nullptr, double range = 1.0, const PortableTile* tile = nullptr);

// The portable document of a bake (`scene` after the atlas, `maps` its pages): world-space meshes (one node
// each, as our writer writes them; split per tile), the cameras, no lights, unlit materials (one per source
// material and tile). Primitives without a page keep their base colour (factor and texture) unlit, without
// emission. The textures are made one tile at a time (two passes: the range, then the PNGs), so the memory
// held is one tile's texels, the percentile's samples and the PNGs.
PortableBake buildPortable(const Scene& scene, const std::vector<Lightmap>& maps, const PortableOptions& options = {});

// The portable GLB at `path` as one file of an all-or-nothing set (the document is built now); `summary`,
// when given, receives {"file", "exposure", "range", "pages": [{page, width, height, scale, clippedFraction,
// litClippedFraction, tiles: [{x, y, width, height}]}]} for the report. Throws Error(Usage, path) unless path
// names a .glb.
PendingFile portableGlbFile(const Scene& scene, const std::vector<Lightmap>& maps, const std::filesystem::path& path,
                            const PortableOptions& options = {}, nlohmann::json* summary = nullptr);

}  // namespace irbake
