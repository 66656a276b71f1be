#include "stages/probes/light_visibility_fit.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

#include <tbb/parallel_for.h>

#include "common/maths.h"
#include "lights/light_kind.h"
#include "sampling/sampling.h"
#include "stages/probes/blend_fit.h"

namespace irbake {
namespace {

constexpr uint64_t kFitStream = 0x9c;  // the fit's sample jitter
constexpr int kMaxSweeps = 400;
constexpr double kConverged = 1e-5;    // largest change of a sweep

}  // namespace

float punctualVisibility(const BakeInputs& in, const Light& light, const glm::vec3& x, glm::vec3* colour) {
  if (colour) *colour = glm::vec3(1.0f);
  const LightKind& kind = lightKind(light.type);
  const bool directional = kind.atInfinity();
  const glm::vec3 toward = kind.toward(light, x);
  const float len = std::sqrt(glm::dot(toward, toward));
  if (!(len > 0.0f)) return 1.0f;
  const glm::vec3 w = toward / len;
  const float tmax = directional ? std::numeric_limits<float>::infinity() : len;
  if (in.rayTracer.occluded(x, w, 0.0f, tmax)) return 0.0f;
  if (!in.rayTracer.hasTransmission()) return 1.0f;
  const glm::vec3 t = in.rayTracer.transmittance(x, w, 0.0f, tmax);
  if (colour) *colour = t;
  return channelMean(t);
}

namespace {

// The lights whose reach meets the box [lo, hi], in index order (every light without a grid).
std::vector<uint32_t> lightsReaching(const BakeInputs& in, const glm::vec3& lo, const glm::vec3& hi) {
  if (in.lightGrid) return in.lightGrid->touching(lo, hi);
  std::vector<uint32_t> all(in.scene.lights.size());
  for (size_t l = 0; l < all.size(); ++l) all[l] = static_cast<uint32_t>(l);
  return all;
}

}  // namespace

LightVisibilityFit fitLightVisibility(const BakeInputs& in, const LightProbeGrid& g, int samplesPerAxis,
                                      uint32_t seed) {
  LightVisibilityFit fit;
  const std::vector<Light>& lights = in.scene.lights;
  const size_t m = fit.lights = lights.size(), n = g.size();
  fit.pointVisibility.assign(n * m, 0.0f);
  if (m == 0) return fit;
  const int S = std::max(0, samplesPerAxis);
  const size_t perProbe = static_cast<size_t>(S) * S * S;
  std::vector<BlendSample> samples(n * perProbe);
  std::vector<float> targets(n * perProbe * m, 0.0f);
  std::atomic<size_t> rays{0};
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    if (!g.valid[i]) return;
    const glm::vec3 corner = g.position(i) - (i < g.offsets.size() ? g.offsets[i] : glm::vec3(0.0f)) - 0.5f * g.spacing;
    // The lights that reach the probe or its cube; the others give it nothing and keep visibility 0.
    const std::vector<uint32_t> reaching = lightsReaching(in, glm::min(corner, g.position(i)),
                                                          glm::max(corner + g.spacing, g.position(i)));
    size_t traced = reaching.size();
    for (uint32_t l : reaching) fit.pointVisibility[i * m + l] = punctualVisibility(in, lights[l], g.position(i));
    Rng rng(hashSeed(seed, kFitStream, i));
    for (size_t s = 0; s < perProbe; ++s) {
      const glm::vec3 cell(static_cast<float>(s % S), static_cast<float>(s / S % S), static_cast<float>(s / (S * S)));
      const glm::vec3 jitter(rng.uniform(), rng.uniform(), rng.uniform());
      const glm::vec3 x = corner + g.spacing * (cell + jitter) / static_cast<float>(S);
      ++traced;
      if (!probeSees(in, g.position(i), x)) continue;
      for (uint32_t l : reaching) targets[(i * perProbe + s) * m + l] = punctualVisibility(in, lights[l], x);
      traced += reaching.size();
      samples[i * perProbe + s] = blendSampleAt(g, x);
    }
    rays += traced;
  });
  fit.rays = rays;
  fit.visibility = fit.pointVisibility;
  if (S == 0) return fit;
  const BlendFitResult solved = solveBlendFit(g, samples, targets, fit.pointVisibility, m, 1.0,
                                              std::make_pair(0.0f, 1.0f), kConverged, kMaxSweeps, fit.visibility);
  fit.samples = solved.samples;
  fit.sweeps = solved.sweeps;
  return fit;
}

}  // namespace irbake
