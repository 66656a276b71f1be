#include "stages/sky/sky_light.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "texels/sample_lattice.h"
#include "common/maths.h"
#include "common/progress.h"
#include "texels/surface_filter_cache.h"
#include "sampling/sampling.h"

namespace irbake {

namespace {
constexpr double kGolden = 0.6180339887498949;  // Fibonacci lattice step

// An environment map's two strategies, half the rays each, balance heuristic: calls
// visit(term, dir, cosθ) for every sample that reaches the sky, with term = L T cosθ / (n (p_cosine + p_sky)),
// whose sum over the rays estimates the irradiance E (the map value is E / π).
template <class Visit>
void visitEnvironmentSamples(const Environment& sky, const RayTracer& rt, const glm::vec3& origin, const glm::vec3& n,
                             int rays, double r1, double r2, Visit&& visit) {
  const int half = std::max(1, rays / 2);
  for (int i = 0; i < 2 * half; ++i) {
    const int k = i % half;
    const double u = std::fmod((k + 0.5) / half + r1, 1.0), v = std::fmod(k * kGolden + r2, 1.0);
    glm::vec3 dir;
    if (i < half) {
      dir = cosineHemisphere(n, u, v);
    } else {
      double pdf;
      dir = sky.sample(u, v, pdf);
    }
    const double cosTheta = glm::dot(n, dir);
    if (!(cosTheta > 0.0)) continue;
    const double pdfCosine = cosTheta / kPi, pdfSky = sky.pdf(dir);
    const glm::vec3 L = sky.radiance(dir);
    if (L == glm::vec3(0.0f) || rt.occluded(origin, dir, 0.0f, 1e30f)) continue;
    visit(glm::dvec3(L * rt.transmittance(origin, dir, 0.0f, 1e30f)) * (cosTheta / (half * (pdfCosine + pdfSky))), dir,
          cosTheta);
  }
}
// Adds per-slot values to a page: averaged over each valid texel's samples, filtered on the surface
// (filterRadius > 0), added where the page is valid.
template <class SlotValue>
void addToPage(const TexelSamples& ts, Lightmap& page, int filterRadius, SurfaceFilterCache* filters, SlotValue&& slotValue) {
  std::vector<glm::vec3> texelValue(ts.layerSize(), glm::vec3(0.0f));
  std::vector<uint8_t> valid(ts.layerSize(), 0);
  for (size_t t = 0; t < ts.layerSize(); ++t) {
    glm::vec3 v;
    if (t < page.valid.size() && page.valid[t] && texelMean(ts, t, slotValue, v)) {
      texelValue[t] = v;
      valid[t] = 1;
    }
  }
  if (filterRadius > 0) {
    TexelFilterOptions fo;
    fo.radius = filterRadius;
    texelValue = filterOnSurface(filters, ts, texelValue, valid, fo);
  }
  for (size_t t = 0; t < ts.layerSize(); ++t)
    if (valid[t]) page.texels[t] += texelValue[t];
}

constexpr uint64_t kSkyStream = 0x5c7;  // the sky's lattice rotations (forEachSampleLattice)

// Rays per texel sample: options.raysPerSample, fewer where the scene's samples would exceed maxRays (≥ minRays,
// and ≥ 2: a map splits its rays between two strategies).
int skyRaysPerSample(const BakeInputs& in, const SkyLightOptions& options) {
  return std::max(std::max(2, options.minRays), std::min(options.raysPerSample,
                              static_cast<int>(options.maxRays / std::max<size_t>(1, weightedSampleCount(in.texels)))));
}

}  // namespace

glm::vec3 skyLightAt(const BakeInputs& in, const glm::vec3& x, const glm::vec3& n, int rays, double r1, double r2) {
  const Environment& sky = in.scene.environment;
  const RayTracer& rt = in.rayTracer;
  const glm::vec3 origin = x + n * rt.epsilon();
  glm::dvec3 sum(0.0);
  if (sky.isUniform()) {
    // Cosine rays: (L cosθ / p) / π = L for p = cosθ/π, so the value is L × the visible fraction.
    glm::vec3 visible(0.0f);  // Σ transmittance over the rays (1 per clear ray without see-through surfaces)
    CosineLattice lattice(n, rays, r1, r2);
    for (int i = 0; i < rays; ++i) {
      const glm::vec3 dir = lattice.next();
      if (!rt.occluded(origin, dir, 0.0f, 1e30f)) visible += rt.transmittance(origin, dir, 0.0f, 1e30f);
    }
    return sky.uniformRadiance() * visible / static_cast<float>(std::max(1, rays));
  }
  visitEnvironmentSamples(sky, rt, origin, n, rays, r1, r2,
                          [&](const glm::dvec3& term, const glm::vec3&, double) { sum += term; });
  return glm::vec3(sum / kPi);
}

// The page's samples with their lattice rotations, interleaved over the filter's windows (sample_lattice.h); an
// environment map's lattices are half the rays each (the cosine and the sky strategy).
template <class At>
void forEachSkySample(const BakeInputs& in, const TexelSamples& ts, const SkyLightOptions& options, int rays, At&& at) {
  const int latticeRays = in.scene.environment.isUniform() ? rays : std::max(1, rays / 2);
  const InterleavedRotations interleaved(ts, options.seed, kSkyStream, options.interleave ? options.filterRadius : 0,
                                         latticeRays);
  forEachSampleLattice(in.rayTracer, ts, options.seed, kSkyStream, at, &interleaved);
}

void addSkyLight(const BakeInputs& in, std::vector<Lightmap>& maps, const SkyLightOptions& options,
                 SkyLightStats* stats) {
  if (!in.scene.environment.present()) return;
  Stopwatch watch;
  const int rays = skyRaysPerSample(in, options);
  for (size_t p = 0; p < in.texels.size() && p < maps.size(); ++p) {
    const TexelSamples& ts = in.texels[p];
    std::vector<glm::vec3> slotValue(ts.slotCount(), glm::vec3(0.0f));
    forEachSkySample(in, ts, options, rays, [&](size_t s, const glm::vec3& x, const glm::vec3& n, double r1, double r2) {
      slotValue[s] = skyLightAt(in, x, n, rays, r1, r2);
    });
    addToPage(ts, maps[p], options.filterRadius, in.surfaceFilters, [&](size_t s) { return slotValue[s]; });
  }
  if (stats) {
    stats->rays = weightedSampleCount(in.texels) * static_cast<size_t>(rays);  // every weighted sample traces `rays`
    stats->raysPerSample = rays;
    stats->seconds = watch.seconds();
  }
}

L1Vectors skyDirectionalAt(const BakeInputs& in, const glm::vec3& x, const glm::vec3& n, int rays, double r1,
                           double r2) {
  // skyLightAt's rays, each ray's share of the map value turned into its irradiance-vector term.
  const Environment& sky = in.scene.environment;
  const RayTracer& rt = in.rayTracer;
  const glm::vec3 origin = x + n * rt.epsilon();
  std::array<glm::dvec3, 3> g{};
  auto add = [&](const glm::dvec3& mapValue, const glm::vec3& dir, double cosTheta) {
    if (!(cosTheta > 0.0)) return;
    for (int k = 0; k < 3; ++k) g[k] += mapValue * (double(dir[k]) / cosTheta);
  };
  if (sky.isUniform()) {
    // The open hemisphere's vector, L n (its tangential part is 0), less what the blocked rays miss:
    // g/π = L n − (2/N) Σ L (1 − T) ω over uniform hemisphere rays (pdf 1/(2π)). An open plane gets t = 0
    // exactly, and every term is bounded (through skyLightAt's cosine rays a term is ω/cosθ, unbounded at
    // the horizon, which left an open floor a tangential part).
    const glm::dvec3 radiance(sky.uniformRadiance());
    for (int k = 0; k < 3; ++k) g[k] = radiance * double(n[k]);
    glm::vec3 tu, tv;
    orthonormalBasis(n, tu, tv);
    const glm::dvec3 share = 2.0 * radiance / double(std::max(1, rays));
    for (int i = 0; i < rays; ++i) {
      const double u = std::fmod((i + 0.5) / rays + r1, 1.0), v = std::fmod(i * kGolden + r2, 1.0);
      const double sinTheta = std::sqrt(std::max(0.0, 1.0 - u * u)), phi = 2.0 * kPi * v;
      const glm::vec3 dir = glm::normalize(tu * float(sinTheta * std::cos(phi)) + tv * float(sinTheta * std::sin(phi)) +
                                           n * float(u));
      const glm::vec3 through =
          rt.occluded(origin, dir, 0.0f, 1e30f) ? glm::vec3(0.0f) : rt.transmittance(origin, dir, 0.0f, 1e30f);
      if (through == glm::vec3(1.0f)) continue;
      const glm::dvec3 missed = share * (1.0 - glm::dvec3(through));
      for (int k = 0; k < 3; ++k) g[k] -= missed * double(dir[k]);
    }
  } else {
    visitEnvironmentSamples(sky, rt, origin, n, rays, r1, r2, [&](const glm::dvec3& term, const glm::vec3& dir, double cosTheta) {
      add(term / kPi, dir, cosTheta);
    });
  }
  return tangentialPart(L1Vectors{glm::vec3(g[0]), glm::vec3(g[1]), glm::vec3(g[2])}, n);
}

void addSkyLightDirectional(const BakeInputs& in, std::array<std::vector<Lightmap>, 3>& axes,
                            const SkyLightOptions& options) {
  if (!in.scene.environment.present()) return;
  const int rays = skyRaysPerSample(in, options);
  for (size_t p = 0; p < in.texels.size() && p < axes[0].size(); ++p) {
    const TexelSamples& ts = in.texels[p];
    std::vector<L1Vectors> slotValue(ts.slotCount(), L1Vectors{});
    forEachSkySample(in, ts, options, rays, [&](size_t s, const glm::vec3& x, const glm::vec3& n, double r1, double r2) {
      slotValue[s] = skyDirectionalAt(in, x, n, rays, r1, r2);
    });
    for (int k = 0; k < 3; ++k)
      addToPage(ts, axes[k][p], options.filterRadius, in.surfaceFilters, [&](size_t s) { return slotValue[s][k]; });
  }
}

}  // namespace irbake
