// A probe-lit object's light as a linear field over its extent: the probes blended at its centre c plus their
// gradient, so that a surface point p takes c_k + (p − c)·∇c_k instead of the centre's SH alone. One blend for
// the whole object misses how a near light changes across it: a ceiling light above a small sphere meets the
// sphere's surface at other angles than its centre, which shows most near the light's terminator
// (docs/validation.md, "Probes against Cycles"). The gradient along each axis is the secant of the blends at c ± r (r the object's bounding radius): exact for light that is linear across the object, and the grid's
// own trilinear variation otherwise.
#pragma once
#include <algorithm>
#include <array>
#include <functional>

#include "lightmap/probe_emitter_field.h"
#include "lightmap/probe_grid.h"

namespace irbake {

struct ProbeField {
  ShCoefficients centre{};                   // the blend at the centre (interpolateProbes)
  std::array<ShCoefficients, 3> gradient{};  // ∂c/∂x, ∂c/∂y, ∂c/∂z, per metre
  int probes = 0;                            // the centre blend's probes and weight (0: no valid probe near)
  float weight = 0.0f;
  float sunVisibility = 0.0f;                // the sun level's visibility at the centre (ProbeBlend) and its
  glm::vec3 sunGradient{0.0f};               // gradient, the same secants: c carries v·sh of the sun
  EmitterVisibilityField emitters;           // the exact emitters' visibility, the same blends (no emitters: empty)

  // The SH at centre + offset.
  ShCoefficients at(const glm::vec3& offset) const {
    ShCoefficients c = centre;
    for (int k = 0; k < kShCoefficients; ++k)
      c[k] += offset.x * gradient[0][k] + offset.y * gradient[1][k] + offset.z * gradient[2][k];
    return c;
  }
  // The sun's visibility at centre + offset, clamped to [0, 1].
  float sunAt(const glm::vec3& offset) const { return std::clamp(sunVisibility + glm::dot(offset, sunGradient), 0.0f, 1.0f); }
};

// The field of an object of bounding radius `radius` around `centre`; `visible` as interpolateProbes. An axis
// whose blend at either end finds no probe keeps a zero gradient.
inline ProbeField probeFieldOver(const LightProbeGrid& g, const glm::vec3& centre, float radius,
                                 const std::function<bool(const glm::vec3&, const glm::vec3&)>& visible = {}) {
  ProbeField out;
  const ProbeBlend c = interpolateProbes(g, centre, visible);
  out.centre = c.coefficients;
  out.probes = c.probes;
  out.weight = c.weight;
  out.sunVisibility = c.sunVisibility;
  out.emitters.centre = blendEmitterVisibility(g, c);
  for (auto& gr : out.emitters.gradient) gr.assign(g.emitters.size(), 0.0f);
  if (c.probes == 0 || !(radius > 0.0f)) return out;
  for (int a = 0; a < 3; ++a) {
    glm::vec3 step(0.0f);
    step[a] = radius;
    const ProbeBlend hi = interpolateProbes(g, centre + step, visible), lo = interpolateProbes(g, centre - step, visible);
    if (hi.probes == 0 || lo.probes == 0) continue;
    for (int k = 0; k < kShCoefficients; ++k)
      out.gradient[a][k] = (hi.coefficients[k] - lo.coefficients[k]) / (2.0f * radius);
    out.sunGradient[a] = (hi.sunVisibility - lo.sunVisibility) / (2.0f * radius);
    const std::vector<float> vh = blendEmitterVisibility(g, hi), vl = blendEmitterVisibility(g, lo);
    for (size_t e = 0; e < g.emitters.size(); ++e) out.emitters.gradient[a][e] = (vh[e] - vl[e]) / (2.0f * radius);
  }
  return out;
}

}  // namespace irbake
