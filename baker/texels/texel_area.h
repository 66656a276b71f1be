// World-space area behind each light-map texel: the weight that makes error figures area-true
// (a texel on a stretched chart covers more surface than one on a dense chart).
#pragma once
#include <vector>

#include "scene/scene.h"

namespace irbake {

// Per page (index = LightmapRef::page), per texel (row y = 0 at v = 0): the 3D area (m²) one texel
// of the triangle whose uv1 contains the texel centre stands for, i.e. area3D / area in texels.
// Texels whose centre is in no triangle get 0. Pages are sized from the primitives' LightmapRef.
std::vector<std::vector<float>> texelWorldAreas(const Scene& scene);

}  // namespace irbake
