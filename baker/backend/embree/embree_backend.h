// The Embree backend: every valid texel sample gathers the punctual lights (exact, one shadow ray each)
// and all VPLs (clamped geometry term, ray-traced visibility), optionally with Kollig & Keller's bias
// compensation. The reference for the GL backend and its fallback. Formulas: geometry_term.h.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "backend/bake_inputs.h"
#include "backend/lightmap.h"
#include "vpl/sampling.h"

namespace irbake {

struct EmbreeOptions {
  int compensationRays = 8;      // residual paths per texel sample when eval.biasCompensation is on
  int compensationDepth = 6;     // deepest recursion of the residual (each level needs a closer hit)
  uint32_t seed = 0;             // seeds the compensation paths (results are deterministic per seed)
  int vplBlock = 256;            // VPLs per block: a block stays in cache while a tile of samples loops over it
  int tileSlots = 64;            // texel samples per parallel task
  bool packets = true;           // shadow rays in packets of 8 (rtcOccluded8): 1.5–1.6× faster than one by one
  // Per page, per texel: evaluate only texels marked ≠ 0, the rest come back invalid (null: every texel).
  // The GL backend resolves its contact texels this way.
  const std::vector<std::vector<uint8_t>>* texelSubset = nullptr;
};

// One Lightmap per TexelSamples page; valid = the texel's valid flag. Throws Error(NumericError) on NaN/Inf.
std::vector<Lightmap> bakeEmbree(const BakeInputs& inputs, const EmbreeOptions& options = {});

// What one texel sample at (x, n) receives, as irradiance / π. For tests and tools.
struct PointShading {
  glm::vec3 direct{0.0f};        // punctual lights, exact
  glm::vec3 vpl{0.0f};           // clamped VPL sum
  glm::vec3 compensation{0.0f};  // recovered clamped energy (0 unless eval.biasCompensation)
  glm::vec3 total() const { return direct + vpl + compensation; }
};
PointShading shadePointEmbree(const BakeInputs& inputs, const glm::vec3& x, const glm::vec3& n, Rng& rng,
                              const EmbreeOptions& options = {});

}  // namespace irbake
