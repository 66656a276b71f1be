// What the viewer shows: a Scene plus its baked light maps, resolved per primitive.
// Light maps come from the float EXR pages of an irbake export when present (full range), else from
// the MOZ_lightmap texture × intensity of each material; a primitive with neither shows albedo only.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "backend/lightmap.h"
#include "scene/scene.h"

namespace irbake::view {

struct ViewerScene {
  Scene scene;
  std::vector<Lightmap> pages;        // float pages, index = LightmapRef::page (empty: none)
  std::vector<std::string> warnings;  // e.g. "no light map: showing albedo only"
};

enum class LightmapSource { Page, MaterialTexture, None };

// Where primitive `p` reads its light map from.
LightmapSource lightmapSourceOf(const ViewerScene& v, const Primitive& p);

// A scene with maps handed over in memory (a bake result, or maps built in code). Warns when no
// primitive has a light map.
ViewerScene makeViewerScene(Scene scene, std::vector<Lightmap> pages);

// Loads a glTF/GLB (an irbake export or any glTF) and its EXR pages. Throws Error naming the file.
ViewerScene loadViewerScene(const std::filesystem::path& path);

// Per-vertex chart id: connected components of triangles sharing a vertex index. After the atlas,
// vertices are split along chart seams, so these are the atlas charts.
std::vector<uint32_t> chartIds(const Primitive& p);

// Whether the primitive is a closed solid facing outward: after welding vertices by position (atlas
// seams split them), every edge of a non-degenerate triangle is used exactly once in each direction
// (closed, consistently wound), and the signed volume is positive (counter-clockwise front faces point
// out). Its back faces can then only be seen from inside the solid, so the viewer culls them.
bool isClosedOutward(const Primitive& p);

}  // namespace irbake::view
