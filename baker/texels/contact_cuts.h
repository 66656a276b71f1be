// Contact lines between neighbouring texels: where an occluder stands on a surface or lies on it (a cupboard
// against a wall, a box on a floor, a lamp under a ceiling), two adjacent texels of one surface can differ in
// light by the whole occluder. The surface filters (texels/texel_filter.h) must not mix them; a ray from one
// texel to the next, just above the surface, finds the occluder between them.
#pragma once
#include <cstdint>
#include <vector>

#include "raytrace/ray_tracer.h"
#include "texels/texel_samples.h"

namespace irbake {

// TexelSamples::cut bits.
constexpr uint8_t kCutRight = 1;  // an occluder between texel (x, y) and (x + 1, y)
constexpr uint8_t kCutDown = 2;   // an occluder between texel (x, y) and (x, y + 1)

// Fills ts.cut: for each pair of adjacent texels with samples whose mean normals face the same side
// (dot > 0), a ray between their mean positions lifted by half their distance along each normal; a hit
// marks the pair cut. An occluder lower than that over the surface (under half a texel spacing) is not seen:
// it changes the light by less than a texel's width. Leaves ts.cut empty when no pair is cut.
void markContactCuts(TexelSamples& ts, const RayTracer& rt);

}  // namespace irbake
