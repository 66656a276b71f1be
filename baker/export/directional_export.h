// Directional light maps in the export (docs/export.md "IRBAKE_lightmap_directional"): the L1
// pages as float EXR pages and 8-bit PNGs, referenced from a vendor extension on each light-mapped material.
// MOZ_lightmap (L0) is unchanged, so clients that know nothing more keep working.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "lightmap/lightmap.h"
#include "export/gltf_writer.h"
#include "export/map_encoding.h"
#include "scene/scene.h"

namespace irbake {

constexpr const char* kDirectionalExtension = "IRBAKE_lightmap_directional";

// The 8-bit image of one L1 page: png8 with MapRange::SignedMax, linear (export/map_encoding.h):
// value = (2 · decode(PNG) − 1) · scale, scale = the page's largest |value| over its valid texels (1 when
// all are 0), so 0 codes as 128/255 ≈ 0.502.
MapEncodeOptions directionalEncoding(const std::string& name);

// EXR file name of axis k (0 x, 1 y, 2 z) of a page: <prefix>_<page>_l1<x|y|z>.exr.
std::string directionalPageUri(const std::string& prefix, int page, int axis);

// Adds the PNGs and the extension to every material whose MOZ_lightmap texture is page P's
// ("lightmap_<P>" image): {"l1": [{"index", "texCoord": 1, "scale"} × 3 (x, y, z)], "exr": [3 URIs] when
// exrPrefix is not empty}; lists the extension in extensionsUsed (never extensionsRequired).
void addDirectionalExtension(GltfDocument& doc, const std::array<std::vector<Lightmap>, 3>& l1,
                             const std::string& exrPrefix);

}  // namespace irbake
