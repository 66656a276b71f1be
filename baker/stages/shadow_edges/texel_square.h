// What the shadow-edge and shadow-mask stages share: where a per-texel value jumps between neighbours, and
// the mean of a value over S×S sub-points of a texel's own square on the triangles that cover it.
#pragma once
#include <cstddef>
#include <functional>
#include <vector>

#include "evaluators/bake_inputs.h"

namespace irbake {

// Texels whose value (≥ 0; < 0: none) differs from a valid 8-neighbour's by more than jump (both marked: the
// edge lies in one of the two squares).
std::vector<uint8_t> edgeTexels(const std::vector<float>& value, int w, int h, float jump);

// Sums of up to two values over the kept sub-points of one texel's square.
struct SquareMean {
  static constexpr int kValues = 2;
  glm::dvec3 sum[kValues] = {glm::dvec3(0.0), glm::dvec3(0.0)};
  int kept = 0;     // sub-points whose values were summed
  int points = 0;   // sub-points on the triangle (traced)
  int dropped = 0;  // of those, dark and cut off from the centre by a surface (under a box on the floor)
};

// Per marked texel, the page's triangles whose texel-space box meets its square, in scene order (the
// rasteriser's "first triangle wins" on shared edges): on a thin chart one texel spans several triangles.
struct SquareTriangles {
  std::vector<uint32_t> first;   // per texel: its triangles are tris[first[t] .. first[t + 1])
  std::vector<glm::uvec2> tris;  // (primitive, triangle)
};
SquareTriangles squareTriangles(const Scene& scene, const TexelSamples& ts, const std::vector<uint8_t>& marked);

// visit(xs, nx, origin, values) for a sub-point xs (on the triangle that covers it, inset), its shading normal
// and its ray origin: writes values[0..1] and returns whether any light reached it (a dark one is dropped where
// a surface cuts it off from the centre: covered, not shadowed). The sub-points cover the square's part on the
// triangles squares names for t (the texel's own triangle alone when squares is null or names none); false
// when texel t has no triangle to sample (the centre's value stays).
using SubPointVisit =
    std::function<bool(const glm::vec3& xs, const glm::vec3& nx, const glm::vec3& origin, glm::vec3* values)>;
bool averageOverTexelSquare(const BakeInputs& in, const TexelSamples& ts, size_t t, int S,
                            const SquareTriangles* squares, const SubPointVisit& visit, SquareMean& out);

}  // namespace irbake
