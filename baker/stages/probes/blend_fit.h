// Least squares on the clients' trilinear blend, shared by the punctual lights' visibility fit
// (light_visibility_fit.h) and the probes' volume fit (ProbeOptions::volumeFitSamples): per-probe values x_i
// (m per probe) whose blend best matches targets f_s at sample points s, each probe's own value y_i kept as one
// more sample:
//   minimise Σ_s |Σ_i a_si x_i − f_s|² + λ Σ_i |x_i − y_i|²
// a_si the blend's weights at s (valid probes, renormalised: interpolateProbes without visibility), solved by
// (projected) Gauss–Seidel on the normal equations, a 27-point stencil (a sample's probes are one cell's corners).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "evaluators/bake_inputs.h"
#include "lightmap/probe_grid.h"

namespace irbake {

// One sample point's blend: its corners (valid probes), their renormalised weights; 0 corners: not kept.
struct BlendSample {
  std::array<uint32_t, 8> probe{};
  std::array<float, 8> weight{};
  int corners = 0;
};

// The blend's weights at p as interpolateProbes forms them (without visibility); corners 0 when no valid probe.
BlendSample blendSampleAt(const LightProbeGrid& g, const glm::vec3& p);

// Whether the probe at p sees x (no opaque surface between): a probe's samples are the free volume around it
// that it sees, not the space under a floor or behind a wall at the grid's border.
bool probeSees(const BakeInputs& in, const glm::vec3& p, const glm::vec3& x);

struct BlendFitResult {
  int sweeps = 0;
  size_t samples = 0;  // samples with at least one corner
};

// Solves the least squares above. targets: samples.size() × m; anchors: n × m (y_i); anchorWeight λ > 0;
// bounds: each value clamped to [lo, hi] after its update (projected Gauss–Seidel), or none. x (n × m) holds
// the start on entry (invalid probes are left as they are). Stops when a sweep changes no value by more than
// tolerance, or after maxSweeps.
BlendFitResult solveBlendFit(const LightProbeGrid& g, const std::vector<BlendSample>& samples,
                             const std::vector<float>& targets, const std::vector<float>& anchors, size_t m,
                             double anchorWeight, std::optional<std::pair<float, float>> bounds, double tolerance,
                             int maxSweeps, std::vector<float>& x);

}  // namespace irbake
