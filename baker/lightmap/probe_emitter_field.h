// The exact emitters' light at a probe-lit surface point (lightmap/probe_emitters.h): Σ_e v_e(p) · radiance_e ·
// Σ_triangles E/L(p, n), E/L by Lambert's polygon formula (lightmap/polygon_irradiance.h), v_e the probes'
// visibility of the emitter blended as the coefficients are (interpolateProbes' own probes and weights) and, over
// an object, its centre value plus its secant gradient, like probeFieldOver's coefficients.
#pragma once
#include <algorithm>
#include <array>
#include <vector>

#include "lightmap/polygon_irradiance.h"
#include "lightmap/probe_grid.h"

namespace irbake {

// Each emitter's visibility at p from a blend that interpolateProbes returned there (0 where it found no probe).
inline std::vector<float> blendEmitterVisibility(const LightProbeGrid& g, const ProbeBlend& blend) {
  std::vector<float> v(g.emitters.size(), 0.0f);
  for (size_t e = 0; e < g.emitters.size(); ++e)
    for (int c = 0; c < blend.probes; ++c)
      if (blend.corners[c].first < g.emitters[e].visibility.size())
        v[e] += blend.corners[c].second * g.emitters[e].visibility[blend.corners[c].first];
  return v;
}

// E/π at point p with unit normal n from the emitters at visibilities v (one per emitter).
inline glm::vec3 exactEmitterLight(const std::vector<ProbeEmitter>& emitters, const std::vector<float>& v,
                                   const glm::vec3& p, const glm::vec3& n) {
  glm::vec3 out(0.0f);
  for (size_t e = 0; e < emitters.size() && e < v.size(); ++e) {
    const std::vector<glm::vec3>& x = emitters[e].positions;
    float f = 0.0f;
    for (size_t t = 0; t + 2 < x.size(); t += 3) f += triangleIrradianceFactor(x[t], x[t + 1], x[t + 2], p, n);
    out += std::clamp(v[e], 0.0f, 1.0f) * f * emitters[e].radiance;
  }
  return out;
}

// The mean of exactEmitterLight over every normal n: radiance · Ω/4 per emitter.
inline glm::vec3 exactEmitterMean(const std::vector<ProbeEmitter>& emitters, const std::vector<float>& v,
                                  const glm::vec3& p) {
  glm::vec3 out(0.0f);
  for (size_t e = 0; e < emitters.size() && e < v.size(); ++e) {
    const std::vector<glm::vec3>& x = emitters[e].positions;
    float omega = 0.0f;
    for (size_t t = 0; t + 2 < x.size(); t += 3) omega += triangleSolidAngle(x[t], x[t + 1], x[t + 2], p);
    out += std::clamp(v[e], 0.0f, 1.0f) * 0.25f * omega * emitters[e].radiance;
  }
  return out;
}

// The emitters' visibility over an object: at its centre and per metre along x, y, z (probeFieldOver: the secant
// of the blends at centre ± r, zero along an axis whose blend at either end finds no probe).
struct EmitterVisibilityField {
  std::vector<float> centre;
  std::array<std::vector<float>, 3> gradient;
  std::vector<float> at(const glm::vec3& offset) const {
    std::vector<float> v = centre;
    for (size_t e = 0; e < v.size(); ++e)
      v[e] += offset.x * gradient[0][e] + offset.y * gradient[1][e] + offset.z * gradient[2][e];
    return v;
  }
};

}  // namespace irbake
