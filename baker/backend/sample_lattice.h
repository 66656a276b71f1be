// The per-sample ray lattices of the stages that trace from every texel sample after a backend (the sky, the
// final gather): each weighted sample's surface point, normal and its own lattice rotation.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "backend/bake_inputs.h"
#include "vpl/sampling.h"

namespace irbake {

// Texel samples that carry weight (the ones these stages trace from), over every page.
inline size_t weightedSampleCount(const std::vector<TexelSamples>& pages) {
  size_t count = 0;
  for (const TexelSamples& ts : pages)
    for (const glm::vec4& pw : ts.positionWeight) count += pw.w > 0.0f;
  return count;
}

// Calls at(s, x, n, r1, r2) for every weighted sample s of a page, in parallel: x its position inset into its
// triangle, n its normal, (r1, r2) its lattice rotation, drawn from (seed, stream << 8 | page, s): a stage's own
// stream keeps its rotations apart from another stage's, and the same for every thread count.
template <class At>
void forEachSampleLattice(const BakeInputs& in, const TexelSamples& ts, uint64_t seed, uint64_t stream, At&& at) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, ts.slotCount(), 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t s = r.begin(); s != r.end(); ++s) {
      if (!(ts.positionWeight[s].w > 0.0f)) continue;
      glm::vec3 x(ts.positionWeight[s]);
      const glm::vec3 n(ts.normal[s]);
      if (s < ts.primitive.size() && ts.primitive[s] < in.scene.primitives.size())
        x = in.rayTracer.insetPoint(ts.primitive[s], ts.triangle[s], x);
      Rng rng(hashSeed(seed, stream << 8 | static_cast<uint64_t>(ts.page), s));
      const double r1 = rng.uniform(), r2 = rng.uniform();
      at(s, x, n, r1, r2);
    }
  });
}

}  // namespace irbake
