// What the viewer shows: a Scene plus its baked light maps, resolved per primitive.
// Light maps come from the float EXR pages of an irbake export when present (full range), else from
// the MOZ_lightmap texture × intensity of each material; a primitive with neither shows albedo only.
//
// Directional maps (IRBAKE_lightmap_directional, docs/export.md): the L1x/L1y/L1z pages likewise come from the
// material's float EXR pages when they can be read, else from its 8-bit PNGs (value = (2·texel − 1)·scale).
#pragma once
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "lightmap/lightmap.h"
#include "scene/scene.h"

namespace irbake::view {

struct ViewerScene {
  Scene scene;
  std::vector<Lightmap> pages;        // float pages, index = LightmapRef::page (empty: none)
  // L1x, L1y, L1z float pages (transport/directional.h), index = LightmapRef::page; a missing or empty one:
  // that page has none.
  std::array<std::vector<Lightmap>, 3> directionalPages;
  std::vector<std::string> warnings;  // e.g. "no light map: showing albedo only"
  // Every file it was loaded from (the glTF, its buffers and images, the EXR pages read): no output of
  // irview may replace one.
  std::vector<std::filesystem::path> inputFiles;
};

enum class LightmapSource { Page, MaterialTexture, None };

// Where primitive `p` reads its light map from.
LightmapSource lightmapSourceOf(const ViewerScene& v, const Primitive& p);

enum class DirectionalSource { Pages, MaterialTextures, None };

// Where primitive `p` reads its L1 pages from: float pages (directionalPages) when all three exist for its
// page, else its material's IRBAKE_lightmap_directional PNGs; None without a light map or without either.
DirectionalSource directionalSourceOf(const ViewerScene& v, const Primitive& p);

// A scene with maps handed over in memory (a bake result, or maps built in code). Warns when no
// primitive has a light map.
ViewerScene makeViewerScene(Scene scene, std::vector<Lightmap> pages,
                            std::array<std::vector<Lightmap>, 3> directionalPages = {});

// Loads a glTF/GLB (an irbake export or any glTF) and its EXR pages. Throws Error naming the file.
ViewerScene loadViewerScene(const std::filesystem::path& path);

// Per-vertex tangents (xyz unit and orthogonal to the vertex normal, w = ±1) for a primitive without TANGENT,
// from the UV set `uv` a normal map reads, the way MikkTSpace (which glTF asks for) builds it: vertices with
// the same position, normal and UV welded first (an export's light-map seams do not split the frame); per
// triangle dP/du and dP/dv (the UV-gradient solve), at each corner projected on the vertex's tangent plane,
// normalised and weighted by the corner's angle there, summed; Gram–Schmidt against the vertex normal. The
// bitangent cross(n, t)·w points towards decreasing v (up in the image: glTF's normal maps have +Y up and
// UV (0,0) at the top left). Vertices of a UV mirror's two sides are kept apart (the orientation of the
// UV triangle is part of the weld key); a vertex that both sides share should be split first
// (splitMirroredUvVertices), else it sums both. A vertex whose triangles have no UV area gets any frame.
std::vector<glm::vec4> generateTangents(const Primitive& p, const std::vector<glm::vec2>& uv);

// MikkTSpace's vertex split: a copy of `p` in which every vertex used by triangles of both UV orientations
// in UV set `uvSet` (0 or 1; a mirror line whose vertices both halves share) is duplicated, every
// per-vertex array with it, and the mirrored (clockwise in UV) triangles use the copy. Unchanged when no
// vertex is shared so, or the UV set is absent.
Primitive splitMirroredUvVertices(const Primitive& p, int uvSet);

// Per-vertex chart id: connected components of triangles sharing a vertex index. After the atlas,
// vertices are split along chart seams, so these are the atlas charts.
std::vector<uint32_t> chartIds(const Primitive& p);

// Whether the primitive is a closed solid facing outward: after welding vertices by position (atlas
// seams split them), every edge of a non-degenerate triangle is used exactly once in each direction
// (closed, consistently wound), and the signed volume is positive (counter-clockwise front faces point
// out). Its back faces can then only be seen from inside the solid, so the viewer culls them.
bool isClosedOutward(const Primitive& p);

}  // namespace irbake::view
