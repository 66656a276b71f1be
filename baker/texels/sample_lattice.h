// The per-sample ray lattices of the stages that trace from every texel sample after a backend (the sky, the
// final gather): each weighted sample's surface point, normal and its own lattice rotation.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "raytrace/ray_tracer.h"
#include "sampling/sampling.h"
#include "texels/texel_samples.h"

namespace irbake {

// Texel samples that carry weight (the ones these stages trace from), over every page.
inline size_t weightedSampleCount(const std::vector<TexelSamples>& pages) {
  size_t count = 0;
  for (const TexelSamples& ts : pages)
    for (const glm::vec4& pw : ts.positionWeight) count += pw.w > 0.0f;
  return count;
}

// Interleaved lattice rotations (Keller & Heidrich 2001) for a stage whose per-sample results a (2r+1)² texel
// filter averages: texel (x, y) of supersample layer l takes class c = (x mod K) + K (y mod K) + K² l, K = 2r + 1,
// C classes in all, and (r1, r2) = ({B1 + c/(C n)}, {B2 + c(√2 − 1)}) for n rays per sample, (B1, B2) random per
// page, seed and stream. Every filter window holds each class of its layer once, so the C n rays it averages
// are stratified in u as one lattice (and spread in azimuth) instead of C lattices rotated independently that
// overlap by chance; each sample's own rotation stays uniform over the page's random B (docs/units.md).
class InterleavedRotations {
 public:
  InterleavedRotations(const TexelSamples& ts, uint64_t seed, uint64_t stream, int filterRadius, int rays)
      : width_(ts.width), layer_(ts.layerSize()), side_(2 * std::max(0, filterRadius) + 1),
        classes_(static_cast<double>(side_) * side_ * ts.supersample * ts.supersample), rays_(std::max(1, rays)) {
    Rng rng(hashSeed(seed, stream << 8 | static_cast<uint64_t>(ts.page), 0x1a77e5ed));
    base1_ = rng.uniform();
    base2_ = rng.uniform();
  }
  bool active() const { return side_ > 1; }  // a filter to interleave over
  void of(size_t s, double& r1, double& r2) const {
    constexpr double kAzimuthStep = 0.41421356237309515;  // √2 − 1, in turns
    const size_t t = s % layer_;
    const int x = static_cast<int>(t % width_), y = static_cast<int>(t / width_);
    const double c = (x % side_) + side_ * (y % side_) + static_cast<double>(side_) * side_ * static_cast<double>(s / layer_);
    r1 = std::fmod(base1_ + c / (classes_ * rays_), 1.0);
    r2 = std::fmod(base2_ + c * kAzimuthStep, 1.0);
  }

 private:
  int width_;
  size_t layer_;
  int side_;
  double classes_;
  int rays_;
  double base1_ = 0.0, base2_ = 0.0;
};

// Calls at(s, x, n, r1, r2) for every weighted sample s of a page, in parallel: x its position inset into its
// triangle, n its normal, (r1, r2) its lattice rotation, drawn from (seed, stream << 8 | page, s): a stage's own
// stream keeps its rotations apart from another stage's, and the same for every thread count.
// With interleaved (active), the rotations are its instead of independent ones.
template <class At>
void forEachSampleLattice(const RayTracer& rayTracer, const TexelSamples& ts, uint64_t seed, uint64_t stream, At&& at,
                          const InterleavedRotations* interleaved = nullptr) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, ts.slotCount(), 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t s = r.begin(); s != r.end(); ++s) {
      if (!(ts.positionWeight[s].w > 0.0f)) continue;
      glm::vec3 x(ts.positionWeight[s]);
      const glm::vec3 n(ts.normal[s]);
      if (s < ts.primitive.size() && ts.primitive[s] < rayTracer.scene().primitives.size())
        x = rayTracer.insetPoint(ts.primitive[s], ts.triangle[s], x);
      double r1, r2;
      if (interleaved && interleaved->active()) {
        interleaved->of(s, r1, r2);
      } else {
        Rng rng(hashSeed(seed, stream << 8 | static_cast<uint64_t>(ts.page), s));
        r1 = rng.uniform();
        r2 = rng.uniform();
      }
      at(s, x, n, r1, r2);
    }
  });
}

}  // namespace irbake
