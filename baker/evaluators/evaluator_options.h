// The options each evaluator is made with, as plain structs: the bake's options carry them without knowing
// the evaluators, and the evaluator factory hands each kind its own.
#pragma once
#include <cstdint>
#include <optional>

namespace irbake {

class GlContext;
struct GlBakeStats;

// The GL evaluator's (evaluators/gl).
struct GlBackendOptions {
  int vplsPerPass = 16;          // K: VPLs (depth cubes, 5 tiles each of one depth atlas) evaluated per accumulation pass
  std::optional<int> cubeFaceSize;  // VPL depth-cube face size (texels, > 0); unset: from the light map (chooseCubeFaceSize)
  float cubeFootprintPerTexel = 1.0f;  // automatic face size: face texel footprint at the median VPL distance, in texel spacings
  int minCubeFaceSize = 128;     // automatic face size: lower bound (occluder detail the light map cannot see; docs/validation.md)
  int maxCubeFaceSize = 256;     // automatic face size: upper bound
  int pointFaceSize = 1024;      // point-light depth-cube face size (texels)
  int lightMapSize = 4096;       // spot / directional shadow map size (texels; 64 MiB): smaller maps miss sub-texel
                                 // slivers of occluders that rays hit (docs/validation.md)
  int shadowFlushTriangles = 32768;  // VPL shadow pass: glFlush after this many triangles drawn into the depth atlas (0: once per batch)
  int foldEveryPasses = 8;       // float passes summed on the GPU before folding into double
  int clusterTriangles = 64;     // triangles per culling cluster (CPU per-face culling: smaller clusters cull more)
  float maxSpotPerspectiveAngle = 1.05f;  // spots with a wider outer cone (rad) get a cube instead of one map
  float nearPlaneScale = 1e-5f;  // shadow near plane = scale × scene diagonal (reversed-Z float depth)
  float constantBiasScale = 2e-5f;  // constant depth bias = scale × scene diagonal
  float slopeBias = 1.0f;        // depth bias in shadow texel footprints × (tanθ + 1.5): the 2×2 filter reads one texel around the lookup
  float normalOffset = 0.0f;     // lookup point pushed along the receiver normal, in texel footprints
  bool shadowPcf = true;         // VPL cubes: 2×2 percentage-closer filtering (fractional shadow edges)
  bool shadowCompare = true;     // PCF by the sampler's depth comparison (GL_LINEAR, one lookup) instead of 4 fetches
  bool skipInvalidTexels = true; // early depth test against a per-page validity mask: invalid texels are not shaded
  // Contact texels: a shadow lookup that the depth bias counts as lit although the stored surface lies in
  // front of the receiver's plane cannot tell a contact (a box on a floor, a lamp 0.1 mm under a ceiling)
  // from the receiver itself. Texels where such lookups carry more than contactLeakFraction of the
  // texel's light go to the contact evaluator (same inputs, those texels only), so an unresolved texel is
  // off by at most that fraction from such lookups. Without a contact evaluator this is off.
  bool resolveContacts = true;
  float contactLeakFraction = 0.01f;
  bool stageTimings = false;     // glFinish between stages so GlBakeStats splits shadow/accumulation time
  bool gpuTimers = false;        // GL_TIME_ELAPSED queries per pass kind (GlBakeStats::gpu*Seconds)
  const GlContext* context = nullptr;  // an existing context, made current per call; null: one made per call
  GlBakeStats* stats = nullptr;  // where every call's figures are added (null: the evaluator keeps its own)
};

// The reference evaluator's (evaluators/reference).
struct ReferenceOptions {
  int spp = 256;           // paths per texel sample
  uint32_t seed = 0;       // every texel sample gets its own stream derived from (seed, page, slot)
  int maxDepth = 256;      // hard cap on bounces (roulette ends paths long before in practice)
  int rouletteStart = 2;   // bounces before Russian roulette may stop a path
};

}  // namespace irbake
