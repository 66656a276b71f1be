#include "stages/probes/light_visibility_fit.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

#include <tbb/parallel_for.h>

#include "common/maths.h"
#include "sampling/sampling.h"

namespace irbake {
namespace {

constexpr uint64_t kFitStream = 0x9c;  // the fit's sample jitter
constexpr int kStencil = 27;           // a probe and its 26 neighbours
constexpr int kMaxSweeps = 400;
constexpr double kConverged = 1e-5;    // largest change of a sweep

// One volume sample: the blend's probes and weights there (valid probes, renormalised), the lights' visibility.
struct FitSample {
  std::array<uint32_t, 8> probe{};
  std::array<float, 8> weight{};
  int corners = 0;
  size_t firstTarget = 0;  // index into the targets array (lights values)
};

// The blend's weights at p as interpolateProbes forms them (without visibility): 0 corners when no valid probe.
int blendWeights(const LightProbeGrid& g, const glm::vec3& p, std::array<uint32_t, 8>& idx, std::array<float, 8>& w) {
  int n = 0;
  float total = 0.0f;
  forEachBlendCorner(g, p, [&](size_t i, float wc) {
    if (!g.valid[i]) return;
    idx[n] = static_cast<uint32_t>(i), w[n] = wc, total += wc, ++n;
  });
  for (int k = 0; k < n; ++k) w[k] /= total;
  return n;
}

// Whether the probe at p sees x: the fit's samples are the free volume around the probe that it sees, not the
// space under a floor or behind a wall at the grid's border (dark to every light, they would drag it down).
bool probeSees(const BakeInputs& in, const glm::vec3& p, const glm::vec3& x) {
  const glm::vec3 d = x - p;
  const float r = std::sqrt(glm::dot(d, d));
  return !(r > 0.0f) || !in.rayTracer.occluded(p, d / r, 0.0f, r);
}

// The normal equations' 27-point stencil slot of neighbour j of probe i (both within one step on every axis).
int stencilSlot(const LightProbeGrid& g, size_t i, size_t j) {
  const auto ijk = [&](size_t v) {
    return glm::ivec3(static_cast<int>(v % g.counts.x), static_cast<int>(v / g.counts.x % g.counts.y),
                      static_cast<int>(v / (static_cast<size_t>(g.counts.x) * g.counts.y)));
  };
  const glm::ivec3 d = ijk(j) - ijk(i) + 1;
  return d.x + 3 * (d.y + 3 * d.z);
}

// Projected Gauss–Seidel on N v = b with v ∈ [0, 1], one right-hand side per light; returns the sweeps run.
int solveBounded(const LightProbeGrid& g, const std::vector<double>& N, const std::vector<double>& b, size_t lights,
                 std::vector<float>& v) {
  const size_t n = g.size();
  int sweep = 0;
  for (; sweep < kMaxSweeps; ++sweep) {
    double change = 0.0;
    for (size_t i = 0; i < n; ++i) {
      const double diag = N[i * kStencil + 13];
      if (!g.valid[i] || !(diag > 0.0)) continue;
      const glm::ivec3 c(static_cast<int>(i % g.counts.x), static_cast<int>(i / g.counts.x % g.counts.y),
                         static_cast<int>(i / (static_cast<size_t>(g.counts.x) * g.counts.y)));
      for (size_t l = 0; l < lights; ++l) {
        double r = b[i * lights + l];
        for (int s = 0; s < kStencil; ++s) {
          const double a = N[i * kStencil + s];
          if (s == 13 || a == 0.0) continue;
          const glm::ivec3 q = c + glm::ivec3(s % 3, s / 3 % 3, s / 9) - 1;
          r -= a * v[g.index(q.x, q.y, q.z) * lights + l];
        }
        const float next = static_cast<float>(std::clamp(r / diag, 0.0, 1.0));
        change = std::max(change, std::abs(double(next) - v[i * lights + l]));
        v[i * lights + l] = next;
      }
    }
    if (change < kConverged) return sweep + 1;
  }
  return sweep;
}

}  // namespace

float punctualVisibility(const BakeInputs& in, const Light& light, const glm::vec3& x, glm::vec3* colour) {
  if (colour) *colour = glm::vec3(1.0f);
  const bool directional = light.type == LightType::Directional;
  const glm::vec3 toward = directional ? -light.direction : light.position - x;
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

LightVisibilityFit fitLightVisibility(const BakeInputs& in, const LightProbeGrid& g, int samplesPerAxis,
                                      uint32_t seed) {
  LightVisibilityFit fit;
  const std::vector<Light>& lights = in.scene.lights;
  const size_t m = fit.lights = lights.size(), n = g.size();
  fit.pointVisibility.assign(n * m, 0.0f);
  if (m == 0) return fit;
  const int S = std::max(0, samplesPerAxis);
  const size_t perProbe = static_cast<size_t>(S) * S * S;
  std::vector<FitSample> samples(n * perProbe);
  std::vector<float> targets(n * perProbe * m, 0.0f);
  std::atomic<size_t> rays{0};
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    if (!g.valid[i]) return;
    size_t traced = m;
    for (size_t l = 0; l < m; ++l) fit.pointVisibility[i * m + l] = punctualVisibility(in, lights[l], g.position(i));
    Rng rng(hashSeed(seed, kFitStream, i));
    const glm::vec3 corner = g.position(i) - (i < g.offsets.size() ? g.offsets[i] : glm::vec3(0.0f)) - 0.5f * g.spacing;
    for (size_t s = 0; s < perProbe; ++s) {
      FitSample& out = samples[i * perProbe + s];
      const glm::vec3 cell(static_cast<float>(s % S), static_cast<float>(s / S % S), static_cast<float>(s / (S * S)));
      const glm::vec3 jitter(rng.uniform(), rng.uniform(), rng.uniform());
      const glm::vec3 x = corner + g.spacing * (cell + jitter) / static_cast<float>(S);
      ++traced;
      if (!probeSees(in, g.position(i), x)) continue;
      out.firstTarget = (i * perProbe + s) * m;
      for (size_t l = 0; l < m; ++l) targets[out.firstTarget + l] = punctualVisibility(in, lights[l], x);
      traced += m;
      out.corners = blendWeights(g, x, out.probe, out.weight);
    }
    rays += traced;
  });
  fit.rays = rays;
  fit.visibility = fit.pointVisibility;
  if (S == 0) return fit;
  // Normal equations: each probe's own point (weight 1 on itself) and every kept sample.
  std::vector<double> N(n * kStencil, 0.0), b(n * m, 0.0);
  for (size_t i = 0; i < n; ++i) {
    if (!g.valid[i]) continue;
    N[i * kStencil + 13] += 1.0;
    for (size_t l = 0; l < m; ++l) b[i * m + l] += fit.pointVisibility[i * m + l];
  }
  for (const FitSample& s : samples) {
    if (s.corners == 0) continue;
    ++fit.samples;
    for (int a = 0; a < s.corners; ++a) {
      for (int c = 0; c < s.corners; ++c)
        N[s.probe[a] * kStencil + stencilSlot(g, s.probe[a], s.probe[c])] += double(s.weight[a]) * s.weight[c];
      for (size_t l = 0; l < m; ++l) b[s.probe[a] * m + l] += double(s.weight[a]) * targets[s.firstTarget + l];
    }
  }
  fit.sweeps = solveBounded(g, N, b, m, fit.visibility);
  return fit;
}

}  // namespace irbake
