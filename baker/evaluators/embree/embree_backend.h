// The Embree backend: every valid texel sample gathers the punctual lights (exact, one shadow ray each)
// and all VPLs (clamped geometry term, ray-traced visibility). The reference for the GL backend and its
// fallback. Formulas: transport/geometry_term.h. The energy the clamp removes is given back after any backend
// by stages/compensation (ClampGather); eval.biasCompensation is not read here.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "evaluators/bake_inputs.h"
#include "lightmap/lightmap.h"
#include "sampling/sampling.h"

namespace irbake {

struct EmbreeOptions {
  int vplBlock = 256;            // VPLs per block: a block stays in cache while a tile of samples loops over it
  int tileSlots = 64;            // texel samples per parallel task
  bool packets = true;           // shadow rays in packets of 8 (rtcOccluded8): faster than one by one (bench: room_floor_occluded8)
  // Per page, per texel: evaluate only texels marked ≠ 0, the rest come back invalid (null: every texel).
  // The GL backend resolves its contact texels this way.
  const std::vector<std::vector<uint8_t>>* texelSubset = nullptr;
  // Out, optional: the directional maps' L1 pages (transport/directional.h: x, y, z world components of the
  // tangential irradiance vector t, RGB each) of the same punctual lights and clamped VPLs, gathered in the
  // same pass (each visible source's direction is at hand there); valid flags as the maps'. The map itself
  // is the same bits with or without it. The sky and the clamp compensation add none here.
  L1Pages* directional = nullptr;
};

// One Lightmap per TexelSamples page; valid = the texel's valid flag. Throws Error(NumericError) on NaN/Inf.
std::vector<Lightmap> bakeEmbree(const BakeInputs& inputs, const EmbreeOptions& options = {});

// What one texel sample at (x, n) receives, as irradiance / π. For tests and tools.
struct PointShading {
  glm::vec3 direct{0.0f};        // punctual lights, exact
  glm::vec3 vpl{0.0f};           // clamped VPL sum
  glm::vec3 total() const { return direct + vpl; }
};
PointShading shadePointEmbree(const BakeInputs& inputs, const glm::vec3& x, const glm::vec3& n,
                              const EmbreeOptions& options = {});
// The same; the generator is not used (it seeded the recursive compensation this backend no longer has).
// Kept until sky_light_test.cpp calls the overload above.
PointShading shadePointEmbree(const BakeInputs& inputs, const glm::vec3& x, const glm::vec3& n, Rng& rng,
                              const EmbreeOptions& options = {});

}  // namespace irbake
