#include "stages/probes/blend_fit.h"

#include <algorithm>
#include <cmath>

namespace irbake {
namespace {

constexpr int kStencil = 27;  // a probe and its 26 neighbours

// The stencil slot of neighbour j of probe i (both within one step on every axis).
int stencilSlot(const LightProbeGrid& g, size_t i, size_t j) {
  const glm::ivec3 d = g.cell(j) - g.cell(i) + 1;
  return d.x + 3 * (d.y + 3 * d.z);
}

}  // namespace

BlendSample blendSampleAt(const LightProbeGrid& g, const glm::vec3& p) {
  BlendSample s;
  float total = 0.0f;
  forEachBlendCorner(g, p, [&](size_t i, float w) {
    if (!g.valid[i]) return;
    s.probe[s.corners] = static_cast<uint32_t>(i), s.weight[s.corners] = w, total += w, ++s.corners;
  });
  for (int k = 0; k < s.corners; ++k) s.weight[k] /= total;
  return s;
}

bool probeSees(const BakeInputs& in, const glm::vec3& p, const glm::vec3& x) {
  const glm::vec3 d = x - p;
  const float r = std::sqrt(glm::dot(d, d));
  return !(r > 0.0f) || !in.rayTracer.occluded(p, d / r, 0.0f, r);
}

BlendFitResult solveBlendFit(const LightProbeGrid& g, const std::vector<BlendSample>& samples,
                             const std::vector<float>& targets, const std::vector<float>& anchors, size_t m,
                             double anchorWeight, std::optional<std::pair<float, float>> bounds, double tolerance,
                             int maxSweeps, std::vector<float>& x) {
  BlendFitResult out;
  const size_t n = g.size();
  std::vector<double> N(n * kStencil, 0.0), b(n * m, 0.0);
  for (size_t i = 0; i < n; ++i) {
    if (!g.valid[i]) continue;
    N[i * kStencil + 13] += anchorWeight;
    for (size_t l = 0; l < m; ++l) b[i * m + l] += anchorWeight * anchors[i * m + l];
  }
  for (size_t k = 0; k < samples.size(); ++k) {
    const BlendSample& s = samples[k];
    if (s.corners == 0) continue;
    ++out.samples;
    for (int a = 0; a < s.corners; ++a) {
      for (int c = 0; c < s.corners; ++c)
        N[s.probe[a] * kStencil + stencilSlot(g, s.probe[a], s.probe[c])] += double(s.weight[a]) * s.weight[c];
      for (size_t l = 0; l < m; ++l) b[s.probe[a] * m + l] += double(s.weight[a]) * targets[k * m + l];
    }
  }
  std::vector<double> r(m);
  for (; out.sweeps < maxSweeps;) {
    ++out.sweeps;
    double change = 0.0;
    for (size_t i = 0; i < n; ++i) {
      const double diag = N[i * kStencil + 13];
      if (!g.valid[i] || !(diag > 0.0)) continue;
      const glm::ivec3 c = g.cell(i);
      for (size_t l = 0; l < m; ++l) r[l] = b[i * m + l];
      for (int s = 0; s < kStencil; ++s) {
        const double a = N[i * kStencil + s];
        if (s == 13 || a == 0.0) continue;
        const glm::ivec3 q = c + glm::ivec3(s % 3, s / 3 % 3, s / 9) - 1;
        const float* xq = &x[g.index(q.x, q.y, q.z) * m];
        for (size_t l = 0; l < m; ++l) r[l] -= a * xq[l];
      }
      for (size_t l = 0; l < m; ++l) {
        double next = r[l] / diag;
        if (bounds) next = std::clamp(next, double(bounds->first), double(bounds->second));
        change = std::max(change, std::abs(next - x[i * m + l]));
        x[i * m + l] = static_cast<float>(next);
      }
    }
    if (change < tolerance) break;
  }
  return out;
}

}  // namespace irbake
