// What the shadow-edge and shadow-mask stages share: where a per-texel value jumps between neighbours, and
// the mean of a value over S×S sub-points of a texel's own square on its triangle.
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

// visit(xs, origin, values) for a sub-point xs (on the triangle, inset) and its ray origin: writes values[0..1]
// and returns whether any light reached it (a dark one is dropped where a surface cuts it off from the centre:
// covered, not shadowed). False when texel t has no triangle to sample (the centre's value stays).
using SubPointVisit = std::function<bool(const glm::vec3& xs, const glm::vec3& origin, glm::vec3* values)>;
bool averageOverTexelSquare(const BakeInputs& in, const TexelSamples& ts, size_t t, int S, const SubPointVisit& visit,
                            SquareMean& out);

}  // namespace irbake
