// Atlas quality measured from a scene's uv1 and lightmap pages alone (so it also scores imported UVs):
// centre-utilisation, area stretch percentiles, L2 stretch, overlapping texels, flips, uncovered triangles.
#pragma once
#include <vector>

#include "atlas/atlas.h"

namespace irbake::atlas {

// Fills charts (UV-connected islands), overlappingTexels, flippedTriangles, uncoveredTriangles,
// centreUtilisation, areaStretchP5/P50/P95 and l2Stretch. Primitives with lightmap.page < 0 are skipped.
void measureAtlas(const Scene& scene, const std::vector<AtlasPage>& pages, AtlasStats& stats);

}  // namespace irbake::atlas
